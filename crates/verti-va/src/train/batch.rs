//! Batches for VertiAdaptor's training and evaluation, built from `verti_va` trajectories:
//! one-step points (for least squares and one-step losses) and multi-step rollouts (Algorithm
//! 1's queries), as flat host arrays turned into tensors in one go.

use crate::data::{VaData, VaTrajectory};
use crate::model::POSE_DIM;
use crate::terrain::TERRAIN_DIM;
use burn::tensor::{Device, Tensor, TensorData};
use verti_core::Rng;
use verti_kino::features::heading_delta;

fn tensor(v: &[f32], dims: [usize; 2], device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(v.to_vec(), dims), device)
}

/// One-step examples: inputs at pose t, the change to t + 1.
#[derive(Clone, Debug, Default)]
pub struct Points {
    pub terrain: Vec<f32>,
    pub roll_pitch: Vec<f32>,
    pub command: Vec<f32>,
    pub delta: Vec<f32>,
}

/// The same as tensors.
pub struct PointTensors {
    pub terrain: Tensor<2>,
    pub roll_pitch: Tensor<2>,
    pub command: Tensor<2>,
    pub delta: Tensor<2>,
}

impl Points {
    pub fn len(&self) -> usize {
        self.delta.len() / POSE_DIM
    }
    pub fn is_empty(&self) -> bool {
        self.delta.is_empty()
    }
    pub fn push(&mut self, data: &VaData, traj: &VaTrajectory, t: usize) {
        let p = &traj.poses[t];
        self.terrain.extend_from_slice(traj.terrain_at(t));
        self.roll_pitch.extend([p.roll as f32, p.pitch as f32]);
        let (v, s) = traj.commands[t];
        self.command.extend([v as f32, s as f32]);
        self.delta
            .extend(traj.delta(t, data.units).map(|x| x as f32));
    }
    /// Adds one example from raw values (terrain latent, attitude, full-scale command and change).
    pub fn push_raw(
        &mut self,
        terrain: &[f32],
        roll: f64,
        pitch: f64,
        command: (f64, f64),
        delta: &[f64; POSE_DIM],
    ) {
        self.terrain.extend_from_slice(terrain);
        self.roll_pitch.extend([roll as f32, pitch as f32]);
        self.command.extend([command.0 as f32, command.1 as f32]);
        self.delta.extend(delta.map(|x| x as f32));
    }
    pub fn extend(&mut self, other: &Points) {
        self.terrain.extend(&other.terrain);
        self.roll_pitch.extend(&other.roll_pitch);
        self.command.extend(&other.command);
        self.delta.extend(&other.delta);
    }
    /// Rows `from..to`.
    pub fn slice(&self, from: usize, to: usize) -> Points {
        Points {
            terrain: self.terrain[from * TERRAIN_DIM..to * TERRAIN_DIM].to_vec(),
            roll_pitch: self.roll_pitch[from * 2..to * 2].to_vec(),
            command: self.command[from * 2..to * 2].to_vec(),
            delta: self.delta[from * POSE_DIM..to * POSE_DIM].to_vec(),
        }
    }
    pub fn tensors(&self, device: &Device) -> PointTensors {
        let n = self.len();
        PointTensors {
            terrain: tensor(&self.terrain, [n, TERRAIN_DIM], device),
            roll_pitch: tensor(&self.roll_pitch, [n, 2], device),
            command: tensor(&self.command, [n, 2], device),
            delta: tensor(&self.delta, [n, POSE_DIM], device),
        }
    }
}

/// Open-loop rollouts of `horizon` steps from true starts, with the true commands and
/// terrain along the way (Algorithm 1, lines 13–21); targets are the true poses relative to
/// the start, in its heading frame (full-scale units; roll and pitch as changes).
#[derive(Clone, Debug, Default)]
pub struct Rollouts {
    pub horizon: usize,
    pub count: usize,
    pub start_roll_pitch: Vec<f32>,
    /// Per rollout, then per step.
    pub terrain: Vec<f32>,
    pub command: Vec<f32>,
    pub target: Vec<f32>,
}

impl Rollouts {
    pub fn new(horizon: usize) -> Rollouts {
        Rollouts {
            horizon,
            ..Default::default()
        }
    }

    /// Adds the rollout of `traj` starting at pose `start` (needs start + horizon < len).
    pub fn push(&mut self, data: &VaData, traj: &VaTrajectory, start: usize) {
        let p0 = &traj.poses[start];
        self.start_roll_pitch
            .extend([p0.roll as f32, p0.pitch as f32]);
        for t in 0..self.horizon {
            self.terrain.extend_from_slice(traj.terrain_at(start + t));
            let (v, s) = traj.commands[start + t];
            self.command.extend([v as f32, s as f32]);
            let d = data
                .units
                .delta_to_model(&heading_delta(p0, &traj.poses[start + t + 1]));
            self.target.extend(d.map(|x| x as f32));
        }
        self.count += 1;
    }
}

/// Algorithm 1's sampling (paper Table I).
#[derive(Clone, Debug, PartialEq)]
pub struct Sampling {
    /// Environments per step F.
    pub envs: usize,
    /// Trajectories per environment N.
    pub trajectories: usize,
    /// The first N_ex of them are examples, the rest queries.
    pub examples: usize,
    /// Rollouts per query trajectory S.
    pub rollouts: usize,
    /// Prediction horizon T_pred.
    pub horizon: usize,
    /// Example points per environment and step (one least-squares batch).
    pub example_points: usize,
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            envs: 5,
            trajectories: 10,
            examples: 4,
            rollouts: 2,
            horizon: 8,
            example_points: 256,
        }
    }
}

/// One training step's draw: example points per environment, and every query rollout with
/// the index of its environment.
pub struct Draw {
    pub examples: Vec<Points>,
    pub queries: Rollouts,
    pub env_of_query: Vec<usize>,
    /// One-step points of the query trajectories (the MAML and MLP objectives).
    pub query_points: Points,
}

/// The environments training may draw: worlds with trajectories long enough for a rollout.
pub fn environments(data: &VaData, horizon: usize) -> Vec<Vec<usize>> {
    data.by_world(horizon + 1).into_values().collect()
}

/// Draws one step's batch. A world with fewer than N trajectories gives some twice.
pub fn draw(data: &VaData, envs: &[Vec<usize>], s: &Sampling, rng: &mut Rng) -> Draw {
    let mut out = Draw {
        examples: Vec::new(),
        queries: Rollouts::new(s.horizon),
        env_of_query: Vec::new(),
        query_points: Points::default(),
    };
    for f in 0..s.envs {
        let env = &envs[rng.below(envs.len() as u64) as usize];
        let mut pool = env.clone();
        let mut chosen = Vec::with_capacity(s.trajectories);
        for _ in 0..s.trajectories {
            if pool.is_empty() {
                pool = env.clone();
            }
            chosen.push(pool.swap_remove(rng.below(pool.len() as u64) as usize));
        }
        let mut ex = Points::default();
        let ex_trajs = &chosen[..s.examples];
        let ex_total: usize = ex_trajs
            .iter()
            .map(|&i| data.trajectories[i].len() - 1)
            .sum();
        for _ in 0..s.example_points.min(ex_total.max(1)) {
            // a uniformly drawn one-step pair of the example trajectories
            let mut r = rng.below(ex_total as u64) as usize;
            for &i in ex_trajs {
                let n = data.trajectories[i].len() - 1;
                if r < n {
                    ex.push(data, &data.trajectories[i], r);
                    break;
                }
                r -= n;
            }
        }
        out.examples.push(ex);
        for &i in &chosen[s.examples..] {
            let traj = &data.trajectories[i];
            for _ in 0..s.rollouts {
                let start = rng.below((traj.len() - s.horizon) as u64) as usize;
                out.queries.push(data, traj, start);
                out.env_of_query.push(f);
                for t in start..start + s.horizon {
                    out.query_points.push(data, traj, t);
                }
            }
        }
    }
    out
}
