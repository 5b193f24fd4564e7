//! The step-wise navigation environment behind `verti.envs` (gymnasium), in plain Rust.
//!
//! One [`EnvCore`] is one vehicle on one task at a time. A step holds one action for one control
//! period (0.1 s at the default 10 Hz) and runs the benchmark's inner loop inside it, exactly as
//! [`verti_bench::run_episode`] does for a system: the speed controller and the termination rules
//! run every inner step (10 ms), the rules through the shared [`Termination`] tracker. A policy
//! that acts like a benchmark system therefore gets the very same trajectory and outcome as the
//! benchmark (tested against `run_episode` with PID below).
//!
//! [`VecCore`] steps many cores in parallel with rayon; the Python layer calls it once per batch
//! with the GIL released.

use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};
use verti_bench::episode::{EpisodeConfig, Outcome, Termination, pose6};
use verti_bench::metrics::AngleStats;
use verti_bench::observation::{CropSpec, Pose6, test_observation};
use verti_bench::speed::SpeedController;
use verti_core::Rng;
use verti_render::{RenderOptions, WorldImage, render_world};
use verti_sim::{Controls, Sim, SimState, StartPose, VehicleSpec};
use verti_systems::path::PathFollower;
use verti_world::{ElevationLevel, ObstacleDensity, Task, TaskId, TerrainType, World};

/// Names of the entries of the state vector, in order.
pub const STATE_FIELDS: [&str; 13] = [
    "vx",        // body-frame linear velocity, m/s (x forward, y left, z up)
    "vy",        //
    "vz",        //
    "wx",        // body-frame angular velocity, rad/s
    "wy",        //
    "wz",        //
    "roll",      // rad
    "pitch",     // rad
    "sin_yaw",   // heading, as sine and cosine so it has no jump
    "cos_yaw",   //
    "steering",  // last applied steering input, [-1, 1]
    "drive",     // last applied throttle - brake, [-1, 1]
    "time_left", // 1 - t / max_time
];
pub const STATE_DIM: usize = STATE_FIELDS.len();

/// Outcome codes used in vectorised info arrays (-1 = still running).
pub fn outcome_code(o: Option<Outcome>) -> i8 {
    match o {
        None => -1,
        Some(o) => Outcome::ALL
            .iter()
            .position(|x| *x == o)
            .map_or(-1, |i| i as i8),
    }
}

/// What an action means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActionMode {
    /// (target speed, steering): the benchmark's speed controller turns the target speed into
    /// throttle and brake every inner step, as for the benchmark's high-level systems.
    HighLevel,
    /// (throttle, brake, steering), held for the whole control period.
    LowLevel,
}

impl ActionMode {
    pub fn dim(self) -> usize {
        match self {
            ActionMode::HighLevel => 2,
            ActionMode::LowLevel => 3,
        }
    }
}

/// An action in physical units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EnvAction {
    /// Target forward speed (m/s) and steering in [-1, 1].
    Speed {
        speed: f64,
        steering: f64,
    },
    Drive(Controls),
}

/// The default reward: the reference RL reward of Verti-Bench (spec §6.4) with its z-target
/// bug fixed. The reference measures progress as the 3-D distance to the local goal placed at
/// z = 0, so climbing or descending changes the reward as much as driving toward the goal;
/// here the distance is planar (the goal taken at the vehicle's own height). The local goal is
/// also held fixed over a step (the one chosen before it), so a lookahead jump is not paid as
/// progress.
///
/// Per control step: `progress · (d_before − d_after)`; `−no_progress_penalty` when the
/// progress is slower than `no_progress_speed` (full-scale m/s, scaled by √scale: the
/// reference's 0.01 m per 5 ms step is 2 m/s); for roll and pitch beyond `tilt_threshold_deg`
/// a penalty `−w · (|a| / threshold) · (|a| − threshold)` (radians); and at the end of an
/// episode a bonus or penalty by outcome (the timeout one grows by `timeout_per_metre` per
/// metre left to the goal). The reference applies the per-step terms every 5 ms; here they
/// apply once per control step.
#[derive(Clone, Debug, PartialEq)]
pub struct RewardConfig {
    pub progress: f64,
    pub no_progress_penalty: f64,
    pub no_progress_speed: f64,
    pub roll_weight: f64,
    pub pitch_weight: f64,
    pub tilt_threshold_deg: f64,
    pub success: f64,
    pub timeout: f64,
    pub timeout_per_metre: f64,
    pub stuck: f64,
    pub rollover: f64,
    pub error: f64,
}

impl Default for RewardConfig {
    fn default() -> Self {
        RewardConfig {
            progress: 50.0,
            no_progress_penalty: 10.0,
            no_progress_speed: 2.0,
            roll_weight: 20.0,
            pitch_weight: 20.0,
            tilt_threshold_deg: 30.0,
            success: 3000.0,
            timeout: -100.0,
            timeout_per_metre: -10.0,
            stuck: -300.0,
            // the reference has no rollover class: a rolled vehicle ends stuck (-300) there
            rollover: -300.0,
            // the reference's harshest penalty (leaving the map, -600) for a blown-up simulation
            error: -600.0,
        }
    }
}

impl RewardConfig {
    fn validate(&self) -> Result<(), String> {
        let all = [
            ("progress", self.progress),
            ("no_progress_penalty", self.no_progress_penalty),
            ("no_progress_speed", self.no_progress_speed),
            ("roll_weight", self.roll_weight),
            ("pitch_weight", self.pitch_weight),
            ("tilt_threshold_deg", self.tilt_threshold_deg),
            ("success", self.success),
            ("timeout", self.timeout),
            ("timeout_per_metre", self.timeout_per_metre),
            ("stuck", self.stuck),
            ("rollover", self.rollover),
            ("error", self.error),
        ];
        for (name, v) in all {
            if !v.is_finite() {
                return Err(format!("reward weight {name} = {v} is not a finite number"));
            }
        }
        if !(self.tilt_threshold_deg > 0.0 && self.tilt_threshold_deg < 180.0) {
            return Err(format!(
                "reward tilt_threshold_deg = {} must be in (0, 180)",
                self.tilt_threshold_deg
            ));
        }
        Ok(())
    }
}

/// The parts of one step's default reward (their sum is the reward).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RewardTerms {
    pub progress: f64,
    pub no_progress: f64,
    pub roll: f64,
    pub pitch: f64,
    pub terminal: f64,
}

impl RewardTerms {
    pub fn total(&self) -> f64 {
        self.progress + self.no_progress + self.roll + self.pitch + self.terminal
    }
}

/// Which tasks a core samples from at reset.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TaskFilter {
    /// Global task numbers (as in `verti eval --tasks`); empty = every task of the worlds.
    pub tasks: Vec<u32>,
    pub levels: Vec<ElevationLevel>,
    pub densities: Vec<ObstacleDensity>,
    pub terrain_types: Vec<TerrainType>,
}

/// Settings of an environment.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvConfig {
    /// Rules, time limit and inner step of the benchmark.
    pub episode: EpisodeConfig,
    /// Actions per simulated second; the control period must be a whole number of inner steps.
    pub control_rate: f64,
    pub action: ActionMode,
    /// Target speed of a normalised high-level action of 1, full-scale m/s (scaled by √scale).
    pub max_speed: f64,
    /// Local goal distance along the global path, full-scale metres (scaled by the world).
    pub lookahead: f64,
    pub elevation: Option<CropSpec>,
    pub semantic: Option<CropSpec>,
    pub occupancy: Option<CropSpec>,
    pub reward: RewardConfig,
}

impl Default for EnvConfig {
    fn default() -> Self {
        EnvConfig {
            episode: EpisodeConfig::default(),
            control_rate: 10.0,
            action: ActionMode::HighLevel,
            max_speed: 4.0,
            lookahead: 10.0,
            elevation: None,
            semantic: None,
            occupancy: None,
            reward: RewardConfig::default(),
        }
    }
}

impl EnvConfig {
    /// Inner steps per control step.
    pub fn inner_steps(&self) -> usize {
        (1.0 / self.control_rate / self.episode.inner_dt).round() as usize
    }

    pub fn validate(&self) -> Result<(), String> {
        self.episode.validate()?;
        if !(self.control_rate.is_finite()
            && self.control_rate > 0.0
            && self.control_rate <= 1000.0)
        {
            return Err(format!(
                "control_rate = {} Hz must be in (0, 1000]",
                self.control_rate
            ));
        }
        let period = 1.0 / self.control_rate;
        let k = (period / self.episode.inner_dt).round();
        if k < 1.0 || (k * self.episode.inner_dt - period).abs() > 1e-9 * period.max(1.0) {
            return Err(format!(
                "the control period 1/control_rate = {period} s must be a whole number of inner steps of {} s",
                self.episode.inner_dt
            ));
        }
        if !(self.max_speed.is_finite() && self.max_speed > 0.0 && self.max_speed <= 50.0) {
            return Err(format!(
                "max_speed = {} m/s must be in (0, 50]",
                self.max_speed
            ));
        }
        if !(self.lookahead.is_finite() && self.lookahead > 0.0 && self.lookahead <= 100.0) {
            return Err(format!(
                "lookahead = {} m must be in (0, 100]",
                self.lookahead
            ));
        }
        for (name, crop) in [
            ("elevation", self.elevation),
            ("semantic", self.semantic),
            ("occupancy", self.occupancy),
        ] {
            if let Some(c) = crop
                && !(c.size >= 1
                    && c.size <= 512
                    && c.resolution.is_finite()
                    && c.resolution > 0.0
                    && c.resolution <= 100.0)
            {
                return Err(format!(
                    "{name} patch: size {} must be in 1..=512 cells and resolution {} in (0, 100] m",
                    c.size, c.resolution
                ));
            }
        }
        self.reward.validate()
    }
}

/// The tasks of `worlds` that pass `filter`, as (world position in `worlds`, pair).
pub fn task_pool(worlds: &[Arc<World>], filter: &TaskFilter) -> Result<Vec<(usize, u32)>, String> {
    if worlds.is_empty() {
        return Err("no worlds given".into());
    }
    let all = verti_bench::eval::select_tasks(worlds, &filter.tasks).map_err(|e| e.to_string())?;
    let keep = |w: &World| {
        (filter.levels.is_empty() || filter.levels.contains(&w.meta.level))
            && (filter.densities.is_empty() || filter.densities.contains(&w.meta.density))
            && (filter.terrain_types.is_empty()
                || filter.terrain_types.contains(&w.meta.terrain_type))
    };
    let pool: Vec<(usize, u32)> = all
        .into_iter()
        .filter(|&(wi, _)| keep(&worlds[wi]))
        .collect();
    if pool.is_empty() {
        let names = |v: Vec<&str>| {
            if v.is_empty() {
                "any".to_string()
            } else {
                v.join("/")
            }
        };
        return Err(format!(
            "no task of the {} world(s) matches the filters (levels: {}, densities: {}, terrain types: {}{})",
            worlds.len(),
            names(filter.levels.iter().map(|l| l.name()).collect()),
            names(filter.densities.iter().map(|d| d.name()).collect()),
            names(filter.terrain_types.iter().map(|t| t.name()).collect()),
            if filter.tasks.is_empty() {
                String::new()
            } else {
                format!(", {} selected task numbers", filter.tasks.len())
            }
        ));
    }
    Ok(pool)
}

/// What a step reports besides the observation.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    pub reward: f64,
    pub terms: RewardTerms,
    /// Set when the episode ended in this step.
    pub outcome: Option<Outcome>,
    pub terminated: bool,
    pub truncated: bool,
}

impl StepReport {
    /// The report of an environment that was reset instead of stepped.
    pub fn idle() -> StepReport {
        StepReport {
            reward: 0.0,
            terms: RewardTerms::default(),
            outcome: None,
            terminated: false,
            truncated: false,
        }
    }
}

/// Per-episode metrics, like the benchmark's trial results.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EpisodeMetrics {
    pub time: f64,
    pub path_length: f64,
    pub roll: AngleStats,
    pub pitch: AngleStats,
    pub distance_to_goal: f64,
    pub traversal_time: Option<f64>,
    pub final_roll_deg: f64,
    pub error: Option<String>,
}

/// One running episode.
#[derive(Clone)]
pub struct Episode {
    pub world: usize,
    pub task: Task,
    pub id: TaskId,
    sim: Arc<Sim>,
    state: SimState,
    rules: Termination,
    follower: PathFollower,
    pose: Pose6,
    inner_steps: u64,
    pub control_steps: u64,
    last_controls: Controls,
    pub outcome: Option<Outcome>,
    pub metrics: EpisodeMetrics,
    local_goal: [f64; 2],
    /// (x, y) at the start and after every control step, for rendering.
    pub trail: Vec<[f64; 2]>,
}

impl Episode {
    pub fn pose(&self) -> Pose6 {
        self.pose
    }
    pub fn state(&self) -> &SimState {
        &self.state
    }
    pub fn local_goal(&self) -> [f64; 2] {
        self.local_goal
    }
    pub fn time(&self) -> f64 {
        self.metrics.time
    }
    /// The simulator of this episode (shared, immutable).
    pub fn sim_arc(&self) -> Arc<Sim> {
        self.sim.clone()
    }
}

/// Observation buffers of one environment (crops are empty when switched off).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObsBuf {
    pub state: [f32; STATE_DIM],
    pub goal: [f32; 2],
    pub local_goal: [f32; 2],
    pub elevation: Vec<f32>,
    pub semantic: Vec<u8>,
    pub occupancy: Vec<u8>,
}

/// Live simulators by (world position, pair).
type SimCache = Arc<Mutex<HashMap<(usize, u32), Weak<Sim>>>>;

/// A world, a vehicle and the benchmark's rules, stepped one control period at a time.
#[derive(Clone)]
pub struct EnvCore {
    worlds: Arc<Vec<Arc<World>>>,
    spec: Arc<VehicleSpec>,
    cfg: Arc<EnvConfig>,
    pool: Arc<Vec<(usize, u32)>>,
    rng: Rng,
    /// Sims in use, by (world, pair), shared with the siblings of a vector environment.
    /// Building one takes about 1 ms and holds about 0.5 MB (obstacle and soil layouts), so
    /// only live ones are kept (weak references): memory stays at most one Sim per
    /// environment, and a reset onto a task some environment is driving reuses its Sim.
    sims: SimCache,
    ep: Option<Episode>,
    /// Rendered map of the current world and task (drawn once, copied per frame).
    base_image: Option<((usize, u32, u32), WorldImage)>,
}

fn planar(x: f64, y: f64, p: [f64; 2]) -> f64 {
    ((x - p[0]).powi(2) + (y - p[1]).powi(2)).sqrt()
}

fn to_body(pose: &Pose6, p: [f64; 2]) -> [f32; 2] {
    let (s, c) = pose.yaw.sin_cos();
    let (dx, dy) = (p[0] - pose.x, p[1] - pose.y);
    [(c * dx + s * dy) as f32, (-s * dx + c * dy) as f32]
}

impl EnvCore {
    pub fn new(
        worlds: Vec<Arc<World>>,
        spec: VehicleSpec,
        cfg: EnvConfig,
        filter: &TaskFilter,
        seed: u64,
    ) -> Result<EnvCore, String> {
        cfg.validate()?;
        spec.validate(&spec.name).map_err(|e| e.to_string())?;
        let pool = task_pool(&worlds, filter)?;
        Ok(EnvCore {
            worlds: Arc::new(worlds),
            spec: Arc::new(spec),
            cfg: Arc::new(cfg),
            pool: Arc::new(pool),
            rng: Rng::new(seed),
            sims: Arc::new(Mutex::new(HashMap::new())),
            ep: None,
            base_image: None,
        })
    }

    /// A copy for another slot of a vector environment (shares worlds, vehicle and settings).
    pub fn sibling(&self, seed: u64) -> EnvCore {
        EnvCore {
            rng: Rng::new(seed),
            ep: None,
            base_image: None,
            ..self.clone()
        }
    }

    pub fn config(&self) -> &EnvConfig {
        &self.cfg
    }
    pub fn worlds(&self) -> &[Arc<World>] {
        &self.worlds
    }
    pub fn spec(&self) -> &VehicleSpec {
        &self.spec
    }
    pub fn pool(&self) -> &[(usize, u32)] {
        &self.pool
    }
    pub fn episode(&self) -> Option<&Episode> {
        self.ep.as_ref()
    }

    /// Starts an episode. `seed` reseeds the task sampler (as gymnasium's `reset(seed=...)`);
    /// `task` picks a global task number of the worlds instead of sampling one.
    pub fn reset(&mut self, seed: Option<u64>, task: Option<u32>) -> Result<(), String> {
        if let Some(s) = seed {
            self.rng = Rng::new(s);
        }
        let (wi, pair) = match task {
            Some(n) => {
                verti_bench::eval::select_tasks(&self.worlds, &[n]).map_err(|e| e.to_string())?[0]
            }
            None => self.pool[self.rng.below(self.pool.len() as u64) as usize],
        };
        let world = &self.worlds[wi];
        let task = *world
            .tasks
            .iter()
            .find(|t| t.pair == pair)
            .ok_or_else(|| format!("world {} has no pair {pair}", world.meta.name))?;
        let cached = self
            .sims
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get(&(wi, pair))
            .and_then(Weak::upgrade);
        let sim = match cached {
            Some(s) => s,
            None => {
                let built = Sim::new(world, &self.spec).map_err(|e| {
                    format!(
                        "cannot start the simulation on {} pair {pair}: {e}",
                        world.meta.name
                    )
                })?;
                let s = Arc::new(built);
                let mut sims = self.sims.lock().unwrap_or_else(|p| p.into_inner());
                if sims.len() >= 1024 {
                    sims.retain(|_, w| w.strong_count() > 0);
                }
                sims.insert((wi, pair), Arc::downgrade(&s));
                s
            }
        };
        let start = StartPose::new(task.start[0], task.start[1], task.start_yaw());
        let state = sim.state_at(start).map_err(|e| {
            format!(
                "cannot start the simulation on {} pair {pair}: {e}",
                world.meta.name
            )
        })?;
        let pose = pose6(&sim, &state);
        let path = world
            .paths
            .get(world.tasks.iter().position(|t| t.pair == pair).unwrap_or(0))
            .map(|p| p.points.clone())
            .unwrap_or_default();
        let mut follower = PathFollower::new(path);
        let local_goal = follower.local_goal(
            pose.x,
            pose.y,
            self.cfg.lookahead * world.meta.scale,
            task.goal,
        );
        let rules = Termination::new(world, task.goal, &self.cfg.episode, &pose);
        let metrics = EpisodeMetrics {
            distance_to_goal: rules.goal_distance(&pose),
            ..Default::default()
        };
        self.ep = Some(Episode {
            world: wi,
            id: world.task_id(pair),
            task,
            sim,
            state,
            rules,
            follower,
            pose,
            inner_steps: 0,
            control_steps: 0,
            last_controls: Controls::IDLE,
            outcome: None,
            metrics,
            local_goal,
            trail: vec![[pose.x, pose.y]],
        });
        Ok(())
    }

    /// Maps a normalised action (the gymnasium action space) to physical units, clipping it to
    /// the box: high-level (speed, steering) in [-1, 1]² with speed · max_speed · √scale m/s;
    /// low-level (throttle, brake, steering) in [0, 1] × [0, 1] × [-1, 1].
    pub fn action_from_normalized(&self, a: &[f64]) -> Result<EnvAction, String> {
        let dim = self.cfg.action.dim();
        if a.len() != dim {
            return Err(format!(
                "expected an action of {dim} numbers, got {}",
                a.len()
            ));
        }
        if let Some(bad) = a.iter().find(|v| !v.is_finite()) {
            return Err(format!("action {a:?} contains a non-finite value ({bad})"));
        }
        let scale = self
            .ep
            .as_ref()
            .map_or(1.0, |e| self.worlds[e.world].meta.scale);
        Ok(match self.cfg.action {
            ActionMode::HighLevel => EnvAction::Speed {
                speed: a[0].clamp(-1.0, 1.0) * self.cfg.max_speed * scale.sqrt(),
                steering: a[1].clamp(-1.0, 1.0),
            },
            ActionMode::LowLevel => EnvAction::Drive(Controls::new(
                a[0].clamp(0.0, 1.0),
                a[1].clamp(0.0, 1.0),
                a[2].clamp(-1.0, 1.0),
            )),
        })
    }

    /// Holds `action` for one control period. Errors if no episode runs or it has ended.
    pub fn step(&mut self, action: EnvAction) -> Result<StepReport, String> {
        let cfg = self.cfg.clone();
        let ep = self.ep.as_mut().ok_or("call reset() before step()")?;
        if ep.outcome.is_some() {
            return Err("the episode has ended; call reset() before step()".into());
        }
        match action {
            EnvAction::Speed { speed, steering }
                if !(speed.is_finite() && steering.is_finite()) =>
            {
                return Err(format!(
                    "invalid action: speed {speed}, steering {steering} must be finite"
                ));
            }
            EnvAction::Drive(c) => c.validate().map_err(|e| e.to_string())?,
            _ => {}
        }
        let world = &self.worlds[ep.world];
        let scale = world.meta.scale;
        let dt = cfg.episode.inner_dt;
        let speed = SpeedController::default();
        // the local goal is chosen before the step and held for its progress reward
        let lg = ep
            .follower
            .local_goal(ep.pose.x, ep.pose.y, cfg.lookahead * scale, ep.task.goal);
        ep.local_goal = lg;
        let d_before = planar(ep.pose.x, ep.pose.y, lg);
        for _ in 0..cfg.inner_steps() {
            let controls = match action {
                EnvAction::Speed {
                    speed: target,
                    steering,
                } => speed.controls(target, ep.state.forward_speed(), steering),
                EnvAction::Drive(c) => c,
            };
            ep.last_controls = controls;
            if let Err(e) = ep.sim.step(&mut ep.state, controls, dt) {
                let t = ep.inner_steps as f64 * dt;
                ep.metrics.error = Some(format!("simulation failed at t = {t:.2} s: {e}"));
                ep.outcome = Some(Outcome::Error);
                break;
            }
            ep.inner_steps += 1;
            let t = ep.inner_steps as f64 * dt;
            let pose = pose6(&ep.sim, &ep.state);
            ep.metrics.roll.push_rad(pose.roll);
            ep.metrics.pitch.push_rad(pose.pitch);
            ep.metrics.path_length += planar(pose.x, pose.y, [ep.pose.x, ep.pose.y]);
            ep.metrics.time = t;
            ep.pose = pose;
            if let Some(ended) = ep.rules.check(t, dt, &pose) {
                let final_roll = pose.roll.to_degrees().abs();
                let outcome = ep.rules.classify(ended, final_roll);
                ep.metrics.final_roll_deg = final_roll;
                if outcome == Outcome::Success {
                    ep.metrics.traversal_time = Some(t);
                }
                ep.outcome = Some(outcome);
                break;
            }
        }
        ep.control_steps += 1;
        ep.trail.push([ep.pose.x, ep.pose.y]);
        ep.metrics.distance_to_goal = ep.rules.goal_distance(&ep.pose);

        // --- reward
        let w = &cfg.reward;
        let d_after = planar(ep.pose.x, ep.pose.y, lg);
        let gained = d_before - d_after;
        let period = 1.0 / cfg.control_rate;
        let threshold = w.tilt_threshold_deg.to_radians();
        let tilt = |a: f64, weight: f64| {
            let a = a.abs();
            if a > threshold {
                -weight * (a / threshold) * (a - threshold)
            } else {
                0.0
            }
        };
        let terminal = match ep.outcome {
            None => 0.0,
            Some(Outcome::Success) => w.success,
            Some(Outcome::Timeout) => w.timeout + w.timeout_per_metre * ep.metrics.distance_to_goal,
            Some(Outcome::Stuck) => w.stuck,
            Some(Outcome::Rollover) => w.rollover,
            Some(Outcome::Error) => w.error,
        };
        let terms = RewardTerms {
            progress: w.progress * gained,
            no_progress: if gained.abs() < w.no_progress_speed * scale.sqrt() * period {
                -w.no_progress_penalty
            } else {
                0.0
            },
            roll: tilt(ep.pose.roll, w.roll_weight),
            pitch: tilt(ep.pose.pitch, w.pitch_weight),
            terminal,
        };
        Ok(StepReport {
            reward: terms.total(),
            terms,
            outcome: ep.outcome,
            terminated: matches!(ep.outcome, Some(o) if o != Outcome::Timeout),
            truncated: ep.outcome == Some(Outcome::Timeout),
        })
    }

    /// Writes the observation of the current state into `buf` (resizing crop buffers).
    pub fn observe(&self, buf: &mut ObsBuf) -> Result<(), String> {
        let ep = self.ep.as_ref().ok_or("call reset() first")?;
        let world = &self.worlds[ep.world];
        let p = ep.pose;
        let v = ep.state.velocity_body();
        let w = ep.state.angular_velocity_body();
        let (s, c) = p.yaw.sin_cos();
        let lc = ep.last_controls;
        buf.state = [
            v.x,
            v.y,
            v.z,
            w.x,
            w.y,
            w.z,
            p.roll,
            p.pitch,
            s,
            c,
            lc.steering,
            lc.throttle - lc.brake,
            1.0 - ep.metrics.time / self.cfg.episode.max_time,
        ]
        .map(|x| x as f32);
        buf.goal = to_body(&p, ep.task.goal);
        buf.local_goal = to_body(&p, ep.local_goal);
        // Crops only read the world and (x, y, yaw); the benchmark's observation type gives
        // them heading-aligned exactly as systems see them.
        let obs = test_observation(world, [p.x, p.y], p.yaw, ep.task.goal, &[]);
        if let Some(spec) = self.cfg.elevation {
            let ground = world.terrain.height_at(p.x, p.y);
            buf.elevation.clear();
            buf.elevation.extend(
                obs.elevation_crop(spec)
                    .data
                    .iter()
                    .map(|h| (h - ground) as f32),
            );
        }
        if let Some(spec) = self.cfg.semantic {
            buf.semantic = obs.semantic_crop(spec).data;
        }
        if let Some(spec) = self.cfg.occupancy {
            buf.occupancy = obs.occupancy_crop(spec).data;
        }
        Ok(())
    }

    /// A top view of the world with the current task, the vehicle's trail and the vehicle.
    pub fn render(&mut self, pixels_per_cell: u32) -> Result<image::RgbImage, String> {
        let ep = self.ep.as_ref().ok_or("call reset() before render()")?;
        let key = (ep.world, ep.task.pair, pixels_per_cell);
        if self.base_image.as_ref().is_none_or(|(k, _)| *k != key) {
            let opts = RenderOptions {
                pixels_per_cell,
                pairs: Some(vec![ep.task.pair]),
                show_legend: false,
                show_title: false,
                ..Default::default()
            };
            let img = render_world(&self.worlds[ep.world], &opts).map_err(|e| e.to_string())?;
            self.base_image = Some((key, img));
        }
        let (_, base) = self.base_image.as_ref().expect("rendered above");
        let mut img = base.clone();
        let unit = f64::from(pixels_per_cell);
        let ink = image::Rgb([20, 20, 30]);
        let trail_color = image::Rgb([255, 200, 0]);
        if ep.trail.len() >= 2 {
            img.draw_polyline(&ep.trail, &[ink], 0.6 * unit + 3.0);
            img.draw_polyline(&ep.trail, &[trail_color], 0.6 * unit + 1.0);
        }
        // the vehicle: an arrow-head of its length, pointing along its heading
        let p = ep.pose;
        let len = (self.spec.wheelbase() * 1.4).max(2.0 * self.worlds[ep.world].terrain.cell());
        let (s, c) = p.yaw.sin_cos();
        let at = |ahead: f64, left: f64| [p.x + ahead * c - left * s, p.y + ahead * s + left * c];
        let arrow = [
            at(0.6 * len, 0.0),
            at(-0.4 * len, 0.35 * len),
            at(-0.2 * len, 0.0),
            at(-0.4 * len, -0.35 * len),
            at(0.6 * len, 0.0),
        ];
        img.draw_polyline(&arrow, &[ink], 0.5 * unit + 3.0);
        img.draw_polyline(&arrow, &[image::Rgb([0, 120, 255])], 0.5 * unit + 1.0);
        Ok(img.image)
    }
}

/// One environment's share of a batch step: index, core, observation, report, pending reset
/// and action.
type Slot<'a> = (
    usize,
    (
        (
            ((&'a mut EnvCore, &'a mut ObsBuf), &'a mut StepReport),
            &'a mut bool,
        ),
        &'a EnvAction,
    ),
);

/// Many environments stepped together, in parallel, with next-step autoreset (gymnasium's
/// default): an environment whose episode ended is reset by the following `step`, which
/// ignores its action and reports reward 0 for it.
pub struct VecCore {
    pub envs: Vec<EnvCore>,
    pub obs: Vec<ObsBuf>,
    pub reports: Vec<StepReport>,
    /// Reset by the next step.
    pub pending_reset: Vec<bool>,
    pool: rayon::ThreadPool,
    threads: usize,
}

impl VecCore {
    pub fn new(template: EnvCore, n: usize, threads: usize) -> Result<VecCore, String> {
        if n == 0 {
            return Err("num_envs must be at least 1".into());
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| format!("cannot start {threads} worker threads: {e}"))?;
        let envs: Vec<EnvCore> = (0..n).map(|i| template.sibling(i as u64)).collect();
        Ok(VecCore {
            obs: vec![ObsBuf::default(); n],
            reports: vec![StepReport::idle(); n],
            pending_reset: vec![false; n],
            envs,
            pool,
            threads,
        })
    }

    pub fn len(&self) -> usize {
        self.envs.len()
    }
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    /// Resets every environment, environment i with `seeds[i]` when seeds are given.
    pub fn reset(&mut self, seeds: Option<&[u64]>) -> Result<(), String> {
        if let Some(s) = seeds
            && s.len() != self.envs.len()
        {
            return Err(format!(
                "expected {} seeds (one per environment), got {}",
                self.envs.len(),
                s.len()
            ));
        }
        let envs = &mut self.envs;
        let obs = &mut self.obs;
        self.pool.install(|| {
            envs.par_iter_mut()
                .zip(obs.par_iter_mut())
                .enumerate()
                .try_for_each(|(i, (env, buf))| {
                    env.reset(seeds.map(|s| s[i]), None)?;
                    env.observe(buf)
                })
        })?;
        self.pending_reset.iter_mut().for_each(|p| *p = false);
        for r in &mut self.reports {
            *r = StepReport::idle();
        }
        Ok(())
    }

    /// Steps every environment with its row of `actions` (normalised, `n × dim`, row-major).
    pub fn step(&mut self, actions: &[f64]) -> Result<(), String> {
        let dim = self.envs.first().map_or(0, |e| e.config().action.dim());
        if actions.len() != dim * self.envs.len() {
            return Err(format!(
                "expected actions of shape ({}, {dim}), got {} numbers",
                self.envs.len(),
                actions.len()
            ));
        }
        // convert (and so validate) every action before stepping any environment
        let converted: Vec<EnvAction> = self
            .envs
            .iter()
            .zip(actions.chunks(dim))
            .enumerate()
            .map(|(i, (env, a))| {
                env.action_from_normalized(a)
                    .map_err(|e| format!("environment {i}: {e}"))
            })
            .collect::<Result<_, _>>()?;
        let one = |(i, ((((env, buf), report), pending), action)): Slot<'_>| -> Result<(), String> {
            if *pending {
                env.reset(None, None)
                    .map_err(|e| format!("environment {i}: {e}"))?;
                *report = StepReport::idle();
                *pending = false;
            } else {
                *report = env
                    .step(*action)
                    .map_err(|e| format!("environment {i}: {e}"))?;
                *pending = report.terminated || report.truncated;
            }
            env.observe(buf)
        };
        let (envs, obs, reports, pending) = (
            &mut self.envs,
            &mut self.obs,
            &mut self.reports,
            &mut self.pending_reset,
        );
        if self.threads == 1 {
            // on the calling thread: handing a batch to a one-thread pool costs a wake-up
            // (tens of µs on a busy machine) for nothing
            return envs
                .iter_mut()
                .zip(obs.iter_mut())
                .zip(reports.iter_mut())
                .zip(pending.iter_mut())
                .zip(converted.iter())
                .enumerate()
                .try_for_each(one);
        }
        self.pool.install(|| {
            envs.par_iter_mut()
                .zip(obs.par_iter_mut())
                .zip(reports.par_iter_mut())
                .zip(pending.par_iter_mut())
                .zip(converted.par_iter())
                .enumerate()
                .try_for_each(one)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_bench::episode::{run_episode, task_info};
    use verti_world::generate::{
        SetConfig, composition, elevation::ProceduralRock, generate_world,
    };

    fn world(index: u32) -> Arc<World> {
        let config = SetConfig {
            count: 100,
            ..Default::default()
        };
        let (l, t, d) = composition(&config)[index as usize - 1];
        Arc::new(generate_world(&config, index, l, t, d, &ProceduralRock::default()).unwrap())
    }

    fn hmmwv() -> VehicleSpec {
        verti_sim::vehicles::builtin("hmmwv").unwrap()
    }

    /// A PID system driving through the environment gets exactly the benchmark's trial.
    #[test]
    fn pid_through_the_env_reproduces_run_episode() {
        let w = world(1);
        let spec = hmmwv();
        let pair = 3;
        let cfg = EpisodeConfig {
            max_time: 20.0,
            ..Default::default()
        };
        let mut pid = verti_systems::create("pid", &[]).unwrap();
        let reference = run_episode(&w, &spec, pair, pid.as_mut(), &cfg, None);

        let env_cfg = EnvConfig {
            episode: cfg.clone(),
            control_rate: pid.control_rate(),
            ..Default::default()
        };
        let mut env = EnvCore::new(
            vec![w.clone()],
            spec.clone(),
            env_cfg,
            &TaskFilter::default(),
            0,
        )
        .unwrap();
        env.reset(None, Some(w.task_id(pair).number())).unwrap();
        let mut pid = verti_systems::create("pid", &[]).unwrap();
        pid.reset(&task_info(&w, &spec, pair, cfg.seed).unwrap());
        let report = loop {
            let ep = env.episode().unwrap();
            let p = ep.pose();
            let obs = test_observation(&w, [p.x, p.y], p.yaw, ep.task.goal, &[]);
            let action = match pid.act(&obs) {
                verti_bench::Action::HighLevel { speed, steering } => {
                    EnvAction::Speed { speed, steering }
                }
                verti_bench::Action::LowLevel(c) => EnvAction::Drive(c),
            };
            let r = env.step(action).unwrap();
            if r.terminated || r.truncated {
                break r;
            }
        };
        let m = &env.episode().unwrap().metrics;
        assert_eq!(report.outcome, Some(reference.outcome));
        assert_eq!(m.time, reference.time);
        assert_eq!(m.path_length, reference.path_length);
        assert_eq!(m.distance_to_goal, reference.final_distance);
        assert_eq!(m.roll, reference.roll);
        assert_eq!(m.traversal_time, reference.traversal_time);
        assert!(
            m.path_length > 5.0,
            "the PID drove somewhere: {}",
            m.path_length
        );
    }

    #[test]
    fn same_seed_same_episode_and_parallel_equals_serial() {
        let w = world(2);
        let mut a = EnvCore::new(
            vec![w.clone()],
            hmmwv(),
            EnvConfig::default(),
            &TaskFilter::default(),
            0,
        )
        .unwrap();
        let mut b = a.sibling(99);
        a.reset(Some(7), None).unwrap();
        b.reset(Some(7), None).unwrap();
        assert_eq!(a.episode().unwrap().id, b.episode().unwrap().id);
        for k in 0..20 {
            let act = a
                .action_from_normalized(&[0.8, (k as f64 * 0.3).sin()])
                .unwrap();
            assert_eq!(a.step(act).unwrap(), b.step(act).unwrap());
        }
        let (mut oa, mut ob) = (ObsBuf::default(), ObsBuf::default());
        a.observe(&mut oa).unwrap();
        b.observe(&mut ob).unwrap();
        assert_eq!(oa, ob);

        // a vector of 3 stepped in parallel equals the same environments stepped one by one
        let mut v = VecCore::new(a.sibling(0), 3, 2).unwrap();
        v.reset(Some(&[5, 6, 7])).unwrap();
        let mut serial: Vec<EnvCore> = (0..3).map(|i| a.sibling(0).tap_reset(5 + i)).collect();
        for k in 0..15 {
            let acts: Vec<f64> = (0..3)
                .flat_map(|i| [1.0, 0.2 * (i as f64 - 1.0) + 0.01 * k as f64])
                .collect();
            v.step(&acts).unwrap();
            for (i, env) in serial.iter_mut().enumerate() {
                let r = env
                    .step(env.action_from_normalized(&acts[2 * i..2 * i + 2]).unwrap())
                    .unwrap();
                assert_eq!(r, v.reports[i]);
                let mut o = ObsBuf::default();
                env.observe(&mut o).unwrap();
                assert_eq!(o, v.obs[i]);
            }
        }
    }

    trait TapReset {
        fn tap_reset(self, seed: u64) -> Self;
    }
    impl TapReset for EnvCore {
        fn tap_reset(mut self, seed: u64) -> Self {
            self.reset(Some(seed), None).unwrap();
            self
        }
    }

    #[test]
    fn rejects_bad_settings_and_actions() {
        let w = world(3);
        let bad = EnvConfig {
            control_rate: 7.0,
            ..Default::default()
        };
        let e = EnvCore::new(vec![w.clone()], hmmwv(), bad, &TaskFilter::default(), 0)
            .err()
            .unwrap();
        assert!(e.contains("whole number of inner steps"), "{e}");
        let filter = TaskFilter {
            levels: vec![],
            tasks: vec![5000],
            ..Default::default()
        };
        let e = EnvCore::new(vec![w.clone()], hmmwv(), EnvConfig::default(), &filter, 0)
            .err()
            .unwrap();
        assert!(e.contains("not in this world set"), "{e}");
        let other = if w.meta.level == ElevationLevel::Low {
            ElevationLevel::High
        } else {
            ElevationLevel::Low
        };
        let filter = TaskFilter {
            levels: vec![other],
            ..Default::default()
        };
        let e = EnvCore::new(vec![w.clone()], hmmwv(), EnvConfig::default(), &filter, 0)
            .err()
            .unwrap();
        assert!(e.contains("no task"), "{e}");
        let mut env = EnvCore::new(
            vec![w],
            hmmwv(),
            EnvConfig::default(),
            &TaskFilter::default(),
            0,
        )
        .unwrap();
        assert!(
            env.step(EnvAction::Speed {
                speed: 1.0,
                steering: 0.0
            })
            .unwrap_err()
            .contains("reset")
        );
        env.reset(Some(1), None).unwrap();
        assert!(env.action_from_normalized(&[f64::NAN, 0.0]).is_err());
        assert!(env.action_from_normalized(&[0.0]).is_err());
        assert!(
            env.step(EnvAction::Drive(Controls::new(2.0, 0.0, 0.0)))
                .unwrap_err()
                .contains("throttle")
        );
    }

    #[test]
    fn progress_reward_is_planar() {
        // a stopped vehicle gains nothing and pays the no-progress penalty; driving toward the
        // local goal earns about 50 per metre
        let w = world(4);
        let mut env = EnvCore::new(
            vec![w],
            hmmwv(),
            EnvConfig::default(),
            &TaskFilter::default(),
            0,
        )
        .unwrap();
        env.reset(Some(3), None).unwrap();
        let r = env
            .step(EnvAction::Drive(Controls::new(0.0, 1.0, 0.0)))
            .unwrap();
        assert!(
            r.terms.progress.abs() < 5.0 && r.terms.no_progress == -10.0,
            "{r:?}"
        );
        let mut total = 0.0;
        for _ in 0..40 {
            total += env
                .step(EnvAction::Speed {
                    speed: 4.0,
                    steering: 0.0,
                })
                .unwrap()
                .terms
                .progress;
        }
        let m = &env.episode().unwrap().metrics;
        assert!(
            total > 0.0 && total <= 50.0 * m.path_length + 1e-6,
            "progress {total} for {} m",
            m.path_length
        );
    }
}
