//! The trial loop: parallel, deterministic evaluation of a task selection, one result line per
//! finished trial.
//!
//! Results go to `OUT/results.jsonl`, one JSON object per finished trial, appended and flushed
//! as each trial ends, so a killed run loses at most the trials in flight. Everything else about
//! the directory (its lock, `OUT/run.json` recording what was run, resuming, the results file's
//! format) is run bookkeeping, in [`crate::run`], which [`evaluate`] calls before its first
//! trial. Each trial depends only on its task and the run seed, so the results are the same for
//! any number of jobs (only `wall_time` differs).

use crate::episode::{EpisodeConfig, TrialResult, run_episode};
use crate::run::identity::{InputFile, SplitRecord};
use crate::run::{RunSettings, io};
use crate::system::MobilitySystem;
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use verti_sim::VehicleSpec;
use verti_world::World;

// The run bookkeeping this module's callers have long reached through it (the directory's file
// names, task selections, the results file, the error and the run's description) lives in
// `crate::run`, below the loop; re-exported here, their long-standing paths.
pub use crate::run::identity::RunInfo;
pub use crate::run::{
    EvalError, LOCK_FILE, RESULTS_FILE, RUN_FILE, STEPS_DIR, format_tasks, parse_tasks,
    read_results, result_line, select_tasks,
};

/// Where per-step logs of trials go: `write` receives each finished trial with its log (the
/// last `seconds` of it, or all of it for infinity) before the trial's result line is appended,
/// so every recorded result has its log.
pub struct StepLogSink<'a> {
    pub seconds: f64,
    pub write: &'a (dyn Fn(&TrialResult, &crate::episode::EpisodeLog) -> Result<(), String> + Sync),
}

/// Settings of one evaluation run.
pub struct EvalSetup<'a> {
    pub worlds: &'a [Arc<World>],
    /// Whether `worlds` are the whole set `run.worlds` names. A run of selected tasks may load
    /// only the worlds they are on ([`crate::run::worlds_to_load`]); its `run.json` then
    /// records each world's digest instead of the set's.
    pub whole_set: bool,
    pub vehicle: &'a VehicleSpec,
    pub episode: EpisodeConfig,
    pub jobs: usize,
    pub out: PathBuf,
    pub resume: bool,
    /// Overwrite an existing results file instead of refusing.
    pub force: bool,
    pub run: RunInfo,
    /// The files the system loads when it drives the given tasks (world position, pair), by
    /// content ([`crate::run::identity::system_inputs`]): recorded, and compared on resume.
    /// Called once the run's tasks are known (a resume may take them from `run.json`).
    #[allow(clippy::type_complexity)]
    pub inputs: Option<&'a (dyn Fn(&[(usize, u32)]) -> Result<Vec<InputFile>, EvalError> + Sync)>,
    /// The split this run is a shard of (`--shard`), recorded for `verti merge`.
    pub shard: Option<SplitRecord>,
    /// Optional per-step logs.
    pub step_log: Option<StepLogSink<'a>>,
    /// Raised to stop the run: trials that finish after it is raised are not recorded (they
    /// may have been cut short), and `evaluate` returns `EvalError::Cancelled`.
    pub cancel: Option<&'a AtomicBool>,
    /// Told about anything repaired on the way (a torn last line dropped on resume).
    pub warn: Option<&'a (dyn Fn(&str) + Sync)>,
}

/// The most worker threads a run may ask for: a few per core is plenty for CPU-bound trials,
/// and far more only thrashes the machine.
pub fn max_jobs() -> usize {
    4 * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Checks a worker-thread count (`what` names the option in the message).
pub fn check_jobs(jobs: usize, what: &str) -> Result<(), String> {
    let max = max_jobs();
    if jobs == 0 {
        return Err(format!("{what} must be at least 1"));
    }
    if jobs > max {
        return Err(format!(
            "{what} {jobs} is too many: this machine has {} cores; use at most {max}",
            max / 4
        ));
    }
    Ok(())
}

/// Runs the selected tasks; returns all results of the run (earlier and new), sorted by task.
pub fn evaluate(
    setup: &EvalSetup,
    selection: &[u32],
    make_system: &(dyn Fn() -> Box<dyn MobilitySystem> + Sync),
    on_result: &(dyn Fn(&TrialResult) + Sync),
) -> Result<Vec<TrialResult>, EvalError> {
    check_jobs(setup.jobs, "--jobs").map_err(EvalError::Argument)?;
    setup.episode.validate().map_err(EvalError::Argument)?;
    // checks the selection before anything is written
    select_tasks(setup.worlds, selection)?;
    // the directory locked (until `run` is dropped, when this function returns), fresh or
    // resumed, with run.json written: the results already there and the tasks left
    let run = crate::run::open(
        &RunSettings {
            worlds: setup.worlds,
            whole_set: setup.whole_set,
            vehicle: setup.vehicle,
            episode: &setup.episode,
            step_log: setup.step_log.as_ref().map(|s| s.seconds),
            out: &setup.out,
            resume: setup.resume,
            force: setup.force,
            run: &setup.run,
            inputs: setup.inputs,
            shard: setup.shard.as_ref(),
            warn: setup.warn,
        },
        selection,
    )?;
    let results_path = &run.results_path;
    let todo = &run.todo;

    let file = std::fs::OpenOptions::new()
        .append(true)
        .open(results_path)
        .map_err(io(results_path))?;
    let sink = Mutex::new(file);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(setup.jobs)
        .build()
        .map_err(|e| {
            EvalError::Argument(format!("cannot start {} worker threads: {e}", setup.jobs))
        })?;
    let fresh: Result<Vec<TrialResult>, EvalError> = pool.install(|| {
        todo.par_iter()
            .map(|&(wi, pair)| {
                let cancelled = || setup.cancel.is_some_and(|c| c.load(Ordering::SeqCst));
                if cancelled() {
                    return Err(EvalError::Cancelled);
                }
                let mut system = make_system();
                let r = match &setup.step_log {
                    None => run_episode(
                        &setup.worlds[wi],
                        setup.vehicle,
                        pair,
                        system.as_mut(),
                        &setup.episode,
                        None,
                    ),
                    Some(sink) => {
                        let mut log = crate::episode::EpisodeLog::default();
                        let cfg = EpisodeConfig {
                            log_seconds: Some(sink.seconds),
                            ..setup.episode.clone()
                        };
                        let r = run_episode(
                            &setup.worlds[wi],
                            setup.vehicle,
                            pair,
                            system.as_mut(),
                            &cfg,
                            Some(&mut log),
                        );
                        if cancelled() {
                            return Err(EvalError::Cancelled);
                        }
                        (sink.write)(&r, &log).map_err(EvalError::Argument)?;
                        r
                    }
                };
                if cancelled() {
                    return Err(EvalError::Cancelled);
                }
                let mut line = result_line(&r);
                line.push('\n');
                {
                    let mut f = sink.lock().unwrap_or_else(|p| p.into_inner());
                    f.write_all(line.as_bytes())
                        .and_then(|_| f.flush())
                        .map_err(io(results_path))?;
                }
                on_result(&r);
                Ok(r)
            })
            .collect()
    });
    let mut all = run.previous;
    all.extend(fresh?);
    all.sort_by_key(|r| r.task);
    Ok(all)
}
