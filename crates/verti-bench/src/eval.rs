//! Parallel, deterministic, resumable evaluation.
//!
//! Results go to `OUT/results.jsonl`, one JSON object per finished trial, appended and flushed
//! as each trial ends, so a killed run loses at most the trials in flight; `resume` reads the
//! file back (dropping a torn last line), skips the tasks already done and appends the rest.
//! `OUT/run.json` records what was run; resuming with different settings is refused. Each
//! trial depends only on its task and the run seed, so the results are the same for any
//! number of jobs (only `wall_time` differs).

use crate::episode::{EpisodeConfig, TrialResult, run_episode};
use crate::identity::RunRecord;
use crate::system::MobilitySystem;
use rayon::prelude::*;
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use verti_sim::VehicleSpec;
use verti_world::{TaskId, World};

// `EvalError` (in `eval_error`) and `RunInfo` (in `identity`) are defined below this module:
// `identity` reads and checks `run.json` with them, and this module records runs through
// `identity`, so defining them here would make the two import each other. Re-exported here,
// their long-standing path.
pub use crate::eval_error::EvalError;
pub use crate::identity::RunInfo;

pub const RESULTS_FILE: &str = "results.jsonl";
pub const RUN_FILE: &str = "run.json";
/// Subdirectory of a run's per-step logs (one Parquet file per trial).
pub const STEPS_DIR: &str = "steps";

fn io(path: &Path) -> impl Fn(std::io::Error) -> EvalError + '_ {
    move |source| EvalError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// A task selection as the text `parse_tasks` reads back: `all` for none, else ranges like
/// `1-60,75`.
pub fn format_tasks(selection: &[u32]) -> String {
    if selection.is_empty() {
        return "all".into();
    }
    let mut sorted = selection.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let mut parts = Vec::new();
    let mut start = sorted[0];
    let mut end = start;
    for &n in &sorted[1..] {
        if n == end + 1 {
            end = n;
        } else {
            parts.push(if start == end {
                start.to_string()
            } else {
                format!("{start}-{end}")
            });
            start = n;
            end = n;
        }
    }
    parts.push(if start == end {
        start.to_string()
    } else {
        format!("{start}-{end}")
    });
    parts.join(",")
}

/// Parses a task selection like `1-1000`, `7`, `1,5,10-20` or `all` into sorted task numbers.
pub fn parse_tasks(spec: &str) -> Result<Vec<u32>, EvalError> {
    let bad = |why: String| EvalError::Argument(format!("bad task range `{spec}`: {why}"));
    if spec.trim() == "all" {
        return Ok(Vec::new());
    }
    let mut out = BTreeSet::new();
    for part in spec.split(',') {
        let part = part.trim();
        if part.is_empty() {
            return Err(bad("empty item".into()));
        }
        let (a, b) = match part.split_once('-') {
            Some((a, b)) => (a.trim(), b.trim()),
            None => (part, part),
        };
        let a: u32 = a
            .parse()
            .map_err(|_| bad(format!("`{a}` is not a task number")))?;
        let b: u32 = b
            .parse()
            .map_err(|_| bad(format!("`{b}` is not a task number")))?;
        if a == 0 || b < a {
            return Err(bad(format!(
                "`{part}` is not an increasing range of task numbers starting at 1"
            )));
        }
        if b - a > 10_000_000 {
            return Err(bad(format!("`{part}` is too large")));
        }
        out.extend(a..=b);
    }
    Ok(out.into_iter().collect())
}

/// Resolves the selected task numbers against a set: all tasks of the set when `selection` is
/// empty; otherwise each number must name a task of a world in the set.
pub fn select_tasks(
    worlds: &[Arc<World>],
    selection: &[u32],
) -> Result<Vec<(usize, u32)>, EvalError> {
    // task numbers come from world indices: two worlds with one index would share numbers
    // (and results), so a set must not hold the same world or index twice
    let mut by_index: std::collections::BTreeMap<u32, &str> = Default::default();
    for w in worlds {
        if let Some(first) = by_index.insert(w.meta.index, &w.meta.name) {
            return Err(EvalError::Argument(format!(
                "worlds `{first}` and `{}` both have index {}: their task numbers would collide (is a world listed twice?)",
                w.meta.name, w.meta.index
            )));
        }
    }
    let mut all = Vec::new();
    for (wi, w) in worlds.iter().enumerate() {
        for t in &w.tasks {
            all.push((
                TaskId {
                    world: w.meta.index,
                    pair: t.pair,
                }
                .number(),
                wi,
                t.pair,
            ));
        }
    }
    all.sort();
    if selection.is_empty() {
        return Ok(all.into_iter().map(|(_, w, p)| (w, p)).collect());
    }
    let mut out = Vec::with_capacity(selection.len());
    let mut missing = Vec::new();
    for &n in selection {
        match all.binary_search_by_key(&n, |a| a.0) {
            Ok(i) => out.push((all[i].1, all[i].2)),
            Err(_) => missing.push(n),
        }
    }
    if !missing.is_empty() {
        let shown: Vec<String> = missing.iter().take(5).map(|n| n.to_string()).collect();
        let (lo, hi) = (
            all.first().map_or(0, |a| a.0),
            all.last().map_or(0, |a| a.0),
        );
        return Err(EvalError::Argument(format!(
            "{} selected task(s) are not in this world set (e.g. {}); it has tasks {lo}..={hi} ({} tasks)",
            missing.len(),
            shown.join(", "),
            all.len()
        )));
    }
    Ok(out)
}

/// One line of a results file (without its newline): the only way results are written, so
/// every reader ([`read_results`]) accepts every line (non-finite numbers are `null`).
pub fn result_line(r: &TrialResult) -> String {
    serde_json::to_string(r).expect("results serialise")
}

/// Reads a results file; a torn last line (from a kill) is dropped and reported as `false`.
pub fn read_results(path: &Path) -> Result<(Vec<TrialResult>, bool), EvalError> {
    read_results_file(path).map(|(results, clean, _)| (results, clean))
}

/// [`read_results`], plus whether the file ends in a newline (a last line that lost only its
/// newline parses, but the next append would be glued onto it).
fn read_results_file(path: &Path) -> Result<(Vec<TrialResult>, bool, bool), EvalError> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    let ends_in_newline = text.is_empty() || text.ends_with('\n');
    let mut out = Vec::new();
    let lines: Vec<&str> = text.split('\n').collect();
    let mut clean = true;
    for (i, line) in lines.iter().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<TrialResult>(line) {
            Ok(r) => out.push(r),
            // only the last line may be torn (no trailing newline)
            Err(_) if i == lines.len() - 1 => clean = false,
            Err(e) => {
                return Err(EvalError::Corrupt {
                    path: path.to_path_buf(),
                    line: i + 1,
                    problem: e.to_string(),
                });
            }
        }
    }
    Ok((out, clean, ends_in_newline))
}

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
    pub vehicle: &'a VehicleSpec,
    pub episode: EpisodeConfig,
    pub jobs: usize,
    pub out: PathBuf,
    pub resume: bool,
    /// Overwrite an existing results file instead of refusing.
    pub force: bool,
    pub run: RunInfo,
    /// The files the system loads when it drives the given tasks (world position, pair), by
    /// content ([`crate::identity::system_inputs`]): recorded, and compared on resume. Called
    /// once the run's tasks are known (a resume may take them from `run.json`).
    #[allow(clippy::type_complexity)]
    pub inputs: Option<
        &'a (dyn Fn(&[(usize, u32)]) -> Result<Vec<crate::identity::InputFile>, EvalError> + Sync),
    >,
    /// The split this run is a shard of (`--shard`), recorded for `verti merge`.
    pub shard: Option<crate::identity::SplitRecord>,
    /// Optional per-step logs.
    pub step_log: Option<StepLogSink<'a>>,
    /// Raised to stop the run: trials that finish after it is raised are not recorded (they
    /// may have been cut short), and `evaluate` returns `EvalError::Cancelled`.
    pub cancel: Option<&'a AtomicBool>,
    /// Told about anything repaired on the way (a torn last line dropped on resume).
    pub warn: Option<&'a (dyn Fn(&str) + Sync)>,
}

/// Name of the lock file that keeps two runs out of one results directory.
pub const LOCK_FILE: &str = ".lock";

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
    // what this call runs, and what run.json records the run as covering
    let mut selection = selection.to_vec();
    let mut recorded_selection = selection.clone();
    std::fs::create_dir_all(&setup.out).map_err(io(&setup.out))?;
    // one run at a time per directory: the lock is released when this function returns or the
    // process dies (a killed run can be resumed at once)
    let lock_path = setup.out.join(LOCK_FILE);
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(io(&lock_path))?;
    match lock.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            return Err(EvalError::Argument(format!(
                "{} is in use by another running evaluation; wait for it to finish or choose another --out",
                setup.out.display()
            )));
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(io(&lock_path)(e)),
    }
    let results_path = setup.out.join(RESULTS_FILE);
    let run_path = setup.out.join(RUN_FILE);
    let steps_path = setup.out.join(STEPS_DIR);
    let mut record = RunRecord::new(
        &setup.run,
        setup.worlds,
        setup.vehicle,
        setup.episode.start,
        setup.step_log.as_ref().map(|s| s.seconds),
    );
    record.perception = setup
        .episode
        .perception
        .as_deref()
        .filter(|m| !m.is_none())
        .cloned();
    record.shard = setup.shard.clone();

    let mut previous = Vec::new();
    if results_path.exists() && !setup.force {
        if !setup.resume {
            return Err(EvalError::Argument(format!(
                "{} already exists: pass --resume to continue that run or --force to start over",
                results_path.display()
            )));
        }
        let mut before = RunRecord::read(&run_path)?;
        if before.by_name_only() {
            // a record from before content digests cannot say whether step logs were kept
            before.step_log = record.step_log.clone();
        }
        // a resume continues the recorded selection unless it is given another (then the run
        // covers both); runs recorded before selections were kept continue with the one given
        if let Some(recorded) = &before.tasks {
            let recorded = parse_tasks(recorded).map_err(|e| EvalError::Corrupt {
                path: run_path.clone(),
                line: 1,
                problem: format!("field tasks: {e}"),
            })?;
            if selection.is_empty() {
                selection = recorded.clone();
                recorded_selection = recorded;
            } else if recorded.is_empty() {
                recorded_selection = recorded;
            } else {
                recorded_selection.extend_from_slice(&recorded);
                recorded_selection.sort_unstable();
                recorded_selection.dedup();
            }
        }
        record.inputs = match setup.inputs {
            Some(inputs) => inputs(&select_tasks(setup.worlds, &selection)?)?,
            None => Vec::new(),
        };
        let differences = record.differences(&before);
        if !differences.is_empty() {
            return Err(EvalError::Argument(format!(
                "cannot resume {}: {} records a different run ({}); start a new run with another --out, or pass --force to discard it",
                setup.out.display(),
                run_path.display(),
                differences.join("; ")
            )));
        }
        if before.by_name_only()
            && let Some(warn) = setup.warn
        {
            warn(&format!(
                "{} predates content digests: its world set and vehicle were checked by name only",
                run_path.display()
            ));
        }
        let (rs, clean, ends_in_newline) = read_results_file(&results_path)?;
        if !clean && let Some(warn) = setup.warn {
            warn(&format!(
                "{}: dropped a torn last line (a run killed while writing); that task runs again",
                results_path.display()
            ));
        }
        if !clean || !ends_in_newline {
            // rewrite without the torn line, ending in a newline, so appends start on a fresh
            // line instead of being glued to the last result
            let mut text = String::new();
            for r in &rs {
                text.push_str(&result_line(r));
                text.push('\n');
            }
            std::fs::write(&results_path, text).map_err(io(&results_path))?;
        }
        previous = rs;
    } else {
        // before anything is written: a file that cannot be read fails the run here
        if let Some(inputs) = setup.inputs {
            record.inputs = inputs(&select_tasks(setup.worlds, &selection)?)?;
        }
        std::fs::write(&results_path, "").map_err(io(&results_path))?;
        // a fresh start keeps no step logs of an earlier run in this directory
        if steps_path.exists() {
            std::fs::remove_dir_all(&steps_path).map_err(io(&steps_path))?;
        }
    }
    if setup.step_log.is_some() {
        std::fs::create_dir_all(&steps_path).map_err(io(&steps_path))?;
    }
    let tasks = select_tasks(setup.worlds, &selection)?;
    record.tasks = Some(format_tasks(&recorded_selection));
    std::fs::write(
        &run_path,
        serde_json::to_string_pretty(&record).expect("run info serialises"),
    )
    .map_err(io(&run_path))?;

    let done: BTreeSet<u32> = previous.iter().map(|r| r.task).collect();
    let todo: Vec<(usize, u32)> = tasks
        .into_iter()
        .filter(|&(wi, pair)| {
            !done.contains(
                &TaskId {
                    world: setup.worlds[wi].meta.index,
                    pair,
                }
                .number(),
            )
        })
        .collect();

    let file = std::fs::OpenOptions::new()
        .append(true)
        .open(&results_path)
        .map_err(io(&results_path))?;
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
                        .map_err(io(&results_path))?;
                }
                on_result(&r);
                Ok(r)
            })
            .collect()
    });
    let mut all = previous;
    all.extend(fresh?);
    all.sort_by_key(|r| r.task);
    Ok(all)
}
