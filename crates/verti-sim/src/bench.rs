//! Speed benchmark and random-input soak, as library functions for `verti sim bench` and
//! `verti sim soak`.

use crate::error::SimError;
use crate::sim::{Controls, Sim, SimState, start_pose};
use crate::spec::VehicleSpec;
use crate::testing::{RoughSurface, rough_world};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;
use std::time::Instant;
use verti_core::Rng;
use verti_world::World;

/// A rigid and a deformable world for one world scale.
#[derive(Clone, Debug)]
pub struct BenchWorldPair {
    pub scale: f64,
    /// High relief, dense obstacles, rigid ground.
    pub rigid: Arc<World>,
    /// Deformable ground (snow, mud and sand patches).
    pub soil: Arc<World>,
}

/// The worlds the benchmark drives on, one pair per vehicle scale.
#[derive(Clone, Debug, Default)]
pub struct BenchWorlds {
    pub pairs: Vec<BenchWorldPair>,
}

impl BenchWorlds {
    /// Synthetic rough worlds (see [`crate::testing::rough_world`]) for each scale.
    pub fn synthetic(scales: &[f64]) -> BenchWorlds {
        let mut pairs: Vec<BenchWorldPair> = Vec::new();
        for &s in scales {
            if pairs.iter().any(|p| (p.scale - s).abs() < 1e-9) {
                continue;
            }
            pairs.push(BenchWorldPair {
                scale: s,
                rigid: Arc::new(rough_world(s, 1, 16.0, RoughSurface::Rigid)),
                soil: Arc::new(rough_world(s, 2, 4.8, RoughSurface::Soil)),
            });
        }
        BenchWorlds { pairs }
    }

    /// Synthetic worlds for the scales of the given vehicles.
    pub fn synthetic_for(vehicles: &[VehicleSpec]) -> BenchWorlds {
        let scales: Vec<f64> = vehicles.iter().map(|v| v.scale).collect();
        BenchWorlds::synthetic(&scales)
    }

    /// Worlds of the built-in generated set `verti-100` (seed 0): for each scale, the first
    /// world that is high-elevation, rigid and dense, and the first deformable world of the
    /// highest elevation level available. Errors when the generator fails.
    pub fn generated(scales: &[f64]) -> Result<BenchWorlds, String> {
        use verti_world::generate::{
            SetConfig, composition, elevation::ProceduralRock, generate_world,
        };
        use verti_world::{ElevationLevel, ObstacleDensity, TerrainType};
        let mut pairs: Vec<BenchWorldPair> = Vec::new();
        for &scale in scales {
            if pairs.iter().any(|p| (p.scale - scale).abs() < 1e-9) {
                continue;
            }
            let config = SetConfig {
                scale,
                ..Default::default()
            };
            let comp = composition(&config);
            let pick = |want: &dyn Fn(&(ElevationLevel, TerrainType, ObstacleDensity)) -> bool| {
                comp.iter().position(want).map(|i| i as u32 + 1)
            };
            let rigid = pick(&|c| {
                c.0 == ElevationLevel::High
                    && c.1 == TerrainType::Rigid
                    && c.2 == ObstacleDensity::Dense
            })
            .or_else(|| pick(&|c| c.1 == TerrainType::Rigid))
            .ok_or("the set has no rigid world")?;
            let soil = [
                ElevationLevel::High,
                ElevationLevel::Mid,
                ElevationLevel::Low,
            ]
            .iter()
            .find_map(|l| pick(&|c| c.0 == *l && c.1 == TerrainType::Deformable))
            .ok_or("the set has no deformable world")?;
            let make = |index: u32| {
                let (l, t, d) = comp[index as usize - 1];
                generate_world(&config, index, l, t, d, &ProceduralRock::default())
                    .map(Arc::new)
                    .map_err(|e| e.to_string())
            };
            pairs.push(BenchWorldPair {
                scale,
                rigid: make(rigid)?,
                soil: make(soil)?,
            });
        }
        Ok(BenchWorlds { pairs })
    }

    /// Generated worlds ([`BenchWorlds::generated`]) for the scales of the given vehicles.
    pub fn generated_for(vehicles: &[VehicleSpec]) -> Result<BenchWorlds, String> {
        let scales: Vec<f64> = vehicles.iter().map(|v| v.scale).collect();
        BenchWorlds::generated(&scales)
    }

    /// The pair whose scale is closest to `scale`.
    pub fn pair_for(&self, scale: f64) -> Option<&BenchWorldPair> {
        self.pairs
            .iter()
            .min_by(|a, b| (a.scale - scale).abs().total_cmp(&(b.scale - scale).abs()))
    }
}

/// One benchmark case: one vehicle on one world.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchCase {
    pub vehicle: String,
    /// `rigid` or `soil`.
    pub terrain: String,
    pub world: String,
    pub sim_seconds: f64,
    /// Median wall time of the runs \[s\].
    pub wall_seconds: f64,
    /// Real-time factor of the median run: simulated seconds per wall second.
    pub real_time_factor: f64,
    /// Real-time factor of the fastest run: the least disturbed by other processes on a
    /// shared machine.
    pub best_real_time_factor: f64,
    /// Every run's real-time factor.
    pub runs: Vec<f64>,
    /// Internal steps per run and the median cost per internal step \[µs\].
    pub internal_steps: u64,
    pub us_per_step: f64,
    /// Distance travelled (start to end, horizontal) \[m\].
    pub distance: f64,
    /// Set when the run ended early with an error.
    pub error: Option<String>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchReport {
    pub cases: Vec<BenchCase>,
    /// Always 1: every case runs on one thread.
    pub threads: usize,
}

impl fmt::Display for BenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{:<8} {:<6} {:>8} {:>10} {:>10} {:>10} {:>9} {:>9}  note",
            "vehicle", "ground", "sim s", "RTF", "best RTF", "µs/step", "steps", "dist m"
        )?;
        for c in &self.cases {
            writeln!(
                f,
                "{:<8} {:<6} {:>8.1} {:>9.0}x {:>9.0}x {:>10.3} {:>9} {:>9.1}  {}",
                c.vehicle,
                c.terrain,
                c.sim_seconds,
                c.real_time_factor,
                c.best_real_time_factor,
                c.us_per_step,
                c.internal_steps,
                c.distance,
                c.error.as_deref().unwrap_or("")
            )?;
        }
        Ok(())
    }
}

/// The benchmark's route: the first task's start (a spot the generator keeps clear of
/// obstacles) and its goal, or, for worlds without tasks, a chord through the map centre.
pub fn bench_route(world: &World) -> ([f64; 2], [f64; 2]) {
    match world.tasks.first() {
        Some(t) => (t.start, t.goal),
        None => {
            let r = 0.4 * world.terrain.half_extent();
            ([-r, 0.0], [r, 0.0])
        }
    }
}

/// The fixed scripted driver of the benchmark, like Verti-Bench's PID system: Verti-Bench's
/// proportional speed controller (gain 1, throttle or brake) toward 4 m/s (scaled by √scale),
/// and proportional steering toward `target`.
pub fn bench_controls(state: &SimState, target: [f64; 2], scale: f64) -> Controls {
    let u = (4.0 * scale.sqrt() - state.forward_speed()).clamp(-1.0, 1.0);
    let p = state.com_position();
    let (_, _, yaw) = state.euler();
    let bearing = (target[1] - p.y).atan2(target[0] - p.x);
    let steering = (2.0 * verti_core::math::wrap_angle(bearing - yaw)).clamp(-1.0, 1.0);
    Controls {
        throttle: u.max(0.0),
        brake: (-u).max(0.0),
        steering,
    }
}

/// Drives each vehicle for `sim_seconds` on the rigid and the soil world of its scale with
/// [`bench_controls`] along [`bench_route`] at a 50 Hz control rate, `runs` times, single-threaded, and reports the
/// median real-time factor per case.
pub fn bench(
    worlds: &BenchWorlds,
    vehicles: &[VehicleSpec],
    sim_seconds: f64,
    runs: usize,
) -> BenchReport {
    let mut cases = Vec::new();
    let control_dt = 0.02;
    for spec in vehicles {
        let Some(pair) = worlds.pair_for(spec.scale) else {
            continue;
        };
        for (terrain, world) in [("rigid", &pair.rigid), ("soil", &pair.soil)] {
            let mut rtfs = Vec::new();
            let mut walls = Vec::new();
            let mut error = None;
            let mut distance = 0.0;
            let mut steps = 0;
            let (from, to) = bench_route(world);
            let yaw0 = (to[1] - from[1]).atan2(to[0] - from[0]);
            let setup = start_pose(world, spec, from[0], from[1], yaw0)
                .and_then(|p| Sim::new(world, spec, p));
            let sim = match setup {
                Ok(s) => s,
                Err(e) => {
                    cases.push(BenchCase {
                        vehicle: spec.name.clone(),
                        terrain: terrain.into(),
                        world: world.meta.name.clone(),
                        sim_seconds: 0.0,
                        wall_seconds: 0.0,
                        real_time_factor: 0.0,
                        best_real_time_factor: 0.0,
                        runs: Vec::new(),
                        internal_steps: 0,
                        us_per_step: 0.0,
                        distance: 0.0,
                        error: Some(e.to_string()),
                    });
                    continue;
                }
            };
            let n = (sim_seconds / control_dt).round() as usize;
            steps = steps.max((sim_seconds / sim.internal_step()).round() as u64);
            let mut simulated = 0.0;
            for _ in 0..runs.max(1) {
                let mut state = sim.initial_state();
                let start = state.com_position();
                let t0 = Instant::now();
                // shuttle between the route's ends, turning back within 8 m (scaled) of each
                let mut target = to;
                let arrive = 8.0 * world.meta.scale;
                for _ in 0..n {
                    let p = state.com_position();
                    if (p.x - target[0]).hypot(p.y - target[1]) < arrive {
                        target = if target == to { from } else { to };
                    }
                    let controls = bench_controls(&state, target, world.meta.scale);
                    if let Err(e) = sim.step(&mut state, controls, control_dt) {
                        error = Some(e.to_string());
                        break;
                    }
                }
                let wall = t0.elapsed().as_secs_f64();
                simulated = state.time();
                let end = state.com_position();
                distance = (end.x - start.x).hypot(end.y - start.y);
                walls.push(wall);
                rtfs.push(simulated / wall.max(1e-12));
            }
            let mut sorted = walls.clone();
            sorted.sort_by(f64::total_cmp);
            let wall = sorted[sorted.len() / 2];
            let rtf = simulated / wall.max(1e-12);
            cases.push(BenchCase {
                vehicle: spec.name.clone(),
                terrain: terrain.into(),
                world: world.meta.name.clone(),
                sim_seconds: simulated,
                wall_seconds: wall,
                real_time_factor: rtf,
                best_real_time_factor: rtfs.iter().copied().fold(0.0, f64::max),
                runs: rtfs,
                internal_steps: steps,
                us_per_step: wall / (simulated / sim.internal_step()).max(1.0) * 1e6,
                distance,
                error,
            });
        }
    }
    BenchReport { cases, threads: 1 }
}

/// One episode that ended with a non-finite or absurd state.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SoakFailure {
    pub world: String,
    pub vehicle: String,
    pub episode: u64,
    pub episode_seed: u64,
    pub time: f64,
    pub error: String,
}

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SoakReport {
    /// Control steps of `control_dt` seconds taken in total.
    pub steps: u64,
    pub control_dt: f64,
    pub episodes: u64,
    pub simulated_seconds: f64,
    pub wall_seconds: f64,
    /// Episodes that ended with an error (NaN, blow-up).
    pub failures: Vec<SoakFailure>,
    /// Episodes in which the vehicle rolled over (not a failure: a physical outcome).
    pub rollovers: u64,
    /// Largest chassis speed seen \[m/s\].
    pub max_speed: f64,
}

impl fmt::Display for SoakReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} steps of {} s in {} episodes ({:.0} simulated s, {:.1} wall s): {} failures, {} rollovers, max speed {:.1} m/s",
            self.steps,
            self.control_dt,
            self.episodes,
            self.simulated_seconds,
            self.wall_seconds,
            self.failures.len(),
            self.rollovers,
            self.max_speed
        )?;
        for fl in &self.failures {
            writeln!(
                f,
                "  FAIL {} on {} episode {} (seed {}), t = {:.3}: {}",
                fl.vehicle, fl.world, fl.episode, fl.episode_seed, fl.time, fl.error
            )?;
        }
        Ok(())
    }
}

/// What one soak episode did.
#[derive(Clone, Debug)]
pub struct SoakEpisode {
    /// Control steps taken.
    pub steps: u64,
    pub simulated_seconds: f64,
    pub rolled_over: bool,
    pub max_speed: f64,
    /// Set when the episode ended with an error (NaN, blow-up, bad start).
    pub error: Option<(f64, SimError)>,
}

/// One soak episode, fully determined by `episode_seed`: a random start on the map (clear of
/// obstacles), then random throttle/brake/steering held for 0.1–2 s, `max_steps` control
/// steps of 10 ms at most, ending early on an error or when the vehicle leaves the map.
/// `on_step` sees the state after every step (for tracing a failure).
pub fn soak_episode(
    world: &Arc<World>,
    spec: &VehicleSpec,
    episode_seed: u64,
    max_steps: u64,
    mut on_step: impl FnMut(&Sim, &SimState, &Controls),
) -> SoakEpisode {
    let control_dt = SOAK_CONTROL_DT;
    let mut rng = Rng::new(episode_seed);
    let half = world.terrain.half_extent() * 0.8;
    let mut out = SoakEpisode {
        steps: 0,
        simulated_seconds: 0.0,
        rolled_over: false,
        max_speed: 0.0,
        error: None,
    };
    // random starts, redrawn (up to 100 times) while they fall inside an obstacle
    let mut pose = Err(SimError::InvalidStart("no start drawn".into()));
    for _ in 0..100 {
        let (x, y, yaw) = (
            rng.range(-half, half),
            rng.range(-half, half),
            rng.range(-std::f64::consts::PI, std::f64::consts::PI),
        );
        pose = start_pose(world, spec, x, y, yaw);
        if pose.is_ok() {
            break;
        }
    }
    let sim = match pose.and_then(|p| Sim::new(world, spec, p)) {
        Ok(s) => s,
        Err(e) => {
            out.error = Some((0.0, e));
            out.steps = 1;
            return out;
        }
    };
    let mut state = sim.initial_state();
    let mut controls = Controls::IDLE;
    let mut hold = 0.0;
    for _ in 0..max_steps {
        if hold <= 0.0 {
            let brake = if rng.uniform() < 0.15 {
                rng.uniform()
            } else {
                0.0
            };
            controls = Controls {
                throttle: rng.uniform(),
                brake,
                steering: rng.range(-1.0, 1.0),
            };
            hold = rng.range(0.1, 2.0);
        }
        hold -= control_dt;
        out.steps += 1;
        if let Err(e) = sim.step(&mut state, controls, control_dt) {
            out.error = Some((state.time(), e));
            break;
        }
        on_step(&sim, &state, &controls);
        out.max_speed = out.max_speed.max(state.velocity_world().norm());
        out.rolled_over |= state.is_rolled_over();
        let p = state.com_position();
        if !world.terrain.contains(p.x, p.y) {
            break; // drove off the map: the next episode starts elsewhere
        }
    }
    out.simulated_seconds = state.time();
    out
}

/// Control step of the soak [s].
pub const SOAK_CONTROL_DT: f64 = 0.01;

/// Drives random inputs (held for random 0.1–2 s) through every world with every vehicle
/// whose scale matches it (within 1 %; all vehicles when none matches), `steps` control steps
/// of 10 ms in all, in episodes of up to 60 s from random starts ([`soak_episode`]; a failure
/// is reproduced by calling it with the reported episode seed). An episode that errors is
/// recorded and ended; the others are unaffected. `progress` gets the steps done so far.
pub fn soak(
    worlds: &[Arc<World>],
    vehicles: &[VehicleSpec],
    steps: u64,
    seed: u64,
    progress: impl Fn(u64),
) -> SoakReport {
    let episode_steps = (60.0 / SOAK_CONTROL_DT) as u64;
    let mut report = SoakReport {
        control_dt: SOAK_CONTROL_DT,
        ..Default::default()
    };
    let t0 = Instant::now();
    let mut pairs = Vec::new();
    for w in worlds {
        let matching: Vec<&VehicleSpec> = vehicles
            .iter()
            .filter(|v| (v.scale / w.meta.scale - 1.0).abs() < 0.01)
            .collect();
        let chosen = if matching.is_empty() {
            vehicles.iter().collect()
        } else {
            matching
        };
        for v in chosen {
            pairs.push((Arc::clone(w), v.clone()));
        }
    }
    if pairs.is_empty() {
        return report;
    }
    let mut episode = 0u64;
    let mut done = 0u64;
    let mut last_progress = 0u64;
    while done < steps {
        let (world, spec) = &pairs[(episode % pairs.len() as u64) as usize];
        let episode_seed = verti_core::rng::mix_seed(&[seed, episode]);
        let ep = soak_episode(
            world,
            spec,
            episode_seed,
            episode_steps.min(steps - done),
            |_, _, _| {},
        );
        done += ep.steps;
        if done / 10_000 > last_progress / 10_000 {
            progress(done);
        }
        last_progress = done;
        if let Some((time, e)) = ep.error {
            report.failures.push(SoakFailure {
                world: world.meta.name.clone(),
                vehicle: spec.name.clone(),
                episode,
                episode_seed,
                time,
                error: e.to_string(),
            });
        }
        report.simulated_seconds += ep.simulated_seconds;
        report.rollovers += u64::from(ep.rolled_over);
        report.max_speed = report.max_speed.max(ep.max_speed);
        episode += 1;
    }
    report.steps = done;
    report.episodes = episode;
    report.wall_seconds = t0.elapsed().as_secs_f64();
    progress(done);
    report
}
