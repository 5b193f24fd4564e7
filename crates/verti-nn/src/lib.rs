//! verti's learned models at inference time, without a learning framework.
//!
//! Training happens in `train`, behind the `train` feature (burn); what the benchmark needs to
//! *run* a trained model lives here, in plain Rust, so that world generation, evaluation and the
//! Python package never build burn:
//!
//! * [`Network`]: feed-forward networks (linear, conv, transposed conv, activations) read from
//!   a model card ([`ModelCard`], YAML) and a raw f32 weight file, evaluated with fixed-order
//!   loops that give bit-identical results on every machine;
//! * [`Mlp`]: the allocation-free MLP path for networks called inside planners;
//! * [`swae`]: the `swae-v1` elevation source (terrain from the trained SWAE decoder);
//! * [`patch`]: the local-patch terrain encoder used by learned systems;
//! * [`embed`](mod@embed): how every crate compiles in the trained models that ship in the repository
//!   (each crate's `models/`), checked against their cards ([`embed!`]), with the one error of model files,
//!   [`ModelError`];
//! * [`shipped`]: verti-nn's own shipped models (`swae-v1`, `patch-v1`);
//! * `train` (feature `train`, burn): the network every family trains with (`train::seq`) and the
//!   SWAE and patch-encoder trainings.

pub mod card;
pub mod dense;
pub mod embed;
pub mod error;
pub mod files;
pub mod layer;
pub mod network;
pub mod patch;
pub mod resize;
pub mod shipped;
pub mod swae;
#[cfg(feature = "train")]
pub mod train;

pub use card::{ModelCard, TrainingInfo, WeightsCard, WeightsInfo};
pub use dense::{Mlp, MlpScratch};
pub use embed::Embedded;
pub use error::ModelError;
pub use layer::{LayerSpec, Shape};
pub use network::Network;
pub use patch::PatchEncoder;
pub use swae::{SWAE_SOURCE, SwaeSource};
