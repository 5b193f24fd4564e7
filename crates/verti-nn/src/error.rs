//! The one error of every learned model's files: its card, its weights, the parts a composite
//! card lists, and the data a model is fitted or adapted on. verti-kino and verti-va use it as
//! they are (`KinoError`, `VaError`), so a damaged model reads the same wherever it is loaded.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// A card or the weights it names is wrong: the card's path, then what is wrong (the field
    /// first, where there is one).
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The data a model is trained, evaluated or adapted on are wrong (the message names them).
    #[error("{0}")]
    Data(String),
}

impl ModelError {
    /// `path: message`.
    pub fn invalid(path: &Path, message: impl Into<String>) -> ModelError {
        ModelError::Invalid {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// `path: field: why`: field `field` of the card at `path` is wrong.
    pub fn card(path: &Path, field: &str, why: impl std::fmt::Display) -> ModelError {
        ModelError::invalid(path, format!("{field}: {why}"))
    }

    /// `path: <the I/O error>`.
    pub fn io(path: &Path, source: std::io::Error) -> ModelError {
        ModelError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}
