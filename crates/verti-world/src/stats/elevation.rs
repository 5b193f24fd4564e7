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
    }
}
