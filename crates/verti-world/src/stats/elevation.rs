//! Elevation per level: a histogram of every vertex height (the paper's Fig. 2 bottom) plus
//! per-world relief and spread.

use super::{HISTOGRAM_BIN_WIDTH, HISTOGRAM_RANGE, Summary};
use crate::world::{ElevationLevel, World};
use serde::Serialize;

/// Elevation of the worlds of one level: a histogram of every vertex height plus per-world
/// shape figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelElevation {
    pub level: String,
    pub worlds: usize,
    /// The level's ceiling at the set's scale, metres (4.8 / 9.6 / 16 m at full scale).
    pub ceiling: f64,
    /// Left edge of bin 0, metres (always 0).
    pub bin_start: f64,
    /// Bin width, metres (0.1 m times the scale).
    pub bin_width: f64,
    /// Vertex counts per bin; bins cover [0, 16 m · scale).
    pub counts: Vec<u64>,
    /// `counts` divided by the number of vertices of the level (sums to 1 minus the
    /// out-of-range share; all zero without worlds).
    pub frequency: Vec<f64>,
    /// Vertices below 0 m or at/above the histogram's top edge.
    pub below_range: u64,
    pub above_range: u64,
    /// Mean and standard deviation of all vertex heights of the level, metres.
    pub mean: Option<f64>,
    pub std: Option<f64>,
    /// Per-world relief (max - min height), metres.
    pub relief: Option<Summary>,
    /// Per-world standard deviation of height, metres.
    pub world_std: Option<Summary>,
    /// Mean over worlds of the terrain-shape figures (worlds with at least 9 vertices per
    /// side; `None` without such worlds).
    pub shape: Option<LevelShape>,
}

/// Terrain-shape figures of one level, each the mean over its worlds: what the README's
/// fidelity table compares between elevation sources and the Verti-Bench worlds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LevelShape {
    /// 95th percentile of the vertex slope, degrees (central differences).
    pub slope_p95_deg: f64,
    /// Autocorrelation of heights along rows at lags of 1 and 2 vertices.
    pub autocorr_lag1: f64,
    pub autocorr_lag2: f64,
    pub skewness: f64,
    pub kurtosis: f64,
    /// Mean and standard deviation of heights as fractions of the level's ceiling.
    pub mean_fraction: f64,
    pub std_fraction: f64,
}

/// 95th percentile of the slope (degrees) over the interior vertices of a heightfield.
fn slope_p95(w: &World) -> f64 {
    let t = &w.terrain;
    let (n, cell) = (t.size(), t.cell());
    let mut slopes = Vec::with_capacity(n * n);
    for r in 1..n - 1 {
        for c in 1..n - 1 {
            let gx = (t.vertex(r, c + 1) - t.vertex(r, c - 1)) / (2.0 * cell);
            let gy = (t.vertex(r + 1, c) - t.vertex(r - 1, c)) / (2.0 * cell);
            slopes.push((gx * gx + gy * gy).sqrt().atan().to_degrees());
        }
    }
    slopes.sort_by(f64::total_cmp);
    slopes[((slopes.len() as f64 * 0.95) as usize).min(slopes.len() - 1)]
}

fn level_shape(worlds: &[&World]) -> Option<LevelShape> {
    let usable: Vec<&&World> = worlds.iter().filter(|w| w.terrain.size() >= 9).collect();
    if usable.is_empty() {
        return None;
    }
    let k = usable.len() as f64;
    let mut acc = LevelShape::default();
    for w in usable {
        let n = w.terrain.size();
        let ceiling = w.meta.max_height;
        let fractions: Vec<f64> = w.terrain.heights().iter().map(|h| h / ceiling).collect();
        let st = crate::generate::elevation::shape_stats(&fractions, n);
        acc.slope_p95_deg += slope_p95(w) / k;
        acc.autocorr_lag1 += st.autocorrelation[0] / k;
        acc.autocorr_lag2 += st.autocorrelation[1] / k;
        acc.skewness += st.skewness / k;
        acc.kurtosis += st.kurtosis / k;
        acc.mean_fraction += st.mean / k;
        acc.std_fraction += st.std / k;
    }
    Some(acc)
}

pub(super) fn level_elevation(
    worlds: &[World],
    level: ElevationLevel,
    scale: f64,
) -> LevelElevation {
    let bin_width = HISTOGRAM_BIN_WIDTH * scale;
    let bins = (HISTOGRAM_RANGE / HISTOGRAM_BIN_WIDTH).round() as usize;
    let top = bins as f64 * bin_width;
    let mut counts = vec![0u64; bins];
    let (mut below, mut above) = (0u64, 0u64);
    let (mut n, mut sum, mut sum_sq) = (0u64, 0.0f64, 0.0f64);
    let mut reliefs = Vec::new();
    let mut stds = Vec::new();
    let mine: Vec<&World> = worlds.iter().filter(|w| w.meta.level == level).collect();
    for w in &mine {
        let h = w.terrain.heights();
        // Not `elevation::shape_stats`: its autocorrelation lags need at least 9 vertices per
        // side, and any valid heightfield (2x2 and up) must work here.
        let len = h.len() as f64;
        let m = h.iter().sum::<f64>() / len;
        reliefs.push(w.terrain.max_height() - w.terrain.min_height());
        stds.push((h.iter().map(|v| (v - m).powi(2)).sum::<f64>() / len).sqrt());
        for &v in h {
            n += 1;
            sum += v;
            sum_sq += v * v;
            if v < 0.0 || !v.is_finite() {
                below += 1;
            } else if v >= top {
                above += 1;
            } else {
                // v < top guarantees the index is below `bins`; min() guards rounding.
                counts[((v / bin_width) as usize).min(bins - 1)] += 1;
            }
        }
    }
    let frequency = counts
        .iter()
        .map(|&c| if n > 0 { c as f64 / n as f64 } else { 0.0 })
        .collect();
    let mean = (n > 0).then(|| sum / n as f64);
    // Heights are at most tens of metres, so the one-pass variance keeps plenty of digits.
    let std = mean.map(|m| (sum_sq / n as f64 - m * m).max(0.0).sqrt());
    LevelElevation {
        level: level.name().to_string(),
        worlds: mine.len(),
        ceiling: level.max_height() * scale,
        bin_start: 0.0,
        bin_width,
        counts,
        frequency,
        below_range: below,
        above_range: above,
        mean,
        std,
        relief: Summary::of(reliefs),
        world_std: Summary::of(stds),
        shape: level_shape(&mine),
    }
}
