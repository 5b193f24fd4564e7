//! Joining the shards of one evaluation (`verti merge`).
//!
//! Each shard (`super::shard`) is an ordinary run directory; [`join`] joins finished shards into
//! one directory whose `results.jsonl` is what a single run would have written, sorted by task.

use super::error::EvalError;
use super::identity::{RunRecord, SplitRecord};
use super::results::{read_results, result_line};
use super::tasks::{format_tasks, parse_tasks};
use super::{RESULTS_FILE, RUN_FILE, STEPS_DIR};
use crate::episode::TrialResult;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Finished shards, joined in memory ([`join`]); [`Joined::write`] puts them on disk.
#[derive(Debug)]
pub struct Joined {
    record: RunRecord,
    results: Vec<TrialResult>,
    /// The shard directory each result was taken from (same order as `results`).
    sources: Vec<PathBuf>,
    /// Tasks that appeared in more than one shard with identical results (kept once).
    pub duplicates: usize,
    /// Tasks of the selection with no result in any shard given, sorted: a shard not given,
    /// or one that has not finished.
    pub missing: Vec<u32>,
    /// Shards of the split that were not given (their indices), and the split's count.
    pub absent_shards: (Vec<usize>, usize),
    /// Tasks some shard was asked to run but had not finished, with that shard's directory.
    pub unfinished: Vec<(u32, PathBuf)>,
    /// The shards predate recorded splits: whether they cover the whole selection is unknown
    /// (only their own unfinished tasks are known).
    pub unchecked: bool,
}

/// A result as it would be compared across runs: everything but the wall time.
fn comparable(r: &TrialResult) -> String {
    let mut r = r.clone();
    r.wall_time = 0.0;
    result_line(&r)
}

/// Joins the run directories `shards` (written by `verti eval --shard`): they must be the same
/// run (system and parameters, worlds, vehicle and loaded files by content, rules, seed, time
/// limit, start, step logs) and shards of one split (same count, same selection), and a task
/// finished by two shards must have the same result (but for wall time). Whether they cover
/// the selection is in [`Joined::missing`]; [`Joined::coverage`] says it in words.
pub fn join(shards: &[PathBuf]) -> Result<Joined, EvalError> {
    if shards.is_empty() {
        return Err(EvalError::Argument(
            "nothing to merge: name the shard directories".into(),
        ));
    }
    let mut first: Option<(RunRecord, PathBuf)> = None;
    let mut selected: BTreeMap<u32, PathBuf> = BTreeMap::new();
    let mut by_task: BTreeMap<u32, (TrialResult, String, PathBuf)> = BTreeMap::new();
    let mut duplicates = 0;
    let mut covers_all = false;
    let mut given_shards = BTreeSet::new();
    // shards of selected tasks record the digests of their own worlds; the join holds them all
    let mut world_digests = BTreeMap::new();
    for dir in shards {
        let record = RunRecord::read(&dir.join(RUN_FILE))?;
        world_digests.extend(record.world_digests.clone());
        match &first {
            None => first = Some((record.clone(), dir.clone())),
            Some((base, base_dir)) => {
                let differences = without_split(&record).differences(&without_split(base));
                if !differences.is_empty() {
                    return Err(EvalError::Argument(format!(
                        "{} and {} are not shards of one run: {}",
                        base_dir.display(),
                        dir.display(),
                        differences.join("; ")
                    )));
                }
                let (a, b) = (&base.shard, &record.shard);
                let same_split = match (a, b) {
                    (Some(a), Some(b)) => a.count == b.count && a.of == b.of,
                    (None, None) => true,
                    _ => false,
                };
                if !same_split {
                    return Err(EvalError::Argument(format!(
                        "{} ({}) and {} ({}) are not shards of one split",
                        base_dir.display(),
                        SplitRecord::describe(a.as_ref()),
                        dir.display(),
                        SplitRecord::describe(b.as_ref())
                    )));
                }
            }
        }
        if let Some(split) = &record.shard {
            given_shards.insert(split.index);
        }
        let tasks = record.tasks.as_deref().unwrap_or("all");
        let tasks = parse_tasks(tasks).map_err(|e| EvalError::Corrupt {
            path: dir.join(RUN_FILE),
            line: 1,
            problem: format!("field tasks: {e}"),
        })?;
        covers_all |= tasks.is_empty();
        for n in tasks {
            selected.entry(n).or_insert_with(|| dir.clone());
        }
        let (results, clean) = read_results(&dir.join(RESULTS_FILE))?;
        if !clean {
            return Err(EvalError::Argument(format!(
                "{}: its last line is torn (a killed run): resume that shard first (`verti eval ... --resume --out {}`)",
                dir.join(RESULTS_FILE).display(),
                dir.display()
            )));
        }
        for r in results {
            let key = comparable(&r);
            match by_task.get(&r.task) {
                Some((_, other, other_dir)) if *other != key => {
                    return Err(EvalError::Argument(format!(
                        "task {} has different results in {} and {}: were they run with different code?",
                        r.task,
                        other_dir.display(),
                        dir.display()
                    )));
                }
                Some(_) => duplicates += 1,
                None => {
                    by_task.insert(r.task, (r, key, dir.clone()));
                }
            }
        }
    }
    let (mut record, _) = first.expect("at least one shard");
    if record.some_worlds() {
        record.world_digests = world_digests;
    }
    let unfinished = selected
        .iter()
        .filter(|(n, _)| !by_task.contains_key(n))
        .map(|(&n, d)| (n, d.clone()))
        .collect();
    let split = record.shard.take();
    let (whole, absent_shards, unchecked) = match &split {
        Some(split) => {
            let whole = parse_tasks(&split.of).map_err(|e| EvalError::Corrupt {
                path: shards[0].join(RUN_FILE),
                line: 1,
                problem: format!("field shard.of: {e}"),
            })?;
            let absent = (0..split.count)
                .filter(|i| !given_shards.contains(i))
                .collect();
            (whole, (absent, split.count), false)
        }
        // recorded before splits were: the union of the shards' selections
        None => (selected.keys().copied().collect(), (Vec::new(), 0), true),
    };
    let missing: Vec<u32> = whole
        .iter()
        .copied()
        .filter(|n| !by_task.contains_key(n))
        .collect();
    record.tasks = Some(if covers_all && split.is_none() {
        "all".into()
    } else {
        format_tasks(&whole)
    });
    record.missing = (!missing.is_empty()).then(|| format_tasks(&missing));
    let (results, sources) = by_task.into_values().map(|(r, _, d)| (r, d)).unzip();
    Ok(Joined {
        record,
        results,
        sources,
        duplicates,
        missing,
        absent_shards,
        unfinished,
        unchecked,
    })
}

/// A record with its split taken out: shards of one run differ only there.
fn without_split(record: &RunRecord) -> RunRecord {
    RunRecord {
        shard: None,
        missing: None,
        ..record.clone()
    }
}

impl Joined {
    /// The joined results, sorted by task.
    pub fn results(&self) -> &[TrialResult] {
        &self.results
    }

    /// What the shards given leave out, in words (shards not given, unfinished tasks, with
    /// examples and what to do); `None` when they cover the whole selection.
    pub fn coverage(&self) -> Option<String> {
        if self.missing.is_empty() {
            return None;
        }
        let mut parts = Vec::new();
        let (absent, count) = &self.absent_shards;
        if !absent.is_empty() {
            let names: Vec<String> = absent.iter().map(|i| format!("{i}/{count}")).collect();
            parts.push(format!(
                "shard(s) {} of the split were not given",
                names.join(", ")
            ));
        }
        if !self.unfinished.is_empty() {
            let mut dirs: Vec<String> = self
                .unfinished
                .iter()
                .map(|(_, d)| d.display().to_string())
                .collect();
            dirs.sort();
            dirs.dedup();
            parts.push(format!(
                "{} task(s) of {} have not finished (resume with `verti eval ... --resume --out DIR`)",
                self.unfinished.len(),
                dirs.join(", ")
            ));
        }
        let shown: Vec<String> = self.missing.iter().take(8).map(|n| n.to_string()).collect();
        Some(format!(
            "{} of the selection's {} task(s) have no result (tasks {}{}): {}",
            self.missing.len(),
            self.missing.len() + self.results.len(),
            shown.join(", "),
            if self.missing.len() > shown.len() {
                ", ..."
            } else {
                ""
            },
            parts.join("; ")
        ))
    }

    /// Writes `out/run.json` (covering the whole selection; with the tasks that have no result
    /// under `missing`), `out/results.jsonl` (sorted by task) and, for runs with per-step logs,
    /// each result's log in `out/steps/` (`log_name` names a task's file, as the writer of the
    /// logs does). An existing results file is refused unless `force`, which also clears the
    /// step logs of the run it replaces; `out` may not be one of the shards.
    pub fn write(
        &self,
        out: &Path,
        force: bool,
        log_name: &dyn Fn(u32) -> String,
    ) -> Result<(), EvalError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| EvalError::Io { path, source }
        };
        let out_results = out.join(RESULTS_FILE);
        if out_results.exists() && !force {
            return Err(EvalError::Argument(format!(
                "{} already exists: pass --force to overwrite it",
                out_results.display()
            )));
        }
        let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if let Some(shard) = self.sources.iter().find(|d| same(d, out)) {
            return Err(EvalError::Argument(format!(
                "--out {} is one of the shards ({}): merge into another directory",
                out.display(),
                shard.display()
            )));
        }
        std::fs::create_dir_all(out).map_err(io(out))?;
        let steps = out.join(STEPS_DIR);
        if steps.exists() {
            std::fs::remove_dir_all(&steps).map_err(io(&steps))?;
        }
        if self.record.step_log.is_some() {
            std::fs::create_dir_all(&steps).map_err(io(&steps))?;
            for (r, dir) in self.results.iter().zip(&self.sources) {
                let name = log_name(r.task);
                let from = dir.join(STEPS_DIR).join(&name);
                if !from.is_file() {
                    return Err(EvalError::Argument(format!(
                        "{}: the step log of task {} is missing, though {} records step logs",
                        from.display(),
                        r.task,
                        dir.join(RUN_FILE).display()
                    )));
                }
                std::fs::copy(&from, steps.join(&name)).map_err(io(&from))?;
            }
        }
        let mut text = String::new();
        for r in &self.results {
            text.push_str(&result_line(r));
            text.push('\n');
        }
        let run_path = out.join(RUN_FILE);
        std::fs::write(
            &run_path,
            serde_json::to_string_pretty(&self.record).expect("run info serialises"),
        )
        .map_err(io(&run_path))?;
        std::fs::write(&out_results, text).map_err(io(&out_results))
    }
}
