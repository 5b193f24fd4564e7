//! The summary as tables of plain-text cells (Table I, one Fig. 6 table per breakdown, the
//! extra metrics), shared by the Markdown and HTML writers in `writers`.

use super::{Breakdown, GroupStats, MeanVar, Summary, SystemSummary};

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
pub(super) struct Table {
    pub(super) header: Vec<String>,
    pub(super) rows: Vec<Vec<String>>,
}

pub(super) fn table_i(summary: &Summary) -> Table {
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

pub(super) fn fig6_table(summary: &Summary, b: Breakdown) -> Table {
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

pub(super) fn extra_table(summary: &Summary) -> Table {
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

/// One row per pair of systems: the tasks only one of them reached, and the sign test.
pub(super) fn paired_table(summary: &Summary) -> Table {
    let header = [
        "",
        "Common tasks",
        "Only first succeeds",
        "Only second succeeds",
        "z",
        "p (sign test)",
    ]
    .map(String::from)
    .to_vec();
    let rows = summary
        .paired
        .iter()
        .map(|p| {
            vec![
                format!("{} vs {}", p.a, p.b),
                p.common_tasks.to_string(),
                p.only_a.to_string(),
                p.only_b.to_string(),
                num(p.z, 1),
                p.p_value.map_or(NONE.to_string(), p_text),
            ]
        })
        .collect();
    Table { header, rows }
}

/// A p-value to two decimals, four below 0.01, and tiny ones as a bound.
fn p_text(p: f64) -> String {
    if p < 1e-4 {
        "< 0.0001".to_string()
    } else if p < 0.01 {
        format!("{p:.4}")
    } else {
        format!("{p:.2}")
    }
}

pub(super) const PAIRED_NOTE: &str = "Each pair of systems on the tasks both ran (same task, \
world and start/goal pair): the tasks exactly one of them reached. If the two were equally \
good each such task would be a coin flip; p is the two-sided exact sign (McNemar) test, z = \
(first − second) / √(first + second), |z| > 2 being unlikely by chance.";

pub(super) const VARIANCE_NOTE: &str = "Cells: mean (population variance). Traversal time over \
successful trials only; roll and pitch: each trial's mean absolute angle, then mean and \
variance across all trials of the group.";
