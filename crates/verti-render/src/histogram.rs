//! Elevation histograms of a set, one panel per elevation level (the paper's Fig. 2 bottom).

use crate::RenderError;
use crate::draw::{Anchor, FONT, ensure_font, save_png, text};
use image::RgbImage;
use plotters::backend::{BitMapBackend, RGBPixel};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;
use verti_world::stats::{LevelElevation, SetStats};

const PANEL_W: u32 = 420;
const PANEL_H: u32 = 340;
/// Bar colours per level (low, mid, high).
const LEVEL_COLORS: [RGBColor; 3] = [
    RGBColor(0x3A, 0x8F, 0xC8),
    RGBColor(0xE8, 0x8A, 0x2E),
    RGBColor(0xC0, 0x39, 0x3B),
];

fn draw_err<E: std::fmt::Display>(e: E) -> RenderError {
    RenderError::Draw(e.to_string())
}

/// Common upper x limit of all panels: the highest occupied bin of any level, rounded up to a
/// whole metre step (so the levels' spreads can be compared at a glance, as in the paper); the
/// highest ceiling when there is no data.
fn x_max(stats: &SetStats) -> f64 {
    let last = stats
        .elevation
        .iter()
        .filter_map(|e| {
            e.counts
                .iter()
                .rposition(|&c| c > 0)
                .map(|i| e.bin_start + (i + 1) as f64 * e.bin_width)
        })
        .fold(f64::NAN, f64::max);
    let m = if last.is_finite() {
        let step = if last > 5.0 * stats.scale {
            stats.scale
        } else {
            0.5 * stats.scale
        };
        (last / step).ceil() * step + step
    } else {
        stats
            .elevation
            .iter()
            .map(|e| e.ceiling)
            .fold(f64::NAN, f64::max)
    };
    if m.is_finite() && m > 0.0 { m } else { 1.0 }
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    e: &LevelElevation,
    xmax: f64,
    color: RGBColor,
) -> Result<Vec<Note>, RenderError>
where
    DB::ErrorType: 'static,
{
    let mut notes = Vec::new();
    let title = format!(
        "{} elevation  ({} world{})",
        capitalise(&e.level),
        e.worlds,
        if e.worlds == 1 { "" } else { "s" }
    );
    let (ax, ay) = area.get_base_pixel();
    let (aw, _) = area.dim_in_pixel();
    notes.push(Note {
        text: title,
        x: f64::from(ax) + 0.5 * f64::from(aw),
        y: f64::from(ay) + 22.0,
        size: 17.0,
        anchor: Anchor::CENTER,
    });
    let fmax = e.frequency.iter().copied().fold(0.0, f64::max);
    // Headroom above the tallest bar for the mean/relief note.
    let ymax = if fmax > 0.0 { fmax * 1.3 } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_top(40)
        .margin_right(22)
        .x_label_area_size(38)
        .y_label_area_size(52)
        .build_cartesian_2d(0.0..xmax, 0.0..ymax)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc("height (m)")
        .y_desc("normalised frequency")
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .x_labels(8)
        .y_labels(6)
        .y_label_formatter(&|v| format!("{v:.2}"))
        .x_label_formatter(&|v| format!("{v:.1}"))
        .light_line_style(RGBColor(0xEE, 0xEE, 0xEE))
        .bold_line_style(RGBColor(0xD8, 0xD8, 0xD8))
        .draw()
        .map_err(draw_err)?;
    if e.worlds == 0 {
        let (x, y) = chart.backend_coord(&(0.5 * xmax, 0.5 * ymax));
        notes.push(Note {
            text: "no worlds".into(),
            x: f64::from(x),
            y: f64::from(y),
            size: 15.0,
            anchor: Anchor::CENTER,
        });
        return Ok(notes);
    }
    let bars = e
        .frequency
        .iter()
        .enumerate()
        .filter(|(_, f)| **f > 0.0)
        .map(|(i, &f)| {
            let x0 = e.bin_start + i as f64 * e.bin_width;
            Rectangle::new([(x0, 0.0), (x0 + e.bin_width, f)], color.mix(0.85).filled())
        });
    chart.draw_series(bars).map_err(draw_err)?;
    // The outline of the histogram as a step line (bars are too narrow for per-bar borders).
    let mut steps = vec![(e.bin_start, 0.0)];
    for (i, &f) in e.frequency.iter().enumerate() {
        let x0 = e.bin_start + i as f64 * e.bin_width;
        steps.push((x0, f));
        steps.push((x0 + e.bin_width, f));
    }
    steps.push((e.bin_start + e.frequency.len() as f64 * e.bin_width, 0.0));
    let edge = RGBColor(color.0 / 2, color.1 / 2, color.2 / 2);
    chart
        .draw_series(std::iter::once(PathElement::new(
            steps,
            edge.stroke_width(1),
        )))
        .map_err(draw_err)?;
    if let (Some(mean), Some(std)) = (e.mean, e.std) {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(mean, 0.0), (mean, fmax * 1.08)],
                BLACK.stroke_width(2),
            )))
            .map_err(draw_err)?;
        let mut lines = vec![format!("mean {mean:.2} m, std {std:.2} m")];
        if let Some(r) = e.relief {
            lines.push(format!(
                "relief {:.2} m [{:.2}, {:.2}]",
                r.mean, r.min, r.max
            ));
        }
        let (x, y) = chart.backend_coord(&(xmax, ymax));
        for (k, l) in lines.into_iter().enumerate() {
            notes.push(Note {
                text: l,
                x: f64::from(x) - 6.0,
                y: f64::from(y) + 10.0 + 16.0 * k as f64,
                size: 12.5,
                anchor: Anchor(HPos::Right, VPos::Center),
            });
        }
    }
    Ok(notes)
}

/// A text drawn after the chart, with verti's own glyph layout (see `glyphs`).
struct Note {
    text: String,
    x: f64,
    y: f64,
    size: f64,
    anchor: Anchor,
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

/// Draws the histograms (one panel per level, left to right low..high) into an image.
pub fn elevation_histograms_image(stats: &SetStats) -> Result<RgbImage, RenderError> {
    ensure_font()?;
    let panels = stats.elevation.len().max(1) as u32;
    let (w, h) = (PANEL_W * panels, PANEL_H);
    let mut img = RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]));
    let mut notes = Vec::new();
    {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(img.as_mut(), (w, h))
            .map_err(draw_err)?;
        let root = backend.into_drawing_area();
        let areas = root.split_evenly((1, panels as usize));
        let xmax = x_max(stats);
        for (k, (area, e)) in areas.iter().zip(&stats.elevation).enumerate() {
            notes.extend(panel(area, e, xmax, LEVEL_COLORS[k % LEVEL_COLORS.len()])?);
        }
        root.present().map_err(draw_err)?;
    }
    for n in notes {
        text(
            &mut img,
            &n.text,
            n.x,
            n.y,
            n.size,
            image::Rgb([0x20, 0x20, 0x20]),
            n.anchor,
        )?;
    }
    Ok(img)
}

/// Writes the elevation histograms of a set as PNG.
pub fn elevation_histograms_png(stats: &SetStats, out: &Path) -> Result<(), RenderError> {
    save_png(&elevation_histograms_image(stats)?, out)
}
