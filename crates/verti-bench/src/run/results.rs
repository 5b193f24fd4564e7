//! The results file (`results.jsonl`): one JSON line per finished trial. [`result_line`] is the
//! one writer of a line (the trial loop appends them, merge and resume rewrite them) and
//! [`read_results`] the one reader (resume, merge, replay, reports), so every line written is
//! read back.

use super::error::{EvalError, io};
use crate::episode::TrialResult;
use std::path::Path;

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
pub(super) fn read_results_file(path: &Path) -> Result<(Vec<TrialResult>, bool, bool), EvalError> {
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
