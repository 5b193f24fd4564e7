//! VertiAdaptor (Xu et al.): kinodynamics as a linear combination of neural-ODE basis
//! functions whose coefficients are identified online by least squares, in plain Rust.
//! Training is the `train` module behind the `train` feature (burn; `verti learn va`); everything needed to adapt, predict
//! and plan with a trained model is here.
//!
//! * [`terrain`]: the elevation and semantic latents under the vehicle;
//! * [`rk4`]: the integrator of the basis fields;
//! * [`lsq`]: least-squares coefficients (batched normal equations, Cholesky) and recursive
//!   least squares with forgetting;
//! * [`model`]: the model card (VertiAdaptor and its baselines) and its evaluation;
//!   `fields` lays the basis fields out for the planner's rollouts (bit-identical, faster);
//! * [`data`]: trajectories of a dataset with their terrain latents, split by world.

pub mod adapter;
pub mod data;
mod dims;
pub mod eval;
pub mod explore;
mod fields;
pub mod lsq;
pub mod model;
pub mod planner;
pub mod rk4;
pub mod shipped;
pub mod system;
pub mod terrain;
#[cfg(feature = "train")]
pub mod train;

pub use model::{Example, Method, VaCard, VaModel};

/// Errors of model files and training data: verti-nn's, the one error of every model (and
/// verti-kino's `KinoError`).
pub use verti_nn::ModelError as VaError;

pub type Result<T> = std::result::Result<T, VaError>;
