//! Re-running reference tasks in verti, set up as the reference describes ("The identical
//! verti run" in `chrono-reference/README.md`): the imported world with one rigid surface
//! everywhere, verti's PID with the reference's steering law, paper rules, 60 s.
//!
//! Every setting lives in [`CompareSetup`], built in one place ([`CompareSetup::reference`]);
//! the episode settings in particular come only from [`reference_episode`], so a later option
//! (e.g. starting the vehicle dropped from 1 m like the reference instead of settled) changes
//! one function.

use crate::driver::ReferenceDriver;
use crate::error::{CompareError, Result};
use crate::reference::{RefGround, RefOutcome, Sample};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use verti_bench::episode::{EpisodeLog, StepRecord};
use verti_bench::{EpisodeConfig, Feature, MobilitySystem, Rules, StartMode, TrialResult};
use verti_sim::VehicleSpec;
use verti_systems::pid::{Pid, PidParams};
use verti_world::import_vb::{ImportOptions, import_vb, scan_vb_dir};
use verti_world::surface::RIGID_RESTITUTION;
use verti_world::{Surface, TerrainClass, World};

/// The reference writes the heading error (rad) straight into the steering input; verti's PID
/// commands a road-wheel angle of `kp · error` scaled by the maximum angle, so the same law is
/// `kp` = the HMMWV's maximum road-wheel angle, 0.5276 rad (30.23°).
pub const REFERENCE_KP: f64 = 0.5276;
/// The reference's driver acts every 5 ms physics step. A system acts at most once per inner
/// step of the benchmark's loop, 10 ms by default (`EpisodeConfig::inner_dt`), so at that
/// default this rate acts every 10 ms, exactly as rate 100 would.
pub const REFERENCE_RATE: f64 = 200.0;
/// Friction of every patch in the reference runs.
pub const REFERENCE_FRICTION: f64 = 0.8;
/// Period of the trajectory samples, s (the reference writes 10 Hz).
pub const SAMPLE_PERIOD: f64 = 0.1;

/// Which system drives verti's vehicle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Driver {
    /// verti's PID with [`CompareSetup::pid`] (the reference README's "identical verti run").
    #[default]
    Pid,
    /// The reference's own driver law ([`ReferenceDriver`]) at the PID's speed, lookahead and
    /// rate, to see what the PID's differences from it change.
    Reference,
}

impl Driver {
    pub fn name(self) -> &'static str {
        match self {
            Driver::Pid => "pid",
            Driver::Reference => "reference",
        }
    }
    pub fn from_name(s: &str) -> Option<Driver> {
        [Driver::Pid, Driver::Reference]
            .into_iter()
            .find(|d| d.name() == s)
    }
}

/// How verti drives every compared task.
#[derive(Clone, Debug, PartialEq)]
pub struct CompareSetup {
    pub vehicle: VehicleSpec,
    pub driver: Driver,
    /// PID parameters; the reference driver takes its speed, lookahead and rate from them.
    pub pid: PidParams,
    pub episode: EpisodeConfig,
    /// The class and surface every patch gets.
    pub class: TerrainClass,
    pub surface: Surface,
}

/// The episode settings of every compared trial: paper rules, 60 s, verti's default inner
/// loop, and the reference's start (level, 1 m above the ground, dropped).
pub fn reference_episode() -> EpisodeConfig {
    EpisodeConfig {
        rules: Rules::Paper,
        max_time: 60.0,
        start: StartMode::Drop,
        ..Default::default()
    }
}

impl CompareSetup {
    /// The setup of the reference's README for `vehicle`: rigid dirt with friction 0.8 and
    /// restitution 0.01 everywhere; PID at 3 m/s, lookahead 10 m, kp [`REFERENCE_KP`], rate
    /// [`REFERENCE_RATE`]; [`reference_episode`].
    pub fn reference(vehicle: VehicleSpec) -> CompareSetup {
        CompareSetup {
            vehicle,
            driver: Driver::Pid,
            pid: PidParams {
                speed: 3.0,
                lookahead: 10.0,
                kp: REFERENCE_KP,
                ki: 0.0,
                kd: 0.0,
                rate: REFERENCE_RATE,
            },
            episode: reference_episode(),
            class: TerrainClass::Dirt,
            surface: Surface::Rigid {
                friction: REFERENCE_FRICTION,
                restitution: RIGID_RESTITUTION,
            },
        }
    }

    /// The world as the comparison drives it on `ground`: with the setup's surface everywhere
    /// (one friction), as imported (one soil, which must be the reference's), or with each
    /// patch's friction that of its section (`reference_dir/frictions/world-NNN.tsv`).
    pub fn prepare(&self, world: &World, ground: RefGround, reference_dir: &Path) -> Result<World> {
        match ground {
            RefGround::OneFriction => Ok(world.with_uniform_surface(self.class, self.surface)?),
            RefGround::Soil(class) => {
                let other =
                    world.patches.patches().iter().find(|p| {
                        p.class != class || !matches!(p.surface, Surface::Deformable { .. })
                    });
                if let Some(p) = other {
                    return Err(CompareError::Argument(format!(
                        "{}: the reference ran it on {class} everywhere, but the imported world has {} patches: not a single-soil world",
                        world.meta.name, p.class
                    )));
                }
                Ok(world.clone())
            }
            RefGround::Sections => {
                let path = reference_dir
                    .join(FRICTIONS_DIR)
                    .join(format!("world-{:03}.tsv", world.meta.index));
                with_section_frictions(world, &path)
            }
        }
    }
}

/// Folder of a sections reference holding each world's sections and their frictions.
pub const FRICTIONS_DIR: &str = "frictions";

/// `world` with every patch's friction that of its section in the file at `path` (lines
/// `i_min i_max j_min j_max friction`, tab-separated after a header; i is the patch row from the
/// north, j the column from the west), restitution the reference's 0.01, classes kept. Every
/// patch must be rigid and in exactly one section.
pub fn with_section_frictions(world: &World, path: &Path) -> Result<World> {
    use verti_world::surface::PATCHES_PER_SIDE as N;
    let text = std::fs::read_to_string(path).map_err(|e| CompareError::io(path, e))?;
    let mut friction: Vec<Option<f64>> = vec![None; N * N];
    for (k, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let bad = |problem: String| CompareError::line(path, k + 1, problem);
        let cols: Vec<&str> = line.split('\t').collect();
        if cols.len() != 5 {
            return Err(bad(format!(
                "expected 5 tab-separated columns (i_min i_max j_min j_max friction), found {}",
                cols.len()
            )));
        }
        let index = |c: &str| -> Result<usize> {
            c.trim()
                .parse::<usize>()
                .ok()
                .filter(|&i| i < N)
                .ok_or_else(|| bad(format!("`{c}` is not a patch index 0-{}", N - 1)))
        };
        let (i0, i1, j0, j1) = (
            index(cols[0])?,
            index(cols[1])?,
            index(cols[2])?,
            index(cols[3])?,
        );
        let f: f64 = cols[4]
            .trim()
            .parse()
            .ok()
            .filter(|f: &f64| f.is_finite() && (0.0..=2.0).contains(f))
            .ok_or_else(|| bad(format!("`{}` is not a friction in [0, 2]", cols[4])))?;
        if i1 < i0 || j1 < j0 {
            return Err(bad("an empty section (max below min)".into()));
        }
        for i in i0..=i1 {
            for j in j0..=j1 {
                if friction[i * N + j].replace(f).is_some() {
                    return Err(bad(format!("patch ({i}, {j}) is in two sections")));
                }
            }
        }
    }
    let mut patches = world.patches.patches().to_vec();
    for (k, p) in patches.iter_mut().enumerate() {
        let (i, j) = (k / N, k % N);
        let Some(f) = friction[k] else {
            return Err(CompareError::Argument(format!(
                "{}: patch ({i}, {j}) of {} is in no section",
                path.display(),
                world.meta.name
            )));
        };
        if p.surface.is_deformable() {
            return Err(CompareError::Argument(format!(
                "{}: patch ({i}, {j}) of {} is deformable; sections are rigid",
                path.display(),
                world.meta.name
            )));
        }
        p.surface = Surface::Rigid {
            friction: f,
            restitution: RIGID_RESTITUTION,
        };
    }
    let mut out = world.clone();
    out.patches = verti_world::PatchGrid::new(patches, world.terrain.cell());
    Ok(out)
}

/// Imports the Verti-Bench worlds the tasks name from `vb_dir` (once each, in parallel) and
/// prepares them with `setup` for the ground their tasks were run on ([`CompareSetup::prepare`];
/// `reference_dir` holds the sections of a sections reference). Each must be the world the
/// reference names (`vb/configN_LEVEL` for world index N), or the task's line is reported; the
/// tasks of one world must share their ground.
pub fn load_worlds(
    vb_dir: &Path,
    reference_dir: &Path,
    tasks: &[&RefOutcome],
    setup: &CompareSetup,
) -> Result<BTreeMap<u32, Arc<World>>> {
    if !vb_dir.is_dir() {
        // a relative default is easy to miss when running from elsewhere
        let whence = if vb_dir.is_relative() {
            " (relative to the current directory)"
        } else {
            ""
        };
        return Err(CompareError::Argument(format!(
            "{}{whence}: no such folder of Verti-Bench worlds (configN_LEVEL.yaml, worldN.bmp); give it with --vb-worlds",
            vb_dir.display()
        )));
    }
    let files = scan_vb_dir(vb_dir)?;
    let mut wanted: BTreeMap<u32, &RefOutcome> = BTreeMap::new();
    for t in tasks {
        let first = *wanted.entry(t.world_index).or_insert(t);
        if first.ground != t.ground {
            return Err(CompareError::Argument(format!(
                "world {} is run on {} on line {} but on {} on line {}: one ground per world",
                t.world_index,
                first.ground.name(),
                first.line,
                t.ground.name(),
                t.line
            )));
        }
    }
    let jobs: Vec<(u32, &RefOutcome)> = wanted.into_iter().collect();
    let worlds = jobs
        .par_iter()
        .map(|&(index, first)| {
            let f = files.iter().find(|f| f.index == index).ok_or_else(|| {
                CompareError::Argument(format!(
                    "{}: no world {index} (reference world `{}`, outcomes line {})",
                    vb_dir.display(),
                    first.world,
                    first.line
                ))
            })?;
            let world = import_vb(
                &f.config,
                &f.heightmap,
                f.labels.as_deref(),
                &ImportOptions::default(),
            )?;
            if world.meta.name != first.world {
                return Err(CompareError::Argument(format!(
                    "{}: world {index} is `{}`, but the reference names `{}` (outcomes line {})",
                    f.config.display(),
                    world.meta.name,
                    first.world,
                    first.line
                )));
            }
            let prepared = setup.prepare(&world, first.ground, reference_dir)?;
            Ok((index, Arc::new(prepared)))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(worlds.into_iter().collect())
}

/// One task driven by verti: the trial's record, its 10 Hz trajectory and, at the same times,
/// each wheel's state.
#[derive(Clone, Debug, PartialEq)]
pub struct VertiRun {
    pub result: TrialResult,
    pub samples: Vec<Sample>,
    pub wheels: Vec<WheelSample>,
}

/// One wheel at one sample time, in the columns of the Chrono harness's per-wheel log
/// (`vb_drive_wheels`, `VB_WHEELS`), so that the two can be set side by side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelSample {
    pub t: f64,
    /// The vehicle's forward speed, m/s.
    pub v: f64,
    /// Wheel number: axle by axle, left then right.
    pub wheel: usize,
    /// Spin rate, rad/s.
    pub omega: f64,
    /// Ground forces on the wheel, N: along and across its contact frame, and normal.
    pub fx: f64,
    pub fy: f64,
    pub fz: f64,
    /// Gear (1-based, as Chrono numbers them) and engine speed, rpm.
    pub gear: usize,
    pub rpm: f64,
}

/// The per-wheel samples as CSV: `t,v,wheel,omega,fx,fy,fz,gear,rpm`, one line per wheel and
/// sample time.
pub fn format_wheels(wheels: &[WheelSample]) -> String {
    let mut out = String::from("t,v,wheel,omega,fx,fy,fz,gear,rpm\n");
    for w in wheels {
        out.push_str(&format!(
            "{:.3},{:.4},{},{:.4},{:.1},{:.1},{:.1},{},{:.0}\n",
            w.t, w.v, w.wheel, w.omega, w.fx, w.fy, w.fz, w.gear, w.rpm
        ));
    }
    out
}

/// Drives task `pair` of `world` (already prepared) as `setup` says.
pub fn run_task(world: &Arc<World>, pair: u32, setup: &CompareSetup) -> VertiRun {
    let p = &setup.pid;
    let mut system: Box<dyn MobilitySystem> = match setup.driver {
        Driver::Pid => Box::new(Pid::new(p.clone())),
        Driver::Reference => Box::new(ReferenceDriver::new(p.speed, p.lookahead, p.rate)),
    };
    let mut log = EpisodeLog::default();
    let mut wheels = Vec::new();
    // each wheel at the same steps as `resample` takes the trajectory
    let mut clock = SampleClock::new(SAMPLE_PERIOD);
    let mut watch = |trial: &verti_bench::Trial| {
        let t = trial.time();
        if !clock.due(t) {
            return;
        }
        let st = trial.state();
        let (rpm, _) = st.engine();
        for (k, w) in st.wheels().iter().enumerate() {
            wheels.push(WheelSample {
                t,
                v: st.forward_speed(),
                wheel: k,
                omega: w.spin_rate,
                fx: w.long_force,
                fy: w.lat_force,
                fz: w.normal_force,
                gear: st.gear() + 1,
                rpm,
            });
        }
    };
    let result = verti_bench::episode::run_episode_watched(
        world,
        &setup.vehicle,
        pair,
        system.as_mut(),
        &setup.episode,
        Some(&mut log),
        &mut watch,
    );
    let mut samples = resample(&log.steps, SAMPLE_PERIOD);
    for s in &mut samples {
        s.agl = s.z - world.terrain.height_at(s.x, s.y);
    }
    VertiRun {
        result,
        samples,
        wheels,
    }
}

/// Runs `tasks` (world index, pair) on `jobs` threads; the results are in the order of
/// `tasks` and do not depend on `jobs`. `done` is called after each task.
pub fn run_tasks(
    worlds: &BTreeMap<u32, Arc<World>>,
    tasks: &[(u32, u32)],
    setup: &CompareSetup,
    jobs: usize,
    done: &(dyn Fn() + Sync),
) -> Result<Vec<VertiRun>> {
    for (w, _) in tasks {
        if !worlds.contains_key(w) {
            return Err(CompareError::Argument(format!("world {w} was not loaded")));
        }
    }
    Ok(pool(jobs)?.install(|| {
        tasks
            .par_iter()
            .map(|&(w, pair)| {
                let run = run_task(&worlds[&w], pair, setup);
                done();
                run
            })
            .collect()
    }))
}

/// A pool of `jobs` worker threads (at least one) for the trials.
pub(crate) fn pool(jobs: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| CompareError::Argument(format!("cannot start {jobs} threads: {e}")))
}

/// Picks, from steps in time order, the first at or after each multiple of `period` (how the
/// reference samples its runs).
struct SampleClock {
    period: f64,
    next: u32,
}

impl SampleClock {
    fn new(period: f64) -> SampleClock {
        SampleClock { period, next: 1 }
    }

    /// Whether the step at time `t` is a sample (then the clock moves past it).
    fn due(&mut self, t: f64) -> bool {
        if t + 1e-9 < f64::from(self.next) * self.period {
            return false;
        }
        while f64::from(self.next) * self.period <= t + 1e-9 {
            self.next += 1;
        }
        true
    }
}

/// Samples of a step log every `period` seconds (the first step at or after each multiple), as
/// the reference writes them.
pub fn resample(steps: &[StepRecord], period: f64) -> Vec<Sample> {
    let get = |s: &StepRecord, f: Feature| s.get(f).unwrap_or(f64::NAN);
    let mut out = Vec::new();
    let mut clock = SampleClock::new(period);
    for s in steps {
        let t = s.t();
        if !clock.due(t) {
            continue;
        }
        out.push(Sample {
            t,
            x: get(s, Feature::X),
            y: get(s, Feature::Y),
            z: get(s, Feature::Z),
            roll: get(s, Feature::Roll).to_degrees(),
            pitch: get(s, Feature::Pitch).to_degrees(),
            yaw: get(s, Feature::Yaw).to_degrees(),
            v: get(s, Feature::Vx),
            steer: get(s, Feature::Steering),
            throttle: get(s, Feature::Throttle),
            brake: get(s, Feature::Brake),
            agl: f64::NAN,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tsv(lines: &str) -> std::path::PathBuf {
        static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let path =
            std::env::temp_dir().join(format!("verti-sections-{}-{k}.tsv", std::process::id()));
        std::fs::write(
            &path,
            format!("i_min\ti_max\tj_min\tj_max\tfriction\n{lines}"),
        )
        .unwrap();
        path
    }

    #[test]
    fn section_frictions_cover_every_patch_once() {
        let world = verti_sim::testing::flat_world(1.0, 0.8);
        let ok = tsv("0\t15\t0\t7\t0.5\n0\t15\t8\t15\t0.7\n");
        let w = with_section_frictions(&world, &ok).unwrap();
        let friction = |k: usize| match w.patches.patches()[k].surface {
            Surface::Rigid { friction, .. } => friction,
            Surface::Deformable { .. } => f64::NAN,
        };
        assert_eq!(
            (friction(0), friction(7), friction(8), friction(255)),
            (0.5, 0.5, 0.7, 0.7)
        );
        for (lines, why) in [
            ("0\t15\t0\t7\t0.5\n", "is in no section"),
            ("0\t15\t0\t15\t0.5\n0\t0\t0\t0\t0.6\n", "in two sections"),
            ("0\t16\t0\t15\t0.5\n", "not a patch index"),
            ("0\t15\t0\t15\tslippery\n", "not a friction"),
            ("0\t15\t0\t15\n", "5 tab-separated columns"),
        ] {
            let e = with_section_frictions(&world, &tsv(lines))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(why) && e.contains("verti-sections"),
                "{lines:?}: {e}"
            );
        }
    }
}
