//! Run bookkeeping: everything about a run directory except running its trials (the loop is
//! `crate::eval`, reports on finished runs are `crate::report`).
//!
//! A run directory `OUT` holds `results.jsonl` (one JSON line per finished trial), `run.json`
//! (what was run, by content), `steps/` when per-step logs are kept, and `.lock` while a run
//! writes to it.
//!
//! * `dir`: opening `OUT` for a run: the lock that keeps a second run out, a fresh start or a
//!   resume (`resume`: the recorded run checked against this one, a torn last line repaired),
//!   `run.json` written, and the tasks left to run.
//! * [`identity`]: what a run is, by content ([`identity::RunRecord`], `run.json`).
//! * `tasks`: task selections as text ([`parse_tasks`], [`format_tasks`]) and against a world
//!   set ([`select_tasks`]).
//! * `results`: the results file's one writer of a line ([`result_line`]) and one reader
//!   ([`read_results`]).
//! * [`shard`] splits a run over machines; [`merge`] joins the finished shards.
//! * `error`: [`EvalError`], at the bottom, since all of the above report with it.
//!
//! The loop's long-standing paths (`crate::eval::RESULTS_FILE`, `crate::eval::read_results`,
//! `crate::identity`, `crate::shard`, ...) re-export these.

mod dir;
mod error;
pub mod identity;
pub mod merge;
mod results;
mod resume;
pub mod shard;
mod tasks;

pub(crate) use dir::open;
pub use error::EvalError;
pub(crate) use error::io;
pub use results::{read_results, result_line};
pub use tasks::{format_tasks, parse_tasks, select_tasks, task_worlds, worlds_to_load};

use crate::episode::EpisodeConfig;
use identity::{InputFile, RunInfo, SplitRecord};
use std::path::Path;
use std::sync::Arc;
use verti_sim::VehicleSpec;
use verti_world::World;

pub const RESULTS_FILE: &str = "results.jsonl";
pub const RUN_FILE: &str = "run.json";
/// Subdirectory of a run's per-step logs (one Parquet file per trial).
pub const STEPS_DIR: &str = "steps";
/// Name of the lock file that keeps two runs out of one results directory.
pub const LOCK_FILE: &str = ".lock";

/// What the bookkeeping reads of a run's settings: `crate::eval::EvalSetup` lends them, so the
/// directory code does not depend on the loop's settings type. Here, below `dir` and `resume`,
/// because both read it.
pub(crate) struct RunSettings<'a> {
    pub worlds: &'a [Arc<World>],
    /// `worlds` are the whole set (else only the worlds of the run's tasks).
    pub whole_set: bool,
    pub vehicle: &'a VehicleSpec,
    /// The episode settings (the start mode and perception noise are recorded).
    pub episode: &'a EpisodeConfig,
    /// The seconds of per-step log kept per trial; `None` when no logs are kept.
    pub step_log: Option<f64>,
    pub out: &'a Path,
    pub resume: bool,
    pub force: bool,
    pub run: &'a RunInfo,
    #[allow(clippy::type_complexity)]
    pub inputs: Option<&'a (dyn Fn(&[(usize, u32)]) -> Result<Vec<InputFile>, EvalError> + Sync)>,
    pub shard: Option<&'a SplitRecord>,
    pub warn: Option<&'a (dyn Fn(&str) + Sync)>,
}
