//! Splitting one evaluation over many machines, and joining the pieces.
//!
//! `--shard i/N` keeps every N-th task of a run's selection, starting at position `i`
//! (0-based, as Slurm array indices and Kubernetes completion indices are): shards are disjoint,
//! together they cover the selection, and consecutive tasks (which share a world, so cost about
//! the same) land on different shards, which balances their wall time. Each shard is an
//! ordinary run directory (resumable on its own); [`join`] joins finished shards into one
//! directory whose `results.jsonl` is what a single run would have written, sorted by task.

use crate::episode::TrialResult;
use crate::eval::{EvalError, RESULTS_FILE, RUN_FILE, format_tasks, parse_tasks, read_results};
use crate::identity::RunRecord;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Shard `index` of `count` (0 ≤ index < count).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// Parses `i/N`, e.g. `0/4` … `3/4`.
    pub fn parse(s: &str) -> Result<Shard, String> {
        let bad = |why: &str| format!("bad shard `{s}`: {why} (use i/N with 0 <= i < N, e.g. 0/4)");
        let (i, n) = s.split_once('/').ok_or_else(|| bad("no `/`"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{i}` is not a number")))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| bad(&format!("`{n}` is not a number")))?;
        if count == 0 {
            return Err(bad("N must be at least 1"));
        }
        if index >= count {
            return Err(bad(&format!("i must be below N ({count})")));
        }
        Ok(Shard { index, count })
    }

    /// The tasks of `all` (sorted task numbers) that belong to this shard.
    pub fn select(&self, all: &[u32]) -> Vec<u32> {
        all.iter()
            .enumerate()
            .filter(|(pos, _)| pos % self.count == self.index)
            .map(|(_, &n)| n)
            .collect()
    }
}

/// Finished shards, joined in memory ([`join`]); [`Joined::write`] puts them on disk.
#[derive(Debug)]
pub struct Joined {
    record: RunRecord,
    results: Vec<TrialResult>,
    /// Tasks that appeared in more than one shard with identical results (kept once).
    pub duplicates: usize,
    /// Tasks some shard was asked to run but had not finished, with that shard's directory.
    pub unfinished: Vec<(u32, PathBuf)>,
}

/// A result as it would be compared across runs: everything but the wall time.
fn comparable(r: &TrialResult) -> String {
    let mut r = r.clone();
    r.wall_time = 0.0;
    serde_json::to_string(&r).expect("results serialise")
}

/// Joins the run directories `shards` (written by `verti eval --shard`): they must be the same
/// run (system and parameters, worlds and vehicle by content, rules, seed, time limit, start,
/// step logs), and a task finished by two shards must have the same result (but for wall time).
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
    for dir in shards {
        let record = RunRecord::read(&dir.join(RUN_FILE))?;
        match &first {
            None => first = Some((record.clone(), dir.clone())),
            Some((base, base_dir)) => {
                let differences = record.differences(base);
                if !differences.is_empty() {
                    return Err(EvalError::Argument(format!(
                        "{} and {} are not shards of one run: {}",
                        base_dir.display(),
                        dir.display(),
                        differences.join("; ")
                    )));
                }
            }
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
    let unfinished = selected
        .iter()
        .filter(|(n, _)| !by_task.contains_key(n))
        .map(|(&n, d)| (n, d.clone()))
        .collect();
    record.tasks = Some(if covers_all {
        "all".into()
    } else {
        format_tasks(&selected.keys().copied().collect::<Vec<_>>())
    });
    Ok(Joined {
        record,
        results: by_task.into_values().map(|(r, _, _)| r).collect(),
        duplicates,
        unfinished,
    })
}

impl Joined {
    /// The joined results, sorted by task.
    pub fn results(&self) -> &[TrialResult] {
        &self.results
    }

    /// Writes `out/run.json` (covering the union of the shards' selections) and
    /// `out/results.jsonl` (sorted by task). An existing results file is refused unless `force`.
    pub fn write(&self, out: &Path, force: bool) -> Result<(), EvalError> {
        let out_results = out.join(RESULTS_FILE);
        if out_results.exists() && !force {
            return Err(EvalError::Argument(format!(
                "{} already exists: pass --force to overwrite it",
                out_results.display()
            )));
        }
        std::fs::create_dir_all(out).map_err(|source| EvalError::Io {
            path: out.to_path_buf(),
            source,
        })?;
        let mut text = String::new();
        for r in &self.results {
            text.push_str(&serde_json::to_string(r).expect("results serialise"));
            text.push('\n');
        }
        let write = |path: PathBuf, text: String| {
            std::fs::write(&path, text).map_err(|source| EvalError::Io { path, source })
        };
        write(
            out.join(RUN_FILE),
            serde_json::to_string_pretty(&self.record).expect("run info serialises"),
        )?;
        write(out_results, text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_disjoint_and_cover_the_selection() {
        let all: Vec<u32> = (1..=103).collect();
        let mut seen = Vec::new();
        for i in 0..4 {
            let s = Shard::parse(&format!("{i}/4")).unwrap();
            let part = s.select(&all);
            // balanced to within one task
            assert!(part.len() == 25 || part.len() == 26, "{}", part.len());
            seen.extend(part);
        }
        seen.sort_unstable();
        assert_eq!(seen, all);
        assert_eq!(Shard::parse("0/1").unwrap().select(&all), all);
    }

    #[test]
    fn bad_shards_are_named() {
        for (s, why) in [
            ("4/4", "below N"),
            ("1/0", "at least 1"),
            ("a/3", "`a` is not a number"),
            ("3", "no `/`"),
        ] {
            let e = Shard::parse(s).unwrap_err();
            assert!(e.contains(why) && e.contains(s), "{s}: {e}");
        }
    }
}
