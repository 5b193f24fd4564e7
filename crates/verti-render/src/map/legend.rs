//! Legend content: the rows a world's legend gets (terrain classes with their friction or
//! soil, obstacles, tasks) and the scale bar's length and labels.

use super::RenderOptions;
use crate::palette::{self, class_color};
use image::Rgb;
use verti_world::{Surface, TerrainClass, World};

/// Legend rows: (swatch, label).
pub(super) enum Swatch {
    Fill(Rgb<u8>),
    Tree,
    Start,
    Goal,
    Path,
}

pub(super) fn legend_rows(
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
pub(super) fn nice_length(target: f64) -> f64 {
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

pub(super) fn metres_label(m: f64) -> String {
    if m >= 1.0 {
        format!("{m:.0} m")
    } else {
        format!("{:.0} cm", m * 100.0)
    }
}

pub(super) fn format_exaggeration(k: f64) -> String {
    if k < 10.0 {
        format!("{k:.1}")
    } else {
        format!("{k:.0}")
    }
}
