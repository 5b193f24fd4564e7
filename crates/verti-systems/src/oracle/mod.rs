//! The `oracle`: sampling-based model-predictive control whose model is the **true
//! simulator**. At each replanning instant it builds a few dozen candidate plans (see
//! [`plan::candidates`]), rolls each out on a branch of the running trial
//! ([`verti_bench::Trial::branch`]), scores them ([`plan::rollout`]) and executes the best one
//! until the next replanning instant.
//!
//! It is privileged: it reads the trial through [`verti_bench::Observation::trial`], which no
//! deployable system has. It answers a question no system of the paper can: which tasks are
//! feasible at all, and it is the expert that demonstrates them for datasets. Given an
//! observation without the trial (built by hand, or from Python) it fails the trial with a
//! message ([`verti_bench::MobilitySystem::failure`]).
//!
//! Deterministic: candidates come from an RNG seeded with the task's seed, rollouts run one
//! after another inside the trial (an evaluation parallelises across tasks), and a rollout
//! reproduces the trial's own stepping exactly. So a task's result depends only on the task,
//! the run seed and the parameters, never on the thread count.

pub mod plan;
pub mod route;

use plan::{Context, Plan, Shape};
use route::Route;
use verti_bench::{Action, MobilitySystem, Observation, Outcome, TaskInfo};
use verti_core::Rng;

/// The oracle acts every control period; plans are made of whole control ticks.
pub const CONTROL_PERIOD: f64 = 0.1;

#[derive(Clone, Debug, PartialEq)]
pub struct OracleParams {
    /// Candidate plans per replanning instant.
    pub samples: usize,
    /// Planning horizon, simulated seconds.
    pub horizon: f64,
    /// Segments per plan (equal lengths, each a speed and a steering mode).
    pub segments: usize,
    /// Replanning period, simulated seconds (at most a segment).
    pub replan: f64,
    /// Nominal, lowest and highest target speed at full scale, m/s (scaled by √s).
    pub speed: f64,
    pub min_speed: f64,
    pub max_speed: f64,
    /// Lateral offset between the tracking lanes of the candidates at full scale, m.
    pub lane: f64,
    /// Tracking lookahead at full scale, m.
    pub lookahead: f64,
    /// Weight of the roll/pitch penalty.
    pub w_tilt: f64,
}

impl Default for OracleParams {
    fn default() -> Self {
        OracleParams {
            samples: 16,
            horizon: 4.0,
            segments: 4,
            replan: 0.5,
            speed: 3.0,
            min_speed: 1.5,
            max_speed: 4.5,
            lane: 4.0,
            lookahead: 10.0,
            w_tilt: 1.0,
        }
    }
}

/// Whole control ticks in `seconds`, if it is a positive multiple of the control period.
fn ticks(seconds: f64) -> Option<usize> {
    let t = seconds / CONTROL_PERIOD;
    let n = t.round();
    ((t - n).abs() < 1e-6 && n >= 1.0).then_some(n as usize)
}

impl OracleParams {
    /// The candidate-set shape, or why these parameters do not make one.
    pub fn shape(&self) -> Result<Shape, String> {
        let whole = |name: &str, v: f64| {
            ticks(v).ok_or_else(|| {
                format!("oracle parameter {name} = {v} s is not a positive multiple of the control period {CONTROL_PERIOD} s")
            })
        };
        let horizon_ticks = whole("horizon", self.horizon)?;
        let replan_ticks = whole("replan", self.replan)?;
        if self.segments == 0 || horizon_ticks % self.segments != 0 {
            return Err(format!(
                "oracle parameters: horizon {} s does not split into {} segments of whole control periods ({CONTROL_PERIOD} s)",
                self.horizon, self.segments
            ));
        }
        let seg_ticks = horizon_ticks / self.segments;
        if replan_ticks > seg_ticks {
            return Err(format!(
                "oracle parameters: replan {} s is longer than a segment ({} s = horizon / segments); a plan is executed only up to its first segment's end",
                self.replan,
                seg_ticks as f64 * CONTROL_PERIOD
            ));
        }
        if !(self.min_speed <= self.speed && self.speed <= self.max_speed) {
            return Err(format!(
                "oracle parameters: need min_speed <= speed <= max_speed, got {} / {} / {}",
                self.min_speed, self.speed, self.max_speed
            ));
        }
        if self.samples == 0 {
            return Err("oracle parameter samples must be at least 1".into());
        }
        Ok(Shape {
            samples: self.samples,
            segments: self.segments,
            seg_ticks,
            horizon_ticks,
            replan_ticks,
            period: CONTROL_PERIOD,
            speed: self.speed,
            min_speed: self.min_speed,
            max_speed: self.max_speed,
            lane: self.lane,
            w_tilt: self.w_tilt,
        })
    }
}

/// The oracle system (see the module doc).
pub struct Oracle {
    params: OracleParams,
    shape: Shape,
    ctx: Context,
    rng: Rng,
    /// The plan being executed and the control ticks since it was made.
    plan: Option<Plan>,
    tick: usize,
    /// The executed plan's rollout reaches the goal: rollouts predict execution exactly, so
    /// it is followed to the end without replanning.
    committed: bool,
    failure: Option<String>,
    /// Plans made and rollouts run in the current trial (for tools and tests).
    pub plans: usize,
    pub rollouts: usize,
}

impl Oracle {
    /// An oracle with validated parameters.
    pub fn new(params: OracleParams) -> Result<Oracle, String> {
        let shape = params.shape()?;
        Ok(Oracle {
            params,
            shape,
            ctx: Context::default(),
            rng: Rng::new(0),
            plan: None,
            tick: 0,
            committed: false,
            failure: None,
            plans: 0,
            rollouts: 0,
        })
    }

    pub fn params(&self) -> &OracleParams {
        &self.params
    }

    /// Plans from the running trial: rolls every candidate out and keeps the best.
    fn replan(&mut self, trial: &verti_bench::Trial) {
        let cands = plan::candidates(&self.shape, self.plan.as_ref(), &mut self.rng);
        // (index, rollout) of the best candidate so far
        let mut best: Option<(usize, plan::Rollout)> = None;
        for (i, c) in cands.iter().enumerate() {
            let r = plan::rollout(trial, c, &self.shape, &self.ctx);
            self.rollouts += 1;
            // strict comparison: ties go to the earlier candidate (warm start, structured)
            if best.is_none_or(|(_, b)| r.score > b.score) {
                best = Some((i, r));
            }
        }
        let (i, plan::Rollout { ended, .. }) = best.expect("at least one candidate");
        self.committed = matches!(ended, Some((Outcome::Success, _)));
        self.plan = Some(cands[i].clone());
        self.tick = 0;
        self.plans += 1;
    }
}

impl MobilitySystem for Oracle {
    fn name(&self) -> &str {
        "oracle"
    }
    fn control_rate(&self) -> f64 {
        1.0 / CONTROL_PERIOD
    }
    fn reset(&mut self, task: &TaskInfo) {
        let scale = task.world_scale;
        self.ctx = Context {
            // resampled every metre at full scale
            route: Route::new(&task.global_path, task.start, task.goal, scale),
            scale,
            lookahead: self.params.lookahead,
            max_steer: task.max_steer_angle,
        };
        self.rng = Rng::new(task.seed);
        self.plan = None;
        self.tick = 0;
        self.committed = false;
        self.failure = None;
        self.plans = 0;
        self.rollouts = 0;
    }
    fn act(&mut self, obs: &Observation) -> Action {
        let Some(trial) = obs.trial() else {
            self.failure = Some(
                "the oracle plans with the true simulator and needs privileged access to the \
                 running trial (Observation::trial), which this observation does not give; \
                 run it through verti eval / run_episode, not on a hand-built observation"
                    .into(),
            );
            return Action::HighLevel {
                speed: 0.0,
                steering: 0.0,
            };
        };
        let horizon_left = self
            .plan
            .as_ref()
            .is_some_and(|_| self.tick < self.shape.horizon_ticks);
        let due = !(self.committed && horizon_left)
            && (self.plan.is_none() || self.tick >= self.shape.replan_ticks);
        if due {
            self.replan(trial);
        }
        let plan = self.plan.as_ref().expect("planned");
        let seg = plan.at(self.tick, self.shape.seg_ticks);
        self.tick += 1;
        Plan::action(seg, trial, &self.ctx)
    }
    fn failure(&self) -> Option<String> {
        self.failure.clone()
    }
}
