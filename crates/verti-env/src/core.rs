//! [`EnvCore`]: one vehicle on one task at a time, stepped one control period per call.
//!
//! A step holds one action for one control period (0.1 s at the default 10 Hz) through
//! [`Trial::step`], the very inner loop the benchmark runs for its systems (speed controller,
//! physics, metrics and rules every inner step). A policy that acts like a benchmark system
//! therefore gets the same trajectory and outcome as under `verti eval`. The environment adds
//! only what a learner needs: task sampling, the reward, and the observation encoding.

use crate::config::{ActionMode, EnvConfig, TaskFilter, task_pool};
use crate::error::EnvError;
use crate::reward::{RewardTerms, StepProgress};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, Weak};
use verti_bench::episode::{Outcome, TrialResult};
use verti_bench::observation::{Observation, Pose6};
use verti_bench::path::PathFollower;
use verti_bench::{Action, Trial};
use verti_core::Rng;
use verti_render::{RenderOptions, WorldImage, render_world};
use verti_sim::{Controls, Sim, SimState, VehicleSpec};
use verti_world::{Task, TaskId, World};

/// What a step reports besides the observation.
#[derive(Clone, Debug, PartialEq)]
pub struct StepReport {
    pub reward: f64,
    pub terms: RewardTerms,
    /// Set when the episode ended in this step.
    pub outcome: Option<Outcome>,
    /// Ended by the task's rules (success, stuck, rollover, error): gymnasium's `terminated`.
    pub terminated: bool,
    /// Ended by the time limit: gymnasium's `truncated`.
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

/// One running episode: the benchmark trial plus what the reward and rendering need.
#[derive(Clone)]
pub struct Episode {
    /// Position of the world in the environment's world list.
    pub world: usize,
    pub id: TaskId,
    trial: Trial,
    follower: PathFollower,
    local_goal: [f64; 2],
    pub control_steps: u64,
    /// (x, y) at the start and after every control step, for rendering.
    pub trail: Vec<[f64; 2]>,
}

impl Episode {
    /// The benchmark trial being driven.
    pub fn trial(&self) -> &Trial {
        &self.trial
    }
    pub fn task(&self) -> &Task {
        self.trial.task()
    }
    pub fn pose(&self) -> Pose6 {
        self.trial.pose()
    }
    pub fn state(&self) -> &SimState {
        self.trial.state()
    }
    pub fn local_goal(&self) -> [f64; 2] {
        self.local_goal
    }
    pub fn time(&self) -> f64 {
        self.trial.time()
    }
    pub fn outcome(&self) -> Option<Outcome> {
        self.trial.outcome()
    }
    /// Planar distance to the goal, m.
    pub fn goal_distance(&self) -> f64 {
        self.trial.goal_distance()
    }
    /// The benchmark's metrics of this episode so far (final once it has ended): the same
    /// record as a line of `results.jsonl`.
    pub fn metrics(&self) -> TrialResult {
        self.trial.result_so_far()
    }
    /// The simulator of this episode (shared, immutable).
    pub fn sim_arc(&self) -> Arc<Sim> {
        self.trial.sim().clone()
    }
}

/// Observation buffers of one environment (crops are empty when switched off).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObsBuf {
    /// The configured state features, in order.
    pub state: Vec<f32>,
    /// Goal and local goal in the body frame (x ahead, y left), m.
    pub goal: [f32; 2],
    pub local_goal: [f32; 2],
    pub elevation: Vec<f32>,
    pub semantic: Vec<u8>,
    pub occupancy: Vec<u8>,
}

/// Live simulators by world position.
type SimCache = Arc<Mutex<HashMap<usize, Weak<Sim>>>>;

/// A world, a vehicle and the benchmark's rules, stepped one control period at a time.
#[derive(Clone)]
pub struct EnvCore {
    worlds: Arc<Vec<Arc<World>>>,
    spec: Arc<VehicleSpec>,
    cfg: Arc<EnvConfig>,
    pool: Arc<Vec<(usize, u32)>>,
    rng: Rng,
    /// Vehicle models in use, by world, shared with the siblings of a vector environment.
    /// Building one takes about 1 ms and holds about 0.5 MB (obstacle and soil layouts), so
    /// only live ones are kept (weak references): memory stays at most one model per
    /// environment, and a reset onto a world some environment is driving reuses its model.
    sims: SimCache,
    ep: Option<Episode>,
    /// Rendered map of the current world and task (drawn once, copied per frame).
    base_image: Option<((usize, u32, u32), WorldImage)>,
}

fn planar(x: f64, y: f64, p: [f64; 2]) -> f64 {
    ((x - p[0]).powi(2) + (y - p[1]).powi(2)).sqrt()
}

/// `p` in the vehicle's heading frame: x ahead, y to the left (m).
pub fn to_body(pose: &Pose6, p: [f64; 2]) -> [f32; 2] {
    let (s, c) = pose.yaw.sin_cos();
    let (dx, dy) = (p[0] - pose.x, p[1] - pose.y);
    [(c * dx + s * dy) as f32, (-s * dx + c * dy) as f32]
}

/// The environment's observation encoding of what a system sees: the configured state
/// features, goal and `local_goal` in the heading frame, and the configured map crops
/// (elevation relative to the ground under the vehicle). Environments and systems that run a
/// policy trained on them under `verti eval` share it, so both see the very same inputs.
pub fn encode_observation(
    cfg: &EnvConfig,
    obs: &Observation<'_>,
    local_goal: [f64; 2],
    buf: &mut ObsBuf,
) {
    let p = obs.pose;
    let features = obs.features();
    buf.state.clear();
    buf.state
        .extend(cfg.state_features.iter().map(|f| features.value(*f) as f32));
    buf.goal = to_body(&p, obs.goal);
    buf.local_goal = to_body(&p, local_goal);
    if let Some(spec) = cfg.elevation {
        let ground = obs.elevation_at(p.x, p.y);
        buf.elevation.clear();
        buf.elevation.extend(
            obs.elevation_crop(spec)
                .data
                .iter()
                .map(|h| (h - ground) as f32),
        );
    }
    if let Some(spec) = cfg.semantic {
        buf.semantic = obs.semantic_crop(spec).data;
    }
    if let Some(spec) = cfg.occupancy {
        buf.occupancy = obs.occupancy_crop(spec).data;
    }
}

impl EnvCore {
    pub fn new(
        worlds: Vec<Arc<World>>,
        spec: VehicleSpec,
        cfg: EnvConfig,
        filter: &TaskFilter,
        seed: u64,
    ) -> Result<EnvCore, EnvError> {
        cfg.validate()?;
        spec.validate(&spec.name)
            .map_err(|e| EnvError::InvalidConfig(e.to_string()))?;
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

    /// The vehicle model for world `wi`, shared while any environment uses it.
    fn sim_for(&self, wi: usize, task: &Task) -> Result<Arc<Sim>, EnvError> {
        let cached = self
            .sims
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get(&wi)
            .and_then(Weak::upgrade);
        if let Some(s) = cached {
            return Ok(s);
        }
        let world = &self.worlds[wi];
        let built = Sim::new(world, &self.spec).map_err(|e| EnvError::Start {
            world: world.meta.name.clone(),
            pair: task.pair,
            message: e.to_string(),
        })?;
        let s = Arc::new(built);
        let mut sims = self.sims.lock().unwrap_or_else(|p| p.into_inner());
        if sims.len() >= 1024 {
            sims.retain(|_, w| w.strong_count() > 0);
        }
        sims.insert(wi, Arc::downgrade(&s));
        Ok(s)
    }

    /// Starts an episode. `seed` reseeds the task sampler (as gymnasium's `reset(seed=...)`);
    /// `task` picks a global task number of the worlds instead of sampling one.
    pub fn reset(&mut self, seed: Option<u64>, task: Option<u32>) -> Result<(), EnvError> {
        if let Some(s) = seed {
            self.rng = Rng::new(s);
        }
        let (wi, pair) = match task {
            Some(n) => verti_bench::eval::select_tasks(&self.worlds, &[n])
                .map_err(|e| EnvError::NoTasks(e.to_string()))?[0],
            None => self.pool[self.rng.below(self.pool.len() as u64) as usize],
        };
        let world = self.worlds[wi].clone();
        let task = *world.tasks.iter().find(|t| t.pair == pair).ok_or_else(|| {
            EnvError::NoTasks(format!("world {} has no pair {pair}", world.meta.name))
        })?;
        let sim = self.sim_for(wi, &task)?;
        let trial = Trial::new(&world, sim, pair, &self.cfg.episode, "policy").map_err(|e| {
            EnvError::Start {
                world: world.meta.name.clone(),
                pair,
                message: e,
            }
        })?;
        let pose = trial.pose();
        let mut follower = PathFollower::new(trial.info().global_path.clone());
        let local_goal = follower.local_goal(
            pose.x,
            pose.y,
            self.cfg.lookahead * world.meta.scale,
            task.goal,
        );
        self.ep = Some(Episode {
            world: wi,
            id: world.task_id(pair),
            trial,
            follower,
            local_goal,
            control_steps: 0,
            trail: vec![[pose.x, pose.y]],
        });
        Ok(())
    }

    /// Maps a normalised action (the gymnasium action space) to physical units, clipping it to
    /// the box: high-level (speed, steering) in [-1, 1]² with speed · max_speed · √scale m/s;
    /// low-level (throttle, brake, steering) in [0, 1] × [0, 1] × [-1, 1].
    pub fn action_from_normalized(&self, a: &[f64]) -> Result<Action, EnvError> {
        let dim = self.cfg.action.dim();
        if a.len() != dim {
            return Err(EnvError::InvalidAction(format!(
                "expected an action of {dim} numbers, got {}",
                a.len()
            )));
        }
        if let Some(bad) = a.iter().find(|v| !v.is_finite()) {
            return Err(EnvError::InvalidAction(format!(
                "action {a:?} contains a non-finite value ({bad})"
            )));
        }
        let scale = self
            .ep
            .as_ref()
            .map_or(1.0, |e| self.worlds[e.world].meta.scale);
        Ok(match self.cfg.action {
            ActionMode::HighLevel => Action::HighLevel {
                speed: a[0].clamp(-1.0, 1.0) * self.cfg.max_speed * scale.sqrt(),
                steering: a[1].clamp(-1.0, 1.0),
            },
            ActionMode::LowLevel => Action::LowLevel(Controls::new(
                a[0].clamp(0.0, 1.0),
                a[1].clamp(0.0, 1.0),
                a[2].clamp(-1.0, 1.0),
            )),
        })
    }

    /// Holds `action` for one control period. Errors if no episode runs or it has ended, or if
    /// the action is not finite or out of range (the episode is then left as it was).
    pub fn step(&mut self, action: Action) -> Result<StepReport, EnvError> {
        let cfg = self.cfg.clone();
        let ep = self.ep.as_mut().ok_or(EnvError::NotReset("step"))?;
        if ep.trial.outcome().is_some() {
            return Err(EnvError::EpisodeEnded);
        }
        match action {
            Action::HighLevel { speed, steering }
                if !(speed.is_finite() && steering.is_finite()) =>
            {
                return Err(EnvError::InvalidAction(format!(
                    "invalid action: speed {speed}, steering {steering} must be finite"
                )));
            }
            Action::LowLevel(c) => c
                .validate()
                .map_err(|e| EnvError::InvalidAction(e.to_string()))?,
            _ => {}
        }
        let scale = self.worlds[ep.world].meta.scale;
        let period = 1.0 / cfg.control_rate;
        // the local goal observed before the step is held for the step's progress reward
        let before = ep.trial.pose();
        let lg = ep.local_goal;
        let outcome = ep.trial.step(action, period).ended;
        let pose = ep.trial.pose();
        ep.local_goal =
            ep.follower
                .local_goal(pose.x, pose.y, cfg.lookahead * scale, ep.task().goal);
        ep.control_steps += 1;
        ep.trail.push([pose.x, pose.y]);
        let terms = cfg.reward.terms(&StepProgress {
            local_goal_before: planar(before.x, before.y, lg),
            local_goal_after: planar(pose.x, pose.y, lg),
            pose,
            outcome,
            goal_distance: ep.trial.goal_distance(),
            world_scale: scale,
            period,
        });
        Ok(StepReport {
            reward: terms.total(),
            terms,
            outcome,
            terminated: matches!(outcome, Some(o) if o != Outcome::Timeout),
            truncated: outcome == Some(Outcome::Timeout),
        })
    }

    /// Writes the observation of the current state into `buf` (resizing its buffers).
    pub fn observe(&self, buf: &mut ObsBuf) -> Result<(), EnvError> {
        let ep = self.ep.as_ref().ok_or(EnvError::NotReset("observe"))?;
        encode_observation(&self.cfg, &ep.trial.observation(), ep.local_goal, buf);
        Ok(())
    }

    /// A top view of the world with the current task, the vehicle's trail and the vehicle.
    pub fn render(&mut self, pixels_per_cell: u32) -> Result<image::RgbImage, EnvError> {
        let ep = self.ep.as_ref().ok_or(EnvError::NotReset("render"))?;
        let key = (ep.world, ep.task().pair, pixels_per_cell);
        if self.base_image.as_ref().is_none_or(|(k, _)| *k != key) {
            let opts = RenderOptions {
                pixels_per_cell,
                pairs: Some(vec![ep.task().pair]),
                show_legend: false,
                show_title: false,
                ..Default::default()
            };
            let img = render_world(&self.worlds[ep.world], &opts)
                .map_err(|e| EnvError::Render(e.to_string()))?;
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
        let p = ep.pose();
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
