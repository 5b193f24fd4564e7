//! What the command-line tests share: running the built `verti`, scratch folders, paths as
//! arguments. (Each test file includes this module and uses a part of it.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `verti args`: whether it succeeded, and its stdout then stderr.
pub fn verti(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_verti"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// Runs `verti args`, which must succeed; its output.
pub fn ok(args: &[&str]) -> String {
    let (success, text) = verti(args);
    assert!(success, "verti {args:?} failed:\n{text}");
    text
}

/// Runs `verti args`, which must fail; its output (the error).
pub fn fails(args: &[&str]) -> String {
    let (success, text) = verti(args);
    assert!(!success, "verti {args:?} should fail:\n{text}");
    text
}

/// A fresh, empty scratch folder for one test: `verti-<group>-<name>-<pid>`.
pub fn tmp(group: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-{group}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The results of run directory `dir` by task, without the wall time (the one field that
/// differs between runs of the same tasks).
pub fn results(dir: &Path) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("results.jsonl")).unwrap();
    let mut rows: Vec<serde_json::Value> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            v.as_object_mut().unwrap().remove("wall_time");
            v
        })
        .collect();
    rows.sort_by_key(|v| v["task"].as_u64());
    rows
}

/// The `run.json` of run directory `dir`.
pub fn run_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
}
