//! PIETRA (Cai et al., RA-L 2025): physics-informed evidential traversability, in plain Rust.
//! Training is the `train` module behind the `train` feature (burn); everything a planner and the
//! benchmark need is here, without it.
//!
//! * [`bins`]: the B = 12 bins of each traversability parameter and one-hot targets;
//! * [`emd`]: EMD², its expectation under a Dirichlet (UEMD², closed form) and Dirichlet entropy;
//! * [`cvar`]: left- and right-tail CVaR of a PMF;
//! * [`prior`]: the physics prior of eqs. 15–18;
//! * [`maps`]: the 30 synthetic rocky 50 m maps (train / validation / test);
//! * [`dataset`]: driving them and extracting footprint features and targets;
//! * [`model`]: a trained model (card + networks) evaluated in plain Rust;
//! * [`cvar_map`]: CVaR maps over cells and 13 headings;
//! * [`planner`]: risk-aware MPPI (CVaR dynamics, time-to-goal cost);
//! * [`system`]: the `pietra` mobility system;
//! * [`shipped`]: the trained `pietra-v1`, compiled in.

mod batch_mlp;
pub mod bins;
pub mod cvar;
pub mod cvar_map;
pub mod dataset;
pub mod emd;
mod lanes;
mod map_rows;
mod map_simd;
mod map_spec;
pub mod maps;
pub mod model;
mod model_lanes;
pub mod planner;
pub mod prior;
pub mod shipped;
pub mod system;
#[cfg(feature = "train")]
pub mod train;
