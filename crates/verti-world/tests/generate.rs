//! The default set: determinism, the paper's proportions, the 10 m rule, global paths and the
//! file format round trip.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use verti_world::format::{load_set, load_world, save_set, save_world};
use verti_world::generate::{SetConfig, generate_set, one_default_world};
use verti_world::paths::PlanningGrid;
use verti_world::{ElevationLevel, ObstacleDensity, TerrainType, World};

fn default_set() -> Vec<World> {
    generate_set(&SetConfig::default(), &|| {}).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn read_tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

#[test]
fn generation_is_byte_identical_across_runs_and_thread_counts() {
    let a = default_set();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(default_set);
    assert_eq!(a, b);
    let (da, db) = (tmp("det-a"), tmp("det-b"));
    save_set(&a, "verti-100", Some(0), &da, &|| {}).unwrap();
    save_set(&b, "verti-100", Some(0), &db, &|| {}).unwrap();
    let (ta, tb) = (read_tree(&da), read_tree(&db));
    assert_eq!(ta.len(), 100 * 3 + 1);
    assert!(ta == tb, "files differ between two generations");
    // and the loaded set equals the generated one bit for bit
    let (m, loaded) = load_set(&da).unwrap();
    assert_eq!(m.worlds.len(), 100);
    assert_eq!(loaded, a);
    std::fs::remove_dir_all(da).ok();
    std::fs::remove_dir_all(db).ok();
}

#[test]
fn composition_matches_the_paper() {
    let worlds = default_set();
    assert_eq!(worlds.len(), 100);
    assert_eq!(worlds.iter().map(|w| w.tasks.len()).sum::<usize>(), 1000);
    let count = |f: &dyn Fn(&World) -> bool| worlds.iter().filter(|w| f(w)).count();
    // levels 1/3 each, types 60/30/10, densities 1/3 each (largest-remainder rounding)
    assert_eq!(count(&|w| w.meta.level == ElevationLevel::Low), 34);
    assert_eq!(count(&|w| w.meta.level == ElevationLevel::Mid), 33);
    assert_eq!(count(&|w| w.meta.level == ElevationLevel::High), 33);
    assert_eq!(count(&|w| w.meta.terrain_type == TerrainType::Rigid), 60);
    assert_eq!(
        count(&|w| w.meta.terrain_type == TerrainType::Deformable),
        30
    );
    assert_eq!(count(&|w| w.meta.terrain_type == TerrainType::Mixed), 10);
    for d in ObstacleDensity::ALL {
        assert!((33..=34).contains(&count(&|w| w.meta.density == d)));
    }
    for w in &worlds {
        let (rocks, trees) = w.meta.density.counts();
        assert_eq!(w.obstacles.iter().filter(|o| o.is_rock()).count(), rocks);
        assert_eq!(w.obstacles.len(), rocks + trees);
        // heights within the level's ceiling
        assert!(
            w.terrain.min_height() >= 0.0 && w.terrain.max_height() <= w.meta.level.max_height()
        );
        // patch kinds follow the world type
        let soil = w
            .patches
            .patches()
            .iter()
            .filter(|p| p.surface.is_deformable())
            .count();
        match w.meta.terrain_type {
            TerrainType::Rigid => assert_eq!(soil, 0),
            TerrainType::Deformable => assert_eq!(soil, 256),
            TerrainType::Mixed => assert!(
                soil > 0 && soil < 256,
                "{}: {soil} soil patches",
                w.meta.name
            ),
        }
    }
    // relief grows with the level (mean relief low < mid < high)
    let relief = |l: ElevationLevel| {
        let ws: Vec<&World> = worlds.iter().filter(|w| w.meta.level == l).collect();
        ws.iter()
            .map(|w| w.terrain.max_height() - w.terrain.min_height())
            .sum::<f64>()
            / ws.len() as f64
    };
    let (lo, mid, hi) = (
        relief(ElevationLevel::Low),
        relief(ElevationLevel::Mid),
        relief(ElevationLevel::High),
    );
    assert!(lo < mid && mid < hi, "{lo} {mid} {hi}");
    // the reference's mean relief per level is 1.8 / 3.5 / 5.9 m
    assert!((hi - 5.9).abs() < 1.5, "high relief {hi}");
}

#[test]
fn ten_metre_rule_holds() {
    for w in default_set() {
        let centres: Vec<[f64; 2]> = w
            .obstacles
            .iter()
            .map(|o| [o.position().x, o.position().y])
            .collect();
        let points: Vec<[f64; 2]> = w.tasks.iter().flat_map(|t| [t.start, t.goal]).collect();
        for (i, a) in centres.iter().enumerate() {
            for b in centres[i + 1..].iter().chain(&points) {
                let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                assert!(
                    d >= 10.0,
                    "{}: obstacle {i} is {d:.2} m from another obstacle or a start/goal",
                    w.meta.name
                );
            }
        }
    }
}

#[test]
fn every_global_path_connects_start_to_goal_with_clearance() {
    for w in default_set() {
        let grid = PlanningGrid::new(
            w.terrain.size(),
            w.terrain.cell(),
            &w.obstacles,
            w.path_clearance,
        );
        for (t, p) in w.tasks.iter().zip(&w.paths) {
            assert!(
                p.points.len() >= 2,
                "{} pair {}: no path",
                w.meta.name,
                t.pair
            );
            assert_eq!(p.points[0], t.start);
            assert_eq!(*p.points.last().unwrap(), t.goal);
            // dense check of every segment against the exact obstacle footprints
            for s in p.points.windows(2) {
                let len = ((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2)).sqrt();
                let k = (len / 0.05).ceil() as usize;
                for i in 0..=k {
                    let f = i as f64 / k.max(1) as f64;
                    let (x, y) = (
                        s[0][0] + f * (s[1][0] - s[0][0]),
                        s[0][1] + f * (s[1][1] - s[0][1]),
                    );
                    let d = w.obstacle_distance(x, y);
                    assert!(
                        d >= w.path_clearance - 1e-9,
                        "{} pair {}: path passes {d:.3} m from an obstacle",
                        w.meta.name,
                        t.pair
                    );
                    assert!(w.terrain.contains(x, y));
                }
            }
            assert!(grid.segment_clear(p.points[0], p.points[1]));
            assert!(p.length() >= t.distance() - 1e-9);
        }
    }
}

#[test]
fn scaled_sets_scale_every_length() {
    let full = generate_set(
        &SetConfig {
            count: 3,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap();
    let small = generate_set(
        &SetConfig {
            count: 3,
            scale: 0.1,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap();
    for (f, s) in full.iter().zip(&small) {
        assert!((s.terrain.half_extent() - 6.4).abs() < 1e-12);
        assert!((s.tasks[0].distance() - 12.0).abs() < 1e-9);
        assert!((s.meta.max_height - 0.1 * f.meta.max_height).abs() < 1e-12);
        assert!((s.path_clearance - 0.25).abs() < 1e-12);
        let rf = f.obstacles[0].radius_xy();
        let rs = s.obstacles[0].radius_xy();
        assert!((rs / rf - 0.1).abs() < 1e-6, "{rs} vs {rf}");
        // same structure, scaled: heights are proportional (to f32 rounding)
        let (hf, hs) = (f.terrain.vertex(40, 50), s.terrain.vertex(40, 50));
        assert!((hs - 0.1 * hf).abs() < 1e-5);
    }
}

/// Writes a valid world, then breaks one thing at a time and checks the error names the file,
/// the field and the problem.
#[test]
fn corrupt_worlds_give_clear_errors() {
    let w = one_default_world().unwrap();
    let base = tmp("corrupt");
    save_world(&w, &base).unwrap();
    assert_eq!(load_world(&base).unwrap(), w);
    let manifest = std::fs::read_to_string(base.join("world.yaml")).unwrap();

    let case = |name: &str, edit: &dyn Fn(&Path)| -> String {
        let d = tmp(&format!("corrupt-{name}"));
        std::fs::create_dir_all(&d).unwrap();
        for f in ["world.yaml", "elevation.npy", "labels.npy"] {
            std::fs::copy(base.join(f), d.join(f)).unwrap();
        }
        edit(&d);
        let e = load_world(&d).expect_err(name).to_string();
        std::fs::remove_dir_all(&d).ok();
        e
    };
    let first_friction = manifest
        .split("friction: ")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_string();

    let e = case("version", &|d| {
        std::fs::write(
            d.join("world.yaml"),
            manifest.replace("version: 1", "version: 7"),
        )
        .unwrap()
    });
    assert!(
        e.contains("world.yaml") && e.contains("version") && e.contains('7'),
        "{e}"
    );
    let e = case("friction", &|d| {
        std::fs::write(
            d.join("world.yaml"),
            manifest.replacen(&first_friction, "5.0", 1),
        )
        .unwrap()
    });
    assert!(e.contains("patches[0].friction") && e.contains("5"), "{e}");
    let e = case("class", &|d| {
        std::fs::write(
            d.join("world.yaml"),
            manifest.replacen("class: ", "class: lava", 1),
        )
        .unwrap()
    });
    assert!(e.contains("world.yaml") && e.contains("lava"), "{e}");
    let e = case("yaml", &|d| {
        std::fs::write(d.join("world.yaml"), &manifest[..manifest.len() / 2]).unwrap()
    });
    assert!(e.contains("world.yaml"), "{e}");
    let e = case("npy-missing", &|d| {
        std::fs::remove_file(d.join("elevation.npy")).unwrap()
    });
    assert!(e.contains("elevation.npy"), "{e}");
    let e = case("npy-garbage", &|d| {
        std::fs::write(d.join("elevation.npy"), b"\x93NUMPY garbage").unwrap()
    });
    assert!(e.contains("elevation.npy"), "{e}");
    let e = case("npy-shape", &|d| {
        verti_world::npy::write_f32(&d.join("elevation.npy"), 3, 3, &[0.0; 9]).unwrap()
    });
    assert!(e.contains("elevation.npy") && e.contains("shape"), "{e}");
    let e = case("npy-nan", &|d| {
        let mut h: Vec<f32> = w.terrain.heights().iter().map(|&v| v as f32).collect();
        h[130] = f32::NAN;
        verti_world::npy::write_f32(&d.join("elevation.npy"), 129, 129, &h).unwrap();
    });
    assert!(
        e.contains("elevation.npy") && e.contains("row 1, column 1") && e.contains("NaN"),
        "{e}"
    );
    let e = case("labels", &|d| {
        let mut l: Vec<i32> = w.labels().into_iter().map(i32::from).collect();
        l[5] = (l[5] + 1) % 10;
        verti_world::npy::write_i32(&d.join("labels.npy"), 129, 129, &l).unwrap();
    });
    assert!(e.contains("labels.npy") && e.contains("disagrees"), "{e}");
    let e = case("task", &|d| {
        std::fs::write(
            d.join("world.yaml"),
            manifest.replacen("start: [60.0, 0.0]", "start: [600.0, 0.0]", 1),
        )
        .unwrap()
    });
    assert!(e.contains("tasks[0].start") && e.contains("600"), "{e}");
    let e = case("unknown-field", &|d| {
        std::fs::write(
            d.join("world.yaml"),
            manifest.replace("density:", "densty: dense\ndensity:"),
        )
        .unwrap()
    });
    assert!(e.contains("densty"), "{e}");
    std::fs::remove_dir_all(base).ok();
}
