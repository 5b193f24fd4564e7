//! What MPPI rolls out and how it scores it, as two separate, replaceable parts:
//!
//! * a [`RolloutModel`] turns K sampled control sequences from the current state into per-step
//!   6-DoF poses (x, y, z, roll, pitch, yaw), plus any extra per-step channels a cost may read
//!   (traversability, uncertainty, ...). [`Bicycle`] is the default: a kinematic bicycle.
//! * a [`RolloutCost`] maps the rollouts (with the controls, the local goal and whatever map
//!   context it prepared) to one cost per sample. [`PathCost`] is the default: distance to the
//!   local goal, obstacles and a control term.
//!
//! Both are prepared once per plan from the observation (`prepare`: map crops, map encodings,
//! recent history) and then called once per plan with the whole batch, so a learned model can
//! evaluate all K samples of a step in one network call. Buffers are owned by MPPI and reused,
//! so a plan allocates nothing in the loop over samples and steps.

pub use verti_bench::observation::Pose6;
use verti_bench::{CropSpec, Observation, TaskInfo};

/// What models and costs know about the plan being made (all world-scaled, SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanContext {
    /// The vehicle's pose at the start of every rollout.
    pub start: Pose6,
    /// The local goal on the global path, world (x, y).
    pub local_goal: [f64; 2],
    /// Rollouts K, steps per rollout H, and the step duration (s).
    pub samples: usize,
    pub horizon: usize,
    pub step: f64,
    /// Nominal speed and the range sampled speeds are clamped to (m/s).
    pub nominal_speed: f64,
    pub speed_range: (f64, f64),
    /// MPPI temperature λ and the sampling noise: speed (m/s) and normalised steering.
    pub lambda: f64,
    pub sigma: (f64, f64),
    /// Length scale of the world.
    pub scale: f64,
}

/// The K control sequences of one plan, H steps each, indexed `k * horizon + t`.
#[derive(Clone, Copy, Debug)]
pub struct ControlSamples<'a> {
    pub samples: usize,
    pub horizon: usize,
    /// Controls to roll out: (speed m/s, steering in [-1, 1], positive = left), already
    /// clamped to the allowed ranges.
    pub controls: &'a [(f64, f64)],
    /// The nominal plan (H entries) and the noise drawn around it (K × H), for control costs.
    pub nominal: &'a [(f64, f64)],
    pub noise: &'a [(f64, f64)],
}

/// Rollout output: the pose after every step of every sample (`k * horizon + t`), and named
/// extra channels of one value per step (`k * horizon + t` too).
#[derive(Clone, Debug, Default)]
pub struct Rollouts {
    samples: usize,
    horizon: usize,
    pub poses: Vec<Pose6>,
    channels: Vec<(&'static str, Vec<f64>)>,
}

impl Rollouts {
    /// Sizes every buffer for K × H (reusing the allocations of earlier plans).
    pub fn resize(&mut self, samples: usize, horizon: usize) {
        self.samples = samples;
        self.horizon = horizon;
        self.poses.resize(samples * horizon, Pose6::default());
        for (_, c) in &mut self.channels {
            c.resize(samples * horizon, 0.0);
        }
    }
    pub fn samples(&self) -> usize {
        self.samples
    }
    pub fn horizon(&self) -> usize {
        self.horizon
    }
    /// The H poses of sample `k`.
    pub fn sample(&self, k: usize) -> &[Pose6] {
        &self.poses[k * self.horizon..(k + 1) * self.horizon]
    }
    /// A channel written by the model, if it wrote one by that name.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.channels
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, c)| c.as_slice())
    }
    /// A channel to write (K × H values), created on first use.
    pub fn channel_mut(&mut self, name: &'static str) -> &mut [f64] {
        let i = match self.channels.iter().position(|(n, _)| *n == name) {
            Some(i) => i,
            None => {
                self.channels
                    .push((name, vec![0.0; self.samples * self.horizon]));
                self.channels.len() - 1
            }
        };
        &mut self.channels[i].1
    }
}

/// Predicts where K control sequences take the vehicle.
pub trait RolloutModel: Send {
    /// Called once per trial.
    fn reset(&mut self, _task: &TaskInfo) {}
    /// Called once per plan before [`RolloutModel::rollout`]: take map crops, encode the map,
    /// record history.
    fn prepare(&mut self, _obs: &Observation, _ctx: &PlanContext) {}
    /// Writes `out.poses` (sized K × H) and any channels, from `ctx.start`.
    fn rollout(&mut self, ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts);
}

/// Scores rollouts: one cost per sample, lower is better.
pub trait RolloutCost: Send {
    /// Called once per trial.
    fn reset(&mut self, _task: &TaskInfo) {}
    /// Called once per plan before [`RolloutCost::evaluate`].
    fn prepare(&mut self, _obs: &Observation, _ctx: &PlanContext) {}
    /// Writes `costs[k]` for every sample k.
    fn evaluate(
        &mut self,
        ctx: &PlanContext,
        controls: &ControlSamples,
        rollouts: &Rollouts,
        costs: &mut [f64],
    );
}

/// Kinematic bicycle: dψ = v / wheelbase · tan(steering · max steer) · dt, heading integrated.
/// Height, roll and pitch are held at the start pose's.
#[derive(Clone, Debug)]
pub struct Bicycle {
    wheelbase: f64,
    max_steer: f64,
}

impl Default for Bicycle {
    fn default() -> Self {
        Bicycle {
            wheelbase: 3.4,
            max_steer: 0.5,
        }
    }
}

impl RolloutModel for Bicycle {
    fn reset(&mut self, task: &TaskInfo) {
        self.wheelbase = task.wheelbase.max(1e-3);
        self.max_steer = task.max_steer_angle.max(1e-3);
    }

    fn rollout(&mut self, ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts) {
        let (k, h, dt) = (controls.samples, controls.horizon, ctx.step);
        let start = ctx.start;
        // No trigonometry in the inner loop: the heading is carried as (cos, sin) and advanced
        // by the rotation for the small per-step turn dψ (|dψ| < 0.1 rad), with series accurate
        // to ~1e-8; tan of the steer angle (≤ ~0.7 rad) by its 7th-order series (error < 2e-3,
        // far below what a kinematic bicycle model resolves). Yaw is the sum of the turns.
        let tan_series = |a: f64| {
            let a2 = a * a;
            a * (1.0 + a2 * (1.0 / 3.0 + a2 * (2.0 / 15.0 + a2 * (17.0 / 315.0))))
        };
        let (c0, s0) = (start.yaw.cos(), start.yaw.sin());
        for s in 0..k {
            let (mut x, mut y, mut yaw) = (start.x, start.y, start.yaw);
            let (mut c, mut sn) = (c0, s0);
            let u = &controls.controls[s * h..(s + 1) * h];
            let poses = &mut out.poses[s * h..(s + 1) * h];
            for (&(v, d), pose) in u.iter().zip(poses) {
                let dpsi = v / self.wheelbase * tan_series(d * self.max_steer) * dt;
                let d2 = dpsi * dpsi;
                let (cd, sd) = (1.0 - 0.5 * d2 + d2 * d2 / 24.0, dpsi * (1.0 - d2 / 6.0));
                let (nc, ns) = (c * cd - sn * sd, sn * cd + c * sd);
                c = nc;
                sn = ns;
                x += v * c * dt;
                y += v * sn * dt;
                yaw += dpsi;
                *pose = Pose6 { x, y, yaw, ..start };
            }
        }
    }
}

/// Weights of [`PathCost`].
#[derive(Clone, Debug, PartialEq)]
pub struct PathCostWeights {
    /// Distance to the local goal (normalised by the distance at the start), per step averaged
    /// over the horizon, and again at the last step.
    pub goal: f64,
    /// Per step inside an obstacle or off the map.
    pub obstacle: f64,
    /// Control term λ·|u·ε|/σ² of the steering, averaged over the horizon.
    pub control: f64,
}

/// The default cost: per step, the distance to the local goal (normalised by the distance at
/// the start), a penalty inside obstacles (read from a heading-aligned occupancy crop taken
/// once per plan) or off the map, and a control term; plus a terminal distance term.
#[derive(Clone, Debug)]
pub struct PathCost {
    pub weights: PathCostWeights,
    occupancy: Option<verti_bench::Crop<u8>>,
}

impl PathCost {
    pub fn new(weights: PathCostWeights) -> Self {
        PathCost {
            weights,
            occupancy: None,
        }
    }
}

impl RolloutCost for PathCost {
    fn prepare(&mut self, obs: &Observation, ctx: &PlanContext) {
        // occupancy crop covering the reachable area: radius v·T plus margin
        let reach = ctx.nominal_speed * 1.5 * ctx.step * ctx.horizon as f64 + 2.0 * ctx.scale;
        // obstacles are at least 3 m across: 0.4 m cells resolve them and keep the crop cheap
        let res = 0.4 * ctx.scale;
        let size = ((2.0 * reach / res).ceil() as usize) | 1;
        self.occupancy = Some(obs.occupancy_crop(CropSpec {
            size,
            resolution: res,
        }));
    }

    fn evaluate(
        &mut self,
        ctx: &PlanContext,
        controls: &ControlSamples,
        rollouts: &Rollouts,
        costs: &mut [f64],
    ) {
        let occ = self
            .occupancy
            .as_ref()
            .expect("PathCost::prepare runs before evaluate");
        let w = &self.weights;
        let (start, local) = (ctx.start, ctx.local_goal);
        let (h, res) = (controls.horizon, occ.spec.resolution);
        let half = 0.5 * (occ.spec.size as f64 - 1.0);
        let (sy, cy) = start.yaw.sin_cos();
        let inv_res = 1.0 / res;
        let max_index = 2.0 * half;
        let occupied = |x: f64, y: f64| -> bool {
            // world -> heading-aligned crop cell; rounding by +0.5 and truncation, because
            // f64::round is a library call on baseline x86-64 and this runs ~50k times a plan
            let (dx, dy) = (x - start.x, y - start.y);
            let ahead = dx * cy + dy * sy;
            let left = -dx * sy + dy * cy;
            let r = half - ahead * inv_res + 0.5;
            let c = half - left * inv_res + 0.5;
            if r < 0.0 || c < 0.0 || r >= max_index + 1.0 || c >= max_index + 1.0 {
                return false;
            }
            occ.get(r as usize, c as usize) != 0
        };
        let d0 = ((local[0] - start.x).powi(2) + (local[1] - start.y).powi(2))
            .sqrt()
            .max(1e-3);
        let inv_h = 1.0 / h as f64;
        let inv_d0 = 1.0 / d0;
        let (sigma_steer, lambda) = (ctx.sigma.1, ctx.lambda);
        let ctrl_scale = w.control * lambda / (sigma_steer * sigma_steer).max(1e-12) * inv_h;
        for (s, cost_out) in costs.iter_mut().enumerate() {
            let poses = rollouts.sample(s);
            let noise = &controls.noise[s * h..(s + 1) * h];
            let mut cost = 0.0;
            for ((p, &(_, nd)), &(_, pd)) in poses.iter().zip(noise).zip(controls.nominal) {
                let dist = ((local[0] - p.x).powi(2) + (local[1] - p.y).powi(2)).sqrt() * inv_d0;
                cost += w.goal * dist * inv_h
                    + if occupied(p.x, p.y) { w.obstacle } else { 0.0 }
                    + ctrl_scale * (pd * nd).abs();
            }
            let last = poses[h - 1];
            let dist = ((local[0] - last.x).powi(2) + (local[1] - last.y).powi(2)).sqrt() * inv_d0;
            *cost_out = cost + w.goal * dist;
        }
    }
}
