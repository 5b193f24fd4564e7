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
