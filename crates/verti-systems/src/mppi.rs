//! MPPI (paper §IV-A; reference constants spec §6.3): sample K steering/speed sequences around
//! the previous plan, roll each out with a kinematic bicycle model, weight them by
//! exp(−(cost − min cost)/λ), and average. Unlike the reference, the cost is accumulated over
//! the whole horizon (not only the last step) and the rollout heading is integrated.
//!
//! Cost per step: distance to the local goal (normalised by the distance at the start),
//! a large penalty inside obstacles (read from a heading-aligned occupancy crop taken once
//! per plan) or off the map, and a control term; plus a terminal distance term.

use crate::path::PathFollower;
use verti_bench::{Action, CropSpec, MobilitySystem, Observation, TaskInfo};
use verti_core::Rng;

#[derive(Clone, Debug, PartialEq)]
pub struct MppiParams {
    /// Rollouts per plan.
    pub samples: usize,
    /// Horizon steps and their duration (s).
    pub horizon: usize,
    pub step: f64,
    /// Temperature λ.
    pub lambda: f64,
    /// Noise on speed (m/s at full scale) and on normalised steering.
    pub sigma_speed: f64,
    pub sigma_steer: f64,
    /// Nominal speed at full scale (m/s, scaled by √s).
    pub speed: f64,
    /// Local-goal lookahead at full scale (m).
    pub lookahead: f64,
    /// Cost weights.
    pub w_goal: f64,
    pub w_obstacle: f64,
    pub w_control: f64,
    /// Planning rate, Hz.
    pub rate: f64,
}

impl Default for MppiParams {
    fn default() -> Self {
        MppiParams {
            // the reference's K = 800; 30 steps of 0.1 s at 3 m/s reach ~9 m ahead, the
            // reference's spatial horizon (20 steps of ~0.45 m)
            samples: 800,
            horizon: 30,
            step: 0.1,
            lambda: 0.1,
            sigma_speed: 0.5,
            sigma_steer: 0.5,
            speed: 3.0,
            lookahead: 10.0,
            w_goal: 10.0,
            w_obstacle: 50.0,
            w_control: 0.1,
            rate: 20.0,
        }
    }
}

/// A planar pose.
#[derive(Clone, Copy, Debug)]
struct Pose2 {
    x: f64,
    y: f64,
    yaw: f64,
}

pub struct Mppi {
    params: MppiParams,
    follower: PathFollower,
    goal: [f64; 2],
    scale: f64,
    wheelbase: f64,
    max_steer: f64,
    /// Nominal plan: (speed, steering) per horizon step.
    plan: Vec<(f64, f64)>,
    rng: Rng,
    // scratch buffers reused between plans
    noise: Vec<(f64, f64)>,
    costs: Vec<f64>,
}

impl Mppi {
    pub fn new(params: MppiParams) -> Self {
        let h = params.horizon;
        Mppi {
            params,
            follower: PathFollower::default(),
            goal: [0.0; 2],
            scale: 1.0,
            wheelbase: 3.4,
            max_steer: 0.5,
            plan: vec![(0.0, 0.0); h],
            rng: Rng::new(0),
            noise: Vec::new(),
            costs: Vec::new(),
        }
    }

    fn nominal_speed(&self) -> f64 {
        self.params.speed * self.scale.sqrt()
    }

    /// One MPPI iteration from the observation; returns the first control of the new plan.
    pub fn plan_once(&mut self, obs: &Observation) -> (f64, f64) {
        let p = &self.params;
        let (k, h) = (p.samples.max(1), p.horizon.max(1));
        let v_nom = self.nominal_speed();
        let local =
            self.follower
                .local_goal(obs.pose.x, obs.pose.y, p.lookahead * self.scale, self.goal);
        let start = Pose2 {
            x: obs.pose.x,
            y: obs.pose.y,
            yaw: obs.pose.yaw,
        };
        let d0 = ((local[0] - start.x).powi(2) + (local[1] - start.y).powi(2))
            .sqrt()
            .max(1e-3);
        // occupancy crop covering the reachable area: radius v·T plus margin
        let reach = v_nom * 1.5 * p.step * h as f64 + 2.0 * self.scale;
        // obstacles are at least 3 m across: 0.4 m cells resolve them and keep the crop cheap
        let res = 0.4 * self.scale;
        let size = ((2.0 * reach / res).ceil() as usize) | 1;
        let spec = CropSpec {
            size,
            resolution: res,
        };
        let occ = obs.occupancy_crop(spec);
        let half = 0.5 * (size as f64 - 1.0);
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

        // warm start: shift the previous plan by one step
        self.plan.rotate_left(1);
        if let Some(last) = self.plan.last_mut() {
            *last = (v_nom, last.1);
        }
        self.noise.resize(k * h, (0.0, 0.0));
        self.costs.resize(k, 0.0);
        let sig_v = p.sigma_speed * self.scale.sqrt();
        for n in self.noise.iter_mut() {
            let (a, b) = self.rng.normal_pair();
            *n = (sig_v * a, p.sigma_steer * b);
        }
        let (v_lo, v_hi) = (0.3 * v_nom, v_nom);
        // Rollouts use no trigonometry in the inner loop: the heading is carried as (cos, sin)
        // and advanced by the rotation for the small per-step turn dψ (|dψ| < 0.1 rad), with
        // series accurate to ~1e-8; tan of the steer angle (≤ ~0.7 rad) by its 7th-order series
        // (error < 2e-3, far below what a kinematic bicycle model resolves).
        let tan_series = |a: f64| {
            let a2 = a * a;
            a * (1.0 + a2 * (1.0 / 3.0 + a2 * (2.0 / 15.0 + a2 * (17.0 / 315.0))))
        };
        let inv_h = 1.0 / h as f64;
        let inv_d0 = 1.0 / d0;
        let ctrl_scale =
            p.w_control * p.lambda / (p.sigma_steer * p.sigma_steer).max(1e-12) * inv_h;
        let (c0, s0) = (start.yaw.cos(), start.yaw.sin());
        for s in 0..k {
            let (mut x, mut y) = (start.x, start.y);
            let (mut c, mut sn) = (c0, s0);
            let mut cost = 0.0;
            for t in 0..h {
                let (nv, nd) = self.noise[s * h + t];
                let (pv, pd) = self.plan[t];
                let v = (pv + nv).clamp(v_lo, v_hi);
                let d = (pd + nd).clamp(-1.0, 1.0);
                let dpsi = v / self.wheelbase * tan_series(d * self.max_steer) * p.step;
                let d2 = dpsi * dpsi;
                let (cd, sd) = (1.0 - 0.5 * d2 + d2 * d2 / 24.0, dpsi * (1.0 - d2 / 6.0));
                let (nc, ns) = (c * cd - sn * sd, sn * cd + c * sd);
                c = nc;
                sn = ns;
                x += v * c * p.step;
                y += v * sn * p.step;
                let dist = ((local[0] - x).powi(2) + (local[1] - y).powi(2)).sqrt() * inv_d0;
                cost += p.w_goal * dist * inv_h
                    + if occupied(x, y) { p.w_obstacle } else { 0.0 }
                    + ctrl_scale * (pd * nd).abs();
            }
            let dist = ((local[0] - x).powi(2) + (local[1] - y).powi(2)).sqrt() * inv_d0;
            self.costs[s] = cost + p.w_goal * dist;
        }
        let min = self.costs.iter().copied().fold(f64::INFINITY, f64::min);
        let mut total = 0.0;
        for c in self.costs.iter_mut() {
            *c = (-(*c - min) / p.lambda).exp();
            total += *c;
        }
        for t in 0..h {
            let (mut dv, mut dd) = (0.0, 0.0);
            for s in 0..k {
                let w = self.costs[s] / total;
                let (nv, nd) = self.noise[s * h + t];
                dv += w * nv;
                dd += w * nd;
            }
            let (pv, pd) = self.plan[t];
            self.plan[t] = ((pv + dv).clamp(v_lo, v_hi), (pd + dd).clamp(-1.0, 1.0));
        }
        self.plan[0]
    }
}

impl MobilitySystem for Mppi {
    fn name(&self) -> &str {
        "mppi"
    }
    fn control_rate(&self) -> f64 {
        self.params.rate
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.follower = PathFollower::new(task.global_path.clone());
        self.goal = task.goal;
        self.scale = task.world_scale;
        self.wheelbase = task.wheelbase.max(1e-3);
        self.max_steer = task.max_steer_angle.max(1e-3);
        let v = self.nominal_speed();
        self.plan = vec![(v, 0.0); self.params.horizon.max(1)];
        self.rng = Rng::new(task.seed);
    }
    fn act(&mut self, obs: &Observation) -> Action {
        let (speed, steering) = self.plan_once(obs);
        Action::HighLevel { speed, steering }
    }
}
