//! Chart data: the Fig. 6 numbers as plain bar-chart panels ([`fig6_charts`]) that map one to
//! one onto `verti_render::charts::Panel`.

use super::{Breakdown, GroupStats, Summary};
use serde::{Deserialize, Serialize};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures::sample;
    use crate::report::summarize;

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
}
