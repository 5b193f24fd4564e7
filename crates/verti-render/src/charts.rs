//! Grouped bar charts laid out in a grid, like the paper's Fig. 6 (rows: elevation level,
//! terrain type, obstacle density; columns: success rate, traversal time, roll, pitch; one
//! bar colour per system).
//!
//! The data model is generic (groups on the x axis, one bar series per system), so this
//! module knows nothing about the benchmark. Everything is drawn with verti's own raster
//! primitives and glyph layout (see `draw` and `glyphs`), bars snapped to whole pixels so
//! they stay crisp.
//!
//! Missing values (NaN, e.g. a traversal time where a system never succeeded) are drawn as no
//! bar with a small grey "n/a" at the baseline; infinite values and values outside a fixed
//! axis range are clamped to the plot area.

use crate::RenderError;
use crate::draw::{Anchor, blend, ensure_font, polyline, rect, save_png, text, text_size};
use image::{Rgb, RgbImage};
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// One bar series: one system's value per group.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// Legend label; series of the same name share a colour across panels.
    pub name: String,
    /// One value per group (missing entries count as NaN, extra ones are ignored).
    pub values: Vec<f64>,
    /// Whisker half-lengths per group (e.g. standard deviations); NaN or <= 0 draws none.
    pub errors: Option<Vec<f64>>,
}

/// One chart panel: groups along the x axis, each with one bar per series.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Panel {
    pub title: String,
    pub y_label: String,
    /// Fixed top of the value axis (e.g. 100 for percentages); automatic when `None`.
    pub y_max: Option<f64>,
    /// Group names along the x axis (e.g. `low`, `mid`, `high`).
    pub groups: Vec<String>,
    pub series: Vec<Series>,
}

/// Size of one panel in pixels.
pub const PANEL_WIDTH: u32 = 360;
pub const PANEL_HEIGHT: u32 = 270;

// Plot area inside a panel (offsets from the panel's corner).
const PLOT_LEFT: f64 = 64.0;
const PLOT_RIGHT: f64 = 12.0;
const PLOT_TOP: f64 = 36.0;
const PLOT_BOTTOM: f64 = 32.0;
/// Share of a group's slot that its bars fill.
const GROUP_FILL: f64 = 0.82;

const LEGEND_ROW: f64 = 22.0;
const LEGEND_PAD: f64 = 10.0;
const LEGEND_FONT: f64 = 14.0;
const LEGEND_SWATCH: f64 = 12.0;
const LEGEND_GAP: f64 = 22.0;

const BACKGROUND: Rgb<u8> = Rgb([0xFF, 0xFF, 0xFF]);
const INK: Rgb<u8> = Rgb([0x22, 0x22, 0x22]);
const AXIS: Rgb<u8> = Rgb([0x44, 0x44, 0x44]);
const GRID: Rgb<u8> = Rgb([0xE6, 0xE6, 0xE6]);
const MUTED: Rgb<u8> = Rgb([0x66, 0x66, 0x66]);
const WHISKER: Rgb<u8> = Rgb([0x30, 0x30, 0x30]);
// Font sizes, all even whole numbers on purpose: plotters 0.3.7 offsets each glyph
// vertically by `(size / 2 + top of glyph) as i32`, which truncates towards zero, so with an
// odd or fractional size tall letters (l, t, T) sit a pixel lower than short ones.
const TITLE_FONT: f64 = 16.0;
const GROUP_FONT: f64 = 14.0;
const LABEL_FONT: f64 = 12.0;
const TICK_FONT: f64 = 12.0;
const NA_FONT: f64 = 10.0;
const NA: Rgb<u8> = Rgb([0x80, 0x80, 0x80]);

/// Series colours (Tableau 10: distinct, print well, readable for most colour-blind readers
/// in the first few); more series than colours reuse them in order.
pub const SERIES_COLORS: [Rgb<u8>; 10] = [
    Rgb([0x4E, 0x79, 0xA7]),
    Rgb([0xF2, 0x8E, 0x2B]),
    Rgb([0xE1, 0x57, 0x59]),
    Rgb([0x76, 0xB7, 0xB2]),
    Rgb([0x59, 0xA1, 0x4F]),
    Rgb([0xED, 0xC9, 0x48]),
    Rgb([0xB0, 0x7A, 0xA1]),
    Rgb([0xFF, 0x9D, 0xA7]),
    Rgb([0x9C, 0x75, 0x5F]),
    Rgb([0xBA, 0xB0, 0xAC]),
];

/// Colour of the `i`-th distinct series name.
pub fn series_color(i: usize) -> Rgb<u8> {
    SERIES_COLORS[i % SERIES_COLORS.len()]
}

/// Colours of the benchmark's systems, one hue per family so that ten bars side by side stay
/// legible: classical planners blue (pid, eh, mppi), RL greens (rl, mcl, acl), learned-model
/// hybrids oranges (wmvct, mppi6, tal, tnt), the privileged oracle grey. A series named
/// `system` or `system-…`/`system …` (a run label) gets its system's colour.
pub fn system_color(name: &str) -> Option<Rgb<u8>> {
    let system = name.split(['-', ' ', '@']).next()?;
    Some(match system {
        "pid" => Rgb([0x9E, 0xCA, 0xE1]),
        "eh" => Rgb([0x42, 0x92, 0xC6]),
        "mppi" => Rgb([0x08, 0x45, 0x94]),
        "rl" => Rgb([0xA1, 0xD9, 0x9B]),
        "mcl" => Rgb([0x41, 0xAB, 0x5D]),
        "acl" => Rgb([0x00, 0x6D, 0x2C]),
        "wmvct" => Rgb([0xFD, 0xD0, 0xA2]),
        "mppi6" => Rgb([0xFD, 0x8D, 0x3C]),
        "tal" => Rgb([0xD9, 0x48, 0x01]),
        "tnt" => Rgb([0x8C, 0x2D, 0x04]),
        "oracle" => Rgb([0x73, 0x73, 0x73]),
        _ => return None,
    })
}

/// Colour of the `i`-th distinct series name: its system's, else the `i`-th series colour.
/// Variants of one system (`pid`, `pid [perception=high]`, ...) share its hue, each later one
/// a shade darker, so they stay apart side by side.
fn name_color(names: &[&str], i: usize) -> Rgb<u8> {
    let Some(base) = names.get(i).and_then(|n| system_color(n)) else {
        return series_color(i);
    };
    let earlier = names[..i]
        .iter()
        .filter(|n| system_color(n) == Some(base))
        .count();
    let keep = 1.0 - (0.22 * earlier as f64).min(0.66);
    Rgb(base.0.map(|c| (f64::from(c) * keep).round() as u8))
}

/// Distinct series names over all panels, in first-seen order (the legend, and the index of
/// each name's colour).
fn series_names(panels: &[Panel]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for s in panels.iter().flat_map(|p| &p.series) {
        if !names.contains(&s.name.as_str()) {
            names.push(&s.name);
        }
    }
    names
}

/// A placed legend entry: (name index, x of the swatch, row).
type LegendEntry = (usize, f64, usize);

/// Legend entries placed in centred rows, and the number of rows.
fn legend_layout(names: &[&str], width: f64) -> Result<(Vec<LegendEntry>, usize), RenderError> {
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut row: Vec<(usize, f64)> = Vec::new();
    let mut used = 0.0;
    let avail = (width - 2.0 * LEGEND_PAD).max(1.0);
    for (i, n) in names.iter().enumerate() {
        let w = LEGEND_SWATCH + 6.0 + f64::from(text_size(n, LEGEND_FONT)?.0);
        if !row.is_empty() && used + LEGEND_GAP + w > avail {
            rows.push(std::mem::take(&mut row));
            used = 0.0;
        }
        if !row.is_empty() {
            used += LEGEND_GAP;
        }
        row.push((i, used));
        used += w;
    }
    if !row.is_empty() {
        rows.push(row);
    }
    // Centre each row.
    let mut out = Vec::new();
    for (r, entries) in rows.iter().enumerate() {
        let last = entries.last().map_or(0.0, |e| e.1);
        let w_last = entries.last().map_or(Ok(0.0), |e| {
            text_size(names[e.0], LEGEND_FONT).map(|s| LEGEND_SWATCH + 6.0 + f64::from(s.0))
        })?;
        let start = (0.5 * (width - (last + w_last))).max(LEGEND_PAD).round();
        out.extend(entries.iter().map(|&(i, x)| (i, start + x, r)));
    }
    Ok((out, rows.len()))
}

fn legend_height(rows: usize) -> u32 {
    if rows == 0 {
        0
    } else {
        (2.0 * LEGEND_PAD + rows as f64 * LEGEND_ROW).round() as u32
    }
}

/// Axis range and tick step of a panel: [lo, hi] always contains 0, and is rounded out to
/// whole steps of 1, 2, 2.5 or 5 times a power of ten (about five ticks).
fn axis(panel: &Panel) -> (f64, f64, f64) {
    let n = panel.groups.len();
    let mut lo = 0.0f64;
    let mut hi = 0.0f64;
    for s in &panel.series {
        for (g, &v) in s.values.iter().take(n).enumerate() {
            if !v.is_finite() {
                continue;
            }
            let e = s
                .errors
                .as_ref()
                .and_then(|e| e.get(g).copied())
                .filter(|e| e.is_finite() && *e > 0.0)
                .unwrap_or(0.0);
            lo = lo.min(v - e);
            hi = hi.max(v + e);
        }
    }
    if let Some(m) = panel.y_max.filter(|m| m.is_finite() && *m > lo) {
        hi = m;
    }
    if !(hi - lo).is_finite() || hi - lo <= 0.0 {
        hi = lo + 1.0;
    }
    let step = nice_step((hi - lo) / 5.0);
    let fixed = panel.y_max.is_some_and(|m| m == hi);
    let lo = if lo < 0.0 {
        (lo / step).floor() * step
    } else {
        0.0
    };
    // A little headroom so whisker caps at a round value do not touch the top of the plot.
    let hi = if fixed {
        hi
    } else {
        (hi * 1.03 / step).ceil() * step
    };
    (lo, hi, step)
}

/// The smallest of 1, 2, 2.5, 5 (times a power of ten) not below `raw`.
pub(crate) fn nice_step(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let m = [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .find(|m| *m >= norm - 1e-9)
        .unwrap_or(10.0);
    m * mag
}

/// Decimals needed to print multiples of `step` exactly.
pub(crate) fn decimals(step: f64) -> usize {
    (0..=6)
        .find(|&d| {
            let x = step * 10f64.powi(d as i32);
            (x - x.round()).abs() < 1e-6 * x.abs().max(1.0)
        })
        .unwrap_or(6)
}

/// Where a panel's plot and bars go, in image pixels.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlotBox {
    pub x0: f64,
    pub x1: f64,
    pub y0: f64,
    pub y1: f64,
    pub lo: f64,
    pub hi: f64,
}

impl PlotBox {
    /// Pixel row of value `v`, clamped to the plot.
    pub fn y(&self, v: f64) -> f64 {
        let t = ((v - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0);
        self.y1 - t * (self.y1 - self.y0)
    }
}

/// Plot area of panel `k` in a grid of `columns` under a legend of `legend_h` pixels.
pub(crate) fn plot_box(panel: &Panel, k: usize, columns: usize, legend_h: u32) -> PlotBox {
    let (px, py) = panel_origin(k, columns, legend_h);
    let (lo, hi, _) = axis(panel);
    PlotBox {
        x0: px + PLOT_LEFT,
        x1: px + f64::from(PANEL_WIDTH) - PLOT_RIGHT,
        y0: py + PLOT_TOP,
        y1: py + f64::from(PANEL_HEIGHT) - PLOT_BOTTOM,
        lo,
        hi,
    }
}

fn panel_origin(k: usize, columns: usize, legend_h: u32) -> (f64, f64) {
    let columns = columns.max(1);
    (
        ((k % columns) as u32 * PANEL_WIDTH) as f64,
        f64::from(legend_h) + ((k / columns) as f64) * f64::from(PANEL_HEIGHT),
    )
}

/// Horizontal pixel span [x0, x1) of bar `s` of group `g` (whole pixels, so edges are crisp).
pub(crate) fn bar_span(
    b: &PlotBox,
    groups: usize,
    series: usize,
    g: usize,
    s: usize,
) -> (f64, f64) {
    let slot = (b.x1 - b.x0) / groups.max(1) as f64;
    let inner = slot * GROUP_FILL;
    let w = inner / series.max(1) as f64;
    let left = b.x0 + g as f64 * slot + 0.5 * (slot - inner) + s as f64 * w;
    let (a, z) = (left.round(), (left + w).round());
    // A one-pixel gap between neighbouring bars when they are wide enough to afford it.
    let z = if z - a >= 5.0 { z - 1.0 } else { z };
    (a, z.max(a + 1.0))
}

/// Text `s` rotated a quarter turn counter-clockwise (reading upwards), centred on (cx, cy).
fn text_up(
    img: &mut RgbImage,
    s: &str,
    cx: f64,
    cy: f64,
    size: f64,
    c: Rgb<u8>,
) -> Result<(), RenderError> {
    let (w, _) = text_size(s, size)?;
    let (tw, th) = (w + 6, (size * 1.5).ceil() as u32 + 2);
    let mut tmp = RgbImage::from_pixel(tw, th, BACKGROUND);
    text(
        &mut tmp,
        s,
        3.0,
        0.5 * f64::from(th),
        size,
        Rgb([0, 0, 0]),
        Anchor::LEFT,
    )?;
    let x0 = (cx - 0.5 * f64::from(th)).round() as i64;
    let y0 = (cy - 0.5 * f64::from(tw)).round() as i64;
    for (x, y, p) in tmp.enumerate_pixels() {
        // Ink coverage from the black-on-white rendering.
        let a = 1.0 - f64::from(p[0]) / 255.0;
        if a > 0.0 {
            blend(img, x0 + i64::from(y), y0 + i64::from(tw - 1 - x), c, a);
        }
    }
    Ok(())
}

fn draw_panel(
    img: &mut RgbImage,
    panel: &Panel,
    k: usize,
    columns: usize,
    legend_h: u32,
    names: &[&str],
) -> Result<(), RenderError> {
    let (px, py) = panel_origin(k, columns, legend_h);
    let b = plot_box(panel, k, columns, legend_h);
    let (_, _, step) = axis(panel);
    let digits = decimals(step);
    text(
        img,
        &panel.title,
        px + 0.5 * f64::from(PANEL_WIDTH),
        py + 17.0,
        TITLE_FONT,
        INK,
        Anchor::CENTER,
    )?;
    text_up(
        img,
        &panel.y_label,
        px + 16.0,
        0.5 * (b.y0 + b.y1),
        LABEL_FONT,
        INK,
    )?;
    // Grid and tick labels.
    let ticks = ((b.hi - b.lo) / step).round().clamp(0.0, 100.0) as usize;
    for i in 0..=ticks {
        let v = b.lo + i as f64 * step;
        let y = b.y(v).round() + 0.5;
        if v != 0.0 {
            rect(img, b.x0, y - 0.5, b.x1, y + 0.5, GRID, 1.0);
        }
        let label = format!("{:.*}", digits, v + 0.0);
        text(
            img,
            &label,
            b.x0 - 6.0,
            y,
            TICK_FONT,
            MUTED,
            Anchor(HPos::Right, VPos::Center),
        )?;
    }
    let ng = panel.groups.len();
    if ng == 0 || panel.series.is_empty() {
        text(
            img,
            "no data",
            0.5 * (b.x0 + b.x1),
            0.5 * (b.y0 + b.y1),
            TITLE_FONT,
            MUTED,
            Anchor::CENTER,
        )?;
    }
    let ns = panel.series.len();
    let base = b.y(0.0).round();
    for (g, name) in panel.groups.iter().enumerate() {
        let slot = (b.x1 - b.x0) / ng as f64;
        text(
            img,
            name,
            b.x0 + (g as f64 + 0.5) * slot,
            b.y1 + 15.0,
            GROUP_FONT,
            INK,
            Anchor::CENTER,
        )?;
        for (s, series) in panel.series.iter().enumerate() {
            let color = name_color(
                names,
                names.iter().position(|n| *n == series.name).unwrap_or(s),
            );
            let (x0, x1) = bar_span(&b, ng, ns, g, s);
            let v = series.values.get(g).copied().unwrap_or(f64::NAN);
            if v.is_nan() {
                let (tw, _) = text_size("n/a", NA_FONT)?;
                if f64::from(tw) + 2.0 <= x1 - x0 {
                    text(
                        img,
                        "n/a",
                        0.5 * (x0 + x1),
                        base - 8.0,
                        NA_FONT,
                        NA,
                        Anchor::CENTER,
                    )?;
                } else {
                    text_up(
                        img,
                        "n/a",
                        0.5 * (x0 + x1),
                        base - 4.0 - 0.5 * f64::from(tw),
                        NA_FONT,
                        NA,
                    )?;
                }
                continue;
            }
            let top = b.y(v).round();
            rect(img, x0, top.min(base), x1, top.max(base), color, 1.0);
            let e = series
                .errors
                .as_ref()
                .and_then(|e| e.get(g).copied())
                .filter(|e| e.is_finite() && *e > 0.0);
            if let (Some(e), true) = (e, v.is_finite()) {
                // On a pixel centre, so the whisker is one crisp pixel column.
                let cx = (0.5 * (x0 + x1)).floor() + 0.5;
                let (ya, yb) = (b.y(v - e).floor() + 0.5, b.y(v + e).floor() + 0.5);
                let cap = (0.3 * (x1 - x0)).clamp(1.5, 5.0);
                polyline(img, &[(cx, ya), (cx, yb)], &[WHISKER], 1.2);
                polyline(img, &[(cx - cap, ya), (cx + cap, ya)], &[WHISKER], 1.2);
                polyline(img, &[(cx - cap, yb), (cx + cap, yb)], &[WHISKER], 1.2);
            }
        }
    }
    // Axes on top of the bars: the value axis and the zero line.
    rect(img, b.x0 - 1.0, b.y0, b.x0, b.y1 + 0.5, AXIS, 1.0);
    rect(img, b.x0 - 1.0, base, b.x1, base + 1.0, AXIS, 1.0);
    Ok(())
}

/// Draws the panels in a grid of `columns` columns (row by row) under a legend of the series
/// names, one colour per name. An empty list of panels is an error.
pub fn grouped_bars_image(panels: &[Panel], columns: usize) -> Result<RgbImage, RenderError> {
    ensure_font()?;
    if panels.is_empty() {
        return Err(RenderError::Input("no chart panels to draw".into()));
    }
    let columns = columns.clamp(1, panels.len());
    let rows = panels.len().div_ceil(columns);
    let width = columns as u32 * PANEL_WIDTH;
    let names = series_names(panels);
    let (legend, legend_rows) = legend_layout(&names, f64::from(width))?;
    let legend_h = legend_height(legend_rows);
    let height = legend_h + rows as u32 * PANEL_HEIGHT;
    let mut img = RgbImage::from_pixel(width, height, BACKGROUND);
    for (i, x, r) in legend {
        let cy = LEGEND_PAD + (r as f64 + 0.5) * LEGEND_ROW;
        let s = 0.5 * LEGEND_SWATCH;
        rect(
            &mut img,
            x,
            (cy - s).round(),
            x + LEGEND_SWATCH,
            (cy + s).round(),
            name_color(&names, i),
            1.0,
        );
        text(
            &mut img,
            names[i],
            x + LEGEND_SWATCH + 6.0,
            cy,
            LEGEND_FONT,
            INK,
            Anchor::LEFT,
        )?;
    }
    for (k, p) in panels.iter().enumerate() {
        draw_panel(&mut img, p, k, columns, legend_h, &names)?;
    }
    Ok(img)
}

/// Writes [`grouped_bars_image`] as PNG.
pub fn grouped_bars_png(panels: &[Panel], columns: usize, out: &Path) -> Result<(), RenderError> {
    save_png(&grouped_bars_image(panels, columns)?, out)
}

#[cfg(test)]
mod tests {

    #[test]
    fn the_ten_systems_have_distinct_colours_by_family() {
        let ten = [
            "pid", "eh", "mppi", "rl", "mcl", "acl", "wmvct", "mppi6", "tal", "tnt",
        ];
        let colours: Vec<_> = ten.iter().map(|n| system_color(n).unwrap()).collect();
        for (i, a) in colours.iter().enumerate() {
            assert!(
                colours[i + 1..].iter().all(|b| b != a),
                "{} repeats",
                ten[i]
            );
        }
        // a run label keeps its system's colour; other names fall back to the series colours
        assert_eq!(system_color("tal-verti-100"), system_color("tal"));
        assert_eq!(system_color("mine"), None);
        assert_eq!(name_color(&["mine", "tnt"], 0), series_color(0));
        assert_eq!(
            name_color(&["mine", "tnt"], 1),
            system_color("tnt").unwrap()
        );
    }

    use super::*;

    fn series(name: &str, values: &[f64]) -> Series {
        Series {
            name: name.into(),
            values: values.to_vec(),
            errors: None,
        }
    }

    fn panel(series: Vec<Series>) -> Panel {
        Panel {
            title: "Success rate".into(),
            y_label: "success (%)".into(),
            y_max: Some(100.0),
            groups: vec!["low".into(), "mid".into(), "high".into()],
            series,
        }
    }

    #[test]
    fn nice_axes() {
        assert_eq!(nice_step(17.0), 20.0);
        assert_eq!(nice_step(0.22), 0.25);
        assert_eq!(nice_step(3.0), 5.0);
        assert_eq!(decimals(0.25), 2);
        assert_eq!(decimals(20.0), 0);
        // values up to 37 (+ whisker 4 = 41): step 10 (41/5 = 8.2 -> 10), top 42.2 -> 50
        let mut p = panel(vec![series("A", &[37.0, 5.0, f64::NAN])]);
        p.y_max = None;
        p.series[0].errors = Some(vec![4.0, 1.0, 1.0]);
        assert_eq!(axis(&p), (0.0, 50.0, 10.0));
        // a fixed top stays; all-NaN or no data still gives a usable axis
        assert_eq!(
            axis(&panel(vec![series("A", &[f64::NAN; 3])])),
            (0.0, 100.0, 20.0)
        );
        let mut p = panel(vec![]);
        p.y_max = None;
        // no data: range 0..1, step 0.2, top 1.03 -> 1.2
        let (lo, hi, step) = axis(&p);
        assert_eq!((lo, step), (0.0, 0.2));
        assert!((hi - 1.2).abs() < 1e-12);
    }

    #[test]
    fn bars_appear_where_they_should() {
        // one row of two panels; A = 50 % and NaN, B = 100 % and 20 %
        let p = panel(vec![
            series("A", &[50.0, f64::NAN, 10.0]),
            series("B", &[100.0, 20.0, 0.0]),
        ]);
        let mut q = p.clone();
        q.title = "Second".into();
        q.series.reverse(); // colours follow names, not positions
        let img = grouped_bars_image(&[p.clone(), q.clone()], 2).unwrap();
        let legend_h = legend_height(1);
        assert_eq!(img.dimensions(), (2 * PANEL_WIDTH, legend_h + PANEL_HEIGHT));
        let (blue, orange) = (series_color(0), series_color(1));
        let b = plot_box(&p, 0, 2, legend_h);
        let px = |x: f64, y: f64| *img.get_pixel(x as u32, y as u32);
        // A, low: filled from the baseline up to 50 % and not above
        let (x0, x1) = bar_span(&b, 3, 2, 0, 0);
        let cx = 0.5 * (x0 + x1);
        assert_eq!(px(cx, b.y(25.0)), blue);
        assert_eq!(px(cx, b.y(49.0)), blue);
        assert_eq!(px(cx, b.y(70.0)), BACKGROUND);
        // B, low: full height
        let (x0, x1) = bar_span(&b, 3, 2, 0, 1);
        assert_eq!(px(0.5 * (x0 + x1), b.y(90.0)), orange);
        // A, mid is NaN: no bar colour anywhere in its column
        let (x0, x1) = bar_span(&b, 3, 2, 1, 0);
        for y in b.y0 as u32..b.y1 as u32 {
            for x in x0 as u32..x1 as u32 {
                assert_ne!(*img.get_pixel(x, y), blue, "NaN drew a bar at ({x}, {y})");
            }
        }
        // ... but its "n/a" mark leaves some grey ink just above the baseline
        let ink = (x0 as u32..x1 as u32)
            .flat_map(|x| (b.y(30.0) as u32..b.y(0.0) as u32).map(move |y| (x, y)))
            .any(|(x, y)| img.get_pixel(x, y)[0] < 0xF0);
        assert!(ink, "no n/a mark");
        // second panel: the same name keeps its colour although it is the second series
        let b2 = plot_box(&q, 1, 2, legend_h);
        let (x0, x1) = bar_span(&b2, 3, 2, 0, 1);
        assert_eq!(px(0.5 * (x0 + x1), b2.y(25.0)), blue);
        // legend swatches of both names at the top
        let top: Vec<Rgb<u8>> = (0..img.width())
            .map(|x| *img.get_pixel(x, (LEGEND_PAD + 0.5 * LEGEND_ROW) as u32))
            .collect();
        assert!(top.contains(&blue) && top.contains(&orange));
    }

    #[test]
    fn whiskers_and_grid_layout() {
        let mut p = panel(vec![series("A", &[40.0, 40.0, 40.0])]);
        p.y_max = None;
        p.series[0].errors = Some(vec![10.0, f64::NAN, 0.0]);
        let panels = vec![p; 5];
        let img = grouped_bars_image(&panels, 2).unwrap();
        // 5 panels in 2 columns: 3 rows
        assert_eq!(
            img.dimensions(),
            (2 * PANEL_WIDTH, legend_height(1) + 3 * PANEL_HEIGHT)
        );
        let b = plot_box(&panels[4], 4, 2, legend_height(1));
        assert_eq!(b.x0, PLOT_LEFT, "fifth panel starts the third row");
        // whisker reaches 40 + 10 = 50: step 50/5 = 10; with 3 % headroom (51.5) the top
        // rounds up to 60. The whisker rises above the bar top at 40.
        assert_eq!((b.lo, b.hi), (0.0, 60.0));
        let (x0, x1) = bar_span(&b, 3, 1, 0, 0);
        let cx = 0.5 * (x0 + x1);
        let p = img.get_pixel(cx as u32, b.y(45.0) as u32);
        assert!(p[0] < 0x80, "whisker missing: {p:?}");
        // no whisker where the error is NaN or 0
        for g in [1, 2] {
            let (x0, x1) = bar_span(&b, 3, 1, g, 0);
            let p = img.get_pixel((0.5 * (x0 + x1)) as u32, b.y(45.0) as u32);
            assert_eq!(*p, BACKGROUND);
        }
    }

    #[test]
    fn odd_input_does_not_panic() {
        assert!(grouped_bars_image(&[], 4).is_err());
        let weird = Panel {
            title: String::new(),
            y_label: String::new(),
            y_max: Some(f64::NAN),
            groups: vec!["a".into()],
            series: vec![
                Series {
                    name: "x".into(),
                    values: vec![f64::INFINITY, 3.0],
                    errors: Some(vec![]),
                },
                series("y", &[-1e300]),
                series("z", &[]),
            ],
        };
        let empty = Panel::default();
        let img = grouped_bars_image(&[weird, empty], 0).unwrap();
        assert_eq!(img.width(), PANEL_WIDTH);
        // many series wrap the legend onto several rows
        let many: Vec<Series> = (0..30)
            .map(|i| series(&format!("system {i}"), &[1.0]))
            .collect();
        let img = grouped_bars_image(&[panel(many)], 1).unwrap();
        assert!(img.height() > legend_height(2) + PANEL_HEIGHT - 1);
    }

    #[test]
    fn writes_a_png() {
        let dir = std::env::temp_dir().join(format!("verti-charts-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("bars.png");
        grouped_bars_png(&[panel(vec![series("A", &[1.0, 2.0, 3.0])])], 4, &out).unwrap();
        let back = image::open(&out).unwrap();
        assert_eq!(
            (back.width(), back.height()),
            (PANEL_WIDTH, legend_height(1) + PANEL_HEIGHT)
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn variants_of_one_system_get_darker_shades_of_its_hue() {
        let names = [
            "pid",
            "pid [perception=low]",
            "mcl",
            "pid [perception=high]",
        ];
        let c: Vec<Rgb<u8>> = (0..names.len()).map(|i| name_color(&names, i)).collect();
        assert_eq!(c[0], system_color("pid").unwrap());
        assert_eq!(c[2], system_color("mcl").unwrap());
        let lum = |c: Rgb<u8>| c.0.iter().map(|&v| u32::from(v)).sum::<u32>();
        assert!(lum(c[0]) > lum(c[1]) && lum(c[1]) > lum(c[3]));
        assert!(
            c.iter()
                .enumerate()
                .all(|(i, a)| c[i + 1..].iter().all(|b| a != b))
        );
    }
}
