//! The top view of a world and what can be drawn over it.
//!
//! This file holds the types callers see ([`RenderOptions`], [`MapTransform`], [`WorldImage`])
//! and the page layout constants; the drawing is split by what it draws:
//!
//! * `render`: [`render_world`] and [`render_world_png`], the page: terrain, grid, obstacles,
//!   paths, border, title and legend.
//! * `shading`: hillshade and elevation tint of the terrain.
//! * `legend`: which legend rows a world gets, and the scale-bar length and labels.
//! * `markers`: start/goal markers and their pair numbers.
//! * `trajectory`: [`draw_trajectory`], a speed-coloured run drawn over a finished render.
//! * `overlay`: [`draw_track`], a run in one colour with a legend row (several runs per map).

mod legend;
mod markers;
mod overlay;
mod render;
mod shading;
mod trajectory;

pub use overlay::draw_track;
pub use render::{render_world, render_world_png};
pub use trajectory::{TrajectoryStyle, draw_trajectory};

use crate::RenderError;
use crate::draw::{self, polyline};
use crate::palette;
use image::{Rgb, RgbImage};
use std::path::Path;

/// Largest accepted `pixels_per_cell` (a 129-vertex world is then 4096 px wide).
pub const MAX_PIXELS_PER_CELL: u32 = 32;

/// What to draw and how large.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Pixels per heightfield cell (1..=[`MAX_PIXELS_PER_CELL`]); 4 gives a 512 px map for a
    /// 129-vertex world.
    pub pixels_per_cell: u32,
    /// Start/goal pairs (by `Task::pair`) whose markers and paths are drawn; `None` = all.
    pub pairs: Option<Vec<u32>>,
    /// Start (green) and goal (red) markers with pair numbers.
    pub show_tasks: bool,
    /// Global paths (red polylines).
    pub show_paths: bool,
    /// Rocks and trees.
    pub show_obstacles: bool,
    /// Tint the terrain by class; without it the terrain is grey (hillshade only).
    pub show_semantics: bool,
    /// Thin lines along the 16x16 semantic patch grid.
    pub show_grid: bool,
    pub show_legend: bool,
    pub show_title: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            pixels_per_cell: 4,
            pairs: None,
            show_tasks: true,
            show_paths: true,
            show_obstacles: true,
            show_semantics: true,
            show_grid: false,
            show_legend: true,
            show_title: true,
        }
    }
}

/// Maps world (x, y) in metres to image pixels and back. Pixel (i, j) covers
/// [i, i+1) x [j, j+1); north is up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapTransform {
    /// Image position of the map's north-west corner, world (-half_extent, +half_extent).
    pub origin: (f64, f64),
    pub pixels_per_metre: f64,
    /// The map spans [-half_extent, half_extent] metres in x and y.
    pub half_extent: f64,
}

impl MapTransform {
    /// Image position (sub-pixel) of world point (x, y).
    #[inline]
    pub fn to_pixel(&self, x: f64, y: f64) -> (f64, f64) {
        (
            self.origin.0 + (x + self.half_extent) * self.pixels_per_metre,
            self.origin.1 + (self.half_extent - y) * self.pixels_per_metre,
        )
    }
    /// World point at image position (px, py).
    #[inline]
    pub fn to_world(&self, px: f64, py: f64) -> (f64, f64) {
        (
            (px - self.origin.0) / self.pixels_per_metre - self.half_extent,
            self.half_extent - (py - self.origin.1) / self.pixels_per_metre,
        )
    }
    /// Side of the map in pixels.
    pub fn size_px(&self) -> f64 {
        2.0 * self.half_extent * self.pixels_per_metre
    }
    /// Pixel of world point (x, y), when it lies on the map.
    pub fn pixel_of(&self, x: f64, y: f64) -> Option<(u32, u32)> {
        let (px, py) = self.to_pixel(x, y);
        let (x0, y0) = self.origin;
        let s = self.size_px();
        (px >= x0 && py >= y0 && px < x0 + s && py < y0 + s)
            .then(|| (px.floor() as u32, py.floor() as u32))
    }
}

/// A rendered world: the image plus what is needed to draw more on it.
#[derive(Clone, Debug)]
pub struct WorldImage {
    pub image: RgbImage,
    pub map: MapTransform,
    /// Pixels per cell it was rendered with (marker sizes follow it).
    pub pixels_per_cell: u32,
    /// Left edge and first free row of the legend column, for extra legend entries.
    legend_next: Option<(f64, f64)>,
}

impl WorldImage {
    /// Writes the image as PNG.
    pub fn save_png(&self, path: &Path) -> Result<(), RenderError> {
        draw::save_png(&self.image, path)
    }

    /// Draws a polyline of world points with one colour per segment (see [`draw_trajectory`]
    /// for the speed-coloured version).
    pub fn draw_polyline(
        &mut self,
        points: &[[f64; 2]],
        segment_colors: &[Rgb<u8>],
        width_px: f64,
    ) {
        let px: Vec<(f64, f64)> = points
            .iter()
            .map(|p| self.map.to_pixel(p[0], p[1]))
            .collect();
        polyline(&mut self.image, &px, segment_colors, width_px);
    }

    /// Marker size unit in pixels: grows with the resolution but stays legible when small.
    fn unit(&self) -> f64 {
        f64::from(self.pixels_per_cell)
    }

    /// Makes the image at least `height` pixels tall (new rows get the background colour).
    fn grow_to(&mut self, height: u32) {
        if height <= self.image.height() {
            return;
        }
        let mut taller = RgbImage::from_pixel(self.image.width(), height, palette::PAPER);
        image::imageops::replace(&mut taller, &self.image, 0, 0);
        self.image = taller;
    }
}

const MARGIN: f64 = 10.0;
const TITLE_HEIGHT: f64 = 30.0;
const LEGEND_GAP: f64 = 16.0;
const LEGEND_WIDTH: f64 = 180.0;
const LEGEND_LINE: f64 = 19.0;
const TITLE_FONT: f64 = 15.0;
const LEGEND_FONT: f64 = 13.0;
const SMALL_FONT: f64 = 11.0;
