//! The record of a trial: its [`TrialResult`] (one line of a results file) and its per-step
//! log ([`EpisodeLog`]).
//!
//! Plain data below the [`Trial`](crate::Trial) that fills it in, so that the trial and the
//! episode driver that runs it (`crate::episode`) both import it and the trial never imports
//! the driver; `crate::episode` re-exports
//! every item at its old path.

use crate::features::{Feature, STEP_LOG};
use crate::metrics::{AngleStats, SignalStats};
use crate::rules::{Outcome, Rules};
use serde::{Deserialize, Serialize};

/// One logged inner step: the values of [`STEP_LOG`](crate::features::STEP_LOG), in order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    pub values: [f64; STEP_LOG.len()],
}

impl StepRecord {
    /// The value of `feature`, if the log records it.
    pub fn get(&self, feature: Feature) -> Option<f64> {
        STEP_LOG
            .iter()
            .position(|f| *f == feature)
            .map(|i| self.values[i])
    }

    /// Trial time of the step, s.
    pub fn t(&self) -> f64 {
        self.values[0]
    }
}

/// Everything measured in one trial. Serialised as one JSON line of the results file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialResult {
    /// Global task number (1..=1000 for a 100-world set).
    pub task: u32,
    pub world: u32,
    pub pair: u32,
    pub world_name: String,
    pub level: verti_world::ElevationLevel,
    pub terrain_type: verti_world::TerrainType,
    pub density: verti_world::ObstacleDensity,
    pub system: String,
    pub vehicle: String,
    pub rules: Rules,
    pub outcome: Outcome,
    /// Simulated time at the end of the trial, seconds.
    #[serde(with = "crate::nullable")]
    pub time: f64,
    /// Time to reach the goal (successes only).
    pub traversal_time: Option<f64>,
    /// Roll and pitch in degrees over the trial, raw and absolute.
    pub roll: AngleStats,
    pub pitch: AngleStats,
    pub throttle: SignalStats,
    pub steering: SignalStats,
    /// Planar distance driven, metres.
    #[serde(with = "crate::nullable")]
    pub path_length: f64,
    /// Planar distance from the goal at the end, metres.
    #[serde(with = "crate::nullable")]
    pub final_distance: f64,
    /// |roll| at the end, degrees.
    #[serde(with = "crate::nullable")]
    pub final_roll: f64,
    /// Why an `error` trial failed.
    pub error: Option<String>,
    /// Wall-clock seconds this trial took (the only field that varies between runs).
    #[serde(with = "crate::nullable")]
    pub wall_time: f64,
}

/// Per-step log of a trial (possibly only its last seconds).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EpisodeLog {
    pub steps: Vec<StepRecord>,
}
