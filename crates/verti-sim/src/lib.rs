//! # verti-sim
//!
//! verti's purpose-built vehicle engine: wheeled and tracked multibody vehicles on rigid,
//! rocky and deformable terrain, fast enough for planners that roll it forward thousands of
//! times per decision.
//!
//! The public API, at a glance:
//! * [`VehicleSpec`]: the immutable vehicle description, read from YAML ([`vehicles`] ships
//!   the built-in ones; [`spec`] holds the types of its parts).
//! * [`Sim`]: the immutable model of one vehicle on one [`verti_world::World`], built once and
//!   shared by any number of states and starts. [`Sim::state_at`] seats the vehicle at a
//!   [`StartPose`] and gives its [`SimState`] at rest; [`Sim::step`] advances a state under
//!   [`Controls`].
//! * [`SimState`]: the mutable, cheap-to-clone state, with per-wheel [`WheelState`],
//!   a [`ContactInfo`] summary and the [`SoilState`] deformation; [`Pose`] of the chassis.
//! * [`SimError`] and [`SpecError`]: every failure is an error, never a panic.
//! * [`testing`]: small programmatic worlds for tests. The speed benchmark and the soak
//!   (`verti sim bench` / `verti sim soak`) live in the CLI, apart from the engine.
//!
//! ```no_run
//! use std::sync::Arc;
//! use verti_sim::{Controls, Sim, StartPose, testing, vehicles};
//! let world = Arc::new(testing::flat_world(1.0, 0.8));
//! let spec = vehicles::builtin("hmmwv").unwrap();
//! let sim = Sim::new(&world, &spec).unwrap();
//! let mut state = sim.state_at(StartPose::new(0.0, 0.0, 0.0)).unwrap();
//! sim.step(&mut state, Controls::new(0.5, 0.0, 0.1), 0.05).unwrap();
//! println!("{:?} {}", state.euler(), state.forward_speed());
//! ```
//!
//! # Inside
//! One internal step runs stages over plain data (see `step.rs`, which reads as their list):
//! `model` compiles the spec; `start` seats a vehicle; `drivetrain` steers, drives and solves
//! the spins; `contact` (`wheel`, `soil`, `body`, and `rigid` for rigid tyres) finds normal
//! forces; `friction` computes every tangential force; `suspension` and `integrate` advance the
//! state; `step_rigid` is the wheel and spin stage of rigid tyres. `terrain`, `soil` and
//! `tyre` hold the lookup structures, the soil storage and the tyre curves they use.

mod contact;
mod drivetrain;
mod error;
mod friction;
mod integrate;
pub mod linkage;
mod math;
mod model;
mod sim;
mod soil;
mod soil_edges;
pub mod spec;
mod start;
mod state;
mod step;
mod step_rigid;
mod suspension;
mod terrain;
pub mod testing;
mod track_runs;
mod tyre;
pub mod vehicles;

pub use drivetrain::skid_speed_ratio;
pub use error::{SimError, SpecError};
pub use sim::Sim;
pub use soil::SoilState;
pub use spec::VehicleSpec;
pub use state::{ContactInfo, Controls, Pose, SimState, StartPose, WheelState};
