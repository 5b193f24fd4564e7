//! The top view of a world and what can be drawn over it.

use crate::RenderError;
use crate::draw::{self, Anchor, disc, fill_sdf, polyline, rect, ring, text, text_size};
use crate::palette::{self, class_color};
use image::{Rgb, RgbImage};
use std::path::Path;
use verti_world::obstacle::polygon_signed_distance;
use verti_world::surface::{CELLS_PER_PATCH, PATCHES_PER_SIDE};
use verti_world::{ObstacleShape, Surface, TerrainClass, World};

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

/// How to draw a trajectory over a world render.
#[derive(Clone, Debug, PartialEq)]
pub struct TrajectoryStyle {
    /// Line width in pixels; `None` = from the render's pixels per cell.
    pub width_px: Option<f64>,
    /// Value range of the colour map; `None` = the finite min..max of the values.
    pub range: Option<(f64, f64)>,
    /// Where the run failed (world x, y): marked with a white disc and a black cross.
    pub failure: Option<[f64; 2]>,
    /// Adds a colour bar with this title (e.g. "speed (m/s)") to the legend.
    pub colorbar: Option<String>,
}

impl Default for TrajectoryStyle {
    fn default() -> Self {
        TrajectoryStyle {
            width_px: None,
            range: None,
            failure: None,
            colorbar: Some("speed (m/s)".into()),
        }
    }
}

/// Draws a trajectory (world x, y per point) coloured by a value per point, usually speed, on
/// a world render. The line has a dark casing so it reads on every terrain colour.
pub fn draw_trajectory(
    img: &mut WorldImage,
    points: &[[f64; 2]],
    values: &[f64],
    style: &TrajectoryStyle,
) -> Result<(), RenderError> {
    if points.len() != values.len() {
        return Err(RenderError::Input(format!(
            "{} trajectory points but {} values",
            points.len(),
            values.len()
        )));
    }
    let (lo, hi) = match style.range {
        Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo <= hi => (lo, hi),
        Some((lo, hi)) => {
            return Err(RenderError::Options(format!(
                "colour range [{lo}, {hi}] is not a finite, ordered pair"
            )));
        }
        None => {
            let finite = values.iter().copied().filter(|v| v.is_finite());
            let lo = finite.clone().fold(f64::INFINITY, f64::min);
            let hi = finite.fold(f64::NEG_INFINITY, f64::max);
            if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) }
        }
    };
    if let Some(w) = style.width_px
        && !(w.is_finite() && w > 0.0 && w <= 100.0)
    {
        return Err(RenderError::Options(format!(
            "trajectory width {w} px must be in (0, 100]"
        )));
    }
    let t = |v: f64| if hi > lo { (v - lo) / (hi - lo) } else { 0.5 };
    let width = style
        .width_px
        .unwrap_or_else(|| (0.6 * img.unit()).max(2.0));
    let colors: Vec<Rgb<u8>> = values
        .windows(2)
        .map(|w| palette::speed_color(t(0.5 * (w[0] + w[1]))))
        .collect();
    let colors = if colors.is_empty() {
        values.iter().map(|&v| palette::speed_color(t(v))).collect()
    } else {
        colors
    };
    img.draw_polyline(points, &[palette::INK], width + 2.0);
    img.draw_polyline(points, &colors, width);
    if let Some([x, y]) = style.failure {
        let (px, py) = img.map.to_pixel(x, y);
        let r = (1.8 * img.unit()).max(6.0);
        disc(&mut img.image, px, py, r, palette::WHITE);
        ring(&mut img.image, px, py, r, 1.5, palette::INK);
        let a = 0.55 * r;
        polyline(
            &mut img.image,
            &[(px - a, py - a), (px + a, py + a)],
            &[palette::INK],
            2.2,
        );
        polyline(
            &mut img.image,
            &[(px - a, py + a), (px + a, py - a)],
            &[palette::INK],
            2.2,
        );
    }
    if let (Some(title), Some((x, y))) = (&style.colorbar, img.legend_next) {
        let (bar_w, bar_h) = (150.0, 10.0);
        img.grow_to((y + 66.0).ceil() as u32);
        text(
            &mut img.image,
            title,
            x,
            y + 8.0,
            LEGEND_FONT,
            palette::INK,
            Anchor::LEFT,
        )?;
        let top = y + 20.0;
        for i in 0..bar_w as usize {
            let c = palette::speed_color(i as f64 / (bar_w - 1.0));
            rect(
                &mut img.image,
                x + i as f64,
                top,
                x + i as f64 + 1.0,
                top + bar_h,
                c,
                1.0,
            );
        }
        text(
            &mut img.image,
            &format!("{lo:.2}"),
            x,
            top + bar_h + 9.0,
            SMALL_FONT,
            palette::INK,
            Anchor::LEFT,
        )?;
        text(
            &mut img.image,
            &format!("{hi:.2}"),
            x + bar_w,
            top + bar_h + 9.0,
            SMALL_FONT,
            palette::INK,
            Anchor(HPos::Right, VPos::Center),
        )?;
        if style.failure.is_some() {
            let fy = top + bar_h + 28.0;
            img.grow_to((fy + 14.0).ceil() as u32);
            disc(&mut img.image, x + 8.0, fy, 6.0, palette::WHITE);
            ring(&mut img.image, x + 8.0, fy, 6.0, 1.5, palette::INK);
            polyline(
                &mut img.image,
                &[(x + 5.0, fy - 3.0), (x + 11.0, fy + 3.0)],
                &[palette::INK],
                1.8,
            );
            polyline(
                &mut img.image,
                &[(x + 5.0, fy + 3.0), (x + 11.0, fy - 3.0)],
                &[palette::INK],
                1.8,
            );
            text(
                &mut img.image,
                "failure",
                x + 22.0,
                fy,
                LEGEND_FONT,
                palette::INK,
                Anchor::LEFT,
            )?;
            img.legend_next = Some((x, fy + 16.0));
        } else {
            img.legend_next = Some((x, top + bar_h + 24.0));
        }
    }
    Ok(())
}

use plotters::style::text_anchor::{HPos, VPos};

const MARGIN: f64 = 10.0;
const TITLE_HEIGHT: f64 = 30.0;
const LEGEND_GAP: f64 = 16.0;
const LEGEND_WIDTH: f64 = 180.0;
const LEGEND_LINE: f64 = 19.0;
const TITLE_FONT: f64 = 15.0;
const LEGEND_FONT: f64 = 13.0;
const SMALL_FONT: f64 = 11.0;
/// Sun elevation of the hillshade; the sun is in the north-west.
const SUN_ELEVATION_DEG: f64 = 40.0;
/// The hillshade exaggerates heights so the 90th-percentile slope reads like this gradient
/// (about 35 degrees); low-relief worlds would otherwise look flat.
const TARGET_GRADIENT: f64 = 0.7;

fn check_options(world: &World, o: &RenderOptions) -> Result<(), RenderError> {
    if o.pixels_per_cell == 0 || o.pixels_per_cell > MAX_PIXELS_PER_CELL {
        return Err(RenderError::Options(format!(
            "pixels per cell must be 1..={MAX_PIXELS_PER_CELL}, got {}",
            o.pixels_per_cell
        )));
    }
    if let Some(pairs) = &o.pairs {
        for p in pairs {
            if !world.tasks.iter().any(|t| t.pair == *p) {
                let have: Vec<String> = world.tasks.iter().map(|t| t.pair.to_string()).collect();
                return Err(RenderError::Options(format!(
                    "world {} has no pair {p} (pairs: {})",
                    world.meta.name,
                    if have.is_empty() {
                        "none".to_string()
                    } else {
                        have.join(", ")
                    }
                )));
            }
        }
    }
    Ok(())
}

/// Per-vertex hillshade brightness factor (about 1 on flat ground) and height in 0..1 of the
/// world's range.
fn shade_and_height(world: &World) -> (Vec<f64>, Vec<f64>, f64) {
    let hf = &world.terrain;
    let n = hf.size();
    let cell = hf.cell();
    let h = hf.heights();
    let at = |r: usize, c: usize| h[r * n + c];
    let mut grads = Vec::with_capacity(n * n);
    for r in 0..n {
        for c in 0..n {
            // Central differences, one-sided at the border.
            let (c0, c1) = (c.saturating_sub(1), (c + 1).min(n - 1));
            let (r0, r1) = (r.saturating_sub(1), (r + 1).min(n - 1));
            let gx = (at(r, c1) - at(r, c0)) / ((c1 - c0) as f64 * cell);
            // Row 0 is north: +y is towards smaller rows.
            let gy = (at(r0, c) - at(r1, c)) / ((r1 - r0) as f64 * cell);
            grads.push((gx, gy));
        }
    }
    let mut mags: Vec<f64> = grads
        .iter()
        .map(|g| g.0.hypot(g.1))
        .filter(|m| m.is_finite())
        .collect();
    mags.sort_by(f64::total_cmp);
    let p90 = mags.get(mags.len() * 9 / 10).copied().unwrap_or(0.0);
    let exaggeration = if p90 > 1e-9 {
        (TARGET_GRADIENT / p90).clamp(1.0, 200.0)
    } else {
        1.0
    };
    let (se, ce) = (
        SUN_ELEVATION_DEG.to_radians().sin(),
        SUN_ELEVATION_DEG.to_radians().cos(),
    );
    // Unit vector towards the sun: north-west and up.
    let light = (
        -ce * std::f64::consts::FRAC_1_SQRT_2,
        ce * std::f64::consts::FRAC_1_SQRT_2,
        se,
    );
    let shade = grads
        .iter()
        .map(|&(gx, gy)| {
            let (nx, ny, nz) = (-exaggeration * gx, -exaggeration * gy, 1.0);
            let len = (nx * nx + ny * ny + nz * nz).sqrt();
            let lambert = (nx * light.0 + ny * light.1 + nz * light.2) / len;
            if lambert.is_finite() {
                (1.0 + 1.25 * (lambert - se)).clamp(0.3, 1.4)
            } else {
                1.0
            }
        })
        .collect();
    let (lo, hi) = (hf.min_height(), hf.max_height());
    let relief = hi - lo;
    let height = h
        .iter()
        .map(|&v| {
            if relief > 0.0 && relief.is_finite() {
                ((v - lo) / relief).clamp(0.0, 1.0)
            } else {
                0.5
            }
        })
        .collect();
    (shade, height, exaggeration)
}

/// Bilinear sample of a per-vertex grid at continuous (col, row), clamped to the grid.
fn bilinear(grid: &[f64], n: usize, gc: f64, gr: f64) -> f64 {
    let m = (n - 1) as f64;
    let (gc, gr) = (gc.clamp(0.0, m), gr.clamp(0.0, m));
    let (c0, r0) = (
        (gc.floor() as usize).min(n - 2),
        (gr.floor() as usize).min(n - 2),
    );
    let (u, v) = (gc - c0 as f64, gr - r0 as f64);
    let g = |r: usize, c: usize| grid[r * n + c];
    (1.0 - v) * ((1.0 - u) * g(r0, c0) + u * g(r0, c0 + 1))
        + v * ((1.0 - u) * g(r0 + 1, c0) + u * g(r0 + 1, c0 + 1))
}

/// Legend rows: (swatch, label).
enum Swatch {
    Fill(Rgb<u8>),
    Tree,
    Start,
    Goal,
    Path,
}

fn legend_rows(
    world: &World,
    o: &RenderOptions,
    tasks_drawn: bool,
    paths_drawn: bool,
) -> Vec<(Option<Swatch>, String)> {
    let mut rows: Vec<(Option<Swatch>, String)> = Vec::new();
    if o.show_semantics {
        rows.push((None, "terrain".into()));
        for class in TerrainClass::ALL {
            let patches: Vec<&verti_world::Patch> = world
                .patches
                .patches()
                .iter()
                .filter(|p| p.class == class)
                .collect();
            if patches.is_empty() {
                continue;
            }
            let frictions: Vec<f64> = patches
                .iter()
                .filter_map(|p| match p.surface {
                    Surface::Rigid { friction, .. } => Some(friction),
                    Surface::Deformable { .. } => None,
                })
                .collect();
            let label = if class.is_deformable() {
                let kind = match class {
                    TerrainClass::Snow => "soft",
                    TerrainClass::Mud => "mid",
                    _ => "hard",
                };
                format!("{class}  ({kind} soil)")
            } else if frictions.is_empty() {
                class.to_string()
            } else {
                format!(
                    "{class}  (μ {:.2})",
                    frictions.iter().sum::<f64>() / frictions.len() as f64
                )
            };
            rows.push((Some(Swatch::Fill(class_color(class))), label));
        }
    }
    let rocks = world.obstacles.iter().filter(|o| o.is_rock()).count();
    let trees = world.obstacles.len() - rocks;
    if o.show_obstacles && !world.obstacles.is_empty() {
        rows.push((None, "obstacles".into()));
        if rocks > 0 {
            rows.push((Some(Swatch::Fill(palette::ROCK)), format!("rock  ×{rocks}")));
        }
        if trees > 0 {
            rows.push((Some(Swatch::Tree), format!("tree  ×{trees}")));
        }
    }
    if tasks_drawn || paths_drawn {
        rows.push((None, "tasks".into()));
    }
    if tasks_drawn {
        rows.push((Some(Swatch::Start), "start (pair no.)".into()));
        rows.push((Some(Swatch::Goal), "goal (pair no.)".into()));
    }
    if paths_drawn {
        rows.push((Some(Swatch::Path), "global path".into()));
    }
    rows
}

/// A round length for a scale bar of about `target` metres.
fn nice_length(target: f64) -> f64 {
    if !(target.is_finite() && target > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(target.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|k| k * p)
        .rfind(|&l| l <= target)
        .unwrap_or(p)
}

fn metres_label(m: f64) -> String {
    if m >= 1.0 {
        format!("{m:.0} m")
    } else {
        format!("{:.0} cm", m * 100.0)
    }
}

/// Renders the top view of a world. Fails only on invalid options.
pub fn render_world(world: &World, options: &RenderOptions) -> Result<WorldImage, RenderError> {
    check_options(world, options)?;
    let o = options;
    let hf = &world.terrain;
    let n = hf.size();
    let ppc = f64::from(o.pixels_per_cell);
    let map_px = (n - 1) as f64 * ppc;
    let top = MARGIN + if o.show_title { TITLE_HEIGHT } else { 0.0 };
    let map = MapTransform {
        origin: (MARGIN, top),
        pixels_per_metre: ppc / hf.cell(),
        half_extent: hf.half_extent(),
    };

    let selected = |pair: u32| o.pairs.as_ref().is_none_or(|p| p.contains(&pair));
    let tasks_drawn = o.show_tasks && world.tasks.iter().any(|t| selected(t.pair));
    let paths_drawn = o.show_paths
        && world
            .tasks
            .iter()
            .zip(&world.paths)
            .any(|(t, p)| selected(t.pair) && !p.points.is_empty());
    let rows = if o.show_legend {
        legend_rows(world, o, tasks_drawn, paths_drawn)
    } else {
        Vec::new()
    };
    // rows + scale bar + note
    let legend_h = if o.show_legend {
        (rows.len() as f64 + 3.5) * LEGEND_LINE
    } else {
        0.0
    };
    let legend_x = MARGIN + map_px + LEGEND_GAP;
    let width = if o.show_legend {
        legend_x + LEGEND_WIDTH + MARGIN
    } else {
        2.0 * MARGIN + map_px
    };
    let height = top + map_px.max(legend_h) + MARGIN;
    let mut img = RgbImage::from_pixel(width.ceil() as u32, height.ceil() as u32, palette::PAPER);

    // Terrain: class colour x hillshade x a gentle elevation tint (higher = lighter).
    let (shade, height01, exaggeration) = shade_and_height(world);
    let grey = Rgb([0xC8, 0xC8, 0xC4]);
    let size = map_px as u32;
    for j in 0..size {
        for i in 0..size {
            let (px, py) = (
                map.origin.0 + f64::from(i) + 0.5,
                map.origin.1 + f64::from(j) + 0.5,
            );
            let (x, y) = map.to_world(px, py);
            let (gc, gr) = hf.grid_coords(x, y);
            let b = bilinear(&shade, n, gc, gr) * (0.8 + 0.32 * bilinear(&height01, n, gc, gr));
            let base = if o.show_semantics {
                class_color(world.patches.at(x, y).class)
            } else {
                grey
            };
            let c = Rgb(base
                .0
                .map(|v| (f64::from(v) * b).round().clamp(0.0, 255.0) as u8));
            img.put_pixel(map.origin.0 as u32 + i, map.origin.1 as u32 + j, c);
        }
    }

    if o.show_grid {
        let step = CELLS_PER_PATCH as f64 * ppc;
        for k in 1..PATCHES_PER_SIDE {
            let d = k as f64 * step;
            if d >= map_px {
                break;
            }
            let (x0, y0) = map.origin;
            rect(
                &mut img,
                x0 + d - 0.5,
                y0,
                x0 + d + 0.5,
                y0 + map_px,
                palette::INK,
                0.3,
            );
            rect(
                &mut img,
                x0,
                y0 + d - 0.5,
                x0 + map_px,
                y0 + d + 0.5,
                palette::INK,
                0.3,
            );
        }
    }

    if o.show_obstacles {
        let ppm = map.pixels_per_metre;
        for ob in &world.obstacles {
            let p = ob.position();
            let (cx, cy) = map.to_pixel(p.x, p.y);
            let r = ob.radius_xy() * ppm + 2.0;
            match ob.shape() {
                ObstacleShape::Rock { .. } => {
                    let poly = ob.footprint();
                    fill_sdf(
                        &mut img,
                        [cx - r, cx + r, cy - r, cy + r],
                        palette::ROCK,
                        1.0,
                        |px, py| {
                            let (x, y) = map.to_world(px, py);
                            polygon_signed_distance(poly, x, y) * ppm
                        },
                    );
                }
                ObstacleShape::Tree { radius, .. } => {
                    // Trunks are thin (tens of centimetres): draw them at least about one
                    // cell across so they stay visible, with a light rim to tell them from
                    // rocks.
                    let r = (radius * ppm).max(0.9 * ppc).max(3.0);
                    disc(&mut img, cx, cy, r + 1.0, Rgb([0xF0, 0xF0, 0xE8]));
                    disc(&mut img, cx, cy, r, palette::TREE);
                }
            }
        }
    }

    let path_width = (0.5 * ppc).max(1.6);
    if o.show_paths {
        let lines: Vec<Vec<(f64, f64)>> = world
            .tasks
            .iter()
            .zip(&world.paths)
            .filter(|(t, p)| selected(t.pair) && !p.points.is_empty())
            .map(|(_, p)| p.points.iter().map(|q| map.to_pixel(q[0], q[1])).collect())
            .collect();
        // A light casing keeps the red visible on red-brown terrain; all casings go first so
        // none cuts across another path's red line.
        for px in &lines {
            polyline(&mut img, px, &[palette::WHITE], path_width + 1.5);
        }
        for px in &lines {
            polyline(&mut img, px, &[palette::PATH], path_width);
        }
    }

    // Map border.
    let (x0, y0) = map.origin;
    for (a, b) in [
        ((x0, y0), (x0 + map_px, y0)),
        ((x0 + map_px, y0), (x0 + map_px, y0 + map_px)),
        ((x0, y0 + map_px), (x0 + map_px, y0 + map_px)),
        ((x0, y0), (x0, y0 + map_px)),
    ] {
        polyline(&mut img, &[a, b], &[palette::INK], 1.0);
    }

    if o.show_tasks {
        draw_markers(
            &mut img,
            world,
            &map,
            ppc,
            &selected,
            o.pixels_per_cell >= 2,
        )?;
    }

    if o.show_title {
        let m = &world.meta;
        let relief = hf.max_height() - hf.min_height();
        let mut title = format!(
            "{}   ·   {} elevation, {}, {} obstacles   ·   relief {:.*} m",
            m.name,
            m.level,
            m.terrain_type,
            m.density,
            // small-scale worlds have centimetre reliefs
            if relief < 1.0 { 2 } else { 1 },
            relief
        );
        if (m.scale - 1.0).abs() > 1e-9 {
            title.push_str(&format!(
                "   ·   scale {}",
                verti_world::scale::scale_label(m.scale)
            ));
        }
        let avail = width - 2.0 * MARGIN;
        let mut fs = TITLE_FONT;
        while fs > 7.0 && f64::from(text_size(&title, fs)?.0) > avail {
            fs -= 1.0;
        }
        text(
            &mut img,
            &title,
            MARGIN,
            MARGIN + 0.5 * TITLE_HEIGHT - 2.0,
            fs,
            palette::INK,
            Anchor::LEFT,
        )?;
    }

    let mut legend_next = None;
    if o.show_legend {
        let mut y = top + 0.5 * LEGEND_LINE;
        for (swatch, label) in &rows {
            let x = legend_x;
            match swatch {
                None => {
                    text(
                        &mut img,
                        label,
                        x,
                        y,
                        LEGEND_FONT + 0.5,
                        palette::INK,
                        Anchor::LEFT,
                    )?;
                    rect(
                        &mut img,
                        x,
                        y + 8.0,
                        x + LEGEND_WIDTH - 10.0,
                        y + 9.0,
                        palette::INK,
                        0.25,
                    );
                }
                Some(s) => {
                    let (sx, sy) = (x + 9.0, y);
                    match s {
                        Swatch::Fill(c) => {
                            rect(&mut img, sx - 7.0, sy - 6.0, sx + 7.0, sy + 6.0, *c, 1.0);
                            rect(
                                &mut img,
                                sx - 7.5,
                                sy - 6.5,
                                sx + 7.5,
                                sy - 5.5,
                                palette::INK,
                                0.35,
                            );
                            rect(
                                &mut img,
                                sx - 7.5,
                                sy + 5.5,
                                sx + 7.5,
                                sy + 6.5,
                                palette::INK,
                                0.35,
                            );
                            rect(
                                &mut img,
                                sx - 7.5,
                                sy - 6.5,
                                sx - 6.5,
                                sy + 6.5,
                                palette::INK,
                                0.35,
                            );
                            rect(
                                &mut img,
                                sx + 6.5,
                                sy - 6.5,
                                sx + 7.5,
                                sy + 6.5,
                                palette::INK,
                                0.35,
                            );
                        }
                        Swatch::Tree => {
                            disc(&mut img, sx, sy, 6.0, Rgb([0xF0, 0xF0, 0xE8]));
                            disc(&mut img, sx, sy, 5.0, palette::TREE);
                        }
                        Swatch::Start => {
                            disc(&mut img, sx, sy, 5.0, palette::START);
                            ring(&mut img, sx, sy, 5.0, 1.2, palette::WHITE);
                        }
                        Swatch::Goal => ring(&mut img, sx, sy, 6.0, 2.2, palette::GOAL),
                        Swatch::Path => {
                            polyline(
                                &mut img,
                                &[(sx - 8.0, sy), (sx + 8.0, sy)],
                                &[palette::WHITE],
                                path_width + 1.5,
                            );
                            polyline(
                                &mut img,
                                &[(sx - 8.0, sy), (sx + 8.0, sy)],
                                &[palette::PATH],
                                path_width,
                            );
                        }
                    }
                    text(
                        &mut img,
                        label,
                        x + 24.0,
                        y,
                        LEGEND_FONT,
                        palette::INK,
                        Anchor::LEFT,
                    )?;
                }
            }
            y += LEGEND_LINE;
        }
        // Scale bar of a round length, about a sixth of the map.
        y += 0.5 * LEGEND_LINE;
        // At most ~110 px so the bar and its label fit the legend column.
        let len = nice_length((2.0 * hf.half_extent() / 6.0).min(110.0 / map.pixels_per_metre));
        let bar = len * map.pixels_per_metre;
        let x = legend_x;
        rect(&mut img, x, y - 2.0, x + bar, y + 2.0, palette::INK, 1.0);
        rect(&mut img, x, y - 5.0, x + 1.5, y + 5.0, palette::INK, 1.0);
        rect(
            &mut img,
            x + bar - 1.5,
            y - 5.0,
            x + bar,
            y + 5.0,
            palette::INK,
            1.0,
        );
        text(
            &mut img,
            &metres_label(len),
            x + bar + 8.0,
            y,
            LEGEND_FONT,
            palette::INK,
            Anchor::LEFT,
        )?;
        y += LEGEND_LINE;
        let note = format!("north up · shading ×{}", format_exaggeration(exaggeration));
        text(
            &mut img,
            &note,
            x,
            y,
            SMALL_FONT,
            Rgb([0x60, 0x60, 0x60]),
            Anchor::LEFT,
        )?;
        y += LEGEND_LINE;
        legend_next = Some((x, y));
    }

    Ok(WorldImage {
        image: img,
        map,
        pixels_per_cell: o.pixels_per_cell,
        legend_next,
    })
}

fn format_exaggeration(k: f64) -> String {
    if k < 10.0 {
        format!("{k:.1}")
    } else {
        format!("{k:.0}")
    }
}

/// Start discs (green), goal rings (red) and pair numbers. Starts and goals share places on
/// the task circle (goal k is start k+5), so a start's number sits on one side of the
/// start-to-goal line and a goal's on the other.
fn draw_markers(
    img: &mut RgbImage,
    world: &World,
    map: &MapTransform,
    ppc: f64,
    selected: &dyn Fn(u32) -> bool,
    numbers: bool,
) -> Result<(), RenderError> {
    let r = (1.6 * ppc).max(3.0);
    let ring_r = r + (0.6 * ppc).max(2.0);
    let ring_w = (0.55 * ppc).max(1.5);
    let fs = (2.6 * ppc).clamp(9.0, 22.0);
    let tasks: Vec<_> = world.tasks.iter().filter(|t| selected(t.pair)).collect();
    for t in &tasks {
        let (gx, gy) = map.to_pixel(t.goal[0], t.goal[1]);
        ring(img, gx, gy, ring_r, ring_w + 1.5, palette::WHITE);
        ring(img, gx, gy, ring_r, ring_w, palette::GOAL);
    }
    for t in &tasks {
        let (sx, sy) = map.to_pixel(t.start[0], t.start[1]);
        disc(img, sx, sy, r + 1.0, palette::WHITE);
        disc(img, sx, sy, r, palette::START);
    }
    if !numbers {
        // Thumbnails have no room for numbers.
        return Ok(());
    }
    let (x0, y0) = map.origin;
    let s = map.size_px();
    for t in &tasks {
        let (sx, sy) = map.to_pixel(t.start[0], t.start[1]);
        let (gx, gy) = map.to_pixel(t.goal[0], t.goal[1]);
        let (dx, dy) = (gx - sx, gy - sy);
        let len = dx.hypot(dy);
        // Unit vector from start to goal (east when they coincide).
        let (ux, uy) = if len > 1e-9 {
            (dx / len, dy / len)
        } else {
            (1.0, 0.0)
        };
        let turn = 40f64.to_radians();
        let rot = |x: f64, y: f64, a: f64| (x * a.cos() - y * a.sin(), x * a.sin() + y * a.cos());
        let label = t.pair.to_string();
        let (tw, th) = text_size(&label, fs)?;
        let dist = ring_r + ring_w + 0.5 * f64::from(tw.max(th)) + 3.0;
        for (anchor, dir, colour) in [
            ((sx, sy), rot(-ux, -uy, turn), Rgb([0x0E, 0x6E, 0x24])),
            ((gx, gy), rot(ux, uy, -turn), Rgb([0xB0, 0x10, 0x10])),
        ] {
            let hw = 0.5 * f64::from(tw) + 2.5;
            let hh = 0.5 * f64::from(th) + 1.5;
            let lx = (anchor.0 + dir.0 * dist).clamp(x0 + hw + 1.0, x0 + s - hw - 1.0);
            let ly = (anchor.1 + dir.1 * dist).clamp(y0 + hh + 1.0, y0 + s - hh - 1.0);
            rect(
                img,
                lx - hw,
                ly - hh,
                lx + hw,
                ly + hh,
                palette::WHITE,
                0.85,
            );
            text(img, &label, lx, ly, fs, colour, Anchor::CENTER)?;
        }
    }
    Ok(())
}

/// Renders a world and writes it as PNG.
pub fn render_world_png(
    world: &World,
    options: &RenderOptions,
    out: &Path,
) -> Result<(), RenderError> {
    render_world(world, options)?.save_png(out)
}
