//! The error of evaluation and of its run records ([`EvalError`], re-exported as
//! `crate::eval::EvalError`).
//!
//! It sits below both `eval` and `identity`: `identity` reads and checks `run.json` with it, and
//! `eval` records runs with `identity`, so defining it in `eval` would make the two import each
//! other.

use std::path::PathBuf;

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
