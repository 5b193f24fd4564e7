//! Tests of [`set_stats`](super::set_stats) and the report: every statistic group is checked
//! on the same hand-built worlds.

use super::*;
use crate::generate::{SetConfig, generate_set};
use crate::heightfield::Heightfield;
use crate::obstacle::{Obstacle, box_faces};
use crate::surface::{Patch, PatchGrid, RIGID_RESTITUTION, SoilParams, Surface, TerrainClass};
use crate::world::{GlobalPath, ObstacleDensity, Task, TerrainType, WorldMeta, WorldSource};
use verti_core::Vec3;

/// A 3x3-vertex world (cell 1 m) whose heights, classes, obstacles and paths are all chosen
/// by hand so every statistic can be checked exactly.
fn tiny(name: &str, level: ElevationLevel, ty: TerrainType, heights: Vec<f64>) -> World {
    let rigid = |class, friction| Patch {
        class,
        surface: Surface::Rigid {
            friction,
            restitution: RIGID_RESTITUTION,
        },
    };
    let mut patches = vec![rigid(TerrainClass::Grass, 0.3); 256];
    patches[0] = rigid(TerrainClass::Grass, 0.5);
    patches[1] = Patch {
        class: TerrainClass::Snow,
        surface: Surface::Deformable {
            soil: SoilParams::SOFT,
        },
    };
    World {
        meta: WorldMeta {
            name: name.to_string(),
            index: 1,
            source: WorldSource::Generated {
                set_seed: 0,
                generator: "hand".into(),
            },
            level,
            terrain_type: ty,
            density: ObstacleDensity::Sparse,
            scale: 1.0,
            max_height: level.max_height(),
        },
        terrain: Heightfield::new(3, 1.0, heights),
        patches: PatchGrid::new(patches, 1.0),
        obstacles: vec![
            Obstacle::rock(
                box_faces(Vec3::new(2.0, 2.0, 1.0)),
                1.0,
                Vec3::new(0.0, 0.0, 0.5),
                0.0,
            )
            .unwrap(),
            Obstacle::tree(0.2, 3.0, Vec3::new(3.0, 4.0, 1.5)).unwrap(),
        ],
        tasks: vec![
            Task {
                pair: 0,
                start: [-10.0, 0.0],
                goal: [10.0, 0.0],
            },
            Task {
                pair: 1,
                start: [0.0, -10.0],
                goal: [0.0, 10.0],
            },
        ],
        // pair 0: a detour of length 2·sqrt(10² + 5²); pair 1: no path
        paths: vec![
            GlobalPath {
                points: vec![[-10.0, 0.0], [0.0, 5.0], [10.0, 0.0]],
            },
            GlobalPath { points: vec![] },
        ],
        path_clearance: 1.0,
    }
}

#[test]
fn hand_built_set_is_counted_exactly() {
    let a = tiny(
        "a",
        ElevationLevel::Low,
        TerrainType::Rigid,
        vec![0.02, 0.05, 0.08, 0.12, 0.18, 0.23, 0.26, 0.29, 0.35],
    );
    let b = tiny("b", ElevationLevel::High, TerrainType::Mixed, vec![1.05; 9]);
    let s = set_stats(&[a, b]);
    assert_eq!(
        (s.worlds, s.tasks, s.scale, s.mixed_scales),
        (2, 4, 1.0, false)
    );
    assert_eq!(
        s.composition
            .by_level
            .iter()
            .map(|c| c.count)
            .collect::<Vec<_>>(),
        vec![1, 0, 1]
    );
    assert_eq!(
        s.composition
            .by_terrain_type
            .iter()
            .map(|c| c.count)
            .collect::<Vec<_>>(),
        vec![1, 0, 1]
    );
    assert_eq!(s.composition.by_density[0].count, 2);
    assert_eq!(
        s.composition.level_by_type[2],
        LevelTypeRow {
            level: "high".into(),
            rigid: 0,
            deformable: 0,
            mixed: 1
        }
    );

    // Low: 0.1 m bins -> 0.02,0.05,0.08 | 0.12,0.18 | 0.23,0.26,0.29 | 0.35 (values kept off
    // the bin edges, where floating-point division could go either way).
    let low = &s.elevation[0];
    assert_eq!(low.counts.len(), 160);
    assert_eq!(&low.counts[..4], &[3, 2, 3, 1]);
    assert!((low.frequency.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    assert!((low.mean.unwrap() - 1.58 / 9.0).abs() < 1e-12);
    assert!((low.relief.unwrap().mean - 0.33).abs() < 1e-12);
    // High: a flat world at 1.05 m, bin 10; no relief.
    let high = &s.elevation[2];
    assert_eq!(high.counts[10], 9);
    assert_eq!(high.relief.unwrap().max, 0.0);
    assert_eq!((high.ceiling, high.worlds), (16.0, 1));
    // Mid: no worlds, all empty but well-formed.
    assert_eq!((s.elevation[1].worlds, s.elevation[1].mean), (0, None));
    assert!(s.elevation[1].frequency.iter().all(|&f| f == 0.0));

    let grass = &s.classes[TerrainClass::Grass.id() as usize];
    assert_eq!((grass.patches, grass.worlds), (2 * 255, 2));
    let fr = grass.friction.unwrap();
    assert_eq!((fr.count, fr.min, fr.max), (510, 0.3, 0.5));
    let snow = &s.classes[TerrainClass::Snow.id() as usize];
    assert_eq!(
        (snow.patches, snow.deformable, snow.friction),
        (2, true, None)
    );
    assert_eq!(s.classes[TerrainClass::Mud.id() as usize].patches, 0);
    assert!((s.classes.iter().map(|c| c.share).sum::<f64>() - 1.0).abs() < 1e-12);

    assert_eq!((s.obstacles.rocks, s.obstacles.trees), (2, 2));
    let spacing = s.obstacles.min_obstacle_spacing.as_ref().unwrap();
    assert!((spacing.metres - 5.0).abs() < 1e-12 && spacing.world == "a");
    // the rock at the origin is 10 m from every start and goal; the tree at (3, 4) is
    // closest to the goal (0, 10)
    assert!(
        (s.obstacles.min_task_spacing.as_ref().unwrap().metres - 3f64.hypot(6.0)).abs() < 1e-12
    );

    assert_eq!((s.paths.planned, s.paths.missing), (2, 2));
    let expected = 2.0 * 10f64.hypot(5.0);
    assert!((s.paths.length.unwrap().mean - expected).abs() < 1e-12);
    assert!((s.paths.straight_ratio.unwrap().mean - expected / 20.0).abs() < 1e-12);

    // The report mentions every section and the JSON keeps its field names.
    let text = s.to_string();
    for needle in [
        "composition",
        "elevation",
        "terrain classes",
        "obstacles",
        "global paths",
        "snow",
    ] {
        assert!(text.contains(needle), "{needle} missing from\n{text}");
    }
    let json = serde_json_like(&s);
    assert!(json.contains("level_by_type") && json.contains("min_task_spacing"));
}

/// Serialises through serde's data model without a JSON crate (verti-world does not depend
/// on one): the derived `Serialize` must at least expose the field names.
fn serde_json_like(s: &SetStats) -> String {
    serde_norway::to_string(s).unwrap()
}

#[test]
fn empty_set_has_no_figures_and_does_not_panic() {
    let s = set_stats(&[]);
    assert_eq!((s.worlds, s.tasks, s.paths.planned), (0, 0, 0));
    assert!(s.obstacles.min_obstacle_spacing.is_none());
    assert!(s.classes.iter().all(|c| c.share == 0.0));
    assert!(!s.to_string().is_empty());
}

#[test]
fn scaled_worlds_scale_the_bins() {
    let mut w = tiny(
        "s",
        ElevationLevel::Mid,
        TerrainType::Rigid,
        vec![
            0.002, 0.005, 0.008, 0.012, 0.018, 0.023, 0.026, 0.029, 0.035,
        ],
    );
    w.meta.scale = 0.1;
    let s = set_stats(&[w]);
    let mid = &s.elevation[1];
    assert!((mid.bin_width - 0.01).abs() < 1e-15 && (mid.ceiling - 0.96).abs() < 1e-12);
    assert_eq!(&mid.counts[..4], &[3, 2, 3, 1]);
}

/// A small generated set obeys the generator's rules as seen through the statistics.
#[test]
fn generated_set_statistics_follow_the_generator() {
    let worlds = generate_set(
        &SetConfig {
            count: 6,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap();
    let s = set_stats(&worlds);
    assert_eq!((s.worlds, s.tasks), (6, 60));
    assert_eq!(
        s.composition
            .by_level
            .iter()
            .map(|c| c.count)
            .sum::<usize>(),
        6
    );
    for e in &s.elevation {
        // heights stay within the level's ceiling, so nothing falls outside the histogram
        assert_eq!((e.below_range, e.above_range), (0, 0));
        if let Some(r) = e.relief {
            assert!(r.max <= e.ceiling + 1e-9, "{e:?}");
        }
    }
    for c in s.classes.iter().filter(|c| !c.deformable) {
        if let Some(fr) = c.friction {
            assert!(fr.min >= 0.1 && fr.max <= 1.0);
        }
    }
    let per_world: usize = worlds.iter().map(|w| w.obstacles.len()).sum();
    assert_eq!(s.obstacles.rocks + s.obstacles.trees, per_world);
    assert_eq!(s.paths.planned + s.paths.missing, 60);
    if let Some(r) = s.paths.straight_ratio {
        assert!(
            r.min >= 1.0 - 1e-9,
            "a path is never shorter than the straight line"
        );
    }
}
