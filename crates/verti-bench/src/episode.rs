//! One trial: one system drives one vehicle on one task ([`run_episode`]).
//!
//! The rules a trial ends by ([`Rules`], [`Termination`]; paper §III-F, §III-G.3, or the
//! reference code's with `Rules::VertiBench`) live in `crate::rules`, and the trial's record
//! ([`TrialResult`], [`EpisodeLog`]) in `crate::result`, below [`Trial`] which applies them;
//! they are re-exported here, their long-standing path.

pub use crate::result::{EpisodeLog, StepRecord, TrialResult};
pub use crate::rules::{EpisodeConfig, Outcome, Rules, StartMode, Termination};

use crate::system::{Action, MobilitySystem};
use crate::trial::{Trial, failed_result};
use std::sync::Arc;
use std::time::Instant;
use verti_sim::VehicleSpec;
use verti_world::World;

/// Runs one trial: `system.act` at the system's rate, each action held by [`Trial::step`].
/// Never panics on bad system output or simulator blow-ups: those end the trial with
/// `Outcome::Error` and a message. With `log`, the trial's per-step log is written into it (the
/// last `cfg.log_seconds` of it, or all of it when that is unset).
pub fn run_episode(
    world: &Arc<World>,
    spec: &VehicleSpec,
    pair: u32,
    system: &mut dyn MobilitySystem,
    cfg: &EpisodeConfig,
    log: Option<&mut EpisodeLog>,
) -> TrialResult {
    run_episode_watched(world, spec, pair, system, cfg, log, &mut |_| {})
}

/// The period (s) between a system's actions, from its control rate, or why the rate is not one
/// (not finite, not positive, above 1 kHz).
pub fn control_period(system: &dyn MobilitySystem) -> Result<f64, String> {
    let rate = system.control_rate();
    if !(rate.is_finite() && rate > 0.0 && rate <= 1000.0) {
        return Err(format!(
            "system {} has an invalid control rate {rate} Hz",
            system.name()
        ));
    }
    Ok(1.0 / rate)
}

/// The system's action on the trial's current observation; None when the system reports a
/// failure, which ends the trial as an error naming it.
pub fn next_action(trial: &mut Trial, system: &mut dyn MobilitySystem) -> Option<Action> {
    let action = system.act(&trial.observation());
    if let Some(message) = system.failure() {
        trial.abort(format!("system {} failed: {message}", system.name()));
        return None;
    }
    Some(action)
}

/// [`run_episode`], showing `watch` the trial at its start and after every control period
/// (3-D recordings, live views). Watching changes nothing: the result is the same bits.
pub fn run_episode_watched(
    world: &Arc<World>,
    spec: &VehicleSpec,
    pair: u32,
    system: &mut dyn MobilitySystem,
    cfg: &EpisodeConfig,
    log: Option<&mut EpisodeLog>,
    watch: &mut dyn FnMut(&Trial),
) -> TrialResult {
    let wall = Instant::now();
    let name = system.name().to_string();
    let cfg = match (&log, cfg.log_seconds) {
        (Some(_), None) => EpisodeConfig {
            log_seconds: Some(f64::INFINITY),
            ..cfg.clone()
        },
        (None, Some(_)) => EpisodeConfig {
            log_seconds: None,
            ..cfg.clone()
        },
        _ => cfg.clone(),
    };
    let failed = |message: String| {
        let mut r = failed_result(world, &spec.name, pair, &name, &cfg, message);
        r.wall_time = wall.elapsed().as_secs_f64();
        r
    };
    let mut trial = match Trial::start(world, spec, pair, &cfg, &name) {
        Ok(t) => t,
        Err(e) => return failed(e),
    };
    system.reset(trial.info());
    let period = match control_period(system) {
        Ok(p) => p,
        Err(e) => return failed(e),
    };
    watch(&trial);
    while let Some(action) = next_action(&mut trial, system) {
        let ended = trial.step(action, period).ended.is_some();
        watch(&trial);
        if ended {
            break;
        }
    }
    if let (Some(out), Some(kept)) = (log, trial.take_log()) {
        *out = kept;
    }
    let mut result = trial.finish();
    result.wall_time = wall.elapsed().as_secs_f64();
    result
}
