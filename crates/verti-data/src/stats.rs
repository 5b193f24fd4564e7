//! Summary of a dataset: hours, trials, outcomes and the distributions of speed, roll and pitch.

use crate::reader::Dataset;
use std::collections::BTreeMap;

/// A fixed-bin histogram of one quantity.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    pub name: String,
    pub unit: String,
    /// Bin edges (counts.len() + 1); values outside are counted in the end bins.
    pub edges: Vec<f64>,
    pub counts: Vec<usize>,
    pub mean: f64,
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

impl Histogram {
    /// Histogram of `values` (non-finite ones skipped) over [lo, hi] in `bins` bins.
    pub fn new(
        name: &str,
        unit: &str,
        values: impl Iterator<Item = f64>,
        lo: f64,
        hi: f64,
        bins: usize,
    ) -> Histogram {
        let width = (hi - lo) / bins as f64;
        let mut counts = vec![0usize; bins];
        let (mut n, mut sum, mut sq) = (0usize, 0.0, 0.0);
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite()) {
            let b = (((v - lo) / width).floor().max(0.0) as usize).min(bins - 1);
            counts[b] += 1;
            n += 1;
            sum += v;
            sq += v * v;
            min = min.min(v);
            max = max.max(v);
        }
        let mean = if n > 0 { sum / n as f64 } else { f64::NAN };
        let std = if n > 0 {
            (sq / n as f64 - mean * mean).max(0.0).sqrt()
        } else {
            f64::NAN
        };
        Histogram {
            name: name.into(),
            unit: unit.into(),
            edges: (0..=bins).map(|k| lo + k as f64 * width).collect(),
            counts,
            mean,
            std,
            min,
            max,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Stats {
    pub kind: String,
    pub source: String,
    pub hours: f64,
    pub trials: usize,
    pub rows: usize,
    pub outcomes: BTreeMap<String, usize>,
    /// Mean trial duration, s.
    pub mean_trial_seconds: f64,
    /// Forward speed (m/s), |roll| and |pitch| (degrees), over every row.
    pub histograms: Vec<Histogram>,
}

pub fn stats(data: &Dataset) -> Stats {
    let t = &data.table;
    let col = |n: &str| t.f64(n).unwrap_or(&[]);
    let mut outcomes = BTreeMap::new();
    let mut seconds = 0.0;
    for trial in data.trials() {
        *outcomes
            .entry(trial.outcome.name().to_string())
            .or_insert(0) += 1;
        seconds += trial.duration();
    }
    let deg = |n: &'static str| col(n).iter().map(|r| r.to_degrees().abs());
    let histograms = vec![
        Histogram::new(
            "forward speed",
            "m/s",
            col("forward_speed").iter().copied(),
            -1.0,
            5.0,
            24,
        ),
        Histogram::new("|roll|", "deg", deg("roll"), 0.0, 60.0, 24),
        Histogram::new("|pitch|", "deg", deg("pitch"), 0.0, 60.0, 24),
    ];
    let trials = data.trial_count();
    Stats {
        kind: data.manifest.kind.name().to_string(),
        source: data.manifest.source.clone(),
        hours: seconds / 3600.0,
        trials,
        rows: t.rows(),
        outcomes,
        mean_trial_seconds: if trials > 0 {
            seconds / trials as f64
        } else {
            0.0
        },
        histograms,
    }
}
