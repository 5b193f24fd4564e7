//! # verti-sim
//!
//! verti's purpose-built vehicle engine: wheeled and tracked multibody vehicles on rigid,
//! rocky and deformable terrain, fast enough for planners that roll it forward thousands of
//! times per decision.
//!
//! * [`VehicleSpec`]: the immutable vehicle description, read from YAML ([`vehicles`] ships
//!   the built-in ones).
//! * [`Sim`]: the immutable model of one vehicle on one [`verti_world::World`];
//!   [`SimState`]: the mutable, cheap-to-clone state; [`Sim::step`] advances it.
//! * [`start_pose`]: seats a vehicle on the terrain at a task start.
//! * [`bench()`] and [`soak()`]: the speed benchmark and the random-input robustness run.
//! * [`testing`]: small programmatic worlds for tests and benchmarks.
//!
//! ```no_run
//! use std::sync::Arc;
//! use verti_sim::{Controls, Sim, start_pose, testing, vehicles};
//! let world = Arc::new(testing::flat_world(1.0, 0.8));
//! let spec = vehicles::builtin("hmmwv").unwrap();
//! let sim = Sim::new(&world, &spec, start_pose(&world, &spec, 0.0, 0.0, 0.0).unwrap()).unwrap();
//! let mut state = sim.initial_state();
//! sim.step(&mut state, Controls::new(0.5, 0.0, 0.1), 0.05).unwrap();
//! println!("{:?} {}", state.euler(), state.forward_speed());
//! ```

pub mod bench;
pub mod error;
pub mod powertrain;
pub mod sim;
pub mod soil;
pub mod spec;
pub mod terrain;
pub mod testing;
pub mod tyre;
pub mod vehicles;

pub use bench::{
    BenchCase, BenchReport, BenchWorlds, SoakEpisode, SoakFailure, SoakReport, bench, soak,
    soak_episode,
};
pub use error::{SimError, SpecError};
pub use sim::{ContactInfo, Controls, Pose, Sim, SimState, WheelState, start_pose};
pub use soil::SoilState;
pub use spec::VehicleSpec;
