//! The error of evaluation and of its run records ([`EvalError`], re-exported as
//! `crate::eval::EvalError`, its long-standing path).
//!
//! It sits at the bottom of the run bookkeeping: `identity` reads and checks `run.json` with it,
//! the directory and resume code and the trial loop (`crate::eval`) above report with it.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    #[error("{0}")]
    Argument(String),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: line {line}: {problem}")]
    Corrupt {
        path: PathBuf,
        line: usize,
        problem: String,
    },
    /// The run was cancelled (`EvalSetup::cancel`); the results recorded before it are kept.
    #[error("the evaluation was cancelled")]
    Cancelled,
}

/// An I/O error on `path`, as `map_err` takes it: shared by the bookkeeping and the trial loop
/// (which appends result lines), so every file error names its file the same way.
pub(crate) fn io(path: &Path) -> impl Fn(std::io::Error) -> EvalError + '_ {
    move |source| EvalError::Io {
        path: path.to_path_buf(),
        source,
    }
}
