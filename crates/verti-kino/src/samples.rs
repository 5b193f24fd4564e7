//! Training and evaluation examples from a verti dataset: trajectories at the model step, and
//! (input, target) pairs built with the same feature code the planners use.

use crate::attentive::{ATTENTIVE_INPUT_DIM, write_row};
use crate::card::KinoKind;
use crate::features::{INPUT_DIM, KinoState, OUTPUT_DIM, Units, heading_delta, write_inputs};
use crate::traversability::{CHANNELS, FIELD, LABEL_HORIZON, labels, write_slopes};
use crate::{KinoError, Result};
use verti_core::Rng;

/// Longest lag between an attentive model's map and its step in training: MPPI's horizon
/// (20 steps), so every step of a rollout is inside what training saw.
pub const MAX_LAG: usize = 20;
use std::path::Path;
use std::sync::Arc;
use verti_bench::observation::Pose6;
use verti_data::Dataset;
use verti_world::{ElevationLevel, World};

/// One trial subsampled at the model step.
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// Index into [`KinoData::worlds`].
    pub world: usize,
    pub level: ElevationLevel,
    pub poses: Vec<Pose6>,
    /// Command (target speed m/s, steering) held from each pose to the next.
    pub commands: Vec<(f64, f64)>,
}

/// A dataset's trajectories with their worlds.
pub struct KinoData {
    pub worlds: Vec<Arc<World>>,
    pub trajectories: Vec<Trajectory>,
    pub units: Units,
    /// Model step, full-scale seconds, and in the data's world seconds.
    pub dt: f64,
    pub dt_world: f64,
    pub vehicle: String,
    /// The world set as recorded (for model cards).
    pub set: String,
    /// True when the data were driven on evaluation worlds (`--allow-eval-worlds`).
    pub eval_worlds: bool,
    pub hours: f64,
}

/// Input and target rows (row-major) and the level of each.
#[derive(Clone, Debug, Default)]
pub struct Examples {
    /// Values per input row.
    pub dim: usize,
    pub inputs: Vec<f32>,
    pub targets: Vec<f32>,
    pub levels: Vec<ElevationLevel>,
}

impl Examples {
    pub fn len(&self) -> usize {
        self.levels.len()
    }
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }
}

impl KinoData {
    /// Loads `dir` and cuts every trial into trajectories with `dt` (full-scale seconds)
    /// between poses: with rows every 0.1 s and dt = 0.2 s, each trial gives two interleaved
    /// trajectories, so every row is used.
    pub fn load(dir: &Path, dt: f64) -> Result<KinoData> {
        let data = Dataset::load(dir).map_err(|e| KinoError::Data(e.to_string()))?;
        let m = &data.manifest;
        let units = Units::new(m.worlds.scale);
        let dt_world = dt / units.time_factor();
        let stride_f = dt_world * m.rate;
        let stride = stride_f.round() as usize;
        if stride == 0 || (stride_f - stride as f64).abs() > 1e-6 {
            return Err(KinoError::Data(format!(
                "{}: rows every {:.4} s do not divide the model step {dt_world:.4} s",
                dir.display(),
                1.0 / m.rate
            )));
        }
        let worlds = data
            .load_worlds()
            .map_err(|e| KinoError::Data(format!("{}: {e}", dir.display())))?;
        let mut trajectories = Vec::new();
        for trial in data.trials() {
            let world = worlds
                .iter()
                .position(|w| w.meta.index == trial.world)
                .ok_or_else(|| {
                    KinoError::Data(format!(
                        "{}: world {} not loaded",
                        dir.display(),
                        trial.world
                    ))
                })?;
            let col = |name: &str| {
                trial.f64(name).ok_or_else(|| {
                    KinoError::Data(format!("{}: column {name} is missing", dir.display()))
                })
            };
            let (x, y, z) = (col("x")?, col("y")?, col("z")?);
            let (roll, pitch, yaw) = (col("roll")?, col("pitch")?, col("yaw")?);
            let (speed, steer) = (col("cmd_speed")?, col("cmd_steering")?);
            for offset in 0..stride.min(trial.len()) {
                let rows: Vec<usize> = (offset..trial.len()).step_by(stride).collect();
                if rows.len() < 3 {
                    continue;
                }
                trajectories.push(Trajectory {
                    world,
                    level: worlds[world].meta.level,
                    poses: rows
                        .iter()
                        .map(|&r| Pose6 {
                            x: x[r],
                            y: y[r],
                            z: z[r],
                            roll: roll[r],
                            pitch: pitch[r],
                            yaw: yaw[r],
                        })
                        .collect(),
                    commands: rows.iter().map(|&r| (speed[r], steer[r])).collect(),
                });
            }
        }
        if trajectories.is_empty() {
            return Err(KinoError::Data(format!(
                "{}: no trial is long enough for one model step",
                dir.display()
            )));
        }
        Ok(KinoData {
            worlds,
            trajectories,
            units,
            dt,
            dt_world,
            vehicle: m.vehicle.clone(),
            set: m.worlds.set.clone(),
            eval_worlds: m.eval_worlds,
            hours: m.hours,
        })
    }

    /// One-step examples: for every pose with a predecessor and a successor, the model input
    /// and the full-scale heading-frame change to the next pose.
    pub fn examples(&self) -> Examples {
        let mut ex = Examples {
            dim: INPUT_DIM,
            ..Default::default()
        };
        let mut input = [0.0f32; INPUT_DIM];
        for tr in &self.trajectories {
            let terrain = &self.worlds[tr.world].terrain;
            for t in 1..tr.poses.len() - 1 {
                let state = KinoState {
                    pose: tr.poses[t],
                    last_delta: heading_delta(&tr.poses[t - 1], &tr.poses[t]),
                };
                write_inputs(
                    &state,
                    tr.commands[t],
                    terrain,
                    self.units,
                    self.dt,
                    &mut input,
                );
                let d = self
                    .units
                    .delta_to_model(&heading_delta(&tr.poses[t], &tr.poses[t + 1]));
                ex.inputs.extend_from_slice(&input);
                ex.targets.extend(d.iter().map(|&v| v as f32));
                ex.levels.push(tr.level);
            }
        }
        debug_assert_eq!(ex.targets.len(), ex.len() * OUTPUT_DIM);
        ex
    }

    /// The examples a model of `kind` trains on (`seed` draws the attentive model's lags).
    pub fn examples_for(&self, kind: KinoKind, seed: u64) -> Examples {
        match kind {
            KinoKind::Ensemble | KinoKind::Decomposed => self.examples(),
            KinoKind::Attentive => self.attentive_examples(MAX_LAG, seed),
        }
    }

    /// One-step examples for an attentive model: each pose's map is the one seen from a pose
    /// up to `max_lag` − 1 steps earlier on the same trajectory (drawn uniformly), as a
    /// rollout step sees the map encoded at the start of its plan.
    pub fn attentive_examples(&self, max_lag: usize, seed: u64) -> Examples {
        let mut ex = Examples {
            dim: ATTENTIVE_INPUT_DIM,
            ..Default::default()
        };
        let mut input = [0.0f32; ATTENTIVE_INPUT_DIM];
        for (i, tr) in self.trajectories.iter().enumerate() {
            let terrain = &self.worlds[tr.world].terrain;
            let mut rng = Rng::derive(seed, "attentive-lag", i as u64);
            for t in 1..tr.poses.len() - 1 {
                let lag = rng.below(max_lag.max(1).min(t + 1) as u64) as usize;
                let state = KinoState {
                    pose: tr.poses[t],
                    last_delta: heading_delta(&tr.poses[t - 1], &tr.poses[t]),
                };
                write_row(
                    &tr.poses[t - lag],
                    &state,
                    tr.commands[t],
                    terrain,
                    self.units,
                    self.dt,
                    &mut input,
                );
                let d = self
                    .units
                    .delta_to_model(&heading_delta(&tr.poses[t], &tr.poses[t + 1]));
                ex.inputs.extend_from_slice(&input);
                ex.targets.extend(d.iter().map(|&v| v as f32));
                ex.levels.push(tr.level);
            }
        }
        ex
    }

    /// Traversability examples: the slope patch under every other pose (heading-aligned,
    /// centred on the vehicle) and its labels over the next [`LABEL_HORIZON`]
    /// (`crate::traversability::labels`); `dim` = the patch size, targets `traversability::OUTPUTS` wide.
    pub fn traversability_examples(&self) -> Examples {
        let patch = CHANNELS * FIELD * FIELD;
        let mut ex = Examples {
            dim: patch,
            ..Default::default()
        };
        let steps = (LABEL_HORIZON / self.dt).round().max(1.0) as usize;
        let mut input = vec![0.0f32; patch];
        for tr in &self.trajectories {
            let terrain = &self.worlds[tr.world].terrain;
            for t in (0..tr.poses.len()).step_by(2) {
                let Some(y) = labels(&tr.poses, &tr.commands, t, steps, self.dt_world, self.units)
                else {
                    continue;
                };
                write_slopes(&tr.poses[t], (0.0, 0.0), 1, terrain, self.units, &mut input);
                ex.inputs.extend_from_slice(&input);
                ex.targets.extend_from_slice(&y);
                ex.levels.push(tr.level);
            }
        }
        ex
    }
}
