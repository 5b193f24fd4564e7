//! # verti-data
//!
//! The datasets of Verti-Bench §III-G, generated with verti's own simulator:
//!
//! * **random** exploration: sinusoidal steering at a constant 2 m/s (the paper's profile) or
//!   VertiAdaptor's sinusoidal steering and speed, from random starts until rollover, stuck,
//!   the map's edge or a length cap ([`generate`](mod@generate));
//! * **failures**: the last 10 s before each rollover or stuck, classified by the paper's rule
//!   ([`classify`]), harvested from random exploration or from a system's evaluation runs;
//! * **expert** demonstrations: the successful trials of a system on a set's tasks.
//!
//! A dataset is a directory with `manifest.yaml` ([`manifest`]) and Parquet step tables, one
//! row per control step ([`table`]). [`reader`] loads and validates one, iterates its trials,
//! and [`sampler`] draws mini-batches of windows of consecutive steps with heading-aligned
//! elevation and semantic patches recomputed from the worlds. [`stats`] summarises one.
//!
//! Every trial goes through `verti_bench::Trial`, the benchmark's one inner loop, so a dataset
//! drives the vehicle exactly as evaluation does.

pub mod classify;
pub mod generate;
pub mod manifest;
pub mod profile;
pub mod reader;
pub mod sampler;
pub mod stats;
pub mod store;
pub mod table;

pub use classify::{FailureKind, TrajectoryPoint, classify_failure};
pub use generate::{GenerateConfig, Generated, Source, generate};
pub use manifest::{DataOutcome, Kind, Manifest};
pub use profile::Profile;
pub use reader::{Dataset, TrialView};
pub use sampler::{Batch, WindowSampler};
pub use store::{WriteInfo, write_dataset, write_trials};

/// Everything that can go wrong with a dataset, each naming the file or flag at fault.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// A bad setting (flag) of generation or loading.
    #[error("{0}")]
    Argument(String),
    #[error("{path}: {message}")]
    File {
        path: std::path::PathBuf,
        message: String,
    },
    #[error("{0}")]
    Run(String),
}

impl DataError {
    pub fn file(path: &std::path::Path, message: impl std::fmt::Display) -> DataError {
        DataError::File {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
}

pub type Result<T> = std::result::Result<T, DataError>;
