//! [`Trial`]: one vehicle on one task under the benchmark's rules, as one value that can be
//! stepped, cloned (branched) and finished.
//!
//! Everything that drives a vehicle through a task goes through a `Trial`: the benchmark's
//! [`run_episode`](crate::episode::run_episode) (a loop of `system.act` and `trial.step`), the
//! step-wise environments of `verti-env`, Python systems, and later datasets, teleoperation and
//! branching rollouts. The inner loop (speed controller, physics, pose, metrics, termination
//! rules, step log) therefore exists once.

use crate::features::{FeatureSource, STEP_LOG};
use crate::metrics::{AngleStats, SignalStats};
use crate::observation::Observation;
use crate::perception::Perception;
use crate::pose::Pose6;
use crate::privileged::PrivilegedView;
use crate::result::{EpisodeLog, StepRecord, TrialResult};
use crate::rules::{EpisodeConfig, Outcome, StartMode, Termination};
use crate::speed::SpeedController;
use crate::system::{Action, TaskInfo};
use std::sync::Arc;
use std::time::Instant;
use verti_core::rng::mix_seed;
use verti_sim::{Controls, Sim, SimState, StartPose, VehicleSpec};
use verti_world::{Task, TaskId, World};

/// What one [`Trial::step`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutcome {
    /// How the trial ended in this step, if it did (the final class, as in the results).
    pub ended: Option<Outcome>,
    /// Inner steps simulated.
    pub inner_steps: u32,
}

/// Seed stream of perception noise ("percept" in ASCII), mixed with the run seed and task.
const PERCEPTION_STREAM: u64 = 0x0070_6572_6365_7074;

/// The oracle's privileged access, defined here rather than in `observation` because the
/// observation sits below the trial and holds it only as an opaque view (see
/// `crate::privileged`, the seam): the trial fills the view in, and oracle-type systems read it
/// back as the trial.
impl<'a> Observation<'a> {
    /// This observation with privileged access to `trial`, the running trial it describes
    /// ([`Trial::observation`] sets it; see [`Observation::trial`]).
    pub fn with_trial(self, trial: &'a Trial) -> Self {
        self.with_privileged(PrivilegedView::new(trial))
    }

    /// **Privileged.** The running trial this observation was made from: the true simulator
    /// and world, which a system may clone ([`Trial::clone`], [`Trial::branch`]) and step to
    /// look ahead. Only oracle-type systems (planners with the true simulator, expert
    /// demonstrators) may use it; a system compared with the paper's must not. `None` where
    /// no trial exists: observations built by hand ([`Observation::new`],
    /// [`test_observation`](crate::observation::test_observation)) or for systems outside a
    /// trial (e.g. Python).
    pub fn trial(&self) -> Option<&'a Trial> {
        self.privileged().and_then(|view| view.get::<Trial>())
    }
}

/// One trial in progress. Cloning it branches the trial: the clone continues independently
/// (the world and the simulator model are shared, the state is copied).
#[derive(Clone)]
pub struct Trial {
    world: Arc<World>,
    sim: Arc<Sim>,
    state: SimState,
    task: Task,
    info: TaskInfo,
    cfg: EpisodeConfig,
    rules: Termination,
    speed: SpeedController,
    /// Chassis pose after the latest inner step.
    pose: Pose6,
    /// Inner steps taken; the trial clock is `step_index · inner_dt`.
    step_index: u64,
    /// Time at which the current action's period ends.
    next_control: f64,
    /// Driver inputs applied in the latest inner step.
    controls: Controls,
    /// The result so far: identity, accumulators, and at the end the outcome.
    result: TrialResult,
    last_xy: (f64, f64),
    ended: Option<Outcome>,
    log: Option<EpisodeLog>,
    started: Instant,
    /// What the system perceives, when perception noise is on (boxed: most trials have none).
    perception: Option<Box<Perception>>,
}

/// The result of a trial that could not start (unknown pair, bad settings, no valid start).
pub fn failed_result(
    world: &World,
    vehicle: &str,
    pair: u32,
    system: &str,
    cfg: &EpisodeConfig,
    message: String,
) -> TrialResult {
    let mut r = blank_result(world, vehicle, pair, system, cfg);
    r.error = Some(message);
    r
}

fn blank_result(
    world: &World,
    vehicle: &str,
    pair: u32,
    system: &str,
    cfg: &EpisodeConfig,
) -> TrialResult {
    TrialResult {
        task: world.task_id(pair).number(),
        world: world.meta.index,
        pair,
        world_name: world.meta.name.clone(),
        level: world.meta.level,
        terrain_type: world.meta.terrain_type,
        density: world.meta.density,
        system: system.to_string(),
        vehicle: vehicle.to_string(),
        rules: cfg.rules,
        outcome: Outcome::Error,
        time: 0.0,
        traversal_time: None,
        roll: AngleStats::default(),
        pitch: AngleStats::default(),
        throttle: SignalStats::default(),
        steering: SignalStats::default(),
        path_length: 0.0,
        final_distance: f64::NAN,
        final_roll: 0.0,
        error: None,
        wall_time: 0.0,
    }
}

/// What a system is told about task `pair` of `world` driven by `spec` (None: no such pair).
pub fn task_info(
    world: &World,
    spec: &VehicleSpec,
    pair: u32,
    cfg: &EpisodeConfig,
) -> Option<TaskInfo> {
    let index = world.tasks.iter().position(|t| t.pair == pair)?;
    let task = &world.tasks[index];
    let id = TaskId {
        world: world.meta.index,
        pair,
    };
    Some(TaskInfo {
        id,
        start: task.start,
        goal: task.goal,
        global_path: world
            .paths
            .get(index)
            .map(|p| p.points.clone())
            .unwrap_or_default(),
        world_scale: world.meta.scale,
        vehicle: spec.name.clone(),
        wheelbase: spec.wheelbase(),
        max_steer_angle: spec.steering.max_angle_deg.to_radians(),
        max_time: cfg.max_time,
        seed: mix_seed(&[cfg.seed, u64::from(id.number())]),
    })
}

/// The chassis pose the rules and systems see: reference-frame position and Z-Y-X Euler angles.
pub fn pose6(sim: &Sim, state: &SimState) -> Pose6 {
    let p = sim.reference_pose(state).position;
    let (roll, pitch, yaw) = state.euler();
    Pose6 {
        x: p.x,
        y: p.y,
        z: p.z,
        roll,
        pitch,
        yaw,
    }
}

/// The start state of a trial at `start`: settled on the ground or dropped, as `cfg` says.
fn initial_state(
    sim: &Sim,
    world: &World,
    cfg: &EpisodeConfig,
    start: StartPose,
) -> Result<SimState, String> {
    match cfg.start {
        StartMode::Settled => sim.state_at(start),
        StartMode::Drop => sim.state_dropped(start, StartMode::DROP_HEIGHT * world.meta.scale),
    }
    .map_err(|e| format!("cannot start the simulation: {e}"))
}

impl Trial {
    /// A trial at its first instant: the clock at zero, idle controls, no outcome yet.
    #[allow(clippy::too_many_arguments)]
    fn fresh(
        world: &Arc<World>,
        sim: Arc<Sim>,
        state: SimState,
        task: Task,
        info: TaskInfo,
        cfg: EpisodeConfig,
        rules: Termination,
        pose: Pose6,
        result: TrialResult,
    ) -> Trial {
        // the perception's draws are the task's own, apart from the system's (same run seed)
        let perception = cfg.perception.as_ref().filter(|m| !m.is_none()).map(|m| {
            let seed = mix_seed(&[cfg.seed, u64::from(result.task), PERCEPTION_STREAM]);
            Box::new(Perception::new(world, m.clone(), seed))
        });
        Trial {
            world: world.clone(),
            state,
            task,
            info,
            rules,
            speed: SpeedController::default(),
            pose,
            step_index: 0,
            next_control: 0.0,
            controls: Controls::IDLE,
            result,
            last_xy: (pose.x, pose.y),
            ended: None,
            log: cfg.log_seconds.map(|_| EpisodeLog::default()),
            started: Instant::now(),
            perception,
            cfg,
            sim,
        }
    }
}

impl Trial {
    /// Starts task `pair` of `world` with the vehicle model `sim` (built for this world with
    /// `Sim::new`; one model serves every task of a world). `system` names who drives, for the results.
    pub fn new(
        world: &Arc<World>,
        sim: Arc<Sim>,
        pair: u32,
        cfg: &EpisodeConfig,
        system: &str,
    ) -> Result<Trial, String> {
        cfg.validate()?;
        let spec = sim.spec();
        let info = task_info(world, spec, pair, cfg)
            .ok_or_else(|| format!("world {} has no pair {pair}", world.meta.name))?;
        let task = *world
            .tasks
            .iter()
            .find(|t| t.pair == pair)
            .expect("task_info found it");
        let start = StartPose::new(task.start[0], task.start[1], task.start_yaw());
        let state = initial_state(&sim, world, cfg, start)?;
        let pose = pose6(&sim, &state);
        let rules = Termination::new(world, task.goal, cfg, &pose);
        let result = blank_result(world, &spec.name, pair, system, cfg);
        Ok(Trial::fresh(
            world,
            sim,
            state,
            task,
            info,
            cfg.clone(),
            rules,
            pose,
            result,
        ))
    }

    /// Starts a goal-less exploration trial at `start` on `world` (datasets: random driving,
    /// teleoperation). The same inner loop and rules as a task, but no goal: success never
    /// happens (the success radius is 0), so the trial ends by rollover, stuck, the time limit
    /// `cfg.max_time`, or when its driver stops stepping it (e.g. at the map's edge). The
    /// result's `task` and `pair` are 0; `final_distance` is the distance from the start.
    pub fn explore(
        world: &Arc<World>,
        sim: Arc<Sim>,
        start: StartPose,
        cfg: &EpisodeConfig,
        system: &str,
    ) -> Result<Trial, String> {
        cfg.validate()?;
        // no goal: `planar distance < 0` is never true, so the success rule never fires
        let cfg = EpisodeConfig {
            success_radius: 0.0,
            ..cfg.clone()
        };
        let state = initial_state(&sim, world, &cfg, start)?;
        let spec = sim.spec();
        let here = [start.x, start.y];
        let task = Task {
            pair: 0,
            start: here,
            goal: here,
        };
        let info = TaskInfo {
            id: world.task_id(0),
            start: here,
            goal: here,
            global_path: Vec::new(),
            world_scale: world.meta.scale,
            vehicle: spec.name.clone(),
            wheelbase: spec.wheelbase(),
            max_steer_angle: spec.steering.max_angle_deg.to_radians(),
            max_time: cfg.max_time,
            seed: cfg.seed,
        };
        let pose = pose6(&sim, &state);
        let rules = Termination::new(world, here, &cfg, &pose);
        let mut result = blank_result(world, &spec.name, 0, system, &cfg);
        result.task = 0;
        Ok(Trial::fresh(
            world, sim, state, task, info, cfg, rules, pose, result,
        ))
    }

    /// Builds the vehicle model for `world` and starts the task (see [`Trial::new`]).
    pub fn start(
        world: &Arc<World>,
        spec: &VehicleSpec,
        pair: u32,
        cfg: &EpisodeConfig,
        system: &str,
    ) -> Result<Trial, String> {
        cfg.validate()?;
        if !world.tasks.iter().any(|t| t.pair == pair) {
            return Err(format!("world {} has no pair {pair}", world.meta.name));
        }
        let sim = Sim::new(world, spec).map_err(|e| format!("cannot start the simulation: {e}"))?;
        Trial::new(world, Arc::new(sim), pair, cfg, system)
    }

    /// Holds `action` for one control period of `period` seconds (a whole number of inner
    /// steps, at least one) and runs the inner loop: speed controller, physics, metrics and the
    /// rules after every inner step. Stops early when the trial ends. An invalid action (not
    /// finite, out of range) ends the trial as an error. Stepping an ended trial does nothing.
    pub fn step(&mut self, action: Action, period: f64) -> StepOutcome {
        let mut out = StepOutcome {
            ended: self.ended,
            inner_steps: 0,
        };
        if self.ended.is_some() {
            return out;
        }
        let valid = match action {
            Action::HighLevel { speed, steering } => speed.is_finite() && steering.is_finite(),
            Action::LowLevel(c) => c.validate().is_ok(),
        };
        if !valid {
            let t = self.time();
            out.ended = Some(self.fail(format!(
                "system {} returned an invalid action {action:?} at t = {t:.2} s",
                self.result.system
            )));
            return out;
        }
        // the estimator's error for the next observation: drift steps on, white noise redrawn
        if let Some(p) = self.perception.as_mut() {
            p.advance(period);
        }
        // the same accumulation as a system acting at a fixed rate: the period ends at the
        // first inner step at or after the running sum of periods
        self.next_control += period;
        let dt = self.cfg.inner_dt;
        loop {
            let controls = match action {
                Action::HighLevel { speed, steering } => {
                    self.speed
                        .controls(speed, self.state.forward_speed(), steering)
                }
                Action::LowLevel(c) => c,
            };
            self.controls = controls;
            self.result
                .throttle
                .push(controls.throttle - controls.brake);
            self.result.steering.push(controls.steering);
            if let Err(e) = self.sim.step(&mut self.state, controls, dt) {
                let t = self.time();
                out.ended = Some(self.fail(format!("simulation failed at t = {t:.2} s: {e}")));
                return out;
            }
            self.step_index += 1;
            out.inner_steps += 1;
            let t = self.time();
            let pose = pose6(&self.sim, &self.state);
            self.pose = pose;
            self.result.roll.push_rad(pose.roll);
            self.result.pitch.push_rad(pose.pitch);
            self.result.path_length +=
                ((pose.x - self.last_xy.0).powi(2) + (pose.y - self.last_xy.1).powi(2)).sqrt();
            self.last_xy = (pose.x, pose.y);
            self.record_step(t);
            if let Some(ended) = self.rules.check(t, dt, &pose) {
                out.ended = Some(self.end(ended));
                return out;
            }
            if t + 1e-9 >= self.next_control {
                return out;
            }
        }
    }

    fn record_step(&mut self, t: f64) {
        let Some(log) = self.log.as_mut() else {
            return;
        };
        let src = FeatureSource::new(&self.state, self.pose, t, self.cfg.max_time, self.controls);
        log.steps.push(StepRecord {
            values: src.extract(&STEP_LOG),
        });
        if let Some(keep) = self.cfg.log_seconds
            && keep.is_finite()
        {
            let cut = log.steps.partition_point(|s| s.t() < t - keep);
            if cut > 1024 {
                log.steps.drain(..cut);
            }
        }
    }

    /// Ends the trial as `ended` (before classification by the final roll).
    fn end(&mut self, ended: Outcome) -> Outcome {
        let t = self.time();
        let r = &mut self.result;
        r.time = t;
        r.final_distance = self.rules.goal_distance(&self.pose);
        r.final_roll = self.pose.roll.to_degrees().abs();
        r.outcome = self.rules.classify(ended, r.final_roll);
        if r.outcome == Outcome::Success {
            r.traversal_time = Some(t);
        }
        self.ended = Some(r.outcome);
        r.outcome
    }

    /// Ends the trial as an error with `message`.
    fn fail(&mut self, message: String) -> Outcome {
        self.result.time = self.time();
        self.result.outcome = Outcome::Error;
        self.result.error = Some(message);
        self.ended = Some(Outcome::Error);
        Outcome::Error
    }

    /// Ends a running trial as an error (a system failed outside `step`, e.g. a Python
    /// exception); does nothing to an ended one.
    pub fn abort(&mut self, message: String) {
        if self.ended.is_none() {
            self.fail(message);
        }
    }

    /// The result, with the wall time since the trial started. A trial still running reports
    /// its metrics so far with outcome `error` and an error saying it did not end.
    pub fn finish(self) -> TrialResult {
        let mut r = self.result_so_far();
        r.wall_time = self.started.elapsed().as_secs_f64();
        r
    }

    /// The record being accumulated, without a copy: its running statistics (roll, pitch,
    /// throttle, steering, path length) are current; the end fields (outcome, time, final
    /// distance and roll) are set only once the trial has ended. See [`Trial::result_so_far`]
    /// for a complete record at any time.
    pub fn running_result(&self) -> &TrialResult {
        &self.result
    }

    /// The result as it stands (outcome `error` while running; `wall_time` 0).
    pub fn result_so_far(&self) -> TrialResult {
        let mut r = self.result.clone();
        if self.ended.is_none() {
            r.time = self.time();
            r.final_distance = self.rules.goal_distance(&self.pose);
            r.final_roll = self.pose.roll.to_degrees().abs();
            r.error = Some(format!(
                "the trial did not end (stopped at t = {:.2} s)",
                r.time
            ));
        }
        r
    }

    /// The observation a system sees now, with privileged access to this trial
    /// ([`Observation::trial`]; only oracle-type systems may use it).
    pub fn observation(&self) -> Observation<'_> {
        let truth = self.features();
        match &self.perception {
            None => Observation::new(&self.world, truth, self.task.goal, &self.info.global_path),
            Some(p) => Observation::new(
                p.world(),
                p.estimate(&truth),
                self.task.goal,
                &self.info.global_path,
            )
            .with_sensing(p.sensing(&self.pose, truth.forward_speed)),
        }
        .with_trial(self)
    }

    /// The perception model's state, when perception noise is on.
    pub fn perception(&self) -> Option<&Perception> {
        self.perception.as_deref()
    }

    /// A branch of this trial for looking ahead: a clone without the step log (a planner's
    /// rollouts need none, and copying a long log per rollout would dominate their cost). The
    /// branch steps exactly as the trial itself would.
    pub fn branch(&self) -> Trial {
        let log = None;
        Trial {
            world: self.world.clone(),
            sim: self.sim.clone(),
            state: self.state.clone(),
            task: self.task,
            info: self.info.clone(),
            cfg: EpisodeConfig {
                log_seconds: None,
                ..self.cfg.clone()
            },
            rules: self.rules.clone(),
            speed: self.speed,
            pose: self.pose,
            step_index: self.step_index,
            next_control: self.next_control,
            controls: self.controls,
            result: self.result.clone(),
            last_xy: self.last_xy,
            ended: self.ended,
            log,
            started: self.started,
            perception: self.perception.clone(),
        }
    }

    /// The features of the current state (for state vectors and logs).
    pub fn features(&self) -> FeatureSource {
        FeatureSource::new(
            &self.state,
            self.pose,
            self.time(),
            self.cfg.max_time,
            self.controls,
        )
    }

    /// Trial clock, s.
    pub fn time(&self) -> f64 {
        self.step_index as f64 * self.cfg.inner_dt
    }
    pub fn pose(&self) -> Pose6 {
        self.pose
    }
    pub fn state(&self) -> &SimState {
        &self.state
    }
    pub fn sim(&self) -> &Arc<Sim> {
        &self.sim
    }
    pub fn world(&self) -> &Arc<World> {
        &self.world
    }
    pub fn task(&self) -> &Task {
        &self.task
    }
    /// What the driving system is told at the start.
    pub fn info(&self) -> &TaskInfo {
        &self.info
    }
    pub fn config(&self) -> &EpisodeConfig {
        &self.cfg
    }
    /// Driver inputs applied in the latest inner step.
    pub fn controls(&self) -> Controls {
        self.controls
    }
    /// The final outcome once the trial has ended.
    pub fn outcome(&self) -> Option<Outcome> {
        self.ended
    }
    /// Planar distance to the goal now, m.
    pub fn goal_distance(&self) -> f64 {
        self.rules.goal_distance(&self.pose)
    }
    /// The per-step log kept so far (when `log_seconds` is set).
    pub fn log(&self) -> Option<&EpisodeLog> {
        self.log.as_ref()
    }
    /// Takes the per-step log out of the trial.
    pub fn take_log(&mut self) -> Option<EpisodeLog> {
        self.log.take()
    }
}
