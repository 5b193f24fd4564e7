//! # verti-compare
//!
//! Fidelity of verti against reference runs of another engine, such as the Chrono runs in
//! `../shared/chrono-reference`: the same tasks are re-run in verti and compared.
//!
//! * [`reference`](mod@reference): reading the reference's `outcomes.jsonl` and 10 Hz trajectory files.
//! * [`select`]: which reference tasks to compare (`--tasks`).
//! * [`artifact`]: reference trials that record an artifact of the reference engine (a chassis
//!   falling through the soil), left out and listed rather than taken as a target.
//! * [`run`]: the verti side, set up as the reference describes ([`CompareSetup`]: world with
//!   one rigid surface everywhere, PID with the reference's steering law), run in parallel and
//!   deterministically.
//! * [`driver`]: the reference runs' own driver law, to measure what the PID's differences
//!   from it change.
//! * [`ensemble`]: each task re-run from starts a few centimetres apart, for the agreement one
//!   run can be expected to reach on chaotic tasks.
//! * [`outcome_counts`]: how many trials ended each way.
//! * [`divergence`]: lateral offset from the reference's trajectory and roll error.
//! * [`summary`]: per-task comparison and aggregates; [`markdown`]: the report's tables.
//!
//! Everything takes and returns plain data; drawing is left to `verti-render` and the command
//! line to `verti-cli` (`verti sim compare`).

pub mod artifact;
pub mod divergence;
pub mod driver;
pub mod ensemble;
pub mod error;
pub mod markdown;
pub mod outcome_counts;
pub mod reference;
pub mod run;
pub mod select;
pub mod summary;

pub use error::{CompareError, Result};
pub use reference::{RefOutcome, RefTask, Reference, Sample, read_reference};
pub use run::{CompareSetup, Driver, VertiRun, load_worlds, reference_episode, run_tasks};
pub use select::select_tasks;
pub use summary::{Summary, TaskComparison, compare_task, summarize};
