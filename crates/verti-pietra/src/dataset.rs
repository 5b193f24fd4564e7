//! The PIETRA dataset (paper §V-A): 20 exploration trials per map with sinusoidal steering at
//! 2 m/s, each ending on rollover, stuck or leaving the map, cut into samples of what the
//! footprint looked like and how the vehicle fared on it.
//!
//! A sample at time t holds
//! * the **feature** o: a yaw-aligned elevation patch of the footprint (12 x 7 cells of 0.4 m,
//!   heights relative to the patch mean; one semantic class, dirt, so no semantic channel);
//! * the **targets** ψ: linear traction (distance made good along the heading over the next
//!   0.1 s / commanded), angular traction (yaw change / commanded yaw change), |roll|, |pitch|;
//! * the **unevenness** (standard deviation of the patch's heights), which splits ID from OOD;
//! * the [`Footprint`] the physics prior reads (wheel heights and slopes along the heading).
//!
//! Everything is a function of the maps, the vehicle and the seed: trials run in parallel and
//! are gathered in order, so the data are the same for any thread count.

use crate::bins::PARAMS;
use crate::maps::{self, Split};
use crate::prior::Footprint;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::sync::Arc;
use verti_bench::{Action, EpisodeConfig, Trial, pose6};
use verti_core::Rng;
use verti_sim::{Sim, StartPose, VehicleSpec};
use verti_world::{Heightfield, World};

/// Patch cells along the heading.
pub const PATCH_LENGTH: usize = 12;
/// Patch cells across the heading.
pub const PATCH_WIDTH: usize = 7;
/// Patch resolution, metres: 4.8 m x 2.8 m covers the HMMWV's wheels (3.4 m x 1.8 m) with a
/// margin.
pub const PATCH_CELL: f64 = 0.4;
/// Numbers in a feature.
pub const FEATURES: usize = PATCH_LENGTH * PATCH_WIDTH;
/// Horizontal distance over which a wheel's slope along the heading is measured, metres.
pub const SLOPE_BASE: f64 = 1.0;

/// Where a vehicle's wheels are, in its own frame (x forward, y left), in the prior's order:
/// front-left, rear-left, rear-right, front-right.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelLayout {
    pub wheels: [[f64; 2]; 4],
    pub track: f64,
    pub wheelbase: f64,
}

impl WheelLayout {
    /// From the first and last axles of a vehicle.
    pub fn of(spec: &VehicleSpec) -> WheelLayout {
        let (front, rear) = (
            spec.axles.first().map_or((0.0, 1.0), |a| (a.x, a.track)),
            spec.axles.last().map_or((0.0, 1.0), |a| (a.x, a.track)),
        );
        let track = 0.5 * (front.1 + rear.1);
        WheelLayout {
            wheels: [
                [front.0, 0.5 * front.1],
                [rear.0, 0.5 * rear.1],
                [rear.0, -0.5 * rear.1],
                [front.0, -0.5 * front.1],
            ],
            track,
            wheelbase: front.0 - rear.0,
        }
    }
}

/// A point `forward` ahead and `left` to the left of (x, y) facing `yaw`.
#[inline]
pub(crate) fn offset(x: f64, y: f64, yaw: f64, forward: f64, left: f64) -> (f64, f64) {
    let (s, c) = yaw.sin_cos();
    (x + forward * c - left * s, y + forward * s + left * c)
}

/// Terrain height at continuous grid coordinates (column, row), clamped to the map: the
/// triangle interpolation of [`Heightfield::sample`], without its slopes (the hot loop of
/// feature extraction and CVaR maps).
#[inline(always)]
pub(crate) fn height_on_grid(t: &Heightfield, gc: f64, gr: f64) -> f64 {
    let n = t.size();
    let m = (n - 1) as f64;
    let (gc, gr) = (gc.clamp(0.0, m), gr.clamp(0.0, m));
    // through i64, one instruction (both casts give 0 for NaN and agree on [0, m])
    let c0 = (gc as i64 as usize).min(n - 2);
    let r0 = (gr as i64 as usize).min(n - 2);
    let u = gc - c0 as i64 as f64;
    let v = 1.0 - (gr - r0 as i64 as f64);
    let h = &t.heights()[r0 * n + c0..];
    let (nw, ne, sw, se) = (h[0], h[1], h[n], h[n + 1]);
    // Both triangles, then a select: which one applies changes from point to point, and a
    // mispredicted branch costs more than the second formula.
    let lower = sw + u * (se - sw) + v * (ne - se);
    let upper = sw + v * (nw - sw) + u * (ne - nw);
    if u >= v { lower } else { upper }
}

/// [`Heightfield::height_at`] (the same arithmetic, so the same value) by
/// [`height_on_grid`].
#[inline(always)]
pub(crate) fn height_at(t: &Heightfield, x: f64, y: f64) -> f64 {
    let (gc, gr) = t.grid_coords(x, y);
    height_on_grid(t, gc, gr)
}

/// Fills `out` with the yaw-aligned footprint patch at (x, y, yaw), heights relative to the
/// patch mean (row-major, forward rows first, left columns first), and returns the patch's
/// unevenness (the standard deviation of its heights).
pub fn footprint_patch(terrain: &Heightfield, x: f64, y: f64, yaw: f64, out: &mut [f32]) -> f64 {
    assert_eq!(out.len(), FEATURES, "feature buffer length");
    let mut h = [0.0f64; FEATURES];
    let half_l = 0.5 * (PATCH_LENGTH - 1) as f64;
    let half_w = 0.5 * (PATCH_WIDTH - 1) as f64;
    // offsets in grid units: column grows with x, row grows with −y
    let (gc0, gr0) = terrain.grid_coords(x, y);
    let (s, c) = yaw.sin_cos();
    let k = PATCH_CELL / terrain.cell();
    let (fx, fy) = (c * k, s * k); // one cell forward, in (column, −row)
    let (lx, ly) = (-s * k, c * k); // one cell left
    for i in 0..PATCH_LENGTH {
        let f = half_l - i as f64;
        for j in 0..PATCH_WIDTH {
            let l = half_w - j as f64;
            let gc = gc0 + f * fx + l * lx;
            let gr = gr0 - (f * fy + l * ly);
            h[i * PATCH_WIDTH + j] = height_on_grid(terrain, gc, gr);
        }
    }
    let mean = h.iter().sum::<f64>() / FEATURES as f64;
    let mut var = 0.0;
    for (o, v) in out.iter_mut().zip(&h) {
        *o = (v - mean) as f32;
        var += (v - mean) * (v - mean);
    }
    (var / FEATURES as f64).sqrt()
}

/// What the physics prior reads at (x, y, yaw): terrain height under each wheel of a level
/// vehicle, and the slope along the heading there (over [`SLOPE_BASE`]).
pub fn footprint(
    terrain: &Heightfield,
    layout: &WheelLayout,
    x: f64,
    y: f64,
    yaw: f64,
) -> Footprint {
    let mut heights = [0.0; 4];
    let mut slopes = [0.0; 4];
    for (k, w) in layout.wheels.iter().enumerate() {
        let (wx, wy) = offset(x, y, yaw, w[0], w[1]);
        heights[k] = terrain.height_at(wx, wy);
        let (ax, ay) = offset(wx, wy, yaw, 0.5 * SLOPE_BASE, 0.0);
        let (bx, by) = offset(wx, wy, yaw, -0.5 * SLOPE_BASE, 0.0);
        slopes[k] = ((terrain.height_at(ax, ay) - terrain.height_at(bx, by)) / SLOPE_BASE).atan();
    }
    Footprint {
        heights,
        slopes,
        track: layout.track,
        wheelbase: layout.wheelbase,
        vegetation: [0.0; 4],
        veg_fraction: 0.0,
        friction: [crate::prior::DIRT_FRICTION; 4],
    }
}

/// One training example.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    pub features: [f32; FEATURES],
    /// ψ1..ψ4: linear traction, angular traction in [0, 1]; |roll|, |pitch| in radians.
    pub targets: [f64; PARAMS],
    pub unevenness: f64,
    pub footprint: Footprint,
    /// Map index (1..=30) and trial number within the map.
    pub map: u32,
    pub trial: u32,
}

/// How the data are driven.
#[derive(Clone, Debug)]
pub struct DataConfig {
    pub vehicle: VehicleSpec,
    pub trials_per_map: u32,
    /// Speed command, m/s (paper: 2).
    pub speed: f64,
    /// Sample period, s.
    pub period: f64,
    /// Samples start this long after a trial's start: the vehicle is still accelerating before.
    pub warmup: f64,
    pub max_trial_seconds: f64,
    /// Trials end when the chassis comes this close to the map's edge, m.
    pub edge_margin: f64,
    /// A trial is stuck when it made less than `stuck_distance` m in the last `stuck_window` s.
    /// Shorter than the benchmark's 10 s: a stalled vehicle would otherwise fill the data with
    /// ~100 identical samples per trial (on the rough test maps most trials end stuck).
    pub stuck_window: f64,
    pub stuck_distance: f64,
    /// Samples whose commanded yaw rate is below this (rad/s) are dropped: angular traction
    /// is a ratio and is meaningless there.
    pub min_yaw_rate: f64,
    pub seed: u64,
}

impl DataConfig {
    /// The paper's protocol with `vehicle`.
    pub fn paper(vehicle: VehicleSpec) -> DataConfig {
        DataConfig {
            vehicle,
            trials_per_map: 20,
            speed: 2.0,
            period: 0.1,
            warmup: 3.0,
            max_trial_seconds: 120.0,
            edge_margin: 4.0,
            stuck_window: 3.0,
            stuck_distance: 0.5,
            min_yaw_rate: 0.05,
            seed: 0,
        }
    }
}

/// The samples of one split, with what the trials did.
#[derive(Clone, Debug, Default)]
pub struct SplitData {
    pub samples: Vec<Sample>,
    pub trials: usize,
    pub seconds: f64,
    /// Trials per ending (rollover, stuck, edge, timeout).
    pub endings: BTreeMap<String, usize>,
}

/// Drives the trials of `split` and gathers their samples.
pub fn collect(split: Split, cfg: &DataConfig) -> Result<SplitData, String> {
    let worlds = maps::split_maps(split);
    let sims: Vec<Arc<Sim>> = worlds
        .iter()
        .map(|w| Sim::new(w, &cfg.vehicle).map(Arc::new))
        .collect::<Result<_, _>>()
        .map_err(|e| format!("cannot build the vehicle model: {e}"))?;
    let layout = WheelLayout::of(&cfg.vehicle);
    let jobs: Vec<(usize, u32)> = (0..worlds.len())
        .flat_map(|w| (0..cfg.trials_per_map).map(move |t| (w, t)))
        .collect();
    let runs: Vec<Result<DrivenTrial, String>> = jobs
        .par_iter()
        .map(|&(w, t)| drive_trial(&worlds[w], &sims[w], &layout, t, cfg))
        .collect();
    let mut out = SplitData::default();
    for run in runs {
        let (samples, seconds, ending) = run?;
        out.samples.extend(samples);
        out.trials += 1;
        out.seconds += seconds;
        *out.endings.entry(ending).or_default() += 1;
    }
    Ok(out)
}

/// A random start on `world` away from the edge and not too tilted.
fn random_start(rng: &mut Rng, world: &World, sim: &Sim) -> Result<StartPose, String> {
    let reach = world.terrain.half_extent() - 10.0;
    for _ in 0..200 {
        let start = StartPose::new(
            rng.range(-reach, reach),
            rng.range(-reach, reach),
            rng.range(-std::f64::consts::PI, std::f64::consts::PI),
        );
        let Ok(state) = sim.state_at(start) else {
            continue;
        };
        let p = pose6(sim, &state);
        if p.roll.abs() < 20f64.to_radians() && p.pitch.abs() < 20f64.to_radians() {
            return Ok(start);
        }
    }
    Err(format!(
        "no valid start on {} in 200 draws",
        world.meta.name
    ))
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI
}

/// One trial's samples, its simulated length and how it ended.
type DrivenTrial = (Vec<Sample>, f64, String);

/// One trial: its samples, its simulated length and how it ended.
fn drive_trial(
    world: &Arc<World>,
    sim: &Arc<Sim>,
    layout: &WheelLayout,
    trial_no: u32,
    cfg: &DataConfig,
) -> Result<DrivenTrial, String> {
    let mut rng = Rng::derive(
        cfg.seed,
        "pietra-trial",
        u64::from(world.meta.index) * 1000 + u64::from(trial_no),
    );
    let start = random_start(&mut rng, world, sim)?;
    let steer_hz = rng.range(0.1, 0.5);
    let phase = rng.range(0.0, TAU);
    let episode = EpisodeConfig {
        max_time: cfg.max_trial_seconds,
        stuck_window: cfg.stuck_window,
        stuck_distance: cfg.stuck_distance,
        seed: rng.next_u64(),
        ..Default::default()
    };
    let mut trial = Trial::explore(world, sim.clone(), start, &episode, "pietra-data")?;
    let max_steer = trial.info().max_steer_angle;
    let edge = world.terrain.half_extent() - cfg.edge_margin;
    let mut samples = Vec::new();
    let ending = loop {
        let t = trial.time();
        let steering = (TAU * steer_hz * t + phase).sin();
        let before = trial.pose();
        let step = trial.step(
            Action::HighLevel {
                speed: cfg.speed,
                steering,
            },
            cfg.period,
        );
        let after = trial.pose();
        if t + 1e-9 >= cfg.warmup {
            let yaw_rate_cmd = cfg.speed * (steering * max_steer).tan() / layout.wheelbase;
            if yaw_rate_cmd.abs() >= cfg.min_yaw_rate {
                let (s, c) = before.yaw.sin_cos();
                let along = (after.x - before.x) * c + (after.y - before.y) * s;
                let linear = (along / (cfg.speed * cfg.period)).clamp(0.0, 1.0);
                let turned = wrap(after.yaw - before.yaw);
                let angular = (turned / (yaw_rate_cmd * cfg.period)).clamp(0.0, 1.0);
                let mut features = [0.0f32; FEATURES];
                let unevenness = footprint_patch(
                    &world.terrain,
                    before.x,
                    before.y,
                    before.yaw,
                    &mut features,
                );
                samples.push(Sample {
                    features,
                    targets: [linear, angular, before.roll.abs(), before.pitch.abs()],
                    unevenness,
                    footprint: footprint(&world.terrain, layout, before.x, before.y, before.yaw),
                    map: world.meta.index,
                    trial: trial_no,
                });
            }
        }
        if let Some(outcome) = step.ended {
            break outcome.name().to_string();
        }
        if after.x.abs() >= edge || after.y.abs() >= edge {
            break "edge".to_string();
        }
    };
    Ok((samples, trial.time(), ending))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(slope_x: f64) -> Heightfield {
        let n = 41;
        let mut h = Vec::with_capacity(n * n);
        for r in 0..n {
            for c in 0..n {
                let _ = r;
                h.push(slope_x * (c as f64 - 20.0) * 0.5);
            }
        }
        Heightfield::new(n, 0.5, h)
    }

    #[test]
    fn grid_lookup_is_the_heightfield_surface() {
        let w = crate::maps::map(crate::maps::Split::Test, 21);
        let t = &w.terrain;
        let mut rng = verti_core::Rng::new(1);
        for _ in 0..1000 {
            let (x, y) = (rng.range(-27.0, 27.0), rng.range(-27.0, 27.0));
            let (gc, gr) = t.grid_coords(x, y);
            let (a, b) = (height_on_grid(t, gc, gr), t.height_at(x, y));
            assert!((a - b).abs() < 1e-9, "({x}, {y}): {a} vs {b}");
        }
    }

    #[test]
    fn patch_of_a_plane_is_centred_and_aligned() {
        let t = plane(0.2);
        let mut f = [0.0f32; FEATURES];
        // facing +x: heights rise along the patch's rows (forward first), not across
        let u = footprint_patch(&t, 0.0, 0.0, 0.0, &mut f);
        assert!(f.iter().map(|v| f64::from(*v)).sum::<f64>().abs() < 1e-4);
        assert!((f64::from(f[0] - f[PATCH_WIDTH]) - 0.2 * PATCH_CELL).abs() < 1e-5);
        assert!(f64::from((f[0] - f[1]).abs()) < 1e-6);
        // facing +y the same plane varies across the patch only
        let u2 = footprint_patch(&t, 0.0, 0.0, std::f64::consts::FRAC_PI_2, &mut f);
        assert!(f64::from((f[0] - f[PATCH_WIDTH]).abs()) < 1e-5);
        assert!(
            u > u2,
            "a slope along 4.8 m is more uneven than across 2.8 m"
        );
        let fp = footprint(
            &t,
            &WheelLayout {
                wheels: [[1.7, 0.9], [-1.7, 0.9], [-1.7, -0.9], [1.7, -0.9]],
                track: 1.8,
                wheelbase: 3.4,
            },
            0.0,
            0.0,
            0.0,
        );
        for s in fp.slopes {
            assert!((s - 0.2f64.atan()).abs() < 1e-9);
        }
        assert!((fp.heights[0] - fp.heights[1] - 0.2 * 3.4).abs() < 1e-9);
    }
}
