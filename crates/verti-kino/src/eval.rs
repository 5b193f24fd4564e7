//! Prediction accuracy on held-out trajectories: one step and open-loop over a horizon, per
//! pose dimension and elevation level, for a learned model and for the kinematic bicycle.

use crate::features::{KinoState, OUTPUT_DIM, heading_delta};
use crate::model::{Geometry, KinoModel, bicycle_step, state_from};
use crate::samples::KinoData;
use verti_world::ElevationLevel;

/// What predicts: a learned model or the bicycle baseline.
#[derive(Clone, Debug)]
pub enum Predictor {
    Model(KinoModel),
    Bicycle,
}

impl Predictor {
    pub fn name(&self) -> String {
        match self {
            Predictor::Model(m) => m.name().to_string(),
            Predictor::Bicycle => "bicycle".into(),
        }
    }
}

/// Root-mean-square errors per pose dimension (forward, left, z in m; yaw, roll, pitch in
/// degrees), over `count` predictions.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Errors {
    pub count: usize,
    sum_sq: [f64; OUTPUT_DIM],
}

impl Errors {
    fn add(&mut self, e: &[f64; OUTPUT_DIM]) {
        self.count += 1;
        for (s, v) in self.sum_sq.iter_mut().zip(e) {
            *s += v * v;
        }
    }
    /// RMSE per dimension, angles in degrees.
    pub fn rmse(&self) -> [f64; OUTPUT_DIM] {
        let n = self.count.max(1) as f64;
        let mut r = [0.0; OUTPUT_DIM];
        for (i, (o, s)) in r.iter_mut().zip(&self.sum_sq).enumerate() {
            *o = (s / n).sqrt()
                * if i >= 3 {
                    180.0 / std::f64::consts::PI
                } else {
                    1.0
                };
        }
        r
    }
}

/// Errors of one predictor: one step and after `horizon` steps, overall and per level
/// (low, medium, high).
#[derive(Clone, Debug, PartialEq)]
pub struct Accuracy {
    pub predictor: String,
    pub horizon: usize,
    pub one_step: [Errors; 4],
    pub multi_step: [Errors; 4],
}

fn level_index(l: ElevationLevel) -> usize {
    match l {
        ElevationLevel::Low => 1,
        ElevationLevel::Mid => 2,
        ElevationLevel::High => 3,
    }
}

/// Predicts open loop from every `horizon`-th pose of every trajectory (the true commands
/// applied), and compares with what the simulator did. Errors are in the heading frame of the
/// window's start pose.
pub fn evaluate(
    data: &KinoData,
    predictor: &Predictor,
    geometry: Geometry,
    horizon: usize,
) -> Accuracy {
    let horizon = horizon.max(1);
    let mut acc = Accuracy {
        predictor: predictor.name(),
        horizon,
        one_step: Default::default(),
        multi_step: Default::default(),
    };
    let mut scratch = match predictor {
        Predictor::Model(m) => Some(m.scratch()),
        Predictor::Bicycle => None,
    };
    for tr in &data.trajectories {
        let terrain = &data.worlds[tr.world].terrain;
        let li = level_index(tr.level);
        let mut t = 1;
        while t + horizon < tr.poses.len() {
            let mut state = state_from(&tr.poses[t - 1], &tr.poses[t]);
            if let (Predictor::Model(m), Some(s)) = (predictor, scratch.as_mut()) {
                m.begin(&tr.poses[t], terrain, data.units, s);
            }
            for k in 0..horizon {
                let command = tr.commands[t + k];
                state = match (predictor, scratch.as_mut()) {
                    (Predictor::Model(m), Some(s)) => {
                        m.step(&state, command, terrain, data.units, geometry, s)
                    }
                    _ => bicycle_step(&state, command, terrain, geometry, data.dt_world),
                };
                let err = error(&tr.poses[t], &state, &tr.poses[t + k + 1]);
                if k == 0 {
                    acc.one_step[0].add(&err);
                    acc.one_step[li].add(&err);
                }
                if k + 1 == horizon {
                    acc.multi_step[0].add(&err);
                    acc.multi_step[li].add(&err);
                }
            }
            t += horizon;
        }
    }
    acc
}

/// Predicted minus true pose, positions in the heading frame of `origin`.
fn error(
    origin: &verti_bench::observation::Pose6,
    predicted: &KinoState,
    truth: &verti_bench::observation::Pose6,
) -> [f64; OUTPUT_DIM] {
    let p = heading_delta(origin, &predicted.pose);
    let q = heading_delta(origin, truth);
    let mut e = [0.0; OUTPUT_DIM];
    for (i, v) in e.iter_mut().enumerate() {
        *v = p[i] - q[i];
    }
    e[3] = verti_core::math::wrap_angle(e[3]);
    e
}

/// A markdown table of several predictors' accuracies.
pub fn table(results: &[Accuracy], dt_world: f64) -> String {
    let mut s = String::new();
    let h = results.first().map(|a| a.horizon).unwrap_or(1);
    s.push_str(&format!(
        "RMSE per pose dimension (fwd/left/z in m, yaw/roll/pitch in degrees); one step = \
         {dt_world:.2} s, multi-step = {h} steps ({:.1} s) open loop.\n\n",
        dt_world * h as f64
    ));
    s.push_str("| predictor | level | n | horizon | fwd | left | z | yaw | roll | pitch |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    for a in results {
        for (li, level) in ["all", "low", "medium", "high"].iter().enumerate() {
            for (which, e) in [("1 step", &a.one_step[li]), ("multi", &a.multi_step[li])] {
                if e.count == 0 {
                    continue;
                }
                let r = e.rmse();
                s.push_str(&format!(
                    "| {} | {level} | {} | {which} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} |\n",
                    a.predictor, e.count, r[0], r[1], r[2], r[3], r[4], r[5]
                ));
            }
        }
    }
    s
}
