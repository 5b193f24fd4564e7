//! MPPI (paper §IV-A; reference constants spec §6.3): sample K steering/speed sequences around
//! the previous plan, roll them out with a [`RolloutModel`], score them with a
//! [`RolloutCost`], weight them by exp(−(cost − min cost)/λ), and average.
//!
//! The default model is a kinematic bicycle ([`Bicycle`]), the default cost [`PathCost`]: per
//! step, distance to the local goal (normalised by the distance at the start), a large penalty
//! inside obstacles or off the map, and a control term; plus a terminal distance term. Unlike
//! the reference, the cost is accumulated over the whole horizon (not only the last step) and
//! the rollout heading is integrated. Learned planners (TAL, TNT, WMVCT, MPPI-6, PIETRA, ...)
//! are this MPPI with another model and cost: [`Mppi::with_model`].

use crate::path::PathFollower;
use crate::rollout::{
    Bicycle, ControlSamples, PathCost, PathCostWeights, PlanContext, RolloutCost, RolloutModel,
    Rollouts,
};
use verti_bench::{Action, MobilitySystem, Observation, TaskInfo};
use verti_core::Rng;

#[derive(Clone, Debug, PartialEq)]
pub struct MppiParams {
    /// Rollouts per plan.
    pub samples: usize,
    /// Horizon steps and their duration (s at full scale, scaled by √s).
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

/// MPPI over a [`RolloutModel`] and a [`RolloutCost`] (by default the kinematic
/// [`Bicycle`] and the [`PathCost`] weighted by the parameters' `w_*`).
pub struct Mppi {
    name: String,
    params: MppiParams,
    model: Box<dyn RolloutModel>,
    cost: Box<dyn RolloutCost>,
    follower: PathFollower,
    goal: [f64; 2],
    scale: f64,
    /// Nominal plan: (speed, steering) per horizon step.
    plan: Vec<(f64, f64)>,
    rng: Rng,
    // buffers reused between plans
    noise: Vec<(f64, f64)>,
    controls: Vec<(f64, f64)>,
    rollouts: Rollouts,
    costs: Vec<f64>,
}

impl Mppi {
    /// The MPPI of the paper: bicycle model, path cost.
    pub fn new(params: MppiParams) -> Self {
        let cost = PathCost::new(PathCostWeights {
            goal: params.w_goal,
            obstacle: params.w_obstacle,
            control: params.w_control,
        });
        Self::with_model("mppi", params, Box::new(Bicycle::default()), Box::new(cost))
    }

    /// MPPI with another rollout model and cost (the `w_*` weights of `params` are then
    /// unused), reported under `name`.
    pub fn with_model(
        name: &str,
        params: MppiParams,
        model: Box<dyn RolloutModel>,
        cost: Box<dyn RolloutCost>,
    ) -> Self {
        let h = params.horizon;
        Mppi {
            name: name.to_string(),
            params,
            model,
            cost,
            follower: PathFollower::default(),
            goal: [0.0; 2],
            scale: 1.0,
            plan: vec![(0.0, 0.0); h],
            rng: Rng::new(0),
            noise: Vec::new(),
            controls: Vec::new(),
            rollouts: Rollouts::default(),
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
        let local_goal =
            self.follower
                .local_goal(obs.pose.x, obs.pose.y, p.lookahead * self.scale, self.goal);
        let (v_lo, v_hi) = (0.3 * v_nom, v_nom);
        let sig_v = p.sigma_speed * self.scale.sqrt();
        let ctx = PlanContext {
            start: obs.pose,
            local_goal,
            samples: k,
            horizon: h,
            // speeds scale by √s and lengths by s, so times by √s: the rollouts then reach as
            // far ahead, relative to the vehicle and the look-ahead, at every scale
            step: p.step * self.scale.sqrt(),
            nominal_speed: v_nom,
            speed_range: (v_lo, v_hi),
            lambda: p.lambda,
            sigma: (sig_v, p.sigma_steer),
            scale: self.scale,
        };
        self.model.prepare(obs, &ctx);
        self.cost.prepare(obs, &ctx);

        // warm start: shift the previous plan by one step
        self.plan.rotate_left(1);
        if let Some(last) = self.plan.last_mut() {
            *last = (v_nom, last.1);
        }
        self.noise.resize(k * h, (0.0, 0.0));
        self.controls.resize(k * h, (0.0, 0.0));
        self.costs.resize(k, 0.0);
        self.rollouts.resize(k, h);
        for n in self.noise.iter_mut() {
            let (a, b) = self.rng.normal_pair();
            *n = (sig_v * a, p.sigma_steer * b);
        }
        for s in 0..k {
            let noise = &self.noise[s * h..(s + 1) * h];
            let u = &mut self.controls[s * h..(s + 1) * h];
            for ((u, &(nv, nd)), &(pv, pd)) in u.iter_mut().zip(noise).zip(&self.plan) {
                *u = ((pv + nv).clamp(v_lo, v_hi), (pd + nd).clamp(-1.0, 1.0));
            }
        }
        let samples = ControlSamples {
            samples: k,
            horizon: h,
            controls: &self.controls,
            nominal: &self.plan,
            noise: &self.noise,
        };
        self.model.rollout(&ctx, &samples, &mut self.rollouts);
        self.cost
            .evaluate(&ctx, &samples, &self.rollouts, &mut self.costs);

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
        &self.name
    }
    fn control_rate(&self) -> f64 {
        self.params.rate
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.follower = PathFollower::new(task.global_path.clone());
        self.goal = task.goal;
        self.scale = task.world_scale;
        self.model.reset(task);
        self.cost.reset(task);
        let v = self.nominal_speed();
        self.plan = vec![(v, 0.0); self.params.horizon.max(1)];
        self.rng = Rng::new(task.seed);
    }
    fn act(&mut self, obs: &Observation) -> Action {
        let (speed, steering) = self.plan_once(obs);
        Action::HighLevel { speed, steering }
    }
}
