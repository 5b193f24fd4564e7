//! The random-input robustness run behind `verti sim soak`: random starts, random held inputs,
//! every error recorded with the seed that reproduces it.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;
use std::time::Instant;
use verti_core::Rng;
use verti_sim::{Controls, Sim, SimError, SimState, StartPose, VehicleSpec};
use verti_world::World;

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
            writeln!(
                f,
                "       trace it: verti sim soak --replay {} --world {} --vehicle {}",
                fl.episode_seed,
                super::trace::world_argument(&fl.world),
                fl.vehicle
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
    let started = Sim::new(world, spec).and_then(|sim| {
        // random starts, redrawn (up to 100 times) while they fall inside an obstacle
        let mut state = Err(SimError::InvalidStart("no start drawn".into()));
        for _ in 0..100 {
            let (x, y, yaw) = (
                rng.range(-half, half),
                rng.range(-half, half),
                rng.range(-std::f64::consts::PI, std::f64::consts::PI),
            );
            state = sim.state_at(StartPose::new(x, y, yaw));
            if state.is_ok() {
                break;
            }
        }
        Ok((sim, state?))
    });
    let (sim, mut state) = match started {
        Ok(s) => s,
        Err(e) => {
            out.error = Some((0.0, e));
            out.steps = 1;
            return out;
        }
    };
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

/// Control step of the soak \[s\].
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

/// Replays the soak episode of `episode_seed` (the very episode `soak` ran: same draws, same
/// steps) and hands `print` a trace line every `every` control steps, then a closing line.
pub fn replay(
    world: &Arc<World>,
    spec: &VehicleSpec,
    episode_seed: u64,
    every: u64,
    mut print: impl FnMut(&str),
) -> SoakEpisode {
    let mut k = 0u64;
    // 6000 steps of 10 ms: the soak's longest episode (60 s)
    let episode = soak_episode(world, spec, episode_seed, 6000, |_, state, controls| {
        k += 1;
        if k.is_multiple_of(every.max(1)) {
            print(&super::trace::trace_line(state, controls));
        }
    });
    print(&format!(
        "{} steps, {:.2} simulated s, error: {}",
        episode.steps,
        episode.simulated_seconds,
        episode
            .error
            .as_ref()
            .map_or("none".to_string(), |(t, e)| format!("at t = {t:.3} s: {e}"))
    ));
    episode
}
