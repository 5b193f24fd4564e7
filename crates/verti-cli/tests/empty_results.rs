//! An empty result is an error, not a success with nothing in it (issue 33, item 11). Both
//! tests failed before: the commands printed an empty table or wrote an unreadable dataset,
//! and exited 0.

mod common;

use common::{s, tmp, verti};
use std::path::{Path, PathBuf};

/// A training world (never an evaluation one), generated here.
fn world(root: &Path) -> PathBuf {
    let w = root.join("w");
    let (ok, text) = verti(&[
        "world",
        "generate",
        "--count",
        "1",
        "--seed",
        "77",
        "--out",
        s(&w),
    ]);
    assert!(ok, "{text}");
    w
}

#[test]
fn an_open_loop_horizon_longer_than_every_trajectory_is_refused() {
    let root = tmp("empty", "kino");
    let w = world(&root);
    let data = root.join("data");
    let (ok, text) = verti(&[
        "data",
        "generate",
        "random",
        "--worlds",
        s(&w),
        "--hours",
        "0.005",
        "--max-trial-seconds",
        "10",
        "--out",
        s(&data),
    ]);
    assert!(ok, "{text}");
    let (ok, text) = verti(&["kino", "eval", "--data", s(&data), "--horizon", "1000"]);
    assert!(!ok, "an empty table is no answer:\n{text}");
    assert!(
        text.contains("--horizon 1000") && text.contains("long enough"),
        "{text}"
    );
    // a horizon that fits gives a table
    let (ok, text) = verti(&["kino", "eval", "--data", s(&data), "--horizon", "5"]);
    assert!(ok, "{text}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn an_expert_dataset_that_keeps_no_trial_is_refused() {
    let root = tmp("empty", "expert");
    let w = world(&root);
    let data = root.join("expert");
    // 10-s trials at 0.1 m/s: no goal is reached, so no demonstration is kept
    let (ok, text) = verti(&[
        "data",
        "generate",
        "expert",
        "--system",
        "pid",
        "--param",
        "speed=0.1",
        "--worlds",
        s(&w),
        "--hours",
        "0.01",
        "--max-trial-seconds",
        "10",
        "--out",
        s(&data),
    ]);
    assert!(!ok, "a dataset with no trial was written:\n{text}");
    assert!(text.contains("no trial"), "{text}");
    assert!(!data.join("manifest.yaml").exists());
    let _ = std::fs::remove_dir_all(&root);
}
