//! Errors of a comparison. Each names the file (and line, for a bad record), the field and the
//! problem, so a damaged reference can be fixed by hand.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A record of a reference file that cannot be used; `line` is 1-based.
    #[error("{}:{line}: {problem}", path.display())]
    Line {
        path: PathBuf,
        line: usize,
        problem: String,
    },
    /// A bad option (task filter, folder, vehicle).
    #[error("{0}")]
    Argument(String),
    #[error(transparent)]
    World(#[from] verti_world::WorldError),
}

impl CompareError {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        CompareError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
    pub fn line(path: &Path, line: usize, problem: impl Into<String>) -> Self {
        CompareError::Line {
            path: path.to_path_buf(),
            line,
            problem: problem.into(),
        }
    }
}

pub type Result<T, E = CompareError> = std::result::Result<T, E>;
