//! What loading results gives ([`Loaded`], [`LoadedFile`]) and why it fails ([`ReportError`]).
//!
//! These sit below both `load`, which reads the files, and `runs`, which keeps the runs of the
//! files read apart (and is called by `load`): defined in `load`, they would make the two import
//! each other. `crate::report` re-exports them.

use crate::episode::TrialResult;
use crate::run::identity::RunRecord;
use crate::run::{EvalError, RESULTS_FILE};
use std::path::PathBuf;

/// Why results could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{}: no such file or directory", .0.display())]
    NotFound(PathBuf),
    #[error(
        "{}: no {RESULTS_FILE} in this directory or its immediate subdirectories",
        .0.display()
    )]
    NoResults(PathBuf),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Reading or parsing a results file failed (the message names the file and line).
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// The same trials were given twice (one file twice, or two copies of one run).
    #[error("{0}")]
    Duplicate(String),
}

/// One results file that was read.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedFile {
    pub path: PathBuf,
    pub trials: usize,
    /// `false` when a torn last line (a trial in flight when the run was killed) was dropped.
    pub clean: bool,
    /// The run's `run.json` (beside a `results.jsonl`), when there is one.
    pub run: Option<RunRecord>,
}

/// Results and the files they came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    pub results: Vec<TrialResult>,
    pub files: Vec<LoadedFile>,
}
