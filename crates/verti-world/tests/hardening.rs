//! Input hardening (issue 10): oversized and deeply nested YAML, values that parse but cannot
//! describe a world, and paths that are not what they seem. Each error must name the file, the
//! field and the problem.

use std::path::{Path, PathBuf};
use std::time::Instant;
use verti_world::World;
use verti_world::format::{load_world, save_set, save_world};
use verti_world::generate::{SetConfig, generate_set, one_default_world};
use verti_world::sets::{resolve_set, resolve_world};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-hard-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn one_world() -> World {
    one_default_world().unwrap()
}

/// Saves `w` to a fresh directory, lets `edit` spoil it, and returns the load error.
fn load_error(name: &str, w: &World, edit: &dyn Fn(&Path, &str)) -> String {
    let d = tmp(name);
    save_world(w, &d).unwrap();
    let manifest = std::fs::read_to_string(d.join("world.yaml")).unwrap();
    edit(&d, &manifest);
    let e = load_world(&d).expect_err(name).to_string();
    std::fs::remove_dir_all(&d).ok();
    e
}

fn heights(w: &World) -> Vec<f32> {
    w.terrain.heights().iter().map(|&h| h as f32).collect()
}

#[test]
fn nested_and_oversized_manifests_are_refused_quickly() {
    let w = one_world();
    // 200 KB of nested lists (56 s in the parser before the pre-scan)
    let t0 = Instant::now();
    let e = load_error("nested", &w, &|d, m| {
        let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
        std::fs::write(
            d.join("world.yaml"),
            m.replacen("patches:", &format!("junk: {deep}\npatches:"), 1),
        )
        .unwrap()
    });
    assert!(t0.elapsed().as_secs_f64() < 1.0, "took {:?}", t0.elapsed());
    assert!(
        e.contains("world.yaml") && e.contains("nesting depth") && e.contains("limit of 64"),
        "{e}"
    );
    // a file over the cap is refused by its size, before it is read
    let e = load_error("huge", &w, &|d, _| {
        let f = std::fs::File::create(d.join("world.yaml")).unwrap();
        f.set_len(50 << 20).unwrap();
    });
    assert!(
        e.contains("world.yaml") && e.contains("50.0 MiB") && e.contains("at most 4.0 MiB"),
        "{e}"
    );
    let e = load_error("binary", &w, &|d, _| {
        std::fs::write(d.join("world.yaml"), [0xff, 0xfe, 0x00, 0x41]).unwrap()
    });
    assert!(e.contains("world.yaml") && e.contains("UTF-8"), "{e}");
}

#[test]
fn values_that_cannot_describe_a_world_are_named() {
    let w = one_world();
    let n = w.terrain.size();
    let max_h = w.meta.max_height;
    let write_heights = |d: &Path, h: &[f32]| {
        verti_world::npy::write_f32(&d.join("elevation.npy"), n, n, h).unwrap()
    };

    let e = load_error("spike", &w, &|d, _| {
        let mut h = heights(&w);
        h[3 * n + 7] = 1e30;
        write_heights(d, &h)
    });
    assert!(
        e.contains("elevation.npy") && e.contains("row 3, column 7") && e.contains("1000000015"),
        "{e}"
    );
    let e = load_error("above", &w, &|d, _| {
        let mut h = heights(&w);
        h[0] = (max_h * 1.01) as f32;
        write_heights(d, &h)
    });
    assert!(e.contains("above the world's max_height"), "{e}");
    let e = load_error("below", &w, &|d, _| {
        let mut h = heights(&w);
        h[1] = -0.5;
        write_heights(d, &h)
    });
    assert!(e.contains("-0.5") && e.contains("below 0"), "{e}");

    // the level names the ceiling: a low world with a high world's max_height
    let level = w.meta.level.name();
    let other = if level == "low" { "high" } else { "low" };
    let e = load_error("level", &w, &|d, m| {
        std::fs::write(
            d.join("world.yaml"),
            m.replace(&format!("level: {level}"), &format!("level: {other}")),
        )
        .unwrap()
    });
    assert!(
        e.contains("world.yaml") && e.contains("field `level`") && e.contains("contradicts"),
        "{e}"
    );
    let e = load_error("cell", &w, &|d, m| {
        std::fs::write(d.join("world.yaml"), m.replace("cell: 1.0", "cell: 0.5")).unwrap()
    });
    assert!(
        e.contains("grid.cell") && e.contains("0.5") && e.contains("scale 1"),
        "{e}"
    );
    let e = load_error("size", &w, &|d, m| {
        std::fs::write(d.join("world.yaml"), m.replace("size: 129", "size: 257")).unwrap()
    });
    assert!(e.contains("grid.size") && e.contains("257"), "{e}");
    let e = load_error("clearance", &w, &|d, m| {
        let c = format!("clearance: {:?}", w.path_clearance);
        std::fs::write(d.join("world.yaml"), m.replace(&c, "clearance: -1.0")).unwrap()
    });
    assert!(e.contains("paths.clearance") && e.contains("-1"), "{e}");

    // an obstacle 1 km up floats; a path point off the map
    let z = w.obstacles[0].position().z;
    let e = load_error("floating", &w, &|d, m| {
        let at = format!("{z:?}]");
        assert!(m.contains(&at), "{at}");
        std::fs::write(d.join("world.yaml"), m.replacen(&at, "1000.0]", 1)).unwrap()
    });
    assert!(
        e.contains("obstacles[0]") && e.contains("floats or is buried"),
        "{e}"
    );
    let p = w
        .paths
        .iter()
        .find(|p| !p.points.is_empty())
        .unwrap()
        .points[1];
    let e = load_error("path", &w, &|d, m| {
        let at = format!("[{:?}, {:?}]", p[0], p[1]);
        assert!(m.contains(&at), "{at}");
        std::fs::write(d.join("world.yaml"), m.replacen(&at, "[5000.0, 0.0]", 1)).unwrap()
    });
    assert!(e.contains("paths.paths[") && e.contains("5000"), "{e}");
}

#[test]
fn manifests_that_are_not_files_say_what_they_are() {
    let w = one_world();
    let d = tmp("kinds");
    save_world(&w, &d).unwrap();
    std::fs::remove_file(d.join("world.yaml")).unwrap();
    std::fs::create_dir(d.join("world.yaml")).unwrap();
    let spec = d.to_str().unwrap();
    for e in [
        load_world(&d).unwrap_err().to_string(),
        resolve_world(spec, 1.0).unwrap_err().to_string(),
        resolve_set(spec, 1.0, &|| {}).unwrap_err().to_string(),
    ] {
        assert!(
            e.contains("world.yaml") && e.contains("is a directory") && !e.contains("not a world"),
            "{e}"
        );
    }
    #[cfg(unix)]
    {
        std::fs::remove_dir(d.join("world.yaml")).unwrap();
        std::os::unix::fs::symlink(d.join("world.yaml"), d.join("world.yaml")).unwrap();
        for e in [
            load_world(&d).unwrap_err().to_string(),
            resolve_world(spec, 1.0).unwrap_err().to_string(),
        ] {
            assert!(
                e.contains("world.yaml") && e.contains("symbolic link loop"),
                "{e}"
            );
        }
        // a set whose set.yaml is a loop
        let s = tmp("set-loop");
        std::os::unix::fs::symlink(s.join("set.yaml"), s.join("set.yaml")).unwrap();
        let e = resolve_set(s.to_str().unwrap(), 1.0, &|| {})
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("set.yaml") && e.contains("symbolic link loop"),
            "{e}"
        );
        std::fs::remove_dir_all(s).ok();
    }
    // a directory with nothing in it is not a set, and the error says what it lacks
    let empty = tmp("empty");
    let e = resolve_set(empty.to_str().unwrap(), 1.0, &|| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("not a world set") && e.contains("set.yaml"),
        "{e}"
    );
    std::fs::remove_dir_all(empty).ok();
    std::fs::remove_dir_all(d).ok();
}

#[test]
fn worlds_at_the_ends_of_the_scale_range_round_trip() {
    for scale in [1e-3, 1.0 / 6.0, 0.1, 10.0] {
        let config = SetConfig {
            count: 3,
            scale,
            ..Default::default()
        };
        let worlds = generate_set(&config, &|| {}).unwrap();
        let d = tmp(&format!("scale-{scale}"));
        save_set(&worlds, "s", None, &d, &|| {}).unwrap();
        let (_, back) = verti_world::format::load_set(&d).unwrap();
        assert_eq!(back, worlds, "scale {scale}");
        std::fs::remove_dir_all(d).ok();
    }
}

#[test]
fn sixteen_bit_heightmaps_are_refused() {
    // a 2x2 RGB555 BMP: 14-byte file header, 40-byte info header, rows padded to 4 bytes
    let mut b = Vec::new();
    let data_len = 2 * 4;
    b.extend_from_slice(b"BM");
    b.extend_from_slice(&(54u32 + data_len).to_le_bytes());
    b.extend_from_slice(&[0; 4]);
    b.extend_from_slice(&54u32.to_le_bytes());
    b.extend_from_slice(&40u32.to_le_bytes());
    b.extend_from_slice(&2i32.to_le_bytes());
    b.extend_from_slice(&2i32.to_le_bytes());
    b.extend_from_slice(&1u16.to_le_bytes());
    b.extend_from_slice(&16u16.to_le_bytes());
    b.extend_from_slice(&[0; 24]);
    b.extend_from_slice(&[0xff, 0x7f, 0xff, 0x7f, 0, 0, 0, 0]);
    let d = tmp("bmp16");
    let p = d.join("world1.bmp");
    std::fs::write(&p, &b).unwrap();
    let e = verti_world::import_vb::read_grey_bmp(&p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("world1.bmp") && e.contains("16-bit BMP"), "{e}");
    std::fs::remove_dir_all(d).ok();
}

#[test]
fn a_set_may_not_hold_one_world_or_one_index_twice() {
    let worlds = generate_set(
        &SetConfig {
            count: 2,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap();
    let dir = tmp("twice");
    save_set(&worlds, "two", Some(0), &dir, &|| {}).unwrap();
    let manifest = dir.join("set.yaml");
    let text = std::fs::read_to_string(&manifest).unwrap();
    assert!(text.contains("[world-001, world-002]"), "{text}");
    std::fs::write(
        &manifest,
        text.replace("[world-001, world-002]", "[world-001, world-001]"),
    )
    .unwrap();
    let e = resolve_set(dir.to_str().unwrap(), 1.0, &|| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("set.yaml") && e.contains("`world-001` is listed twice"),
        "{e}"
    );
    // two directories, one index
    std::fs::write(&manifest, &text).unwrap();
    let second = dir.join("world-002").join("world.yaml");
    let w2 = std::fs::read_to_string(&second).unwrap();
    assert!(w2.contains("\nindex: 2\n"), "{w2}");
    std::fs::write(&second, w2.replace("\nindex: 2\n", "\nindex: 1\n")).unwrap();
    let e = resolve_set(dir.to_str().unwrap(), 1.0, &|| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("both have index 1"), "{e}");
}
