//! Per-task comparison of verti with the reference, and its aggregation (all tasks and per
//! elevation level): outcome agreement, outcome rates, attitude ratios, time to goal on common
//! successes, and trajectory divergence.

use crate::divergence::{Window, divergence};
// re-exported: `OutcomeCounts` was defined here, and `summary::OutcomeCounts` stays its path
pub use crate::outcome_counts::OutcomeCounts;
use crate::reference::RefTask;
use crate::run::{CompareSetup, VertiRun};
use serde::Serialize;
use verti_bench::Outcome;
use verti_world::ElevationLevel;

/// Window of the early divergence, s: long enough to leave the start, short enough that the
/// runs have not yet parted for good.
pub const EARLY_WINDOW: f64 = 10.0;

/// What one engine did on one task.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EngineStats {
    pub outcome: Outcome,
    /// Simulated seconds at the end.
    pub time: f64,
    pub traversal_time: Option<f64>,
    /// Degrees.
    pub mean_abs_roll: f64,
    pub max_abs_roll: f64,
    pub mean_abs_pitch: f64,
    pub max_abs_pitch: f64,
    pub final_distance: Option<f64>,
    pub path_length: Option<f64>,
}

/// Both engines on one task.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TaskComparison {
    /// `vb/configN_LEVEL`.
    pub world: String,
    pub world_index: u32,
    pub pair: u32,
    pub level: ElevationLevel,
    /// The ground the task was run on ([`crate::reference::RefGround::name`]).
    pub ground: String,
    pub reference: EngineStats,
    pub verti: EngineStats,
    /// Same outcome class.
    pub agree: bool,
    /// verti / reference time to goal, when both succeeded.
    pub time_ratio: Option<f64>,
    /// verti / reference of the mean and max |roll| and |pitch|.
    pub mean_roll_ratio: f64,
    pub max_roll_ratio: f64,
    pub mean_pitch_ratio: f64,
    pub max_pitch_ratio: f64,
    /// Divergence of verti from the reference over the first [`EARLY_WINDOW`] s and overall.
    pub early: Window,
    pub whole: Window,
    /// Why verti's trial failed, for an `error` outcome.
    pub error: Option<String>,
}

/// Compares verti's run of a task with the reference's.
pub fn compare_task(reference: &RefTask, run: &VertiRun) -> TaskComparison {
    let o = &reference.outcome;
    let r = &run.result;
    let ref_stats = EngineStats {
        outcome: o.outcome,
        time: o.time,
        traversal_time: o.traversal_time,
        mean_abs_roll: o.mean_abs_roll,
        max_abs_roll: o.max_abs_roll,
        mean_abs_pitch: o.mean_abs_pitch,
        max_abs_pitch: o.max_abs_pitch,
        final_distance: o.final_distance,
        path_length: o.path_length,
    };
    let verti = EngineStats {
        outcome: r.outcome,
        time: r.time,
        traversal_time: r.traversal_time,
        mean_abs_roll: r.roll.abs.mean,
        max_abs_roll: r.roll.abs.max,
        mean_abs_pitch: r.pitch.abs.mean,
        max_abs_pitch: r.pitch.abs.max,
        final_distance: Some(r.final_distance).filter(|d| d.is_finite()),
        path_length: Some(r.path_length),
    };
    let time_ratio = match (verti.traversal_time, ref_stats.traversal_time) {
        (Some(v), Some(c)) if c > 0.0 => Some(v / c),
        _ => None,
    };
    TaskComparison {
        world: o.world.clone(),
        world_index: o.world_index,
        pair: o.pair,
        level: r.level,
        ground: o.ground.name(),
        agree: verti.outcome == ref_stats.outcome,
        time_ratio,
        mean_roll_ratio: verti.mean_abs_roll / ref_stats.mean_abs_roll,
        max_roll_ratio: verti.max_abs_roll / ref_stats.max_abs_roll,
        mean_pitch_ratio: verti.mean_abs_pitch / ref_stats.mean_abs_pitch,
        max_pitch_ratio: verti.max_abs_pitch / ref_stats.max_abs_pitch,
        early: divergence(&reference.trajectory, &run.samples, Some(EARLY_WINDOW)),
        whole: divergence(&reference.trajectory, &run.samples, None),
        error: r.error.clone(),
        reference: ref_stats,
        verti,
    }
}

/// One quantity of both engines over a group of tasks.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Paired {
    /// Mean over the tasks.
    pub reference: f64,
    pub verti: f64,
    /// verti's mean over the reference's. A few reference rollovers (|roll| to 90°) weigh
    /// heavily in it.
    pub ratio_of_means: f64,
    /// Median over tasks of verti / reference per task: the typical task, the headline figure.
    pub median_ratio: Option<f64>,
}

impl Paired {
    fn of(tasks: &[&TaskComparison], f: impl Fn(&EngineStats) -> f64) -> Paired {
        let reference = mean(tasks.iter().map(|t| f(&t.reference)));
        let verti = mean(tasks.iter().map(|t| f(&t.verti)));
        Paired {
            reference,
            verti,
            ratio_of_means: verti / reference,
            median_ratio: median(
                tasks
                    .iter()
                    .map(|t| f(&t.verti) / f(&t.reference))
                    .collect(),
            ),
        }
    }
}

/// Divergence averaged over tasks: the mean of the per-task means, and the largest maximum.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DivergenceSummary {
    pub mean_lateral: f64,
    pub max_lateral: f64,
    pub mean_roll_error: f64,
    pub max_roll_error: f64,
}

impl DivergenceSummary {
    fn of(windows: &[&Window]) -> DivergenceSummary {
        let max = |f: fn(&Window) -> f64| {
            windows
                .iter()
                .map(|w| f(w))
                .filter(|v| v.is_finite())
                .fold(f64::NAN, f64::max)
        };
        DivergenceSummary {
            mean_lateral: mean(windows.iter().map(|w| w.mean_lateral)),
            max_lateral: max(|w| w.max_lateral),
            mean_roll_error: mean(windows.iter().map(|w| w.mean_roll_error)),
            max_roll_error: max(|w| w.max_roll_error),
        }
    }
}

/// A group of tasks (all, or one elevation level) summarised.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Aggregate {
    /// `all`, `low`, `mid` or `high`.
    pub group: String,
    pub tasks: usize,
    /// Tasks with the same outcome class, and their share.
    pub agreeing: usize,
    pub agreement: f64,
    pub reference: OutcomeCounts,
    pub verti: OutcomeCounts,
    /// Tasks both engines succeeded on, and the median of verti / reference time to goal.
    pub common_successes: usize,
    pub median_time_ratio: Option<f64>,
    pub mean_abs_roll: Paired,
    pub max_abs_roll: Paired,
    pub mean_abs_pitch: Paired,
    pub max_abs_pitch: Paired,
    pub early: DivergenceSummary,
    pub whole: DivergenceSummary,
}

fn aggregate(group: &str, tasks: &[&TaskComparison]) -> Aggregate {
    let mut reference = OutcomeCounts::default();
    let mut verti = OutcomeCounts::default();
    for t in tasks {
        reference.add(t.reference.outcome);
        verti.add(t.verti.outcome);
    }
    let agreeing = tasks.iter().filter(|t| t.agree).count();
    let ratios: Vec<f64> = tasks.iter().filter_map(|t| t.time_ratio).collect();
    let early: Vec<&Window> = tasks.iter().map(|t| &t.early).collect();
    let whole: Vec<&Window> = tasks.iter().map(|t| &t.whole).collect();
    Aggregate {
        group: group.to_string(),
        tasks: tasks.len(),
        agreeing,
        agreement: agreeing as f64 / tasks.len().max(1) as f64,
        reference,
        verti,
        common_successes: ratios.len(),
        median_time_ratio: median(ratios),
        mean_abs_roll: Paired::of(tasks, |e| e.mean_abs_roll),
        max_abs_roll: Paired::of(tasks, |e| e.max_abs_roll),
        mean_abs_pitch: Paired::of(tasks, |e| e.mean_abs_pitch),
        max_abs_pitch: Paired::of(tasks, |e| e.max_abs_pitch),
        early: DivergenceSummary::of(&early),
        whole: DivergenceSummary::of(&whole),
    }
}

/// The settings of the verti side, recorded with the results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetupRecord {
    pub vehicle: String,
    pub driver: crate::run::Driver,
    pub speed: f64,
    pub lookahead: f64,
    pub kp: f64,
    pub rate: f64,
    pub rules: verti_bench::Rules,
    pub max_time: f64,
    /// Period of the benchmark's inner loop (speed controller, actions at most this often), s.
    pub inner_dt: f64,
    /// How verti's vehicle starts (`drop`: the reference's spawn).
    pub start: verti_bench::StartMode,
    pub surface: String,
    pub friction: f64,
}

impl SetupRecord {
    pub fn of(setup: &CompareSetup) -> SetupRecord {
        SetupRecord {
            vehicle: setup.vehicle.name.clone(),
            driver: setup.driver,
            speed: setup.pid.speed,
            lookahead: setup.pid.lookahead,
            kp: setup.pid.kp,
            rate: setup.pid.rate,
            rules: setup.episode.rules,
            max_time: setup.episode.max_time,
            inner_dt: setup.episode.inner_dt,
            start: setup.episode.start,
            surface: setup.class.to_string(),
            friction: setup.surface.effective_friction(),
        }
    }
}

/// The whole comparison.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Reference engine, e.g. `chrono-9.0.1`.
    pub engine: String,
    pub setup: SetupRecord,
    /// All tasks first, then each elevation level present, then (when the tasks were run on
    /// more than one-friction rigid ground) each ground present.
    pub groups: Vec<Aggregate>,
    /// The grounds the tasks were run on, in order of first appearance.
    pub grounds: Vec<String>,
    pub tasks: Vec<TaskComparison>,
    /// Reference trials left out as artifacts of the reference engine
    /// ([`crate::artifact`]); not in `tasks` or any group.
    pub excluded: Vec<crate::artifact::Excluded>,
    /// Each task re-run from jittered starts (`--ensemble`), when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<crate::ensemble::Ensemble>,
}

/// Aggregates task comparisons (all of them, then per level).
pub fn summarize(setup: &CompareSetup, engine: &str, tasks: Vec<TaskComparison>) -> Summary {
    let all: Vec<&TaskComparison> = tasks.iter().collect();
    let mut groups = vec![aggregate("all", &all)];
    for level in ElevationLevel::ALL {
        let of_level: Vec<&TaskComparison> =
            all.iter().copied().filter(|t| t.level == level).collect();
        if !of_level.is_empty() {
            groups.push(aggregate(level.name(), &of_level));
        }
    }
    let mut grounds: Vec<String> = Vec::new();
    for t in &all {
        if !grounds.contains(&t.ground) {
            grounds.push(t.ground.clone());
        }
    }
    if grounds.iter().any(|g| g != "one-friction") {
        for g in &grounds {
            let on: Vec<&TaskComparison> = all.iter().copied().filter(|t| &t.ground == g).collect();
            groups.push(aggregate(g, &on));
        }
    }
    Summary {
        engine: engine.to_string(),
        setup: SetupRecord::of(setup),
        groups,
        grounds,
        tasks,
        excluded: Vec::new(),
        ensemble: None,
    }
}

/// Mean of the finite values (NaN when none).
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values
        .filter(|v| v.is_finite())
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// Median of the finite values.
pub fn median(mut values: Vec<f64>) -> Option<f64> {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_means_skip_missing_values() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, f64::NAN, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(vec![]), None);
        assert_eq!(mean([1.0, f64::NAN, 3.0].into_iter()), 2.0);
        assert!(mean(std::iter::empty()).is_nan());
    }
}
