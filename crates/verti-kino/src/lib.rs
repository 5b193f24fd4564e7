//! Learned 6-DoF kinodynamic models for verti's sampling planners (paper §IV-A: WMVCT,
//! MPPI-6, TAL, TNT), without a learning framework: what planning and evaluation need is here, in plain Rust, and
//! the training of every model is in `train`, behind the `train` feature (burn).
//!
//! * [`features`]: what a model sees and predicts, one code path for training and planning;
//! * [`attentive`]: TAL's map encoder, offset gate and dynamics inputs;
//! * [`traversability`]: TNT's learned traversability map and its labels;
//! * [`card`]: the model file (a YAML card plus verti-nn networks);
//! * [`model`]: one model step in world units, and the kinematic bicycle baseline;
//! * [`rollout`]: a model inside MPPI ([`rollout::LearnedRollout`]) and the attitude-aware cost;
//! * [`systems`]: the registered planners (`mppi6`, `wmvct`, `tal`, `tnt`);
//! * [`shipped`]: the trained models compiled in;
//! * `train` (feature `train`, burn): training MPPI-6's and WMVCT's networks, TAL and TNT.

pub mod attentive;
pub mod card;
pub mod eval;
pub mod features;
pub mod model;
pub mod rollout;
pub mod samples;
pub mod shipped;
pub mod systems;
#[cfg(feature = "train")]
pub mod train;
pub mod traversability;

pub use card::{KinoCard, KinoFile, KinoKind};
pub use features::{KinoState, Units};
pub use model::{Geometry, KinoModel};

/// Errors of model files and training data: verti-nn's, the one error of every model.
pub use verti_nn::ModelError as KinoError;

pub type Result<T> = std::result::Result<T, KinoError>;
