//! Opening a run directory for a run ([`open`]): created and locked, started fresh or resumed
//! (`super::resume`), with `run.json` written, before the trial loop appends a single result.

use super::error::{EvalError, io};
use super::identity::RunRecord;
use super::resume::resume;
use super::tasks::{format_tasks, select_tasks};
use super::{LOCK_FILE, RESULTS_FILE, RUN_FILE, RunSettings, STEPS_DIR};
use crate::episode::TrialResult;
use std::collections::BTreeSet;
use std::fs::File;
use std::path::{Path, PathBuf};
use verti_world::TaskId;

/// A run directory ready for the trial loop.
pub(crate) struct OpenRun {
    /// The lock on the directory: held while this value lives (the caller keeps it until the
    /// run ends), released when it is dropped or the process dies.
    _lock: File,
    /// `results.jsonl`, ending in a newline, for the loop to append result lines to.
    pub results_path: PathBuf,
    /// The results already in the file (a resume), in file order.
    pub previous: Vec<TrialResult>,
    /// The tasks (world position, pair) still to run, in task order.
    pub todo: Vec<(usize, u32)>,
}

/// Opens `setup.out` for a run of `selection` (checked by the caller): locks it, continues the
/// run there (`setup.resume`), starts over (`setup.force`) or starts fresh, records the run in
/// `run.json`, and says which tasks are left.
pub(crate) fn open(setup: &RunSettings, selection: &[u32]) -> Result<OpenRun, EvalError> {
    // what this call runs, and what run.json records the run as covering
    let mut selection = selection.to_vec();
    let mut recorded_selection = selection.clone();
    let lock = lock(setup.out)?;
    let results_path = setup.out.join(RESULTS_FILE);
    let run_path = setup.out.join(RUN_FILE);
    let steps_path = setup.out.join(STEPS_DIR);
    let mut record = RunRecord::new(
        setup.run,
        setup.worlds,
        setup.whole_set,
        setup.vehicle,
        setup.episode.start,
        setup.step_log,
    );
    record.perception = setup
        .episode
        .perception
        .as_deref()
        .filter(|m| !m.is_none())
        .cloned();
    record.shard = setup.shard.cloned();

    let previous = if results_path.exists() && !setup.force {
        resume(
            setup,
            &mut record,
            &mut selection,
            &mut recorded_selection,
            &run_path,
            &results_path,
        )?
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
        Vec::new()
    };
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
    Ok(OpenRun {
        _lock: lock,
        results_path,
        previous,
        todo,
    })
}

/// Creates `out` and takes its lock file. One run at a time per directory: the lock is released
/// when the returned file is dropped or the process dies (a killed run can be resumed at once).
fn lock(out: &Path) -> Result<File, EvalError> {
    std::fs::create_dir_all(out).map_err(io(out))?;
    let lock_path = out.join(LOCK_FILE);
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
                out.display()
            )));
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(io(&lock_path)(e)),
    }
    Ok(lock)
}
