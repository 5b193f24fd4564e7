//! # verti-bench
//!
//! The benchmark around the simulator:
//!
//! * [`system`]: the [`MobilitySystem`] interface. Systems see an [`Observation`] and return an
//!   [`Action`]; they never touch simulator internals. A [`SystemRegistry`] builds them by
//!   name from typed [`Params`].
//! * [`observation`]: ground-truth observations with lazily computed, heading-aligned map crops.
//! * [`episode`]: one trial of one system on one task, with the paper's success and failure
//!   rules (or the reference code's, with `Rules::VertiBench`).
//! * [`metrics`]: per-trial metrics and their aggregation into the paper's Table I and Fig. 6.
//! * [`eval`]: parallel, deterministic, resumable evaluation over task ranges.

pub mod episode;
pub mod eval;
pub mod metrics;
pub mod observation;
pub mod report;
pub mod speed;
pub mod system;

pub use episode::{EpisodeConfig, Outcome, Rules, Termination, TrialResult, run_episode};
pub use observation::{Crop, CropSpec, Observation};
pub use system::{Action, MobilitySystem, SystemFactory, SystemInfo, SystemRegistry, TaskInfo};
pub use verti_core::params::{ParamKind, ParamSpec, ParamValue, Params};
