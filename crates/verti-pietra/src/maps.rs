//! The PIETRA maps (paper §V-A): 30 synthetic rocky elevation maps of 50 m x 50 m, all rigid
//! dirt, split 10 / 10 / 10 into training, validation and test maps; the test maps are scaled up
//! vertically, so their footprints are more uneven than anything seen in training (the
//! distribution shift of the paper's Fig. 5).
//!
//! The rock fields come from verti's own procedural rock generator (the one behind verti-100),
//! on a 0.39 m grid so rocks are one to two metres across — the scale of a rock testbed under a
//! 3.4 m vehicle. Maps are a pure function of their index: nothing is stored on disk, and none
//! of them is a verti-100 or original Verti-Bench world.

use std::sync::Arc;
use verti_core::Rng;
use verti_world::generate::elevation::{ElevationSource, ProceduralRock};
use verti_world::surface::{PATCHES_PER_SIDE, Patch, PatchGrid, Surface, TerrainClass};
use verti_world::{
    ElevationLevel, GlobalPath, Heightfield, ObstacleDensity, Task, TerrainType, World, WorldMeta,
    WorldSource,
};

/// Side of a map, metres.
pub const SIDE: f64 = 50.0;
/// Vertices per side: verti's world format (16 x 16 semantic patches of 8 cells), so the maps
/// save, load and replay like any world.
pub const VERTICES: usize = 129;
/// Grid spacing, metres (0.39 m).
pub const CELL: f64 = SIDE / (VERTICES - 1) as f64;
/// Maps per split.
pub const PER_SPLIT: u32 = 10;
/// Height of a height fraction of 1 on training and validation maps, metres: verti's low
/// elevation level (the generator maps a rock field to a spread of 2.7–4.5 % of this, 0.13–0.22
/// m standard deviation), smooth enough that exploration at 2 m/s almost never stalls.
pub const BASE_RELIEF: f64 = 4.8;
/// Vertical scale of the test maps relative to training (the paper's "scaled more"). At 2 the
/// HMMWV stalled on most test tasks whatever the planner knew (the physics prior reached 19 of
/// 100 goals); at 1.5 it reaches about half, which leaves room to tell methods apart.
pub const TEST_SCALE: f64 = 1.5;
/// Coulomb friction of the dirt (the class's mean friction in verti).
pub const DIRT_FRICTION: f64 = 0.6;
/// Distance between a navigation task's start and goal (paper: 40 m).
pub const TASK_DISTANCE: f64 = 40.0;
/// The set seed recorded in the maps' provenance (never 0, the evaluation set's seed).
pub const SEED: u64 = 0x5049_4554; // "PIET"

/// Which third of the maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Split {
    Train,
    Validation,
    Test,
}

impl Split {
    pub const ALL: [Split; 3] = [Split::Train, Split::Validation, Split::Test];

    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Validation => "validation",
            Split::Test => "test",
        }
    }

    /// Global indices (1-based, 1..=30) of this split's maps.
    pub fn indices(self) -> std::ops::RangeInclusive<u32> {
        let first = match self {
            Split::Train => 1,
            Split::Validation => PER_SPLIT + 1,
            Split::Test => 2 * PER_SPLIT + 1,
        };
        first..=first + PER_SPLIT - 1
    }

    /// Metres per unit height fraction.
    pub fn relief(self) -> f64 {
        match self {
            Split::Test => BASE_RELIEF * TEST_SCALE,
            _ => BASE_RELIEF,
        }
    }
}

/// The ten start/goal pairs of a map: opposite points of a circle of radius 20 m centred on the
/// map, 36° apart, so every pair is [`TASK_DISTANCE`] apart and crosses the middle of the map.
pub fn tasks() -> Vec<Task> {
    (0..10u32)
        .map(|pair| {
            let a = f64::from(pair) * std::f64::consts::PI / 5.0;
            let r = 0.5 * TASK_DISTANCE;
            Task {
                pair,
                start: [r * a.cos(), r * a.sin()],
                goal: [-r * a.cos(), -r * a.sin()],
            }
        })
        .collect()
}

/// Map `index` (1..=30) of `split`. The index alone fixes the rocks; the split fixes the
/// vertical scale.
pub fn map(split: Split, index: u32) -> World {
    let fractions = ProceduralRock::default().generate(
        &mut Rng::derive(SEED, "pietra-map", u64::from(index)),
        VERTICES,
    );
    let relief = split.relief();
    // heights rounded to f32 like every generated world, so a saved map reloads bit for bit
    let heights = fractions
        .iter()
        .map(|f| f64::from((f * relief) as f32))
        .collect();
    let dirt = Patch {
        class: TerrainClass::Dirt,
        surface: Surface::Rigid {
            friction: DIRT_FRICTION,
            restitution: 0.0,
        },
    };
    let tasks = tasks();
    let paths = tasks
        .iter()
        .map(|t| GlobalPath {
            points: vec![t.start, t.goal],
        })
        .collect();
    World {
        meta: WorldMeta {
            name: format!("pietra/{}/{index:02}", split.name()),
            index,
            source: WorldSource::Generated {
                set_seed: SEED,
                generator: "pietra-rock-v1".into(),
            },
            // descriptive only: these maps never go through the world format
            level: if split == Split::Test {
                ElevationLevel::Mid
            } else {
                ElevationLevel::Low
            },
            terrain_type: TerrainType::Rigid,
            // no obstacles at all; the field needs a value and "sparse" is the nearest
            density: ObstacleDensity::Sparse,
            scale: 1.0,
            max_height: relief,
        },
        terrain: Heightfield::new(VERTICES, CELL, heights),
        patches: PatchGrid::new(vec![dirt; PATCHES_PER_SIDE * PATCHES_PER_SIDE], CELL),
        obstacles: Vec::new(),
        tasks,
        paths,
        path_clearance: 0.0,
    }
}

/// The ten maps of a split, in index order.
pub fn split_maps(split: Split) -> Vec<Arc<World>> {
    split.indices().map(|i| Arc::new(map(split, i))).collect()
}

/// Standard deviation of the heights of a whole map, metres (how rough a split is).
pub fn relief_std(world: &World) -> f64 {
    let h = world.terrain.heights();
    let n = h.len() as f64;
    let mean = h.iter().sum::<f64>() / n;
    (h.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_are_disjoint_and_test_maps_are_rougher() {
        let mut all: Vec<u32> = Split::ALL.iter().flat_map(|s| s.indices()).collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all, (1..=30).collect::<Vec<_>>());
        let train = map(Split::Train, 1);
        assert_eq!(train.terrain.size(), VERTICES);
        assert!((train.terrain.half_extent() - 0.5 * SIDE).abs() < 1e-12);
        let mean = |s: Split| {
            let v: Vec<f64> = s.indices().map(|i| relief_std(&map(s, i))).collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        let (tr, te) = (mean(Split::Train), mean(Split::Test));
        assert!(tr > 0.1 && tr < 0.3, "training relief std {tr}");
        assert!(te > 1.5 * tr, "test maps must be rougher: {te} vs {tr}");
    }

    #[test]
    fn maps_are_deterministic_and_tasks_are_40_m() {
        assert_eq!(map(Split::Validation, 12), map(Split::Validation, 12));
        for t in tasks() {
            assert!((t.distance() - TASK_DISTANCE).abs() < 1e-9);
            let w = map(Split::Test, 21);
            assert!(w.terrain.contains(t.start[0], t.start[1]));
        }
    }
}
