//! Which tasks a run covers: a selection as text (`1-60,75`, `all`), as `--tasks` gives it and
//! `run.json` records it ([`parse_tasks`], [`format_tasks`]), and resolved against a world set
//! ([`select_tasks`]). Shared by the trial loop, resume (which continues the recorded
//! selection) and merge (which checks that shards cover it).

use super::error::EvalError;
use std::collections::BTreeSet;
use std::sync::Arc;
use verti_world::{TaskId, World};

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

/// The indices of the worlds a run of `selection` (task numbers; empty for all) with its
/// directory at `out` needs, or `None` for the whole set. A resume (`resume` without `force`,
/// results in `out`) continues the recorded selection too (and runs it alone when given
/// none), so its tasks' worlds are added; a run recorded over the whole set or all its tasks
/// (or whose `run.json` cannot be read: the resume reports that) needs the whole set again,
/// to be compared with it by content.
pub fn worlds_to_load(
    out: &std::path::Path,
    resume: bool,
    force: bool,
    selection: &[u32],
) -> Option<BTreeSet<u32>> {
    let mut tasks: BTreeSet<u32> = selection.iter().copied().collect();
    let mut worlds = BTreeSet::new();
    if resume && !force && out.join(super::RESULTS_FILE).exists() {
        let record = super::identity::RunRecord::read(&out.join(super::RUN_FILE)).ok()?;
        if !record.some_worlds() {
            return None;
        }
        let recorded = parse_tasks(record.tasks.as_deref()?).ok()?;
        if recorded.is_empty() {
            return None;
        }
        tasks.extend(recorded);
        worlds.extend(record.world_digests.keys().copied());
    } else if selection.is_empty() {
        return None;
    }
    worlds.extend(task_worlds(&tasks.into_iter().collect::<Vec<_>>()));
    Some(worlds)
}

/// The indices of the worlds tasks `tasks` are on (`TaskId::from_number`'s numbering, which
/// every set shares).
pub fn task_worlds(tasks: &[u32]) -> BTreeSet<u32> {
    tasks
        .iter()
        .filter_map(|&n| TaskId::from_number(n).map(|t| t.world))
        .collect()
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
