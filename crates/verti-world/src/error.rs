//! Errors for everything that reads, writes or builds worlds. Every message names the file,
//! the field and the problem, so a user can fix a corrupt or inconsistent world by hand.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file that exists but whose content is wrong.
    #[error("{path}: field `{field}`: {problem}")]
    Invalid {
        path: PathBuf,
        field: String,
        problem: String,
    },
    /// A bad argument (scale, seed range, count...) given by the user.
    #[error("{0}")]
    Argument(String),
}

impl WorldError {
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        WorldError::Io {
            path: path.into(),
            source,
        }
    }
    pub fn invalid(
        path: impl Into<PathBuf>,
        field: impl Into<String>,
        problem: impl Into<String>,
    ) -> Self {
        WorldError::Invalid {
            path: path.into(),
            field: field.into(),
            problem: problem.into(),
        }
    }
}

pub type Result<T, E = WorldError> = std::result::Result<T, E>;
