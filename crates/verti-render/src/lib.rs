//! # verti-render
//!
//! Pictures of verti worlds and world sets, as PNG files:
//!
//! * [`render_world`]: a top view of one world like the paper's Fig. 2 (top) and Fig. 4 (top):
//!   hill-shaded elevation tinted by terrain class, obstacles, start/goal pairs and global
//!   paths, with a title line and a legend. The result, a [`WorldImage`], keeps its
//!   world-to-pixel mapping ([`MapTransform`]) so more can be drawn on it later, e.g. a driven
//!   trajectory coloured by speed with [`draw_trajectory`].
//! * [`elevation_histograms_png`]: the elevation histograms of a set, one panel per elevation
//!   level (the paper's Fig. 2 bottom).
//! * [`grouped_bars_png`]: grouped bar charts in a grid with one colour per series, like the
//!   paper's Fig. 6 (see [`charts`]).
//! * [`lines`]: line charts of series over a shared axis (e.g. roll over time).
//! * [`comparison_png`]: several runs of one task side by side: their tracks over the map
//!   ([`draw_track`], one colour each) and their roll and pitch over time.
//!
//! Shapes are rasterised here with analytic anti-aliasing (coverage from the signed distance
//! to each shape); text goes through `plotters` with a vendored DejaVu Sans so output does not
//! depend on the fonts of the machine.

pub mod charts;
mod compare;
mod draw;
mod glyphs;
mod histogram;
pub mod lines;
mod map;
pub mod palette;

pub use charts::{Panel, Series, grouped_bars_image, grouped_bars_png};
pub use compare::{ComparePage, RunTrace, comparison_image, comparison_png};
pub use draw::save_png;
pub use histogram::{elevation_histograms_image, elevation_histograms_png};
pub use map::{
    MAX_PIXELS_PER_CELL, MapTransform, RenderOptions, TrajectoryStyle, WorldImage, draw_track,
    draw_trajectory, render_world, render_world_png,
};

use std::path::PathBuf;

/// Everything that can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The options cannot produce a picture (0 pixels per cell, a pair the world lacks, ...).
    #[error("invalid render options: {0}")]
    Options(String),
    /// The data to draw is inconsistent (e.g. a speed per trajectory point is missing).
    #[error("invalid input: {0}")]
    Input(String),
    /// The output path is not one verti writes to (another extension, a missing directory).
    #[error("cannot write {}: {problem}", path.display())]
    Output { path: PathBuf, problem: String },
    /// Writing the PNG failed.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: image::ImageError,
    },
    /// The text/chart library failed (should not happen with the vendored font).
    #[error("drawing failed: {0}")]
    Draw(String),
}
