//! A page comparing runs of one task (e.g. verti and a reference engine): the tracks over the
//! world map, and roll and pitch over time, one colour per run throughout.

use crate::RenderError;
use crate::charts::series_color;
use crate::draw::{Anchor, ensure_font, save_png, text, text_size};
use crate::lines::{LinePanel, LineSeries, draw_line_panel};
use crate::map::{RenderOptions, draw_track, render_world};
use crate::palette;
use image::RgbImage;
use std::path::Path;
use verti_world::World;

/// One run of the task. Run `i` of a page is drawn in [`series_color`]`(i)`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunTrace {
    /// Short name for the charts' legends, e.g. `Chrono`.
    pub name: String,
    /// Legend row on the map, e.g. `Chrono: rollover, 8.6 s`.
    pub label: String,
    /// One sample per entry: time (s), world (x, y), roll and pitch (degrees).
    pub times: Vec<f64>,
    pub points: Vec<[f64; 2]>,
    pub roll: Vec<f64>,
    pub pitch: Vec<f64>,
}

/// What a comparison page shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ComparePage {
    /// Headline above everything.
    pub title: String,
    /// The task (start/goal pair) whose markers and path are drawn.
    pub pair: u32,
    pub runs: Vec<RunTrace>,
    /// Reference lines on the roll chart, degrees (e.g. ±30, the rollover threshold).
    pub roll_marks: Vec<f64>,
    /// Pixels per heightfield cell of the map.
    pub pixels_per_cell: u32,
}

const HEADER: u32 = 34;
const CHART_WIDTH: u32 = 620;
const MIN_CHART_HEIGHT: u32 = 230;
const TITLE_FONT: f64 = 15.0;

/// Draws the page: headline; the map with each run's track (labelled in its legend); roll and
/// pitch over time to its right.
pub fn comparison_image(world: &World, page: &ComparePage) -> Result<RgbImage, RenderError> {
    ensure_font()?;
    for r in &page.runs {
        let n = r.times.len();
        if r.points.len() != n || r.roll.len() != n || r.pitch.len() != n {
            return Err(RenderError::Input(format!(
                "run {}: {} times, {} points, {} roll and {} pitch values",
                r.name,
                n,
                r.points.len(),
                r.roll.len(),
                r.pitch.len()
            )));
        }
    }
    let options = RenderOptions {
        pixels_per_cell: page.pixels_per_cell,
        pairs: Some(vec![page.pair]),
        ..Default::default()
    };
    let mut map = render_world(world, &options)?;
    for (i, r) in page.runs.iter().enumerate() {
        draw_track(&mut map, &r.points, series_color(i), &r.label)?;
    }
    let chart_h = (map.image.height() / 2).max(MIN_CHART_HEIGHT);
    let width = map.image.width() + CHART_WIDTH;
    let height = HEADER + map.image.height().max(2 * chart_h);
    let mut img = RgbImage::from_pixel(width, height, palette::PAPER);
    image::imageops::replace(&mut img, &map.image, 0, i64::from(HEADER));
    let series = |f: &dyn Fn(&RunTrace) -> &Vec<f64>| -> Vec<LineSeries> {
        page.runs
            .iter()
            .map(|r| LineSeries {
                name: r.name.clone(),
                points: r.times.iter().zip(f(r)).map(|(&t, &v)| [t, v]).collect(),
            })
            .collect()
    };
    let panels = [
        LinePanel {
            title: "Roll".into(),
            x_label: "time (s)".into(),
            y_label: "deg".into(),
            series: series(&|r| &r.roll),
            marks: page.roll_marks.clone(),
        },
        LinePanel {
            title: "Pitch".into(),
            x_label: "time (s)".into(),
            y_label: "deg".into(),
            series: series(&|r| &r.pitch),
            marks: Vec::new(),
        },
    ];
    let x0 = f64::from(map.image.width());
    for (k, p) in panels.iter().enumerate() {
        let y0 = f64::from(HEADER + k as u32 * chart_h);
        draw_line_panel(
            &mut img,
            p,
            x0,
            y0 + 4.0,
            f64::from(CHART_WIDTH) - 10.0,
            f64::from(chart_h) - 8.0,
        )?;
    }
    // the headline shrinks rather than running off the page
    let avail = f64::from(width) - 20.0;
    let mut fs = TITLE_FONT;
    while fs > 8.0 && f64::from(text_size(&page.title, fs)?.0) > avail {
        fs -= 1.0;
    }
    text(
        &mut img,
        &page.title,
        10.0,
        0.5 * f64::from(HEADER),
        fs,
        palette::INK,
        Anchor::LEFT,
    )?;
    Ok(img)
}

/// Writes [`comparison_image`] as PNG.
pub fn comparison_png(world: &World, page: &ComparePage, out: &Path) -> Result<(), RenderError> {
    save_png(&comparison_image(world, page)?, out)
}
