//! Obstacles: rock and tree counts, rock footprints, and the spacing rules they obey
//! (§III-D): closest pair of obstacles, closest obstacle to a start or goal.

use super::Summary;
use crate::world::World;
use serde::Serialize;

/// Smallest distance of some kind and the world that has it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MinDistance {
    pub metres: f64,
    pub world: String,
}

/// Obstacle counts and spacing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObstacleStats {
    pub rocks: usize,
    pub trees: usize,
    /// Obstacles per world (rocks + trees).
    pub per_world: Option<Summary>,
    /// Horizontal footprint radius of rocks, metres.
    pub rock_radius: Option<Summary>,
    /// Closest pair of obstacle centres within one world (horizontal), metres.
    pub min_obstacle_spacing: Option<MinDistance>,
    /// Closest obstacle centre to any start or goal, metres.
    pub min_task_spacing: Option<MinDistance>,
}

fn keep_min(slot: &mut Option<MinDistance>, metres: f64, world: &World) {
    if metres.is_finite() && slot.as_ref().is_none_or(|m| metres < m.metres) {
        *slot = Some(MinDistance {
            metres,
            world: world.meta.name.clone(),
        });
    }
}

pub(super) fn obstacle_stats(worlds: &[World]) -> ObstacleStats {
    let mut min_obstacle_spacing = None;
    let mut min_task_spacing = None;
    let mut rock_radius = Vec::new();
    for w in worlds {
        let centres: Vec<(f64, f64)> = w
            .obstacles
            .iter()
            .map(|o| (o.position().x, o.position().y))
            .collect();
        rock_radius.extend(
            w.obstacles
                .iter()
                .filter(|o| o.is_rock())
                .map(|o| o.radius_xy()),
        );
        for (i, a) in centres.iter().enumerate() {
            for b in &centres[i + 1..] {
                keep_min(&mut min_obstacle_spacing, (a.0 - b.0).hypot(a.1 - b.1), w);
            }
            for t in &w.tasks {
                for p in [t.start, t.goal] {
                    keep_min(&mut min_task_spacing, (a.0 - p[0]).hypot(a.1 - p[1]), w);
                }
            }
        }
    }
    ObstacleStats {
        rocks: worlds
            .iter()
            .map(|w| w.obstacles.iter().filter(|o| o.is_rock()).count())
            .sum(),
        trees: worlds
            .iter()
            .map(|w| w.obstacles.iter().filter(|o| !o.is_rock()).count())
            .sum(),
        per_world: Summary::of(worlds.iter().map(|w| w.obstacles.len() as f64)),
        rock_radius: Summary::of(rock_radius),
        min_obstacle_spacing,
        min_task_spacing,
    }
}
