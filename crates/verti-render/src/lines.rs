//! Line charts of series over a shared x axis (e.g. roll over time of two engines), drawn into
//! a region of an image so pages can combine them with maps.
//!
//! Axes come from the data (rounded out to whole ticks of 1, 2, 2.5 or 5 times a power of ten,
//! as the bar charts do); non-finite points break a line instead of being drawn.

use crate::RenderError;
use crate::charts::{decimals, nice_step, series_color};
use crate::draw::{Anchor, ensure_font, polyline, rect, text};
use image::{Rgb, RgbImage};
use plotters::style::text_anchor::{HPos, VPos};

/// One line: (x, y) points in order, drawn in the colour of its position in the panel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LineSeries {
    pub name: String,
    pub points: Vec<[f64; 2]>,
}

/// One chart.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LinePanel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Series `i` is drawn in [`series_color`]`(i)`.
    pub series: Vec<LineSeries>,
    /// Horizontal reference lines (e.g. a threshold), drawn thin and grey.
    pub marks: Vec<f64>,
}

const BACKGROUND: Rgb<u8> = Rgb([0xFF, 0xFF, 0xFF]);
const INK: Rgb<u8> = Rgb([0x22, 0x22, 0x22]);
const AXIS: Rgb<u8> = Rgb([0x44, 0x44, 0x44]);
const GRID: Rgb<u8> = Rgb([0xE6, 0xE6, 0xE6]);
const MARK: Rgb<u8> = Rgb([0xA0, 0xA0, 0xA0]);
const MUTED: Rgb<u8> = Rgb([0x66, 0x66, 0x66]);
// even sizes, for the reason given in `charts`
const TITLE_FONT: f64 = 14.0;
const TICK_FONT: f64 = 12.0;
const LEGEND_FONT: f64 = 12.0;
const LEFT: f64 = 52.0;
const RIGHT: f64 = 14.0;
const TOP: f64 = 30.0;
const BOTTOM: f64 = 38.0;
const LINE_WIDTH: f64 = 1.8;

/// Rounded axis range [lo, hi] and tick step covering `values` (and `extra`, e.g. 0).
fn axis_range(values: impl Iterator<Item = f64>, extra: &[f64]) -> (f64, f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values
        .chain(extra.iter().copied())
        .filter(|v| v.is_finite())
    {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0, 0.2);
    }
    if hi - lo <= 0.0 {
        hi = lo + 1.0;
    }
    let step = nice_step((hi - lo) / 5.0);
    ((lo / step).floor() * step, (hi / step).ceil() * step, step)
}

/// Draws `panel` into the `w` x `h` pixel region at (`x0`, `y0`) of `img` (white background,
/// legend in the top right corner).
pub fn draw_line_panel(
    img: &mut RgbImage,
    panel: &LinePanel,
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
) -> Result<(), RenderError> {
    ensure_font()?;
    if !(w > LEFT + RIGHT + 10.0 && h > TOP + BOTTOM + 10.0) {
        return Err(RenderError::Options(format!(
            "a line chart needs at least {} x {} pixels, got {w} x {h}",
            LEFT + RIGHT + 10.0,
            TOP + BOTTOM + 10.0
        )));
    }
    rect(img, x0, y0, x0 + w, y0 + h, BACKGROUND, 1.0);
    let pts = || panel.series.iter().flat_map(|s| s.points.iter());
    let (xlo, xhi, xstep) = axis_range(pts().map(|p| p[0]), &[0.0]);
    let (ylo, yhi, ystep) = axis_range(pts().map(|p| p[1]), &[0.0]);
    let (px0, px1, py0, py1) = (x0 + LEFT, x0 + w - RIGHT, y0 + TOP, y0 + h - BOTTOM);
    let to_px = |x: f64, y: f64| {
        (
            px0 + (x - xlo) / (xhi - xlo) * (px1 - px0),
            py1 - (y - ylo) / (yhi - ylo) * (py1 - py0),
        )
    };
    text(
        img,
        &panel.title,
        x0 + 0.5 * w,
        y0 + 14.0,
        TITLE_FONT,
        INK,
        Anchor::CENTER,
    )?;
    // grid and ticks
    let ticks = |lo: f64, hi: f64, step: f64| {
        let n = ((hi - lo) / step).round().clamp(0.0, 100.0) as usize;
        (0..=n).map(move |i| lo + i as f64 * step)
    };
    for v in ticks(ylo, yhi, ystep) {
        let y = to_px(xlo, v).1.round() + 0.5;
        rect(img, px0, y - 0.5, px1, y + 0.5, GRID, 1.0);
        let label = format!("{:.*}", decimals(ystep), v + 0.0);
        text(
            img,
            &label,
            px0 - 6.0,
            y,
            TICK_FONT,
            MUTED,
            Anchor(HPos::Right, VPos::Center),
        )?;
    }
    for v in ticks(xlo, xhi, xstep) {
        let x = to_px(v, ylo).0.round() + 0.5;
        rect(img, x - 0.5, py0, x + 0.5, py1, GRID, 1.0);
        let label = format!("{:.*}", decimals(xstep), v + 0.0);
        text(img, &label, x, py1 + 10.0, TICK_FONT, MUTED, Anchor::CENTER)?;
    }
    text(
        img,
        &panel.x_label,
        0.5 * (px0 + px1),
        py1 + 27.0,
        TICK_FONT,
        INK,
        Anchor::CENTER,
    )?;
    text(
        img,
        &panel.y_label,
        x0 + 4.0,
        y0 + 14.0,
        TICK_FONT,
        INK,
        Anchor::LEFT,
    )?;
    for &m in panel.marks.iter().filter(|m| m.is_finite()) {
        if m >= ylo && m <= yhi {
            let y = to_px(xlo, m).1;
            polyline(img, &[(px0, y), (px1, y)], &[MARK], 1.0);
        }
    }
    // zero line and axes
    let zero = to_px(xlo, 0.0).1.round();
    rect(img, px0, zero, px1, zero + 1.0, AXIS, 0.5);
    rect(img, px0 - 1.0, py0, px0, py1 + 0.5, AXIS, 1.0);
    rect(img, px0 - 1.0, py1, px1, py1 + 1.0, AXIS, 1.0);
    for (i, s) in panel.series.iter().enumerate() {
        // a non-finite point ends one run of the line; the next finite point starts another
        for run in s.points.split(|p| !(p[0].is_finite() && p[1].is_finite())) {
            let px: Vec<(f64, f64)> = run.iter().map(|p| to_px(p[0], p[1])).collect();
            polyline(img, &px, &[series_color(i)], LINE_WIDTH);
        }
    }
    // legend, right-aligned in the title row's second half
    let mut x = px1;
    for (i, s) in panel.series.iter().enumerate().rev() {
        let (tw, _) = crate::draw::text_size(&s.name, LEGEND_FONT)?;
        x -= f64::from(tw);
        text(img, &s.name, x, py0 - 8.0, LEGEND_FONT, INK, Anchor::LEFT)?;
        x -= 20.0;
        polyline(
            img,
            &[(x, py0 - 8.0), (x + 14.0, py0 - 8.0)],
            &[series_color(i)],
            3.0,
        );
        x -= 14.0;
    }
    Ok(())
}

/// A `w` x `h` image of one line chart.
pub fn line_chart_image(panel: &LinePanel, w: u32, h: u32) -> Result<RgbImage, RenderError> {
    let mut img = RgbImage::from_pixel(w, h, BACKGROUND);
    draw_line_panel(&mut img, panel, 0.0, 0.0, f64::from(w), f64::from(h))?;
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_round_out_and_cover_zero() {
        assert_eq!(
            axis_range([3.0, 17.0].into_iter(), &[0.0]),
            (0.0, 20.0, 5.0)
        );
        assert_eq!(
            axis_range([-12.0, 31.0].into_iter(), &[0.0]),
            (-20.0, 40.0, 10.0)
        );
        assert_eq!(axis_range(std::iter::empty(), &[]), (0.0, 1.0, 0.2));
        assert_eq!(axis_range([f64::NAN].into_iter(), &[]), (0.0, 1.0, 0.2));
    }

    #[test]
    fn lines_are_drawn_in_series_colours() {
        let panel = LinePanel {
            title: "roll".into(),
            x_label: "time (s)".into(),
            y_label: "deg".into(),
            series: vec![
                LineSeries {
                    name: "A".into(),
                    points: (0..=100).map(|i| [f64::from(i) * 0.1, 5.0]).collect(),
                },
                LineSeries {
                    name: "B".into(),
                    points: vec![[0.0, -5.0], [f64::NAN, 0.0], [10.0, -5.0]],
                },
            ],
            marks: vec![30.0, -30.0],
        };
        let img = line_chart_image(&panel, 500, 260).unwrap();
        // pixels close to a colour (lines are anti-aliased, so few are exactly it)
        let count = |c: Rgb<u8>| {
            img.pixels()
                .filter(|p| (0..3).all(|k| (i32::from(p[k]) - i32::from(c[k])).abs() < 40))
                .count()
        };
        // series A is a long horizontal line; B is broken by its NaN point into two single
        // points (dots), far fewer pixels
        assert!(count(series_color(0)) > 300, "{}", count(series_color(0)));
        let b = count(series_color(1));
        assert!(b > 0 && b < 120, "{b}");
        assert!(line_chart_image(&panel, 40, 40).is_err());
        // an empty panel still draws
        line_chart_image(&LinePanel::default(), 300, 200).unwrap();
    }
}
