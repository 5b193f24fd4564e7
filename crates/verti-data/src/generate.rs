//! Generating the three datasets: random exploration, failure cases and expert demonstrations.
//!
//! Trials are independent and seeded by their id, so they run in parallel (rayon) in fixed-size
//! batches and are kept in id order: the data are the same for any thread count. The hour
//! budget is counted in id order too, and the trial that reaches it is the last one kept.

use crate::classify::{FailureKind, FailureRule, TrajectoryPoint, classify_failure};
use crate::manifest::{DataOutcome, Kind};
use crate::profile::Profile;
use crate::table::{FEATURES, Row, TrialRecord, WheelGround};
use crate::{DataError, Result};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};
use verti_bench::features::Feature;
use verti_bench::{Action, EpisodeConfig, MobilitySystem, Trial, pose6};
use verti_core::rng::{Rng, mix_seed};
use verti_sim::{Sim, StartPose, VehicleSpec};
use verti_world::{World, WorldSource};

/// Trials simulated per parallel batch. A constant, not the thread count, so the trials that
/// are simulated (and hence kept) never depend on the machine.
pub const BATCH: usize = 32;
/// Default length cap of an exploration trial, simulated seconds.
pub const MAX_TRIAL_SECONDS: f64 = 300.0;
/// Exploration starts at least this far (m, full scale) from the map's edge...
pub const START_MARGIN: f64 = 20.0;
/// ...and ends when the chassis comes this close to it (m, full scale): beyond, wheels would
/// leave the heightfield.
pub const EDGE_MARGIN: f64 = 5.0;
/// Starts keep this clearance (m, full scale) from every obstacle footprint.
pub const START_CLEARANCE: f64 = 3.0;
/// A start tilted more than this (degrees) is drawn again: it would roll over at once.
pub const START_MAX_TILT_DEG: f64 = 25.0;
/// Seconds before the end kept by the failure dataset (the paper's "last ten seconds").
pub const FAILURE_WINDOW: f64 = 10.0;

/// Builds a fresh mobility system (one per trial, as evaluation does).
pub type SystemMaker = dyn Fn() -> Box<dyn MobilitySystem> + Send + Sync;

/// Who drives.
#[derive(Clone)]
pub enum Source {
    /// Random exploration with a command profile, from random starts.
    Random(Profile),
    /// A mobility system on the set's tasks, in task order.
    System {
        name: String,
        make: Arc<SystemMaker>,
    },
}

impl Source {
    pub fn name(&self) -> &str {
        match self {
            Source::Random(_) => "random",
            Source::System { name, .. } => name,
        }
    }
}

/// What to generate.
#[derive(Clone)]
pub struct GenerateConfig {
    pub kind: Kind,
    pub source: Source,
    pub worlds: Vec<Arc<World>>,
    pub vehicle: VehicleSpec,
    /// Simulated hours: of exploration (random), of source driving to harvest (failures), of
    /// kept successful driving (expert).
    pub hours: f64,
    /// Rows per simulated second.
    pub rate: f64,
    pub seed: u64,
    /// Exploration length cap, s.
    pub max_trial_seconds: f64,
}

impl GenerateConfig {
    pub fn validate(&self) -> Result<()> {
        if !(self.hours.is_finite() && self.hours > 0.0) {
            return Err(DataError::Argument(format!(
                "--hours must be a positive number of hours, not {}",
                self.hours
            )));
        }
        if !(self.rate.is_finite() && self.rate >= 1.0 && self.rate <= 100.0) {
            return Err(DataError::Argument(format!(
                "--rate must be in [1, 100] Hz (the simulator's inner loop runs at 100 Hz), not {}",
                self.rate
            )));
        }
        if !(self.max_trial_seconds.is_finite() && self.max_trial_seconds >= 10.0) {
            return Err(DataError::Argument(format!(
                "--max-trial-seconds must be at least 10, not {}",
                self.max_trial_seconds
            )));
        }
        if self.worlds.is_empty() {
            return Err(DataError::Argument("the world set has no worlds".into()));
        }
        match (&self.kind, &self.source) {
            (Kind::Random, Source::System { .. }) => Err(DataError::Argument(
                "random exploration is driven by a profile, not a system".into(),
            )),
            (Kind::Expert, Source::Random(_)) => Err(DataError::Argument(
                "expert data needs a system (--system)".into(),
            )),
            _ => Ok(()),
        }
    }
}

/// Why a world set may not be used for training data, if it may not: it holds evaluation
/// worlds (the built-in set of seed 0, `verti-100`, or imported original Verti-Bench worlds).
/// The paper's tasks were never used for training; data from them would leak into evaluation.
pub fn eval_world_reason(worlds: &[Arc<World>]) -> Option<String> {
    let w = worlds.iter().find(|w| match &w.meta.source {
        WorldSource::Generated { set_seed, .. } => *set_seed == 0,
        WorldSource::VertiBench { .. } => true,
    })?;
    Some(format!(
        "world {} is an evaluation world ({}): datasets are refused on the evaluation worlds so that no evaluated task is trained on (as in the paper); use another seed, e.g. --worlds verti-100-s1, or pass --allow-eval-worlds to mark the data eval_worlds: true",
        w.meta.name,
        match w.meta.source {
            WorldSource::Generated { .. } => "a generated set of seed 0, as verti-100",
            WorldSource::VertiBench { .. } => "an original Verti-Bench world",
        }
    ))
}

/// Totals of a generation run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Generated {
    pub trials: usize,
    pub rows: usize,
    /// Seconds of driving kept, and simulated in all.
    pub seconds: f64,
    pub seconds_simulated: f64,
    pub outcomes: BTreeMap<String, usize>,
    pub world_indices: Vec<u32>,
    /// Trials that could not run (no valid start, a system that failed), with why.
    pub errors: Vec<String>,
}

/// One simulated trial: what it adds to the data and how long it drove.
struct Simulated {
    kept: Option<TrialRecord>,
    simulated: f64,
    error: Option<String>,
}

/// Runs the generation, handing each batch of kept trials (in id order) to `sink`, and calling
/// `progress` with the budget seconds each batch used. Stops at the budget, or when a system's
/// tasks run out.
pub fn generate(
    cfg: &GenerateConfig,
    sink: &mut dyn FnMut(Vec<TrialRecord>) -> Result<()>,
    progress: &dyn Fn(f64),
) -> Result<Generated> {
    cfg.validate()?;
    let sims: Vec<OnceLock<std::result::Result<Arc<Sim>, String>>> =
        cfg.worlds.iter().map(|_| OnceLock::new()).collect();
    let sim_for = |w: usize| -> std::result::Result<Arc<Sim>, String> {
        sims[w]
            .get_or_init(|| {
                Sim::new(&cfg.worlds[w], &cfg.vehicle)
                    .map(Arc::new)
                    .map_err(|e| format!("cannot build the vehicle model: {e}"))
            })
            .clone()
    };
    let tasks: Vec<(usize, u32)> = cfg
        .worlds
        .iter()
        .enumerate()
        .flat_map(|(w, world)| world.tasks.iter().map(move |t| (w, t.pair)))
        .collect();
    let budget = cfg.hours * 3600.0;
    let mut total = Generated::default();
    let mut used = 0.0;
    let mut next = 0usize;
    let mut indices = std::collections::BTreeSet::new();
    while used < budget {
        let ids: Vec<usize> = match cfg.source {
            Source::Random(_) => (next..next + BATCH).collect(),
            Source::System { .. } => (next..(next + BATCH).min(tasks.len())).collect(),
        };
        if ids.is_empty() {
            break;
        }
        next += ids.len();
        let batch: Vec<Simulated> = ids
            .par_iter()
            .map(|&i| simulate(cfg, i, &tasks, &sim_for))
            .collect();
        let mut kept = Vec::new();
        let before = used;
        for s in batch {
            if used >= budget {
                break;
            }
            total.seconds_simulated += s.simulated;
            if let Some(e) = s.error {
                total.errors.push(e);
            }
            let kept_seconds = s.kept.as_ref().map_or(0.0, TrialRecord::duration);
            used += match cfg.kind {
                Kind::Expert => kept_seconds,
                Kind::Random | Kind::Failures => s.simulated,
            };
            if let Some(r) = s.kept {
                total.trials += 1;
                total.rows += r.rows.len();
                total.seconds += kept_seconds;
                *total.outcomes.entry(r.outcome.name().into()).or_default() += 1;
                indices.insert(r.world);
                kept.push(r);
            }
        }
        progress(used.min(budget) - before);
        if !kept.is_empty() {
            sink(kept)?;
        }
        // a source that never drives (every start invalid) would loop forever
        if total.seconds_simulated == 0.0 && next >= 4 * BATCH {
            return Err(DataError::Run(format!(
                "no trial could run: {}",
                total.errors.first().map_or("?", String::as_str)
            )));
        }
    }
    total.world_indices = indices.into_iter().collect();
    Ok(total)
}

/// Simulates trial `i` and keeps what the dataset kind keeps of it.
fn simulate(
    cfg: &GenerateConfig,
    i: usize,
    tasks: &[(usize, u32)],
    sim_for: &(dyn Fn(usize) -> std::result::Result<Arc<Sim>, String> + Sync),
) -> Simulated {
    let run = match &cfg.source {
        Source::Random(profile) => explore(cfg, *profile, i, sim_for),
        Source::System { name, make } => {
            let (w, pair) = tasks[i];
            run_task(cfg, name, &**make, w, pair, sim_for)
        }
    };
    let record = match run {
        Ok(r) => r,
        Err(e) => {
            return Simulated {
                kept: None,
                simulated: 0.0,
                error: Some(format!("trial {i}: {e}")),
            };
        }
    };
    let simulated = record.duration();
    let error = (record.outcome == DataOutcome::Error)
        .then(|| format!("trial {} ended in error", record.trial));
    let kept = match cfg.kind {
        Kind::Random => Some(record),
        Kind::Expert => (record.outcome == DataOutcome::Success).then_some(record),
        Kind::Failures => failure_window(record, cfg.worlds[0].meta.scale),
    };
    Simulated {
        kept,
        simulated,
        error,
    }
}

/// The last [`FAILURE_WINDOW`] seconds of `record` with its failure class, when the paper's rule
/// classifies its end as one.
pub fn failure_window(mut record: TrialRecord, scale: f64) -> Option<TrialRecord> {
    if record.outcome == DataOutcome::Error {
        return None;
    }
    let f = |feature: Feature| {
        let k = Feature::ALL
            .iter()
            .position(|g| *g == feature)
            .expect("in ALL");
        move |r: &Row| r.features[k]
    };
    let (t, x, y, roll) = (
        f(Feature::Time),
        f(Feature::X),
        f(Feature::Y),
        f(Feature::Roll),
    );
    let traj: Vec<TrajectoryPoint> = record
        .rows
        .iter()
        .map(|r| TrajectoryPoint {
            t: t(r),
            x: x(r),
            y: y(r),
            roll: roll(r),
        })
        .collect();
    let kind = classify_failure(&traj, FailureRule::scaled(scale))?;
    let end = traj.last()?.t;
    let first = traj.partition_point(|p| p.t < end - FAILURE_WINDOW - 1e-6);
    record.rows.drain(..first);
    record.first_step += first as u32;
    record.outcome = match kind {
        FailureKind::Rollover => DataOutcome::Rollover,
        FailureKind::Stuck => DataOutcome::Stuck,
    };
    Some(record)
}

/// A random valid start on `world`: away from the edge and the obstacles, not too tilted.
fn random_start(rng: &mut Rng, world: &World, sim: &Sim) -> std::result::Result<StartPose, String> {
    let scale = world.meta.scale;
    let reach = world.terrain.half_extent() - START_MARGIN * scale;
    if reach <= 0.0 {
        return Err(format!("world {} is too small to explore", world.meta.name));
    }
    let max_tilt = START_MAX_TILT_DEG.to_radians();
    for _ in 0..200 {
        let start = StartPose::new(
            rng.range(-reach, reach),
            rng.range(-reach, reach),
            rng.range(-std::f64::consts::PI, std::f64::consts::PI),
        );
        if world.obstacle_distance(start.x, start.y) < START_CLEARANCE * scale {
            continue;
        }
        let Ok(state) = sim.state_at(start) else {
            continue;
        };
        let p = pose6(sim, &state);
        if p.roll.abs() < max_tilt && p.pitch.abs() < max_tilt {
            return Ok(start);
        }
    }
    Err(format!(
        "no valid start found on {} in 200 draws",
        world.meta.name
    ))
}

/// Exploration trial `i`: a random world, start and command profile, all from the seed and `i`.
fn explore(
    cfg: &GenerateConfig,
    profile: Profile,
    i: usize,
    sim_for: &(dyn Fn(usize) -> std::result::Result<Arc<Sim>, String> + Sync),
) -> std::result::Result<TrialRecord, String> {
    let mut rng = Rng::derive(cfg.seed, "verti-data/explore", i as u64);
    let w = rng.below(cfg.worlds.len() as u64) as usize;
    let world = &cfg.worlds[w];
    let sim = sim_for(w)?;
    let start = random_start(&mut rng, world, &sim)?;
    let commands = profile.draw(&mut rng);
    let episode = EpisodeConfig {
        max_time: cfg.max_trial_seconds,
        seed: mix_seed(&[cfg.seed, i as u64]),
        ..Default::default()
    };
    let mut trial = Trial::explore(world, sim, start, &episode, "random")?;
    let period = 1.0 / cfg.rate;
    let edge = world.terrain.half_extent() - EDGE_MARGIN * world.meta.scale;
    let (rows, outcome) = drive(&mut trial, cfg.rate, period, Some(edge), &mut |t| {
        let (steering, speed) = commands.at(t.time());
        Action::HighLevel { speed, steering }
    });
    Ok(TrialRecord {
        trial: i as u32,
        world: world.meta.index,
        first_step: 0,
        rows,
        outcome,
    })
}

/// Task `pair` of world `w` driven by a fresh system built by `make`.
fn run_task(
    cfg: &GenerateConfig,
    name: &str,
    make: &SystemMaker,
    w: usize,
    pair: u32,
    sim_for: &(dyn Fn(usize) -> std::result::Result<Arc<Sim>, String> + Sync),
) -> std::result::Result<TrialRecord, String> {
    let world = &cfg.worlds[w];
    let episode = EpisodeConfig {
        seed: cfg.seed,
        ..Default::default()
    };
    let mut trial = Trial::new(world, sim_for(w)?, pair, &episode, name)?;
    let mut system = make();
    system.reset(trial.info());
    let period = verti_bench::episode::control_period(system.as_ref())?;
    let (rows, outcome) = drive(&mut trial, cfg.rate, period, None, &mut |t| {
        system.act(&t.observation())
    });
    Ok(TrialRecord {
        trial: world.task_id(pair).number(),
        world: world.meta.index,
        first_step: 0,
        rows,
        outcome,
    })
}

/// Drives `trial` to its end: `act` every `act_period` seconds, a row every 1/`rate` seconds
/// and a last row at the end. With `edge`, the trial also ends (as `Edge`) when the chassis
/// leaves the square |x|, |y| < edge. Splitting a held action's period at record times does not
/// change the physics: `Trial::step` runs whole inner steps up to the running sum of periods.
fn drive(
    trial: &mut Trial,
    rate: f64,
    act_period: f64,
    edge: Option<f64>,
    act: &mut dyn FnMut(&Trial) -> Action,
) -> (Vec<Row>, DataOutcome) {
    let record_period = 1.0 / rate;
    let (mut next_act, mut next_record) = (0.0f64, 0.0f64);
    let mut rows = Vec::new();
    let mut action = Action::HighLevel {
        speed: 0.0,
        steering: 0.0,
    };
    loop {
        let now = trial.time();
        if now + 1e-9 >= next_act {
            action = act(trial);
            next_act += act_period;
        }
        if now + 1e-9 >= next_record {
            rows.push(row(trial, action));
            next_record += record_period;
        }
        let target = next_act.min(next_record);
        if let Some(ended) = trial.step(action, target - now).ended {
            rows.push(row(trial, action));
            return (rows, DataOutcome::from_bench(ended));
        }
        let p = trial.pose();
        if edge.is_some_and(|e| p.x.abs() >= e || p.y.abs() >= e) {
            rows.push(row(trial, action));
            return (rows, DataOutcome::Edge);
        }
    }
}

/// The row of `trial`'s current state with `action` as the command (every kind of data,
/// human demonstrations included, is recorded through this one function).
pub fn row(trial: &Trial, action: Action) -> Row {
    let features: [f64; FEATURES] = trial.features().extract(&Feature::ALL);
    let (steering, speed) = match action {
        Action::HighLevel { speed, steering } => (steering, speed),
        // direct driver inputs have no target speed
        Action::LowLevel(c) => (c.steering, f64::NAN),
    };
    let world = trial.world();
    let wheels = trial
        .sim()
        .wheel_centers(trial.state())
        .iter()
        .map(|c| {
            let patch = world.patches.at(c.x, c.y);
            WheelGround {
                class: patch.class.id(),
                friction: patch.surface.effective_friction(),
                soil: patch.surface.is_deformable(),
            }
        })
        .collect();
    Row {
        features,
        steering,
        speed,
        wheels,
    }
}

/// A drive's rows: pose, and the command (target speed, steering) held from it.
pub type DriveRows = Vec<(verti_bench::observation::Pose6, (f64, f64))>;

/// One exploration drive on `world` for a system that gathers adaptation data in its own
/// world before a task (privileged, like the environment data of VertiAdaptor's VA*): a start
/// and command profile drawn from `seed`, up to `max_seconds`, one row every 1/`rate` s.
/// Returns each row's pose and the command (target speed, steering) held from it to the next.
pub fn explore_poses(
    world: &Arc<World>,
    sim: Arc<Sim>,
    profile: Profile,
    seed: u64,
    max_seconds: f64,
    rate: f64,
) -> std::result::Result<DriveRows, String> {
    let mut rng = Rng::derive(seed, "verti-data/explore-poses", 0);
    let start = random_start(&mut rng, world, &sim)?;
    let commands = profile.draw(&mut rng);
    let episode = EpisodeConfig {
        max_time: max_seconds,
        seed,
        ..Default::default()
    };
    let mut trial = Trial::explore(world, sim, start, &episode, "explore")?;
    let period = 1.0 / rate;
    let edge = world.terrain.half_extent() - EDGE_MARGIN * world.meta.scale;
    let mut out = Vec::new();
    loop {
        let (steering, speed) = commands.at(trial.time());
        out.push((trial.pose(), (speed, steering)));
        let ended = trial
            .step(Action::HighLevel { speed, steering }, period)
            .ended
            .is_some();
        let p = trial.pose();
        if ended || p.x.abs() >= edge || p.y.abs() >= edge {
            out.push((p, (speed, steering)));
            return Ok(out);
        }
    }
}
