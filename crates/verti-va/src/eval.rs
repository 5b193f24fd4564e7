//! Prediction accuracy of an (adapted) model on held-out trajectories: one-step errors per
//! pose dimension and the error of open-loop rollouts by step (paper Fig. 3, Tables II–III).
//!
//! A rollout starts at a true pose and applies the model's changes step after step, with the
//! true commands and the true terrain under each step (as Algorithm 1's queries). Errors are
//! measured relative to the start, in its heading frame: forward, left, up (m, full scale)
//! and yaw, roll, pitch (rad).

use crate::data::{VaData, VaTrajectory};
use crate::model::{EMBED, POSE_DIM, VaModel};
use rayon::prelude::*;
use verti_core::math::wrap_angle;
use verti_kino::features::Units;
use verti_kino::features::heading_delta;

/// Sums of errors over many predictions.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorSums {
    pub one_step_abs: [f64; POSE_DIM],
    pub one_step_sq: [f64; POSE_DIM],
    pub one_step_count: usize,
    /// Per rollout step (index 0 = after one step): squared error per dimension.
    pub step_sq: Vec<[f64; POSE_DIM]>,
    /// Per rollout step: Euclidean position error and its square; angular error (yaw, roll,
    /// pitch together) and its square.
    pub step_pos: Vec<[f64; 2]>,
    pub step_ang: Vec<[f64; 2]>,
    pub rollouts: usize,
}

impl ErrorSums {
    pub fn new(horizon: usize) -> ErrorSums {
        ErrorSums {
            one_step_abs: [0.0; POSE_DIM],
            one_step_sq: [0.0; POSE_DIM],
            one_step_count: 0,
            step_sq: vec![[0.0; POSE_DIM]; horizon],
            step_pos: vec![[0.0; 2]; horizon],
            step_ang: vec![[0.0; 2]; horizon],
            rollouts: 0,
        }
    }

    pub fn merge(&mut self, o: &ErrorSums) {
        for d in 0..POSE_DIM {
            self.one_step_abs[d] += o.one_step_abs[d];
            self.one_step_sq[d] += o.one_step_sq[d];
        }
        self.one_step_count += o.one_step_count;
        for t in 0..self.step_sq.len() {
            for d in 0..POSE_DIM {
                self.step_sq[t][d] += o.step_sq[t][d];
            }
            for j in 0..2 {
                self.step_pos[t][j] += o.step_pos[t][j];
                self.step_ang[t][j] += o.step_ang[t][j];
            }
        }
        self.rollouts += o.rollouts;
    }

    /// Mean squared error over the first `steps` rollout steps and all six dimensions (the
    /// training loss's measure; Tables II–III).
    pub fn rollout_mse(&self, steps: usize) -> f64 {
        let steps = steps.min(self.step_sq.len());
        let total: f64 = self.step_sq[..steps].iter().flatten().sum();
        total / (steps * POSE_DIM * self.rollouts.max(1)) as f64
    }

    /// Mean absolute one-step error per dimension.
    pub fn one_step_mae(&self) -> [f64; POSE_DIM] {
        self.one_step_abs
            .map(|s| s / self.one_step_count.max(1) as f64)
    }

    /// Mean and standard deviation of the position (`angular` false) or angular error after
    /// each rollout step.
    pub fn by_step(&self, angular: bool) -> Vec<(f64, f64)> {
        let n = self.rollouts.max(1) as f64;
        let rows = if angular {
            &self.step_ang
        } else {
            &self.step_pos
        };
        rows.iter()
            .map(|[s, s2]| {
                let mean = s / n;
                (mean, (s2 / n - mean * mean).max(0.0).sqrt())
            })
            .collect()
    }
}

/// Adds the one-step error of predicting step `t` of `traj` with `predict`.
fn score_step(
    sums: &mut ErrorSums,
    traj: &VaTrajectory,
    units: Units,
    t: usize,
    predict: &dyn Fn(usize, f64, f64) -> [f64; POSE_DIM],
) {
    let p = &traj.poses[t];
    let d = predict(t, p.roll, p.pitch);
    let truth = traj.delta(t, units);
    for k in 0..POSE_DIM {
        let e = d[k] - truth[k];
        sums.one_step_abs[k] += e.abs();
        sums.one_step_sq[k] += e * e;
    }
    sums.one_step_count += 1;
}

/// Adds the errors of an open-loop rollout of `traj` from pose `start` (`predict` gives the
/// change at step t from roll and pitch), relative to the start in its heading frame.
fn score_rollout(
    sums: &mut ErrorSums,
    traj: &VaTrajectory,
    units: Units,
    start: usize,
    predict: &dyn Fn(usize, f64, f64) -> [f64; POSE_DIM],
) {
    let p0 = &traj.poses[start];
    // relative pose: forward, left, up, yaw, roll and pitch changes
    let mut s = [0.0; POSE_DIM];
    for t in 0..sums.step_sq.len() {
        let d = predict(start + t, p0.roll + s[4], p0.pitch + s[5]);
        let (sn, cs) = s[3].sin_cos();
        s[0] += cs * d[0] - sn * d[1];
        s[1] += sn * d[0] + cs * d[1];
        s[2] += d[2];
        s[3] = wrap_angle(s[3] + d[3]);
        s[4] += d[4];
        s[5] += d[5];
        let truth = units.delta_to_model(&heading_delta(p0, &traj.poses[start + t + 1]));
        let mut e = [0.0; POSE_DIM];
        for k in 0..POSE_DIM {
            e[k] = if k == 3 {
                wrap_angle(s[k] - truth[k])
            } else {
                s[k] - truth[k]
            };
            sums.step_sq[t][k] += e[k] * e[k];
        }
        let pos = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
        let ang = (e[3] * e[3] + e[4] * e[4] + e[5] * e[5]).sqrt();
        sums.step_pos[t][0] += pos;
        sums.step_pos[t][1] += pos * pos;
        sums.step_ang[t][0] += ang;
        sums.step_ang[t][1] += ang * ang;
    }
    sums.rollouts += 1;
}

/// Errors of `model` with coefficients `alpha` on `trajectories` of `data`: every one-step
/// prediction, and rollouts of `horizon` steps starting every `stride` steps.
pub fn errors(
    model: &VaModel,
    alpha: &[f64],
    data: &VaData,
    trajectories: &[usize],
    horizon: usize,
    stride: usize,
) -> ErrorSums {
    let parts: Vec<ErrorSums> = trajectories
        .par_iter()
        .map(|&i| {
            let traj = &data.trajectories[i];
            let n = traj.len();
            let embeddings: Vec<[f32; 2 * EMBED]> =
                (0..n).map(|t| model.embed(traj.terrain_at(t))).collect();
            let mut sums = ErrorSums::new(horizon);
            let predict = |t: usize, roll: f64, pitch: f64| {
                model.predict(alpha, roll, pitch, &embeddings[t], traj.commands[t])
            };
            for t in 0..n - 1 {
                score_step(&mut sums, traj, data.units, t, &predict);
            }
            let mut start = 0;
            while start + horizon < n {
                score_rollout(&mut sums, traj, data.units, start, &predict);
                start += stride;
            }
            sums
        })
        .collect();
    let mut total = ErrorSums::new(horizon);
    for p in &parts {
        total.merge(p);
    }
    total
}

/// Errors of `model` adapting online while it drives `trajectories` (one world's, in order):
/// before each step the model predicts with its current coefficients (one step, and a
/// rollout every `stride` steps), then the [`Adapter`](crate::adapter::Adapter) takes in the step, as the `va` system
/// does. The adapter carries over from one trajectory to the next (the same world), but no
/// example spans two. `mode` `once`/`none` keep the coefficients they start with, `alpha0`.
pub fn online_errors(
    model: &std::sync::Arc<VaModel>,
    mode: crate::adapter::AdaptMode,
    alpha0: &[f64],
    data: &VaData,
    trajectories: &[usize],
    horizon: usize,
    stride: usize,
) -> ErrorSums {
    use crate::adapter::Adapter;
    let mut adapter = Adapter::new(model.clone(), mode);
    adapter.reset(data.units.scale);
    adapter.set_alpha(alpha0.to_vec());
    let dt_world = adapter.dt_world();
    let mut sums = ErrorSums::new(horizon);
    let mut clock = 0.0;
    for &i in trajectories {
        let traj = &data.trajectories[i];
        let n = traj.len();
        let embeddings: Vec<[f32; 2 * EMBED]> =
            (0..n).map(|t| model.embed(traj.terrain_at(t))).collect();
        for s in 0..n {
            let alpha = adapter.alpha().to_vec();
            let predict = |t: usize, roll: f64, pitch: f64| {
                model.predict(&alpha, roll, pitch, &embeddings[t], traj.commands[t])
            };
            if s + 1 < n {
                score_step(&mut sums, traj, data.units, s, &predict);
            }
            if s % stride == 0 && s + horizon < n {
                score_rollout(&mut sums, traj, data.units, s, &predict);
            }
            // the command is in model units; the adapter takes world units
            let (v, steer) = traj.commands[s];
            let e = embeddings[s];
            adapter.observe(
                clock + s as f64 * dt_world,
                traj.poses[s],
                (v * data.units.scale.sqrt(), steer),
                &mut |_| e,
            );
        }
        // a gap between trajectories: no example joins two trials
        clock += (n as f64 + 10.0) * dt_world;
    }
    sums
}
