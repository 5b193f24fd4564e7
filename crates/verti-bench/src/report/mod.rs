//! Aggregation of trial results into the paper's Table I and Fig. 6, and their rendering as
//! Markdown and HTML.
//!
//! * [`summarize`]: per system, the failure analysis of Table I (success, rollover, stuck,
//!   timeout and error shares) and the Fig. 6 breakdowns (elevation level, terrain type,
//!   obstacle density) of success rate, traversal time, roll and pitch, plus action and path
//!   metrics (§III-F).
//! * [`load_results`]: reads `results.jsonl` files (or directories holding them).
//! * [`markdown`], [`html`]: the summary as tables, systems side by side as in the paper.
//! * [`fig6_charts`]: the Fig. 6 numbers as plain chart data (one panel per breakdown and
//!   metric) that maps one to one onto `verti_render::charts::Panel`.
//!
//! ## Which trials feed which number
//!
//! * Success rate and the failure split: all trials of the group.
//! * Traversal time: successful trials only (paper §IV-B: "Traversal Time is only averaged
//!   over successful trials").
//! * Roll and pitch ([`GroupStats::roll`], [`GroupStats::pitch`]): every trial of the group
//!   contributes one number, its own mean absolute angle over the trial (`roll.abs.mean`);
//!   the group mean and *population* variance are taken across those per-trial means. All
//!   trials of the group are used, failures included, because the paper states that Fig. 6
//!   shows its metrics "for all systems and tasks" and only singles out traversal time as
//!   success-only. The success-only variant (what the Verti-Bench reference scripts average)
//!   is kept alongside in [`GroupStats::roll_success`] and [`GroupStats::pitch_success`].
//!   A trial that recorded no angle samples (e.g. an error before the first step) or has a
//!   non-finite mean has no per-trial angle and is left out of the angle statistics (the
//!   `count` fields say how many trials were used).
//! * Extra per-system metrics ([`ExtraMetrics`]): per-trial values averaged over all trials
//!   with equal weight per trial; maxima over all trials.
//!
//! Numbers that do not exist (a mean over no trials) are `None`, written `null` in JSON and
//! `–` in tables; nothing here panics on any input, an empty result set included.
//!
//! ## Layout
//!
//! The shared data types (this file) are separate from what computes and writes them:
//!
//! * `aggregate`: [`summarize`], trials reduced to the types below.
//! * `load`: [`load_results`], [`load_results_from`]; `loaded`: what they return and their
//!   error type (below `load` and `runs`, which both use them).
//! * `paired`: [`PairedComparison`]s, the sign test between systems on shared tasks.
//! * `charts`: [`fig6_charts`] and its panel types.
//! * `tables`: the summary as tables of text cells, shared by both writers.
//! * `writers`: [`markdown`] and [`html`].
//! * `fixtures` (tests only): the sample trials the tests share.
//!
//! Runs are read through the run bookkeeping's public types (`crate::run`: the results file,
//! `run.json`), never through the trial loop (`crate::eval`): a report only needs what a run
//! left on disk.
//!
//! Tests live with the code they test; the ones spanning several of these files are here.

mod aggregate;
mod charts;
#[cfg(test)]
mod fixtures;
mod load;
mod loaded;
mod paired;
mod runs;
mod tables;
mod writers;

pub use aggregate::summarize;
pub use charts::{ChartPanel, ChartSeries, Fig6Metric, fig6_charts};
pub use load::{load_results, load_results_from};
pub use loaded::{Loaded, LoadedFile, ReportError};
pub use writers::{html, markdown, system_page, system_page_name};

use crate::episode::TrialResult;
use crate::metrics::Stats;
use serde::{Deserialize, Serialize};
use verti_world::{ElevationLevel, ObstacleDensity, TerrainType};

/// Mean and population variance of a sample; `None` when the sample is empty.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeanVar {
    /// How many values the statistics are taken over.
    pub count: usize,
    pub mean: Option<f64>,
    /// Population variance (divides by `count`), as `metrics::Stats`.
    pub var: Option<f64>,
}

impl MeanVar {
    /// Statistics of the finite values of `xs` (non-finite values are skipped, so a single
    /// corrupt number cannot turn a whole column into NaN).
    pub fn of(xs: impl IntoIterator<Item = f64>) -> MeanVar {
        let mut s = Stats::default();
        for x in xs.into_iter().filter(|x| x.is_finite()) {
            s.push(x);
        }
        if s.count == 0 {
            return MeanVar::default();
        }
        MeanVar {
            count: s.count as usize,
            mean: Some(s.mean),
            // Welford can leave a tiny negative m2 through rounding; a variance is >= 0.
            var: Some(s.var.max(0.0)),
        }
    }

    /// Standard deviation (square root of the population variance).
    pub fn std(&self) -> Option<f64> {
        self.var.map(f64::sqrt)
    }
}

/// Table I of the paper for one system: how its trials ended.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OutcomeTable {
    pub trials: usize,
    pub successes: usize,
    pub rollovers: usize,
    pub stuck: usize,
    pub timeouts: usize,
    pub errors: usize,
    /// Shares of all trials in percent; `None` without trials.
    pub success_pct: Option<f64>,
    pub rollover_pct: Option<f64>,
    pub stuck_pct: Option<f64>,
    pub timeout_pct: Option<f64>,
    pub error_pct: Option<f64>,
    /// Traversal time over the successful trials, seconds.
    pub traversal_time: MeanVar,
}

/// Fig. 6 numbers of one group (e.g. the `high` elevation level) for one system.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GroupStats {
    /// Group name: `low`/`mid`/`high`, `rigid`/`deformable`/`mixed` or
    /// `sparse`/`medium`/`dense`.
    pub group: String,
    pub trials: usize,
    pub successes: usize,
    /// Percentage of successful trials; `None` without trials.
    pub success_pct: Option<f64>,
    /// Traversal time of the successful trials, seconds.
    pub traversal_time: MeanVar,
    /// Per-trial mean |roll| (degrees), statistics across all trials of the group.
    pub roll: MeanVar,
    /// Per-trial mean |pitch| (degrees), statistics across all trials of the group.
    pub pitch: MeanVar,
    /// As `roll`, successful trials only (the reference scripts' choice).
    pub roll_success: MeanVar,
    /// As `pitch`, successful trials only.
    pub pitch_success: MeanVar,
}

/// The three breakdowns of Fig. 6.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Breakdown {
    ElevationLevel,
    TerrainType,
    ObstacleDensity,
}

impl Breakdown {
    /// In the paper's row order (Fig. 6 top to bottom).
    pub const ALL: [Breakdown; 3] = [
        Breakdown::ElevationLevel,
        Breakdown::TerrainType,
        Breakdown::ObstacleDensity,
    ];

    /// Human-readable title.
    pub fn title(self) -> &'static str {
        match self {
            Breakdown::ElevationLevel => "Elevation level",
            Breakdown::TerrainType => "Terrain type",
            Breakdown::ObstacleDensity => "Obstacle density",
        }
    }

    /// The group names, always all three in a fixed order (empty groups included, so tables
    /// and charts of different runs line up).
    pub fn groups(self) -> [&'static str; 3] {
        match self {
            Breakdown::ElevationLevel => ElevationLevel::ALL.map(|l| l.name()),
            Breakdown::TerrainType => TerrainType::ALL.map(|t| t.name()),
            Breakdown::ObstacleDensity => ObstacleDensity::ALL.map(|d| d.name()),
        }
    }

    /// Index of the group a trial belongs to.
    fn index_of(self, r: &TrialResult) -> usize {
        match self {
            Breakdown::ElevationLevel => ElevationLevel::ALL.iter().position(|l| *l == r.level),
            Breakdown::TerrainType => TerrainType::ALL.iter().position(|t| *t == r.terrain_type),
            Breakdown::ObstacleDensity => ObstacleDensity::ALL.iter().position(|d| *d == r.density),
        }
        .unwrap_or(0)
    }
}

/// Action, path and extreme-angle metrics of one system (§III-F: "vehicle actions ... can be
/// used as metrics to quantify energy consumption, planning confidence, and path smoothness").
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExtraMetrics {
    /// Mean over trials of the per-trial mean |throttle| (effort).
    pub throttle_mean_abs: Option<f64>,
    /// Mean over trials of the per-trial throttle total variation, sum of |Δ| per trial
    /// (smoothness; grows with trial length).
    pub throttle_total_variation: Option<f64>,
    /// Mean over trials of the per-trial mean |steering| (planning confidence).
    pub steering_mean_abs: Option<f64>,
    /// Mean over trials of the per-trial steering total variation.
    pub steering_total_variation: Option<f64>,
    /// Mean planar distance driven per trial, metres.
    pub path_length: Option<f64>,
    /// Mean planar distance driven per successful trial, metres.
    pub path_length_success: Option<f64>,
    /// Largest |roll| / |pitch| seen in any trial, degrees.
    pub max_abs_roll: Option<f64>,
    pub max_abs_pitch: Option<f64>,
}

/// Everything about one system.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SystemSummary {
    /// Column label: the system name, or `system/vehicle` when the same system was run with
    /// more than one vehicle in the summarised results.
    pub name: String,
    pub system: String,
    pub vehicle: String,
    /// Trials whose task number was already seen for this system and vehicle (e.g. the same
    /// results file given twice). They are counted like any other trial; a non-zero value
    /// means the numbers are probably not what was meant.
    pub duplicate_tasks: usize,
    /// Table I.
    pub outcomes: OutcomeTable,
    /// Fig. 6 statistics over all trials of the system.
    pub overall: GroupStats,
    /// Fig. 6 rows: by elevation level (low, mid, high), terrain type (rigid, deformable,
    /// mixed) and obstacle density (sparse, medium, dense); always three groups each.
    pub by_level: Vec<GroupStats>,
    pub by_terrain: Vec<GroupStats>,
    pub by_density: Vec<GroupStats>,
    pub extra: ExtraMetrics,
}

impl SystemSummary {
    /// The groups of one breakdown.
    pub fn breakdown(&self, b: Breakdown) -> &[GroupStats] {
        match b {
            Breakdown::ElevationLevel => &self.by_level,
            Breakdown::TerrainType => &self.by_terrain,
            Breakdown::ObstacleDensity => &self.by_density,
        }
    }
}

/// Two systems on the tasks both ran (see `paired` for the test).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PairedComparison {
    /// Column labels of the two systems, in report order.
    pub a: String,
    pub b: String,
    /// Tasks both ran (same task number, world and start/goal pair).
    pub common_tasks: usize,
    /// Of those, tasks `a` reached and `b` did not, and the other way round.
    pub only_a: usize,
    pub only_b: usize,
    /// (only_a − only_b) / √(only_a + only_b); `None` when no task separates them.
    pub z: Option<f64>,
    /// Two-sided exact sign test (McNemar); `None` when no task separates them.
    pub p_value: Option<f64>,
}

/// The summary of a set of trials, systems side by side.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub trials: usize,
    /// In the order each system (and vehicle) first appears in the results.
    pub systems: Vec<SystemSummary>,
    /// Every pair of systems compared on their shared tasks, in report order (empty with one
    /// system; absent in summaries written before it existed).
    #[serde(default)]
    pub paired: Vec<PairedComparison>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::episode::Outcome::*;
    use crate::report::fixtures::{sample, trial};
    use ElevationLevel::*;
    use ObstacleDensity::*;
    use TerrainType::*;

    #[test]
    fn empty_and_degenerate_inputs_do_not_panic() {
        let s = summarize(&[]);
        assert_eq!((s.trials, s.systems.len()), (0, 0));
        assert!(markdown(&s).contains("No results"));
        assert!(html(&s, &[("Fig. 6", "fig6.png")]).contains("fig6.png"));
        assert!(fig6_charts(&s).iter().all(|p| p.series.is_empty()));
        // NaN values are skipped, not propagated
        let mut t = trial("A", 1, (Low, Rigid, Sparse), Success, 1.0, 1.0);
        t.traversal_time = Some(f64::NAN);
        t.path_length = f64::NAN;
        let s = summarize(&[t]);
        let a = &s.systems[0];
        assert_eq!(a.outcomes.traversal_time.mean, None);
        assert_eq!(a.extra.path_length, None);
        let md = markdown(&s);
        assert!(!md.contains("NaN"), "{md}");
        serde_json::to_string(&s).expect("serialisable");
    }

    #[test]
    fn summary_json_has_stable_snake_case_names() {
        let v = serde_json::to_value(summarize(&sample())).unwrap();
        let a = &v["systems"][0];
        assert_eq!(a["outcomes"]["success_pct"], 50.0);
        assert_eq!(a["by_level"][0]["roll"]["mean"], 3.0);
        assert_eq!(
            a["by_level"][2]["traversal_time"]["mean"],
            serde_json::Value::Null
        );
        assert!(a["extra"]["throttle_total_variation"].is_number());
        let back: Summary = serde_json::from_value(v).unwrap();
        assert_eq!(back, summarize(&sample()));
    }
}
