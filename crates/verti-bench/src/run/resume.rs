//! Resuming a run: an existing results file is continued only by the same run (`run.json`
//! compared setting by setting, by content), over the recorded selection (or, given another,
//! over both), and with a torn last line (a run killed while writing) repaired first.

use super::RunSettings;
use super::error::{EvalError, io};
use super::identity::RunRecord;
use super::results::{read_results_file, result_line};
use super::tasks::{parse_tasks, select_tasks};
use crate::episode::TrialResult;
use std::path::Path;

/// Continues the run whose results are at `results_path` (its record at `run_path`): checks it
/// is the run `setup` describes (`record`, which gets the system's input files here), widens
/// `selection` (what this call runs) and `recorded_selection` (what `run.json` will say the
/// run covers) by the recorded selection, and returns the results already there.
pub(super) fn resume(
    setup: &RunSettings,
    record: &mut RunRecord,
    selection: &mut Vec<u32>,
    recorded_selection: &mut Vec<u32>,
    run_path: &Path,
    results_path: &Path,
) -> Result<Vec<TrialResult>, EvalError> {
    if !setup.resume {
        return Err(EvalError::Argument(format!(
            "{} already exists: pass --resume to continue that run or --force to start over",
            results_path.display()
        )));
    }
    let mut before = RunRecord::read(run_path)?;
    if before.by_name_only() {
        // a record from before content digests cannot say whether step logs were kept
        before.step_log = record.step_log.clone();
    }
    // a resume continues the recorded selection unless it is given another (then the run
    // covers both); runs recorded before selections were kept continue with the one given
    if let Some(recorded) = &before.tasks {
        let recorded = parse_tasks(recorded).map_err(|e| EvalError::Corrupt {
            path: run_path.to_path_buf(),
            line: 1,
            problem: format!("field tasks: {e}"),
        })?;
        if selection.is_empty() {
            *selection = recorded.clone();
            *recorded_selection = recorded;
        } else if recorded.is_empty() {
            *recorded_selection = recorded;
        } else {
            recorded_selection.extend_from_slice(&recorded);
            recorded_selection.sort_unstable();
            recorded_selection.dedup();
        }
    }
    record.inputs = match setup.inputs {
        Some(inputs) => inputs(&select_tasks(setup.worlds, selection)?)?,
        None => Vec::new(),
    };
    // a run of selected tasks records each world's digest; continued over the whole set (or
    // over more worlds) it is compared world by world, and keeps the digests of the worlds it
    // recorded before
    let mut now = record.clone();
    if before.some_worlds() && !record.some_worlds() {
        now.worlds_digest = None;
        now.world_digests = super::identity::world_digests(setup.worlds);
    }
    let differences = now.differences(&before);
    if !differences.is_empty() {
        return Err(EvalError::Argument(format!(
            "cannot resume {}: {} records a different run ({}); start a new run with another --out, or pass --force to discard it",
            setup.out.display(),
            run_path.display(),
            differences.join("; ")
        )));
    }
    if record.some_worlds() {
        for (index, digest) in &before.world_digests {
            record.world_digests.entry(*index).or_insert(digest.clone());
        }
    }
    if before.by_name_only()
        && let Some(warn) = setup.warn
    {
        warn(&format!(
            "{} predates content digests: its world set and vehicle were checked by name only",
            run_path.display()
        ));
    }
    let (rs, clean, ends_in_newline) = read_results_file(results_path)?;
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
        std::fs::write(results_path, text).map_err(io(results_path))?;
    }
    Ok(rs)
}
