//! Tracks in one colour each, labelled in the legend: for drawing several runs of one task on
//! one map (e.g. verti's and a reference engine's), where colour says which run a line is.

use super::{LEGEND_FONT, LEGEND_LINE, LEGEND_WIDTH, SMALL_FONT, WorldImage};
use crate::RenderError;
use crate::draw::{Anchor, disc, polyline, ring, text, text_size};
use crate::palette;
use image::Rgb;

/// Draws a track (world x, y per point) in `color` with a dark casing, marks where it ends with
/// a ring, and adds a legend row (a line swatch and `label`) below the legend's last row.
pub fn draw_track(
    img: &mut WorldImage,
    points: &[[f64; 2]],
    color: Rgb<u8>,
    label: &str,
) -> Result<(), RenderError> {
    let width = (0.5 * img.unit()).max(2.0);
    img.draw_polyline(points, &[palette::INK], width + 2.0);
    img.draw_polyline(points, &[color], width);
    if let Some(&[x, y]) = points.last() {
        let (px, py) = img.map.to_pixel(x, y);
        let r = (1.2 * img.unit()).max(4.0);
        disc(&mut img.image, px, py, r, palette::WHITE);
        ring(&mut img.image, px, py, r, 2.0, color);
    }
    let Some((x, y)) = img.legend_next else {
        return Ok(());
    };
    img.grow_to((y + LEGEND_LINE).ceil() as u32);
    polyline(
        &mut img.image,
        &[(x, y), (x + 22.0, y)],
        &[palette::INK],
        5.0,
    );
    polyline(&mut img.image, &[(x, y), (x + 22.0, y)], &[color], 3.0);
    // a long label gets the smaller font rather than running off the page
    let avail = LEGEND_WIDTH - 30.0;
    let fs = if f64::from(text_size(label, LEGEND_FONT)?.0) > avail {
        SMALL_FONT
    } else {
        LEGEND_FONT
    };
    text(
        &mut img.image,
        label,
        x + 30.0,
        y,
        fs,
        palette::INK,
        Anchor::LEFT,
    )?;
    img.legend_next = Some((x, y + LEGEND_LINE));
    Ok(())
}
