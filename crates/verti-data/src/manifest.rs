//! `manifest.yaml`: what a dataset is and how it was made.

use crate::profile::Profile;
use crate::{DataError, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The manifest's file name inside a dataset directory.
pub const MANIFEST: &str = "manifest.yaml";
/// The format tag; a reader refuses any other.
pub const FORMAT: &str = "verti-data/1";

/// Which dataset.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Random,
    Failures,
    Expert,
}

impl Kind {
    pub const ALL: [Kind; 3] = [Kind::Random, Kind::Failures, Kind::Expert];
    pub fn name(self) -> &'static str {
        match self {
            Kind::Random => "random",
            Kind::Failures => "failures",
            Kind::Expert => "expert",
        }
    }
    pub fn from_name(s: &str) -> Result<Kind> {
        Kind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                DataError::Argument(format!(
                    "unknown dataset kind `{s}`: use random, failures or expert"
                ))
            })
    }
    /// Default simulated hours: the paper's 10 h of exploration (failures are harvested from
    /// as much), and 4 h of expert driving.
    pub fn default_hours(self) -> f64 {
        match self {
            Kind::Random | Kind::Failures => 10.0,
            Kind::Expert => 4.0,
        }
    }
}

/// How a recorded trial ended (the `outcome` column of its last row).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DataOutcome {
    /// Reached the goal (expert trials).
    Success,
    Rollover,
    Stuck,
    /// Ran into the trial's time limit (the exploration length cap, or a task's 60 s).
    Timeout,
    /// Came within the edge margin of the map (exploration).
    Edge,
    Error,
}

impl DataOutcome {
    pub const ALL: [DataOutcome; 6] = [
        DataOutcome::Success,
        DataOutcome::Rollover,
        DataOutcome::Stuck,
        DataOutcome::Timeout,
        DataOutcome::Edge,
        DataOutcome::Error,
    ];
    pub fn name(self) -> &'static str {
        match self {
            DataOutcome::Success => "success",
            DataOutcome::Rollover => "rollover",
            DataOutcome::Stuck => "stuck",
            DataOutcome::Timeout => "timeout",
            DataOutcome::Edge => "edge",
            DataOutcome::Error => "error",
        }
    }
    pub fn from_name(s: &str) -> Option<DataOutcome> {
        DataOutcome::ALL.into_iter().find(|o| o.name() == s)
    }
    pub fn from_bench(o: verti_bench::Outcome) -> DataOutcome {
        use verti_bench::Outcome as O;
        match o {
            O::Success => DataOutcome::Success,
            O::Rollover => DataOutcome::Rollover,
            O::Stuck => DataOutcome::Stuck,
            O::Timeout => DataOutcome::Timeout,
            O::Error => DataOutcome::Error,
        }
    }
}

/// The worlds a dataset was recorded on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldsInfo {
    /// The set as given on the command line (`verti-100-s1`, a directory, ...).
    pub set: String,
    /// The set's name as resolved.
    pub name: String,
    /// Seed of a generated set (None for imported worlds).
    pub seed: Option<u64>,
    /// Generator or elevation source (`verti-bench-import` for imported worlds).
    pub generator: String,
    pub scale: f64,
    /// World indices (`world` column) that occur in the data, ascending.
    pub indices: Vec<u32>,
}

/// `manifest.yaml`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub format: String,
    pub kind: Kind,
    /// Exploration profile (random data, and failures harvested from it).
    pub profile: Option<Profile>,
    /// What drove: `random` or a system name.
    pub source: String,
    pub worlds: WorldsInfo,
    pub vehicle: String,
    /// Wheels of the vehicle: the per-wheel columns are `wheel0_*` .. `wheel{n-1}_*`.
    pub wheels: usize,
    /// Rows per simulated second.
    pub rate: f64,
    /// Length cap of an exploration trial, simulated seconds.
    pub max_trial_seconds: f64,
    pub seed: u64,
    /// Hours asked for, and hours of driving recorded (sum of trial durations).
    pub hours_requested: f64,
    pub hours: f64,
    /// Hours of driving simulated to produce the data (failures and expert drop trials).
    pub hours_simulated: f64,
    pub trials: usize,
    pub rows: usize,
    /// Trials per outcome.
    pub outcomes: BTreeMap<String, usize>,
    /// True when recorded on evaluation worlds (`--allow-eval-worlds`): trainers should refuse.
    pub eval_worlds: bool,
    /// Parquet files in trial order.
    pub files: Vec<String>,
    /// FNV-1a 64 of each file's bytes (hex), checked on load: Parquet pages carry no checksum,
    /// so without it a flipped byte inside a page would load as silently wrong values.
    #[serde(default)]
    pub checksums: BTreeMap<String, String>,
    pub command: String,
    pub verti_version: String,
}

/// FNV-1a 64 of `bytes` as 16 hex digits.
pub fn checksum(bytes: &[u8]) -> String {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

impl Manifest {
    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join(MANIFEST);
        let text = serde_norway::to_string(self).map_err(|e| DataError::file(&path, e))?;
        std::fs::write(&path, text).map_err(|e| DataError::file(&path, e))
    }

    pub fn read(dir: &Path) -> Result<Manifest> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            DataError::file(&path, format!("{e} (is {} a dataset?)", dir.display()))
        })?;
        let m: Manifest = serde_norway::from_str(&text).map_err(|e| DataError::file(&path, e))?;
        if m.format != FORMAT {
            return Err(DataError::file(
                &path,
                format!("format `{}` is not {FORMAT}", m.format),
            ));
        }
        if !(m.rate.is_finite() && m.rate > 0.0) {
            return Err(DataError::file(
                &path,
                format!(
                    "field rate: {} must be a positive number of rows per second",
                    m.rate
                ),
            ));
        }
        // the reader names 3 columns per wheel: a damaged count must not make it name billions
        let most = verti_sim::spec::MAX_WHEELS;
        if !(1..=most).contains(&m.wheels) {
            return Err(DataError::file(
                &path,
                format!(
                    "field wheels: {} is not the wheel count of a vehicle (1 to {most})",
                    m.wheels
                ),
            ));
        }
        Ok(m)
    }
}
