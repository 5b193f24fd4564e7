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

use crate::episode::{Outcome, TrialResult};
use crate::eval::{EvalError, RESULTS_FILE, read_results};
use crate::metrics::Stats;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
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

/// The summary of a set of trials, systems side by side.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub trials: usize,
    /// In the order each system (and vehicle) first appears in the results.
    pub systems: Vec<SystemSummary>,
}

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
    let systems = keys
        .iter()
        .zip(&groups)
        .map(|((s, v), trials)| {
            let name = if vehicles_per_system.get(s).copied().unwrap_or(0) > 1 {
                format!("{s}/{v}")
            } else {
                s.to_string()
            };
            system_summary(name, trials)
        })
        .collect();
    Summary {
        trials: results.len(),
        systems,
    }
}

// ---------------------------------------------------------------------------------------------
// Loading
// ---------------------------------------------------------------------------------------------

/// Why results could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{}: no such file or directory", .0.display())]
    NotFound(PathBuf),
    #[error(
        "{}: no {RESULTS_FILE} in this directory or its immediate subdirectories",
        .0.display()
    )]
    NoResults(PathBuf),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Reading or parsing a results file failed (the message names the file and line).
    #[error(transparent)]
    Eval(#[from] EvalError),
}

/// One results file that was read.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedFile {
    pub path: PathBuf,
    pub trials: usize,
    /// `false` when a torn last line (a trial in flight when the run was killed) was dropped.
    pub clean: bool,
}

/// Results and the files they came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    pub results: Vec<TrialResult>,
    pub files: Vec<LoadedFile>,
}

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
pub fn load_results_from(paths: &[PathBuf]) -> Result<Loaded, ReportError> {
    let mut out = Loaded::default();
    for p in paths {
        for f in result_files(p)? {
            let (results, clean) = read_results(&f)?;
            out.files.push(LoadedFile {
                path: f,
                trials: results.len(),
                clean,
            });
            out.results.extend(results);
        }
    }
    Ok(out)
}

/// Reads results from files (`.jsonl`) and result directories (see [`load_results_from`]).
pub fn load_results(paths: &[PathBuf]) -> Result<Vec<TrialResult>, ReportError> {
    Ok(load_results_from(paths)?.results)
}

// ---------------------------------------------------------------------------------------------
// Chart data
// ---------------------------------------------------------------------------------------------

/// One Fig. 6 metric.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fig6Metric {
    SuccessRate,
    TraversalTime,
    Roll,
    Pitch,
}

impl Fig6Metric {
    /// In the paper's column order.
    pub const ALL: [Fig6Metric; 4] = [
        Fig6Metric::SuccessRate,
        Fig6Metric::TraversalTime,
        Fig6Metric::Roll,
        Fig6Metric::Pitch,
    ];

    pub fn title(self) -> &'static str {
        match self {
            Fig6Metric::SuccessRate => "Success rate",
            Fig6Metric::TraversalTime => "Traversal time",
            Fig6Metric::Roll => "Roll",
            Fig6Metric::Pitch => "Pitch",
        }
    }

    pub fn unit_label(self) -> &'static str {
        match self {
            Fig6Metric::SuccessRate => "success (%)",
            Fig6Metric::TraversalTime => "time (s)",
            Fig6Metric::Roll => "mean |roll| (°)",
            Fig6Metric::Pitch => "mean |pitch| (°)",
        }
    }

    /// Value and spread (standard deviation; none for the success rate) of a group.
    fn of(self, g: &GroupStats) -> (Option<f64>, Option<f64>) {
        match self {
            Fig6Metric::SuccessRate => (g.success_pct, None),
            Fig6Metric::TraversalTime => (g.traversal_time.mean, g.traversal_time.std()),
            Fig6Metric::Roll => (g.roll.mean, g.roll.std()),
            Fig6Metric::Pitch => (g.pitch.mean, g.pitch.std()),
        }
    }
}

/// One bar series of a chart panel: one system's values per group.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChartSeries {
    pub name: String,
    /// One value per group; NaN where there is none (e.g. no successful trial).
    pub values: Vec<f64>,
    /// Whisker half-lengths (standard deviations), when the metric has a spread.
    pub errors: Option<Vec<f64>>,
}

/// Plain data for one bar-chart panel, field for field `verti_render::charts::Panel`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChartPanel {
    pub breakdown: Breakdown,
    pub metric: Fig6Metric,
    pub title: String,
    pub y_label: String,
    /// Fixed top of the value axis (100 for percentages), else automatic.
    pub y_max: Option<f64>,
    pub groups: Vec<String>,
    pub series: Vec<ChartSeries>,
}

/// The panels of Fig. 6 in the paper's layout, row by row: elevation level, terrain type,
/// obstacle density; in each row success rate, traversal time, roll, pitch (so draw them with
/// 4 columns). Bars are means; whiskers are standard deviations (square roots of the
/// variances in the summary).
pub fn fig6_charts(summary: &Summary) -> Vec<ChartPanel> {
    let mut out = Vec::new();
    for b in Breakdown::ALL {
        for m in Fig6Metric::ALL {
            let series = summary
                .systems
                .iter()
                .map(|s| {
                    let vals: Vec<(Option<f64>, Option<f64>)> =
                        s.breakdown(b).iter().map(|g| m.of(g)).collect();
                    ChartSeries {
                        name: s.name.clone(),
                        values: vals.iter().map(|v| v.0.unwrap_or(f64::NAN)).collect(),
                        errors: (m != Fig6Metric::SuccessRate)
                            .then(|| vals.iter().map(|v| v.1.unwrap_or(f64::NAN)).collect()),
                    }
                })
                .collect();
            out.push(ChartPanel {
                breakdown: b,
                metric: m,
                title: format!("{} – {}", m.title(), b.title().to_lowercase()),
                y_label: m.unit_label().to_string(),
                y_max: (m == Fig6Metric::SuccessRate).then_some(100.0),
                groups: b.groups().iter().map(|g| g.to_string()).collect(),
                series,
            });
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Markdown and HTML
// ---------------------------------------------------------------------------------------------

const NONE: &str = "–";

fn num(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => NONE.to_string(),
    }
}

/// "mean (variance)" with the given number of decimals.
fn mean_var(m: &MeanVar, digits: usize) -> String {
    match (m.mean, m.var) {
        (Some(a), Some(v)) if a.is_finite() && v.is_finite() => {
            format!("{a:.digits$} ({v:.digits$})")
        }
        _ => NONE.to_string(),
    }
}

/// A table: header row and body rows of cells (plain text, escaped by the writer).
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

fn table_i(summary: &Summary) -> Table {
    let mut header = vec![String::new()];
    header.extend(summary.systems.iter().map(|s| s.name.clone()));
    let row = |label: &str, f: &dyn Fn(&SystemSummary) -> String| {
        let mut r = vec![label.to_string()];
        r.extend(summary.systems.iter().map(f));
        r
    };
    let rows = vec![
        row("Trials", &|s| s.outcomes.trials.to_string()),
        row("Success (%)", &|s| num(s.outcomes.success_pct, 1)),
        row("Rollover (%)", &|s| num(s.outcomes.rollover_pct, 1)),
        row("Stuck (%)", &|s| num(s.outcomes.stuck_pct, 1)),
        row("Timeout (%)", &|s| num(s.outcomes.timeout_pct, 1)),
        row("Error (%)", &|s| num(s.outcomes.error_pct, 1)),
        row("Traversal time (s)", &|s| {
            num(s.outcomes.traversal_time.mean, 2)
        }),
    ];
    Table { header, rows }
}

fn fig6_table(summary: &Summary, b: Breakdown) -> Table {
    let mut header = vec![String::new()];
    header.extend(summary.systems.iter().map(|s| s.name.clone()));
    let mut rows = Vec::new();
    for (k, g) in b.groups().iter().enumerate() {
        let row = |label: &str, f: &dyn Fn(&GroupStats) -> String| {
            let mut r = vec![format!("{g}: {label}")];
            r.extend(
                summary
                    .systems
                    .iter()
                    .map(|s| s.breakdown(b).get(k).map_or(NONE.to_string(), f)),
            );
            r
        };
        rows.push(row("trials", &|x| x.trials.to_string()));
        rows.push(row("success (%)", &|x| num(x.success_pct, 1)));
        rows.push(row("traversal time (s)", &|x| {
            mean_var(&x.traversal_time, 2)
        }));
        rows.push(row("roll (°)", &|x| mean_var(&x.roll, 2)));
        rows.push(row("pitch (°)", &|x| mean_var(&x.pitch, 2)));
    }
    Table { header, rows }
}

fn extra_table(summary: &Summary) -> Table {
    let mut header = vec![String::new()];
    header.extend(summary.systems.iter().map(|s| s.name.clone()));
    let row = |label: &str, f: &dyn Fn(&SystemSummary) -> String| {
        let mut r = vec![label.to_string()];
        r.extend(summary.systems.iter().map(f));
        r
    };
    let rows = vec![
        row("Vehicle", &|s| s.vehicle.clone()),
        row("Roll, all trials (°)", &|s| mean_var(&s.overall.roll, 2)),
        row("Pitch, all trials (°)", &|s| mean_var(&s.overall.pitch, 2)),
        row("Roll, successes (°)", &|s| {
            mean_var(&s.overall.roll_success, 2)
        }),
        row("Pitch, successes (°)", &|s| {
            mean_var(&s.overall.pitch_success, 2)
        }),
        row("Max |roll| (°)", &|s| num(s.extra.max_abs_roll, 1)),
        row("Max |pitch| (°)", &|s| num(s.extra.max_abs_pitch, 1)),
        row("Mean |throttle|", &|s| num(s.extra.throttle_mean_abs, 3)),
        row("Throttle total variation", &|s| {
            num(s.extra.throttle_total_variation, 2)
        }),
        row("Mean |steering|", &|s| num(s.extra.steering_mean_abs, 3)),
        row("Steering total variation", &|s| {
            num(s.extra.steering_total_variation, 2)
        }),
        row("Path length (m)", &|s| num(s.extra.path_length, 1)),
        row("Path length, successes (m)", &|s| {
            num(s.extra.path_length_success, 1)
        }),
        row("Duplicate tasks", &|s| s.duplicate_tasks.to_string()),
    ];
    Table { header, rows }
}

fn md_cell(s: &str) -> String {
    s.replace('\\', "\\\\")
        .replace('|', "\\|")
        .replace('\n', " ")
}

fn md_table(out: &mut String, t: &Table) {
    let line = |cells: &[String]| {
        let cells: Vec<String> = cells.iter().map(|c| md_cell(c)).collect();
        format!("| {} |\n", cells.join(" | "))
    };
    out.push_str(&line(&t.header));
    let mut sep = vec![":---".to_string()];
    sep.extend((1..t.header.len()).map(|_| "---:".to_string()));
    out.push_str(&format!("|{}|\n", sep.join("|")));
    for r in &t.rows {
        out.push_str(&line(r));
    }
}

const VARIANCE_NOTE: &str = "Cells: mean (population variance). Traversal time over \
successful trials only; roll and pitch: each trial's mean absolute angle, then mean and \
variance across all trials of the group.";

/// The summary as Markdown: Table I (systems as columns), one Fig. 6 table per breakdown, and
/// the extra metrics.
pub fn markdown(summary: &Summary) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Evaluation report\n\n{} trials, {} system(s).\n",
        summary.trials,
        summary.systems.len()
    );
    if summary.systems.is_empty() {
        out.push_str("No results.\n");
        return out;
    }
    out.push_str("## Table I: outcomes\n\n");
    md_table(&mut out, &table_i(summary));
    out.push_str("\nTraversal time: mean over successful trials.\n");
    for b in Breakdown::ALL {
        let _ = writeln!(out, "\n## Fig. 6: {}\n", b.title().to_lowercase());
        md_table(&mut out, &fig6_table(summary, b));
    }
    let _ = writeln!(out, "\n{VARIANCE_NOTE}");
    out.push_str("\n## Other metrics\n\n");
    md_table(&mut out, &extra_table(summary));
    out.push_str(
        "\nThrottle and steering: per-trial mean |value| and total variation (sum of \
         |change|), averaged over trials.\n",
    );
    out
}

fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

fn html_table(out: &mut String, t: &Table) {
    out.push_str("<table>\n<thead><tr>");
    for h in &t.header {
        let _ = write!(out, "<th>{}</th>", esc(h));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for r in &t.rows {
        out.push_str("<tr>");
        for (i, c) in r.iter().enumerate() {
            let tag = if i == 0 { "th" } else { "td" };
            let _ = write!(out, "<{tag}>{}</{tag}>", esc(c));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table>\n");
}

const CSS: &str = "body{font-family:-apple-system,'Segoe UI',Helvetica,Arial,sans-serif;\
margin:2em auto;max-width:1200px;padding:0 1em;color:#222;line-height:1.4}\
h1,h2{font-weight:600}h2{margin-top:1.8em;border-bottom:1px solid #ddd;padding-bottom:.2em}\
table{border-collapse:collapse;margin:.6em 0;font-size:.92em}\
th,td{padding:.3em .7em;border-bottom:1px solid #e4e4e4;text-align:right;white-space:nowrap}\
thead th{border-bottom:2px solid #888;text-align:center}tbody th{text-align:left;font-weight:500}\
tbody tr:hover{background:#f6f8fa}.note{color:#555;font-size:.9em}\
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #eee}\
figcaption{color:#444;font-size:.9em;margin-top:.3em}";

/// The summary as a self-contained HTML page (inline CSS, no scripts) with the given figures
/// embedded by relative path: `(title, png file name)`, e.g. `("Fig. 6", "fig6.png")`.
pub fn html(summary: &Summary, figures: &[(&str, &str)]) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>verti evaluation report</title>\n<style>{CSS}</style>\n</head>\n<body>\n\
         <h1>Evaluation report</h1>\n<p>{} trials, {} system(s).</p>\n",
        summary.trials,
        summary.systems.len()
    );
    if summary.systems.is_empty() {
        out.push_str("<p>No results.</p>\n");
    } else {
        out.push_str("<h2>Table I: outcomes</h2>\n");
        html_table(&mut out, &table_i(summary));
        out.push_str("<p class=\"note\">Traversal time: mean over successful trials.</p>\n");
    }
    for (title, file) in figures {
        let _ = write!(
            out,
            "<figure>\n<img src=\"{}\" alt=\"{}\">\n<figcaption>{}</figcaption>\n</figure>\n",
            esc(file),
            esc(title),
            esc(title)
        );
    }
    if !summary.systems.is_empty() {
        for b in Breakdown::ALL {
            let _ = writeln!(out, "<h2>Fig. 6: {}</h2>", esc(&b.title().to_lowercase()));
            html_table(&mut out, &fig6_table(summary, b));
        }
        let _ = writeln!(out, "<p class=\"note\">{}</p>", esc(VARIANCE_NOTE));
        out.push_str("<h2>Other metrics</h2>\n");
        html_table(&mut out, &extra_table(summary));
    }
    out.push_str("</body>\n</html>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::episode::Rules;
    use crate::metrics::{AngleStats, SignalStats};

    /// A trial whose per-trial mean |roll| is `roll` and mean |pitch| is `pitch` (one sample
    /// each, so mean = max = the value).
    fn trial(
        system: &str,
        task: u32,
        (level, terrain, density): (ElevationLevel, TerrainType, ObstacleDensity),
        outcome: Outcome,
        roll: f64,
        pitch: f64,
    ) -> TrialResult {
        let mut r = AngleStats::default();
        r.push_rad(roll.to_radians());
        let mut p = AngleStats::default();
        p.push_rad(pitch.to_radians());
        let mut throttle = SignalStats::default();
        for x in [0.5, 1.0] {
            throttle.push(x);
        }
        TrialResult {
            task,
            world: 1,
            pair: 1,
            world_name: "w".into(),
            level,
            terrain_type: terrain,
            density,
            system: system.into(),
            vehicle: "hmmwv".into(),
            rules: Rules::Paper,
            outcome,
            time: 60.0,
            traversal_time: None,
            roll: r,
            pitch: p,
            throttle,
            steering: SignalStats::default(),
            path_length: 10.0 * f64::from(task),
            final_distance: 0.0,
            final_roll: 0.0,
            error: None,
            wall_time: 0.0,
        }
    }

    fn close(a: Option<f64>, b: f64) -> bool {
        a.is_some_and(|a| (a - b).abs() < 1e-9)
    }

    use ElevationLevel::*;
    use ObstacleDensity::*;
    use Outcome::*;
    use TerrainType::*;

    /// System A: 4 trials (2 successes, 1 rollover, 1 stuck); system B: 1 timeout, 1 error.
    fn sample() -> Vec<TrialResult> {
        let mut a1 = trial("A", 1, (Low, Rigid, Sparse), Success, 2.0, 4.0);
        a1.traversal_time = Some(20.0);
        let mut a2 = trial("A", 2, (Low, Deformable, Dense), Success, 4.0, 8.0);
        a2.traversal_time = Some(30.0);
        let a3 = trial("A", 3, (High, Rigid, Sparse), Rollover, 40.0, 10.0);
        let b1 = trial("B", 1, (Mid, Mixed, Medium), Timeout, 1.0, 1.0);
        let a4 = trial("A", 4, (Mid, Mixed, Medium), Stuck, 6.0, 2.0);
        let mut b2 = trial("B", 2, (Mid, Mixed, Medium), Error, 0.0, 0.0);
        // an error before the first step: no angle samples at all
        b2.roll = AngleStats::default();
        b2.pitch = AngleStats::default();
        vec![a1, a2, a3, b1, a4, b2]
    }

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

    #[test]
    fn markdown_and_html_show_systems_side_by_side() {
        let s = summarize(&sample());
        let md = markdown(&s);
        assert!(md.contains("|  | A | B |"), "{md}");
        assert!(md.contains("| Success (%) | 50.0 | 0.0 |"), "{md}");
        assert!(md.contains("| Stuck (%) | 25.0 | 0.0 |"), "{md}");
        assert!(md.contains("| Traversal time (s) | 25.00 | – |"), "{md}");
        // low elevation, A: roll mean 3 variance 1; B: no trials
        assert!(md.contains("| low: roll (°) | 3.00 (1.00) | – |"), "{md}");
        let mut odd = sample();
        odd[0].system = "<x|y>".into();
        let h = html(&summarize(&odd), &[("Fig. 6 <all>", "fig6.png")]);
        assert!(h.contains("&lt;x|y&gt;") && !h.contains("<x|y>"));
        assert!(h.contains("<img src=\"fig6.png\" alt=\"Fig. 6 &lt;all&gt;\">"));
        assert!(markdown(&summarize(&odd)).contains("<x\\|y>"));
    }

    #[test]
    fn fig6_charts_follow_the_paper_layout() {
        let p = fig6_charts(&summarize(&sample()));
        assert_eq!(p.len(), 12);
        assert_eq!(
            (p[0].breakdown, p[0].metric),
            (Breakdown::ElevationLevel, Fig6Metric::SuccessRate)
        );
        assert_eq!(
            (p[11].breakdown, p[11].metric),
            (Breakdown::ObstacleDensity, Fig6Metric::Pitch)
        );
        assert_eq!(p[0].y_max, Some(100.0));
        assert_eq!(p[0].series[0].values, [100.0, 0.0, 0.0]);
        assert!(p[0].series[0].errors.is_none());
        // traversal time by level, A: low 25 ± 5, mid and high without successes -> NaN
        let t = &p[1].series[0];
        assert_eq!(t.values[0], 25.0);
        assert!(t.values[1].is_nan() && t.values[2].is_nan());
        assert_eq!(t.errors.as_ref().unwrap()[0], 5.0);
    }

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
        let all = load_results(&[dir.join("runs"), file.clone()]).unwrap();
        assert_eq!(all.len(), 4);
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
