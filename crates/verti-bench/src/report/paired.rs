//! Paired comparison of systems on the tasks they share: which goals one reaches and the other
//! does not, and whether that imbalance is beyond chance.
//!
//! Two systems' success rates over the same tasks are not independent samples: most tasks are
//! easy (or impossible) for both, and those say nothing about which system is better. What
//! tells them apart is the tasks where exactly one succeeds. If the two were equally good, each
//! such task would be a fair coin, so the number the first system wins is Binomial(n, ½): the
//! exact sign test (McNemar's test on the 2 x 2 table of outcomes). `z = (a − b) / √(a + b)` is
//! its normal approximation, quoted because it reads at a glance (|z| > 2: unlikely by chance).

use super::PairedComparison;
use crate::episode::{Outcome, TrialResult};
use std::collections::HashMap;

/// A task's identity across runs: its number, world and start/goal pair (task numbers alone
/// repeat between world sets).
type TaskKey<'a> = (u32, &'a str, u32);

/// Every pair of `systems` (labels with their trials, in report order) compared on the tasks
/// both ran. A task a system ran twice counts with its first result.
pub(super) fn paired(systems: &[(String, Vec<&TrialResult>)]) -> Vec<PairedComparison> {
    let successes: Vec<HashMap<TaskKey, bool>> = systems
        .iter()
        .map(|(_, trials)| {
            let mut m = HashMap::new();
            for t in trials {
                m.entry((t.task, t.world_name.as_str(), t.pair))
                    .or_insert(t.outcome == Outcome::Success);
            }
            m
        })
        .collect();
    let mut out = Vec::new();
    for i in 0..systems.len() {
        for j in i + 1..systems.len() {
            let (mut common, mut only_a, mut only_b) = (0, 0, 0);
            for (task, &a) in &successes[i] {
                let Some(&b) = successes[j].get(task) else {
                    continue;
                };
                common += 1;
                match (a, b) {
                    (true, false) => only_a += 1,
                    (false, true) => only_b += 1,
                    _ => {}
                }
            }
            let n = only_a + only_b;
            out.push(PairedComparison {
                a: systems[i].0.clone(),
                b: systems[j].0.clone(),
                common_tasks: common,
                only_a,
                only_b,
                z: (n > 0).then(|| (only_a as f64 - only_b as f64) / (n as f64).sqrt()),
                p_value: (n > 0).then(|| sign_test_p(only_a, only_b)),
            });
        }
    }
    out
}

/// Two-sided exact sign test: the probability, with `a + b` fair coins, of a split at least as
/// uneven as `a` against `b` (twice the smaller tail, at most 1).
fn sign_test_p(a: usize, b: usize) -> f64 {
    let n = a + b;
    let k = a.min(b);
    // the tail sum of C(n, i) / 2^n for i <= k, each term in logs so large n cannot overflow
    let ln_half_n = n as f64 * std::f64::consts::LN_2;
    let mut ln_c = 0.0; // ln C(n, 0)
    let mut tail = 0.0;
    for i in 0..=k {
        tail += (ln_c - ln_half_n).exp();
        ln_c += ((n - i) as f64).ln() - ((i + 1) as f64).ln();
    }
    (2.0 * tail).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures::trial;
    use crate::report::summarize;
    use Outcome::*;
    use verti_world::{ElevationLevel::*, ObstacleDensity::*, TerrainType::*};

    #[test]
    fn sign_test_matches_closed_forms() {
        // 10 coins all one way: 2 / 2^10
        assert!((sign_test_p(0, 10) - 2.0 / 1024.0).abs() < 1e-15);
        assert!((sign_test_p(10, 0) - 2.0 / 1024.0).abs() < 1e-15);
        // 1 against 9: 2 (1 + 10) / 1024
        assert!((sign_test_p(1, 9) - 22.0 / 1024.0).abs() < 1e-15);
        // an even split is no evidence at all
        assert_eq!(sign_test_p(5, 5), 1.0);
        assert_eq!(sign_test_p(0, 0), 1.0);
        // large n stays finite and agrees with the normal approximation's order of magnitude:
        // 66 against 39 (z = 2.63): two-sided p about 0.01
        let p = sign_test_p(66, 39);
        assert!(p > 0.005 && p < 0.015, "{p}");
        let far = sign_test_p(2000, 1000);
        assert!(far.is_finite() && far < 1e-30, "{far}");
    }

    #[test]
    fn pairs_match_tasks_by_number_world_and_pair() {
        let cell = (Low, Rigid, Sparse);
        let mut trials = vec![
            // task 1: both succeed; task 2: only A; task 3: only B; task 4: only A ran it
            trial("A", 1, cell, Success, 1.0, 1.0),
            trial("B", 1, cell, Success, 1.0, 1.0),
            trial("A", 2, cell, Success, 1.0, 1.0),
            trial("B", 2, cell, Stuck, 1.0, 1.0),
            trial("A", 3, cell, Rollover, 1.0, 1.0),
            trial("B", 3, cell, Success, 1.0, 1.0),
            trial("A", 4, cell, Success, 1.0, 1.0),
        ];
        // the same task number on another world set is another task
        let mut other = trial("B", 4, cell, Stuck, 1.0, 1.0);
        other.world_name = "vb80/001".into();
        trials.push(other);
        let s = summarize(&trials);
        assert_eq!(s.paired.len(), 1);
        let p = &s.paired[0];
        assert_eq!((p.a.as_str(), p.b.as_str()), ("A", "B"));
        assert_eq!((p.common_tasks, p.only_a, p.only_b), (3, 1, 1));
        assert_eq!(p.z, Some(0.0));
        assert_eq!(p.p_value, Some(1.0));
    }

    #[test]
    fn one_system_or_no_shared_task_gives_no_evidence() {
        let cell = (High, Deformable, Dense);
        let s = summarize(&[trial("A", 1, cell, Success, 1.0, 1.0)]);
        assert!(s.paired.is_empty());
        let b = trial("B", 2, cell, Stuck, 1.0, 1.0);
        let s = summarize(&[trial("A", 1, cell, Success, 1.0, 1.0), b]);
        let p = &s.paired[0];
        assert_eq!((p.common_tasks, p.only_a, p.only_b), (0, 0, 0));
        assert_eq!((p.z, p.p_value), (None, None));
    }
}
