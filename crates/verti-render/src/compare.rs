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

#[cfg(test)]
mod tests {
    use super::*;
    use verti_world::sets::resolve_world;

    fn run(name: &str, offset: f64, world: &World) -> RunTrace {
        // along the first task's straight line from start to goal, shifted sideways
        let t = &world.tasks[0];
        let (dx, dy) = (t.goal[0] - t.start[0], t.goal[1] - t.start[1]);
        let n = 50;
        let len = dx.hypot(dy);
        let times: Vec<f64> = (0..n).map(|k| 0.1 * f64::from(k)).collect();
        RunTrace {
            name: name.into(),
            label: format!("{name}: success"),
            points: (0..n)
                .map(|k| {
                    let s = f64::from(k) / f64::from(n - 1);
                    [
                        t.start[0] + s * dx - offset * dy / len,
                        t.start[1] + s * dy + offset * dx / len,
                    ]
                })
                .collect(),
            roll: times.iter().map(|t| 10.0 * t.sin() + offset).collect(),
            pitch: times.iter().map(|t| 5.0 * t.cos()).collect(),
            times,
        }
    }

    #[test]
    fn page_shows_both_tracks_and_charts() {
        let world = resolve_world("verti-1:1", 1.0).unwrap();
        let page = ComparePage {
            title: "world 1 pair 0".into(),
            pair: 0,
            runs: vec![run("A", -6.0, &world), run("B", 6.0, &world)],
            roll_marks: vec![-30.0, 30.0],
            pixels_per_cell: 2,
        };
        let img = comparison_image(&world, &page).unwrap();
        let map = render_world(
            &world,
            &RenderOptions {
                pixels_per_cell: 2,
                pairs: Some(vec![0]),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(img.width(), map.image.width() + CHART_WIDTH);
        assert!(img.height() >= HEADER + 2 * MIN_CHART_HEIGHT);
        // each track's colour at the middle of its line on the map
        for (i, r) in page.runs.iter().enumerate() {
            let [x, y] = r.points[25];
            let (px, py) = map.map.to_pixel(x, y);
            let p = img.get_pixel(px as u32, py as u32 + HEADER);
            assert_eq!(*p, series_color(i), "run {i} at ({px}, {py})");
        }
        // and both colours in the chart column
        let charts: Vec<_> = (map.image.width()..img.width())
            .flat_map(|x| (HEADER..img.height()).map(move |y| (x, y)))
            .map(|(x, y)| *img.get_pixel(x, y))
            .collect();
        for i in 0..2 {
            assert!(charts.contains(&series_color(i)), "run {i} not charted");
        }
        let mut bad = page.clone();
        bad.runs[1].roll.pop();
        let e = comparison_image(&world, &bad).unwrap_err().to_string();
        assert!(e.contains("run B: 50 times, 50 points, 49 roll"), "{e}");
    }
}
