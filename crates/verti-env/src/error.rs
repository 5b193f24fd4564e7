//! What can go wrong with an environment.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum EnvError {
    /// A setting is out of range or inconsistent.
    #[error("{0}")]
    InvalidConfig(String),
    /// No task passes the filters, or a task number is not in the worlds.
    #[error("{0}")]
    NoTasks(String),
    /// `step`, `observe` or `render` before the first `reset`.
    #[error("call reset() before {0}()")]
    NotReset(&'static str),
    /// `step` after the episode ended.
    #[error("the episode has ended; call reset() before step()")]
    EpisodeEnded,
    /// An action of the wrong size or with non-finite or out-of-range values.
    #[error("{0}")]
    InvalidAction(String),
    /// The vehicle could not be placed at the task's start.
    #[error("cannot start the simulation on {world} pair {pair}: {message}")]
    Start {
        world: String,
        pair: u32,
        message: String,
    },
    /// Drawing the world failed.
    #[error("cannot render: {0}")]
    Render(String),
    /// One environment of a vector environment failed.
    #[error("environment {index}: {source}")]
    InVector { index: usize, source: Box<EnvError> },
}

impl EnvError {
    /// Tags an error with the index of the environment of a vector environment it came from.
    pub fn in_vector(self, index: usize) -> EnvError {
        EnvError::InVector {
            index,
            source: Box::new(self),
        }
    }
}
