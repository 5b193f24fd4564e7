//! Loading: `results.jsonl` files, or directories holding them, read into trial results
//! ([`load_results`], [`load_results_from`]).

use super::loaded::{Loaded, LoadedFile, ReportError};
use crate::episode::TrialResult;
use crate::run::identity::RunRecord;
use crate::run::{RESULTS_FILE, RUN_FILE, read_results};
use std::path::{Path, PathBuf};

/// The results files a path stands for: a file itself; a directory's `results.jsonl`; or,
/// for a directory without one (e.g. a folder of runs), the `results.jsonl` of each immediate
/// subdirectory, sorted by name.
fn result_files(path: &Path) -> Result<Vec<PathBuf>, ReportError> {
    if path.is_file() {
        return Ok(vec![path.to_path_buf()]);
    }
    if !path.is_dir() {
        return Err(ReportError::NotFound(path.to_path_buf()));
    }
    let direct = path.join(RESULTS_FILE);
    if direct.is_file() {
        return Ok(vec![direct]);
    }
    let io = |source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut found = Vec::new();
    for entry in std::fs::read_dir(path).map_err(io)? {
        let f = entry.map_err(io)?.path().join(RESULTS_FILE);
        if f.is_file() {
            found.push(f);
        }
    }
    if found.is_empty() {
        return Err(ReportError::NoResults(path.to_path_buf()));
    }
    found.sort();
    Ok(found)
}

/// Reads results from files (`.jsonl`) and result directories, in the order given, and says
/// which files were read. A torn last line is dropped (and reported in [`LoadedFile::clean`]);
/// any other unparsable line is an error naming the file and line.
///
/// Runs are told apart by their `run.json` (see `runs`): files of one run merge, runs of one
/// system with different settings get labels naming what differs (`pid [speed=6]`, in each
/// result's `system`), and trials given twice are refused.
pub fn load_results_from(paths: &[PathBuf]) -> Result<Loaded, ReportError> {
    let mut out = Loaded::default();
    let mut per_file = Vec::new();
    for p in paths {
        for f in result_files(p)? {
            let (results, clean) = read_results(&f)?;
            let run_path = f.with_file_name(RUN_FILE);
            let run = if f.file_name().is_some_and(|n| n == RESULTS_FILE) && run_path.is_file() {
                Some(RunRecord::read(&run_path)?)
            } else {
                None
            };
            out.files.push(LoadedFile {
                path: f,
                trials: results.len(),
                clean,
                run,
            });
            per_file.push(results);
        }
    }
    super::runs::separate_runs(&out.files, &mut per_file)?;
    out.results = per_file.into_iter().flatten().collect();
    Ok(out)
}

/// Reads results from files (`.jsonl`) and result directories (see [`load_results_from`]).
pub fn load_results(paths: &[PathBuf]) -> Result<Vec<TrialResult>, ReportError> {
    Ok(load_results_from(paths)?.results)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures::sample;

    #[test]
    fn load_results_reads_files_directories_and_names_bad_files() {
        let dir = std::env::temp_dir().join(format!("verti-report-test-{}", std::process::id()));
        let run = dir.join("runs").join("a");
        std::fs::create_dir_all(&run).unwrap();
        let lines: Vec<String> = sample()
            .iter()
            .map(|r| serde_json::to_string(r).unwrap())
            .collect();
        let file = run.join(RESULTS_FILE);
        // a torn last line is dropped
        std::fs::write(&file, format!("{}\n{}\n{{\"task\":", lines[0], lines[1])).unwrap();
        let loaded = load_results_from(std::slice::from_ref(&run)).unwrap();
        assert_eq!(loaded.results.len(), 2);
        assert!(!loaded.files[0].clean);
        // a folder of runs, and a file given directly
        let other = dir.join("other.jsonl");
        std::fs::write(&other, format!("{}\n{}\n", lines[2], lines[3])).unwrap();
        let all = load_results(&[dir.join("runs"), other.clone()]).unwrap();
        assert_eq!(all.len(), 4);
        // ... but not one file twice: its trials would count twice
        let e = load_results(&[dir.join("runs"), file.clone()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("given twice"), "{e}");
        // errors name the path
        let e = load_results(&[dir.join("nope")]).unwrap_err().to_string();
        assert!(e.contains("nope"), "{e}");
        std::fs::create_dir_all(dir.join("empty")).unwrap();
        let e = load_results(&[dir.join("empty")]).unwrap_err().to_string();
        assert!(e.contains("empty") && e.contains(RESULTS_FILE), "{e}");
        std::fs::write(&file, format!("garbage\n{}\n", lines[0])).unwrap();
        let e = load_results(std::slice::from_ref(&file))
            .unwrap_err()
            .to_string();
        assert!(e.contains("results.jsonl") && e.contains("line 1"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
