//! Aggregation: trials grouped per system (and vehicle) and reduced to Table I, the Fig. 6
//! breakdowns and the extra metrics ([`summarize`]).

use super::{Breakdown, ExtraMetrics, GroupStats, MeanVar, OutcomeTable, Summary, SystemSummary};
use crate::episode::{Outcome, TrialResult};
use std::collections::BTreeMap;

fn pct(k: usize, n: usize) -> Option<f64> {
    (n > 0).then(|| 100.0 * k as f64 / n as f64)
}

fn mean_of(xs: impl IntoIterator<Item = f64>) -> Option<f64> {
    MeanVar::of(xs).mean
}

fn max_of(xs: impl IntoIterator<Item = f64>) -> Option<f64> {
    xs.into_iter().filter(|x| x.is_finite()).reduce(f64::max)
}

/// Per-trial mean |angle| of a trial, if it recorded any samples.
fn trial_mean_abs(a: &crate::metrics::AngleStats) -> Option<f64> {
    (a.abs.count > 0 && a.abs.mean.is_finite()).then_some(a.abs.mean)
}

fn group_stats(group: &str, trials: &[&TrialResult]) -> GroupStats {
    let ok: Vec<&TrialResult> = trials
        .iter()
        .copied()
        .filter(|r| r.outcome == Outcome::Success)
        .collect();
    GroupStats {
        group: group.to_string(),
        trials: trials.len(),
        successes: ok.len(),
        success_pct: pct(ok.len(), trials.len()),
        traversal_time: MeanVar::of(ok.iter().filter_map(|r| r.traversal_time)),
        roll: MeanVar::of(trials.iter().filter_map(|r| trial_mean_abs(&r.roll))),
        pitch: MeanVar::of(trials.iter().filter_map(|r| trial_mean_abs(&r.pitch))),
        roll_success: MeanVar::of(ok.iter().filter_map(|r| trial_mean_abs(&r.roll))),
        pitch_success: MeanVar::of(ok.iter().filter_map(|r| trial_mean_abs(&r.pitch))),
    }
}

fn outcome_table(trials: &[&TrialResult]) -> OutcomeTable {
    let n = trials.len();
    let count = |o: Outcome| trials.iter().filter(|r| r.outcome == o).count();
    let (s, r, st, t, e) = (
        count(Outcome::Success),
        count(Outcome::Rollover),
        count(Outcome::Stuck),
        count(Outcome::Timeout),
        count(Outcome::Error),
    );
    OutcomeTable {
        trials: n,
        successes: s,
        rollovers: r,
        stuck: st,
        timeouts: t,
        errors: e,
        success_pct: pct(s, n),
        rollover_pct: pct(r, n),
        stuck_pct: pct(st, n),
        timeout_pct: pct(t, n),
        error_pct: pct(e, n),
        traversal_time: MeanVar::of(
            trials
                .iter()
                .filter(|r| r.outcome == Outcome::Success)
                .filter_map(|r| r.traversal_time),
        ),
    }
}

fn extra_metrics(trials: &[&TrialResult]) -> ExtraMetrics {
    let with_angles = |f: fn(&TrialResult) -> &crate::metrics::AngleStats| {
        max_of(
            trials
                .iter()
                .map(|r| f(r))
                .filter(|a| a.abs.count > 0)
                .map(|a| a.abs.max),
        )
    };
    ExtraMetrics {
        throttle_mean_abs: mean_of(trials.iter().map(|r| r.throttle.mean_abs)),
        throttle_total_variation: mean_of(trials.iter().map(|r| r.throttle.total_variation)),
        steering_mean_abs: mean_of(trials.iter().map(|r| r.steering.mean_abs)),
        steering_total_variation: mean_of(trials.iter().map(|r| r.steering.total_variation)),
        path_length: mean_of(trials.iter().map(|r| r.path_length)),
        path_length_success: mean_of(
            trials
                .iter()
                .filter(|r| r.outcome == Outcome::Success)
                .map(|r| r.path_length),
        ),
        max_abs_roll: with_angles(|r| &r.roll),
        max_abs_pitch: with_angles(|r| &r.pitch),
    }
}

fn system_summary(name: String, trials: &[&TrialResult]) -> SystemSummary {
    let mut seen = std::collections::BTreeSet::new();
    let duplicate_tasks = trials.iter().filter(|r| !seen.insert(r.task)).count();
    let by = |b: Breakdown| -> Vec<GroupStats> {
        let mut parts: [Vec<&TrialResult>; 3] = Default::default();
        for r in trials {
            parts[b.index_of(r)].push(r);
        }
        b.groups()
            .iter()
            .zip(&parts)
            .map(|(g, part)| group_stats(g, part))
            .collect()
    };
    SystemSummary {
        name,
        system: trials.first().map(|r| r.system.clone()).unwrap_or_default(),
        vehicle: trials
            .first()
            .map(|r| r.vehicle.clone())
            .unwrap_or_default(),
        duplicate_tasks,
        outcomes: outcome_table(trials),
        overall: group_stats("all", trials),
        by_level: by(Breakdown::ElevationLevel),
        by_terrain: by(Breakdown::TerrainType),
        by_density: by(Breakdown::ObstacleDensity),
        extra: extra_metrics(trials),
    }
}

/// Summarises trials per system (and vehicle), in first-seen order. See the module
/// documentation for which trials enter which number.
pub fn summarize(results: &[TrialResult]) -> Summary {
    // (system, vehicle) -> trials, in first-seen order.
    let mut keys: Vec<(&str, &str)> = Vec::new();
    let mut groups: Vec<Vec<&TrialResult>> = Vec::new();
    for r in results {
        let key = (r.system.as_str(), r.vehicle.as_str());
        match keys.iter().position(|k| *k == key) {
            Some(i) => groups[i].push(r),
            None => {
                keys.push(key);
                groups.push(vec![r]);
            }
        }
    }
    // A system run with several vehicles gets `system/vehicle` labels so columns stay apart.
    let mut vehicles_per_system: BTreeMap<&str, usize> = BTreeMap::new();
    for (s, _) in &keys {
        *vehicles_per_system.entry(s).or_default() += 1;
    }
    let labelled: Vec<(String, Vec<&TrialResult>)> = keys
        .iter()
        .zip(groups)
        .map(|((s, v), trials)| {
            let name = if vehicles_per_system.get(s).copied().unwrap_or(0) > 1 {
                format!("{s}/{v}")
            } else {
                s.to_string()
            };
            (name, trials)
        })
        .collect();
    Summary {
        trials: results.len(),
        systems: labelled
            .iter()
            .map(|(name, trials)| system_summary(name.clone(), trials))
            .collect(),
        paired: super::paired::paired(&labelled),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures::{close, sample, trial};
    use ElevationLevel::*;
    use ObstacleDensity::*;
    use Outcome::*;
    use TerrainType::*;
    use verti_world::{ElevationLevel, ObstacleDensity, TerrainType};

    #[test]
    fn table_i_shares_and_order() {
        let s = summarize(&sample());
        assert_eq!(s.trials, 6);
        let names: Vec<&str> = s.systems.iter().map(|x| x.name.as_str()).collect();
        assert_eq!(names, ["A", "B"], "first-seen order");
        let a = &s.systems[0].outcomes;
        assert_eq!((a.trials, a.successes, a.rollovers, a.stuck), (4, 2, 1, 1));
        // 2/4, 1/4, 1/4, 0/4
        assert!(close(a.success_pct, 50.0) && close(a.rollover_pct, 25.0));
        assert!(close(a.stuck_pct, 25.0) && close(a.timeout_pct, 0.0));
        assert!(close(a.error_pct, 0.0));
        // traversal time over the two successes: (20 + 30) / 2 = 25, var = 5^2 = 25
        assert_eq!(a.traversal_time.count, 2);
        assert!(close(a.traversal_time.mean, 25.0) && close(a.traversal_time.var, 25.0));
        let b = &s.systems[1].outcomes;
        assert!(close(b.timeout_pct, 50.0) && close(b.error_pct, 50.0));
        assert!(close(b.success_pct, 0.0));
        assert_eq!(
            b.traversal_time,
            MeanVar::default(),
            "no successes: no time"
        );
    }

    #[test]
    fn fig6_breakdowns_by_hand() {
        let s = summarize(&sample());
        let a = &s.systems[0];
        // elevation: low {a1, a2}, mid {a4}, high {a3}
        let lv: Vec<usize> = a.by_level.iter().map(|g| g.trials).collect();
        assert_eq!(lv, [2, 1, 1]);
        let low = &a.by_level[0];
        assert_eq!(low.group, "low");
        assert!(close(low.success_pct, 100.0));
        assert!(close(low.traversal_time.mean, 25.0));
        // |roll| means 2 and 4: mean 3, population variance ((1)^2 + (1)^2) / 2 = 1
        assert!(close(low.roll.mean, 3.0) && close(low.roll.var, 1.0));
        // |pitch| 4 and 8: mean 6, variance 4
        assert!(close(low.pitch.mean, 6.0) && close(low.pitch.var, 4.0));
        let high = &a.by_level[2];
        assert!(close(high.success_pct, 0.0));
        assert_eq!(high.traversal_time.mean, None);
        // the rollover counts for roll (all trials) but not for the success-only variant
        assert!(close(high.roll.mean, 40.0) && close(high.roll.var, 0.0));
        assert_eq!(high.roll_success.count, 0);
        // terrain: rigid {a1, a3}, deformable {a2}, mixed {a4}
        let rigid = &a.by_terrain[0];
        assert_eq!((rigid.trials, rigid.successes), (2, 1));
        assert!(close(rigid.success_pct, 50.0));
        // all trials: roll 2 and 40 -> mean 21, variance 19^2 = 361; successes: 2 only
        assert!(close(rigid.roll.mean, 21.0) && close(rigid.roll.var, 361.0));
        assert!(close(rigid.roll_success.mean, 2.0) && close(rigid.roll_success.var, 0.0));
        // pitch 4 and 10: mean 7, variance 9
        assert!(close(rigid.pitch.mean, 7.0) && close(rigid.pitch.var, 9.0));
        // density: sparse {a1, a3}, medium {a4}, dense {a2}
        let dv: Vec<usize> = a.by_density.iter().map(|g| g.trials).collect();
        assert_eq!(dv, [2, 1, 1]);
        assert!(close(a.by_density[2].traversal_time.mean, 30.0));
        // overall over A's four trials: roll 2, 4, 40, 6 -> mean 13,
        // variance (121 + 81 + 729 + 49) / 4 = 245
        assert!(close(a.overall.roll.mean, 13.0) && close(a.overall.roll.var, 245.0));
        // B: the error trial has no angle samples and is left out of roll, not counted as 0
        let bm = &s.systems[1].by_level[1];
        assert_eq!((bm.trials, bm.roll.count), (2, 1));
        assert!(close(bm.roll.mean, 1.0));
        // B has no low/high trials: groups exist but are empty
        assert_eq!(s.systems[1].by_level[0].trials, 0);
        assert_eq!(s.systems[1].by_level[0].success_pct, None);
    }

    #[test]
    fn extra_metrics_by_hand() {
        let s = summarize(&sample());
        let e = &s.systems[0].extra;
        // each trial: throttle 0.5 then 1.0 -> mean |.| 0.75, total variation 0.5
        assert!(close(e.throttle_mean_abs, 0.75) && close(e.throttle_total_variation, 0.5));
        assert!(close(e.steering_mean_abs, 0.0));
        // path lengths 10, 20, 30, 40 -> 25; successes 10, 20 -> 15
        assert!(close(e.path_length, 25.0) && close(e.path_length_success, 15.0));
        assert!(close(e.max_abs_roll, 40.0) && close(e.max_abs_pitch, 10.0));
        // B's only trial with angles has |roll| 1
        assert!(close(s.systems[1].extra.max_abs_roll, 1.0));
    }

    #[test]
    fn same_system_with_two_vehicles_gets_two_columns_and_duplicates_are_counted() {
        let t1 = trial("A", 1, (Low, Rigid, Sparse), Success, 1.0, 1.0);
        let mut t2 = t1.clone();
        t2.vehicle = "art".into();
        let s = summarize(&[t1.clone(), t2, t1]);
        let names: Vec<&str> = s.systems.iter().map(|x| x.name.as_str()).collect();
        assert_eq!(names, ["A/hmmwv", "A/art"]);
        assert_eq!(s.systems[0].duplicate_tasks, 1);
        assert_eq!(s.systems[1].duplicate_tasks, 0);
    }
}
