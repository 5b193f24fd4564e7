//! The page: options checked, then terrain, patch grid, obstacles, global paths, map border,
//! start/goal markers, title and legend drawn in that order.

use super::legend::{Swatch, format_exaggeration, legend_rows, metres_label, nice_length};
use super::markers::draw_markers;
use super::shading::{bilinear, shade_and_height};
use super::{
    LEGEND_FONT, LEGEND_GAP, LEGEND_LINE, LEGEND_WIDTH, MARGIN, MAX_PIXELS_PER_CELL, MapTransform,
    RenderOptions, SMALL_FONT, TITLE_FONT, TITLE_HEIGHT, WorldImage,
};
use crate::RenderError;
use crate::draw::{Anchor, disc, fill_sdf, polyline, rect, ring, text, text_size};
use crate::palette::{self, class_color};
use image::{Rgb, RgbImage};
use std::path::Path;
use verti_world::obstacle::polygon_signed_distance;
use verti_world::surface::{CELLS_PER_PATCH, PATCHES_PER_SIDE};
use verti_world::{ObstacleShape, World};

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

/// Renders a world and writes it as PNG.
pub fn render_world_png(
    world: &World,
    options: &RenderOptions,
    out: &Path,
) -> Result<(), RenderError> {
    render_world(world, options)?.save_png(out)
}
