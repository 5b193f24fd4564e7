//! A driven trajectory, coloured by a value per point (usually speed), drawn over a finished
//! world render, with its colour bar and failure marker added to the legend.

use super::{LEGEND_FONT, SMALL_FONT, WorldImage};
use crate::RenderError;
use crate::draw::{Anchor, disc, polyline, rect, ring, text};
use crate::palette;
use image::Rgb;
use plotters::style::text_anchor::{HPos, VPos};

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
