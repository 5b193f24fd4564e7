//! # verti-bench
//!
//! The benchmark around the simulator. Evaluating systems on task sets is three separate
//! parts, each only using the ones listed before it:
//!
//! 1. [`run`], the bookkeeping of a run directory: its lock, resuming, what a run is by content
//!    (`run.json`, [`identity`]), the results file, and splitting a run into shards and merging
//!    them back ([`shard`]).
//! 2. [`eval`], the trial loop: the tasks of a selection run in parallel, deterministically,
//!    one result line appended per finished trial (it opens the directory through `run`).
//! 3. [`report`]: finished runs read back (through `run`'s public types) and summarised as the
//!    paper's tables and figures.
//!
//! [`replay`] re-runs one trial of a finished run. Below them:
//!
//! * [`system`]: the [`MobilitySystem`] interface. Systems see an [`Observation`] and return an
//!   [`Action`]; they never touch simulator internals. A [`SystemRegistry`] builds them by
//!   name from typed [`Params`].
//! * [`observation`]: ground-truth observations with lazily computed, heading-aligned map crops.
//!   The oracle's privileged view of the running trial reaches it through one explicit seam
//!   (`privileged`), so observations do not depend on the trial.
//! * [`trial`]: [`Trial`], one vehicle on one task as one value that is stepped, cloned
//!   (branched) and finished; the only place the inner loop (speed controller, physics,
//!   metrics, rules) exists.
//! * [`episode`]: [`run_episode`], a system driving a `Trial`, and (re-exported from the
//!   private `rules` and `result`, which sit below the trial that applies them) the paper's
//!   success and failure rules (or the reference code's, with `Rules::VertiBench`) and the
//!   trial result.
//! * [`features`]: the one schema of named state features (step logs, state vectors).
//! * [`path`]: following the global path (local goal, heading error), for systems and rewards.
//! * [`metrics`]: per-trial metrics and their aggregation into the paper's Table I and Fig. 6.
//! * [`perception`]: seeded perception noise on what systems observe (never on the physics).
//!
//! # A system in a few lines
//!
//! A mobility system maps observations to actions; [`run_episode`] drives it through one task
//! with the paper's rules and returns the record `results.jsonl` stores. This one drives
//! straight at 3 m/s on a flat test world, with a task 80 m long:
//!
//! ```
//! use std::sync::Arc;
//! use verti_bench::episode::Outcome;
//! use verti_bench::{Action, EpisodeConfig, MobilitySystem, Observation, TaskInfo, run_episode};
//! use verti_sim::{testing, vehicles};
//! use verti_world::{GlobalPath, Task};
//!
//! struct Straight;
//! impl MobilitySystem for Straight {
//!     fn name(&self) -> &str { "straight" }
//!     fn control_rate(&self) -> f64 { 10.0 }
//!     fn reset(&mut self, _task: &TaskInfo) {}
//!     fn act(&mut self, _obs: &Observation) -> Action {
//!         Action::HighLevel { speed: 3.0, steering: 0.0 }
//!     }
//! }
//!
//! let mut world = testing::flat_world(1.0, 0.8);
//! world.tasks = vec![Task { pair: 0, start: [-40.0, 0.0], goal: [40.0, 0.0] }];
//! world.paths = vec![GlobalPath { points: vec![[-40.0, 0.0], [40.0, 0.0]] }];
//! let hmmwv = vehicles::builtin("hmmwv").unwrap();
//! let result = run_episode(&Arc::new(world), &hmmwv, 0, &mut Straight, &EpisodeConfig::default(), None);
//! assert_eq!(result.outcome, Outcome::Success);
//! ```
//!
//! The built-in systems are registered by name in `verti-registry`; `verti eval` and Python's
//! `verti.evaluate` run them over whole task sets.

pub mod episode;
pub mod eval;
pub mod features;
pub mod metrics;
mod nullable;
pub mod observation;
pub mod path;
pub mod perception;
mod pose;
mod privileged;
pub mod replay;
pub mod report;
mod result;
mod rules;
pub mod run;
pub mod speed;
pub mod system;
pub mod trial;

// Long-standing paths of run bookkeeping, kept for the crates that use them.
pub use run::identity;

/// Splitting one evaluation over machines ([`Shard`](run::shard::Shard)) and joining the
/// finished shards ([`join`](run::merge::join)): the long-standing path of [`run::shard`] and
/// [`run::merge`] together.
pub mod shard {
    pub use crate::run::merge::{Joined, join};
    pub use crate::run::shard::Shard;
}

pub use episode::{
    EpisodeConfig, Outcome, Rules, StartMode, Termination, TrialResult, run_episode,
    run_episode_watched,
};
pub use features::{Feature, FeatureSource};
pub use observation::{Crop, CropSpec, Observation};
pub use system::{Action, MobilitySystem, SystemFactory, SystemInfo, SystemRegistry, TaskInfo};
pub use trial::{StepOutcome, Trial, pose6, task_info};
pub use verti_core::params::{ParamKind, ParamSpec, ParamValue, Params};
