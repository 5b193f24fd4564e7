//! # verti-env
//!
//! Step-wise navigation environments over the benchmark's trials, in plain Rust (the Python
//! package's gymnasium environments bind this crate; a Rust trainer uses it directly):
//!
//! * [`EnvCore`]: one vehicle on one task at a time: `reset`, `step(action)` for one control
//!   period through [`verti_bench::Trial`], `observe` into an [`ObsBuf`], `render`.
//! * [`VecCore`]: many environments stepped in parallel with next-step autoreset.
//! * [`EnvConfig`], [`TaskFilter`], [`task_pool`]: settings and which tasks are sampled.
//! * [`RewardConfig`]: the default reward (the reference RL reward with its bug fixed).
//! * [`EnvError`]: every failure, typed.
//!
//! The state vector is a selection of the benchmark's feature schema
//! ([`verti_bench::features`]), so a policy trained here sees the very inputs it can be given
//! under `verti eval`.

mod config;
mod core;
mod error;
mod reward;
mod vector;

pub use config::{ActionMode, EnvConfig, TaskFilter, task_pool};
pub use core::{EnvCore, Episode, ObsBuf, StepReport, encode_observation, outcome_code, to_body};
pub use error::EnvError;
pub use reward::{RewardConfig, RewardTerms, StepProgress};
pub use vector::VecCore;
