//! The speed benchmark behind `verti sim bench`: a scripted driver on a rigid, a soil and a
//! mixed world per vehicle scale, timed single-threaded.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;
use std::time::Instant;
use verti_sim::{Controls, Sim, SimState, StartPose, VehicleSpec};
use verti_world::World;

/// A rigid, a deformable and a mixed world for one world scale.
#[derive(Clone, Debug)]
pub struct BenchWorldPair {
    pub scale: f64,
    /// High relief, dense obstacles, rigid ground.
    pub rigid: Arc<World>,
    /// Deformable ground (snow, mud and sand patches).
    pub soil: Arc<World>,
    /// Rigid patches beside soil (where their edges meet the wheels).
    pub mixed: Arc<World>,
}

/// The worlds the benchmark drives on, one pair per vehicle scale.
#[derive(Clone, Debug, Default)]
pub struct BenchWorlds {
    pub pairs: Vec<BenchWorldPair>,
}

impl BenchWorlds {
    /// Worlds of the built-in generated set `verti-100` (seed 0): for each scale, the first
    /// world that is high-elevation, rigid and dense, and the first deformable and the first
    /// mixed world of the highest elevation level available. Errors when the generator fails.
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
            let highest = |kind: TerrainType| {
                [
                    ElevationLevel::High,
                    ElevationLevel::Mid,
                    ElevationLevel::Low,
                ]
                .iter()
                .find_map(|l| pick(&|c| c.0 == *l && c.1 == kind))
            };
            let soil = highest(TerrainType::Deformable).ok_or("the set has no deformable world")?;
            let mixed = highest(TerrainType::Mixed).ok_or("the set has no mixed world")?;
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
                mixed: make(mixed)?,
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
    /// `rigid`, `soil` or `mixed`.
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
            "{:<11} {:<6} {:>8} {:>10} {:>10} {:>10} {:>9} {:>9}  note",
            "vehicle", "ground", "sim s", "RTF", "best RTF", "µs/step", "steps", "dist m"
        )?;
        for c in &self.cases {
            writeln!(
                f,
                "{:<11} {:<6} {:>8.1} {:>9.0}x {:>9.0}x {:>10.3} {:>9} {:>9.1}  {}",
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

/// Drives each vehicle for `sim_seconds` on the rigid, the soil and the mixed world of its scale with
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
        for (terrain, world) in [
            ("rigid", &pair.rigid),
            ("soil", &pair.soil),
            ("mixed", &pair.mixed),
        ] {
            let mut rtfs = Vec::new();
            let mut walls = Vec::new();
            let mut error = None;
            let mut distance = 0.0;
            let mut steps = 0;
            let (from, to) = bench_route(world);
            let yaw0 = (to[1] - from[1]).atan2(to[0] - from[0]);
            let setup = Sim::new(world, spec).and_then(|sim| {
                let start = sim.state_at(StartPose::new(from[0], from[1], yaw0))?;
                Ok((sim, start))
            });
            let (sim, start_state) = match setup {
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
                let mut state = start_state.clone();
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
