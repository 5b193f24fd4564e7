//! Statistics of world sets, for `verti world stats`: what a set is made of (elevation levels,
//! terrain types, obstacle densities), how its elevation is distributed per level (the paper's
//! Fig. 2 bottom), its semantic classes and friction samples (Fig. 3), its obstacles and the
//! spacing rules they obey (§III-D), and its global paths.
//!
//! Everything is plain data with stable snake_case field names so the JSON output can be
//! compared across versions; [`fmt::Display`](std::fmt::Display) gives the compact text report.
//!
//! ## Layout
//!
//! This file holds the set-level type [`SetStats`], the shared [`Summary`] and [`set_stats`],
//! which calls one file per statistic group; each group's types live with the code that fills
//! them:
//!
//! * `composition`: world counts per level, terrain type and density.
//! * `elevation`: per-level height histograms and shape figures.
//! * `classes`: semantic classes and their friction samples.
//! * `obstacles`: obstacle counts and spacing.
//! * `paths`: global path figures.
//! * `display`: the text report.
//! * `tests`: tests of the whole computation (they check every group on the same worlds).

mod classes;
mod composition;
mod display;
mod elevation;
mod obstacles;
mod paths;
#[cfg(test)]
mod tests;

pub use classes::ClassStats;
pub use composition::{Composition, LevelTypeRow, NamedCount};
pub use elevation::LevelElevation;
pub use obstacles::{MinDistance, ObstacleStats};
pub use paths::PathStats;

use crate::world::{ElevationLevel, MAX_RELIEF_FULL_SCALE, World};
use classes::class_stats;
use composition::composition;
use elevation::level_elevation;
use obstacles::obstacle_stats;
use paths::path_stats;
use serde::Serialize;

/// Histogram bin width at full scale, metres (multiplied by the set's scale).
pub const HISTOGRAM_BIN_WIDTH: f64 = 0.1;
/// Histogram range at full scale, metres: the highest level's ceiling.
pub const HISTOGRAM_RANGE: f64 = MAX_RELIEF_FULL_SCALE;

/// Statistics of a whole set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetStats {
    pub worlds: usize,
    pub tasks: usize,
    /// Length scale of the set (the largest world scale when worlds disagree, so the
    /// histograms cover every world).
    pub scale: f64,
    /// True when not every world has the same scale.
    pub mixed_scales: bool,
    pub composition: Composition,
    /// One entry per elevation level, in the order low, mid, high (levels without worlds
    /// included, with zero counts).
    pub elevation: Vec<LevelElevation>,
    /// One entry per terrain class, in Verti-Bench label order (classes never used included).
    pub classes: Vec<ClassStats>,
    pub obstacles: ObstacleStats,
    pub paths: PathStats,
}

/// count / mean / population standard deviation / min / max of a sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub count: usize,
    pub mean: f64,
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

impl Summary {
    /// Summarises the finite values; `None` when there are none.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Summary> {
        let mut count = 0usize;
        let (mut sum, mut min, mut max) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
        let mut kept = Vec::new();
        for v in values.into_iter().filter(|v| v.is_finite()) {
            count += 1;
            sum += v;
            min = min.min(v);
            max = max.max(v);
            kept.push(v);
        }
        if count == 0 {
            return None;
        }
        let mean = sum / count as f64;
        // Two passes: the variance of friction samples (~0.6 ± 0.1) would lose digits with the
        // one-pass sum-of-squares formula.
        let var = kept.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / count as f64;
        Some(Summary {
            count,
            mean,
            std: var.sqrt(),
            min,
            max,
        })
    }
}

/// Computes the statistics of a set of worlds (any number, including none).
pub fn set_stats(worlds: &[World]) -> SetStats {
    let scales: Vec<f64> = worlds
        .iter()
        .map(|w| w.meta.scale)
        .filter(|s| s.is_finite() && *s > 0.0)
        .collect();
    let scale = scales.iter().copied().fold(f64::NAN, f64::max);
    let scale = if scale.is_finite() { scale } else { 1.0 };
    let mixed_scales = scales.iter().any(|s| (s - scale).abs() > 1e-12 * scale);
    SetStats {
        worlds: worlds.len(),
        tasks: worlds.iter().map(|w| w.tasks.len()).sum(),
        scale,
        mixed_scales,
        composition: composition(worlds),
        elevation: ElevationLevel::ALL
            .iter()
            .map(|&l| level_elevation(worlds, l, scale))
            .collect(),
        classes: class_stats(worlds),
        obstacles: obstacle_stats(worlds),
        paths: path_stats(worlds),
    }
}
