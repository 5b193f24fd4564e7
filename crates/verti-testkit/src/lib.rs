//! Test support for verti's crates, for their tests only (a dev-dependency, never published).
//!
//! Several crates fuzz their readers the same way: a real file (a world, a model card, a
//! dataset manifest, a vehicle, an HTTP request) is damaged by a few seeded edits and read
//! back, and the read must return `Ok` or `Err`, never panic. What they share lives here, so
//! that a fix to the mutations (or a new extreme number) reaches every target at once:
//!
//! - [`mutate`]: the edits, proptest strategies drawing them, and [`mutate::apply`];
//! - [`config`]: a proptest configuration whose case count `PROPTEST_CASES` can raise for a
//!   longer run than CI's;
//! - [`case_dir`]: a fresh scratch directory per call, for cases that write files.

pub mod mutate;

use proptest::prelude::ProptestConfig;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A proptest configuration of `default` cases, or of `PROPTEST_CASES` when that is set.
///
/// Proptest reads `PROPTEST_CASES` only into its default configuration, which a target that
/// caps its cases (so CI stays fast in the dev profile) replaces; this keeps the variable
/// working for a longer run (`PROPTEST_CASES=5000 cargo test --release -p … --test fuzz`).
/// No failure file is persisted: a failing case is shrunk and printed, and nothing is written
/// into the source tree.
pub fn config(default: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// A fresh, empty directory under the system's temporary directory, named
/// `{prefix}-{tag}-{process id}-{k}` with `k` counting the calls of this process.
///
/// Proptest may run the cases of one test binary on several threads, and several test
/// binaries at once: the process id and the counter keep every call's directory its own.
/// The caller removes it when done (a leftover of a failed case is kept for a look).
///
/// # Panics
///
/// When the directory cannot be created.
pub fn case_dir(prefix: &str, tag: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let k = COUNTER.fetch_add(1, Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("{prefix}-{tag}-{}-{k}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn case_dirs_are_fresh_empty_and_distinct() {
        let a = case_dir("verti-testkit", "t");
        let b = case_dir("verti-testkit", "t");
        assert_ne!(a, b);
        for d in [&a, &b] {
            assert!(d.is_dir() && std::fs::read_dir(d).unwrap().next().is_none());
            std::fs::remove_dir_all(d).unwrap();
        }
    }

    #[test]
    fn config_persists_no_failures() {
        assert!(config(7).failure_persistence.is_none());
    }
}
