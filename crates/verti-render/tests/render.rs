//! Renders real generated worlds and checks, through the public coordinate mapping, that what
//! should be where is there: dark obstacles, red paths, green starts, red goal rings.

use image::Rgb;
use std::path::PathBuf;
use verti_core::Vec3;
use verti_render::{
    MapTransform, RenderError, RenderOptions, TrajectoryStyle, draw_trajectory,
    elevation_histograms_png, palette, render_world,
};
use verti_world::generate::{SetConfig, generate_set};
use verti_world::obstacle::box_faces;
use verti_world::stats::set_stats;
use verti_world::surface::{Patch, PatchGrid, RIGID_RESTITUTION};
use verti_world::{
    ElevationLevel, Heightfield, Obstacle, ObstacleDensity, Surface, TerrainClass, TerrainType,
    World, WorldMeta, WorldSource,
};

fn worlds() -> Vec<World> {
    generate_set(
        &SetConfig {
            count: 3,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap()
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-render-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn is_dark(p: &Rgb<u8>) -> bool {
    p.0.iter().all(|&v| v < 70)
}

fn is_red(p: &Rgb<u8>) -> bool {
    p[0] > 180 && p[1] < 90 && p[2] < 90
}

/// Distance from (x, y) to the nearest point of every drawn path, start and goal.
fn clear_of_tasks(w: &World, x: f64, y: f64) -> f64 {
    let mut d = f64::INFINITY;
    for t in &w.tasks {
        d = d
            .min((t.start[0] - x).hypot(t.start[1] - y))
            .min((t.goal[0] - x).hypot(t.goal[1] - y));
    }
    for p in &w.paths {
        for q in &p.points {
            d = d.min((q[0] - x).hypot(q[1] - y));
        }
    }
    d
}

#[test]
fn world_render_has_the_expected_layout_and_content() {
    let w = &worlds()[0];
    let img = render_world(w, &RenderOptions::default()).unwrap();
    // 128 cells x 4 px: the map covers exactly the world's extent.
    assert_eq!(img.map.size_px(), 512.0);
    assert!(img.image.width() >= 512 + 150 && img.image.height() >= 512);
    // The map's corners map to the world's corners.
    let h = w.terrain.half_extent();
    assert_eq!(img.map.to_pixel(-h, h), img.map.origin);
    let (px, py) = img.map.to_pixel(h, -h);
    assert_eq!(
        (px - img.map.origin.0, py - img.map.origin.1),
        (512.0, 512.0)
    );

    // Every rock is dark at its centre (rocks whose centre is clear of paths and markers).
    let mut checked = 0;
    for o in w.obstacles.iter().filter(|o| o.is_rock()) {
        let p = o.position();
        if o.footprint_distance(p.x, p.y) < -0.5 && clear_of_tasks(w, p.x, p.y) > 4.0 {
            let (i, j) = img.map.pixel_of(p.x, p.y).unwrap();
            assert!(
                is_dark(img.image.get_pixel(i, j)),
                "rock at {p:?} is {:?}",
                img.image.get_pixel(i, j)
            );
            checked += 1;
        }
    }
    assert!(checked >= 5, "only {checked} rocks checked");

    // Path pixels are red halfway along every path segment that is away from the markers.
    let mut reds = 0;
    for p in &w.paths {
        for s in p.points.windows(2) {
            let (x, y) = (0.5 * (s[0][0] + s[1][0]), 0.5 * (s[0][1] + s[1][1]));
            let near_marker = w.tasks.iter().any(|t| {
                (t.start[0] - x).hypot(t.start[1] - y) < 6.0
                    || (t.goal[0] - x).hypot(t.goal[1] - y) < 6.0
            });
            if !near_marker {
                // The 2 px line is anti-aliased: the pixel under the point may be partly covered,
                // but one of its neighbours is fully on the line.
                let (i, j) = img.map.pixel_of(x, y).unwrap();
                let red = (i - 1..=i + 1)
                    .any(|a| (j - 1..=j + 1).any(|b| is_red(img.image.get_pixel(a, b))));
                assert!(red, "no red pixel around the path at ({x}, {y})");
                reds += 1;
            }
        }
    }
    assert!(reds > 10);

    // Starts are green discs; goals are red rings (the ring passes ~2.5 cells from the goal).
    let t = &w.tasks[0];
    let (i, j) = img.map.pixel_of(t.start[0], t.start[1]).unwrap();
    assert_eq!(img.image.get_pixel(i, j), &palette::START);
    let mut options = RenderOptions {
        pairs: Some(vec![0]),
        ..Default::default()
    };
    let one = render_world(w, &options).unwrap();
    let (gx, gy) = one.map.to_pixel(t.goal[0], t.goal[1]);
    let ring_px = (0..8)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::FRAC_PI_4;
            one.image
                .get_pixel((gx + 8.8 * a.cos()) as u32, (gy + 8.8 * a.sin()) as u32)
        })
        .filter(|p| is_red(p))
        .count();
    assert!(ring_px >= 6, "goal ring: {ring_px} of 8 samples red");

    // Without paths and markers, the same places show terrain.
    options.show_paths = false;
    options.show_tasks = false;
    let bare = render_world(w, &options).unwrap();
    let (i, j) = bare.map.pixel_of(t.start[0], t.start[1]).unwrap();
    assert_ne!(bare.image.get_pixel(i, j), &palette::START);
}

#[test]
fn options_and_inputs_are_checked() {
    let w = &worlds()[1];
    let bad = render_world(
        w,
        &RenderOptions {
            pixels_per_cell: 0,
            ..Default::default()
        },
    );
    assert!(matches!(bad, Err(RenderError::Options(ref m)) if m.contains("pixels per cell")));
    let bad = render_world(
        w,
        &RenderOptions {
            pairs: Some(vec![42]),
            ..Default::default()
        },
    );
    assert!(matches!(bad, Err(RenderError::Options(ref m)) if m.contains("no pair 42")));

    let mut img = render_world(w, &RenderOptions::default()).unwrap();
    let e = draw_trajectory(
        &mut img,
        &[[0.0, 0.0], [1.0, 1.0]],
        &[1.0],
        &TrajectoryStyle::default(),
    );
    assert!(matches!(e, Err(RenderError::Input(_))));

    let missing = out_dir("missing").join("no/such/dir/w.png");
    let e = img.save_png(&missing).unwrap_err();
    assert!(e.to_string().contains("no/such/dir/w.png"), "{e}");
}

#[test]
fn pictures_are_written_only_as_png_into_existing_directories() {
    let img = render_world(&worlds()[0], &RenderOptions::default()).unwrap();
    let dir = out_dir("formats");
    let e = img.save_png(&dir.join("w.jpg")).unwrap_err().to_string();
    assert!(
        e.contains("w.jpg: `.jpg` is not a supported format; supported: .png"),
        "{e}"
    );
    assert!(!dir.join("w.jpg").exists());
    let e = img.save_png(&dir.join("w")).unwrap_err().to_string();
    assert!(e.contains("no extension; supported: .png"), "{e}");
    let missing = dir.join("typo");
    let e = img
        .save_png(&missing.join("deeper/w.png"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!(
            "directory {} does not exist",
            missing.join("deeper").display()
        )),
        "{e}"
    );
    assert!(!missing.exists(), "no directory is created");
    img.save_png(&dir.join("w.PNG")).unwrap();
}

#[test]
fn trajectory_is_coloured_by_speed_and_failure_is_marked() {
    let w = &worlds()[2];
    let mut img = render_world(
        w,
        &RenderOptions {
            show_paths: false,
            show_tasks: false,
            ..Default::default()
        },
    )
    .unwrap();
    let h_before = img.image.height();
    // A straight west-to-east drive along y = 20 m, slow to fast.
    let pts: Vec<[f64; 2]> = (0..=100).map(|i| [-50.0 + f64::from(i), 20.0]).collect();
    let speeds: Vec<f64> = (0..=100).map(f64::from).collect();
    let style = TrajectoryStyle {
        width_px: Some(4.0),
        failure: Some([50.0, 20.0]),
        ..Default::default()
    };
    draw_trajectory(&mut img, &pts, &speeds, &style).unwrap();
    let at = |x: f64| {
        let (i, j) = img.map.pixel_of(x, 20.0).unwrap();
        *img.image.get_pixel(i, j)
    };
    // Each segment takes the colour of its mean speed (the line is drawn over everything).
    for (x, t) in [(-45.5, 0.045), (0.5, 0.505), (40.5, 0.905)] {
        let want = palette::speed_color(t);
        let got = at(x);
        let d: i32 = (0..3)
            .map(|k| (i32::from(got[k]) - i32::from(want[k])).abs())
            .sum();
        assert!(d < 30, "at x = {x}: {got:?} vs {want:?}");
    }
    // The failure cross is dark at its centre.
    assert!(is_dark(&at(50.0)));
    assert!(img.image.height() >= h_before);
}

#[test]
fn histograms_png_is_written() {
    let stats = set_stats(&worlds());
    let path = out_dir("hist").join("elevation.png");
    elevation_histograms_png(&stats, &path).unwrap();
    let meta = std::fs::metadata(&path).unwrap();
    assert!(
        meta.len() > 5_000,
        "suspiciously small PNG: {} bytes",
        meta.len()
    );
    let back = image::open(&path).unwrap().to_rgb8();
    assert_eq!(back.width(), 3 * 420);
    // Not blank: bars and text are drawn.
    assert!(back.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 10_000);
    // An empty set draws empty panels rather than failing.
    elevation_histograms_png(&set_stats(&[]), &path).unwrap();
}

/// A hand-made world with the awkward cases: 2x2 vertices, flat, a rock half off the map, a
/// tree far outside, no tasks or paths.
#[test]
fn degenerate_worlds_render_without_panics() {
    let patch = Patch {
        class: TerrainClass::Sand,
        surface: Surface::Rigid {
            friction: 0.5,
            restitution: RIGID_RESTITUTION,
        },
    };
    let world = World {
        meta: WorldMeta {
            name: "edge".into(),
            index: 1,
            source: WorldSource::Generated {
                set_seed: 0,
                generator: "test".into(),
            },
            level: ElevationLevel::Low,
            terrain_type: TerrainType::Mixed,
            density: ObstacleDensity::Dense,
            scale: 1.0,
            max_height: 4.8,
        },
        terrain: Heightfield::new(2, 1.0, vec![1.0; 4]),
        patches: PatchGrid::new(vec![patch; 256], 1.0),
        obstacles: vec![
            Obstacle::rock(
                box_faces(Vec3::new(2.0, 2.0, 1.0)),
                1.0,
                Vec3::new(0.5, 0.0, 0.5),
                0.3,
            )
            .unwrap(),
            Obstacle::tree(0.3, 4.0, Vec3::new(1e7, -1e7, 2.0)).unwrap(),
        ],
        tasks: vec![],
        paths: vec![],
        path_clearance: 1.0,
    };
    for ppc in [1, 3, 32] {
        let img = render_world(
            &world,
            &RenderOptions {
                pixels_per_cell: ppc,
                show_grid: true,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(img.map.size_px(), f64::from(ppc));
    }
    let mut img = render_world(&world, &RenderOptions::default()).unwrap();
    draw_trajectory(
        &mut img,
        &[],
        &[],
        &TrajectoryStyle {
            failure: Some([f64::NAN, 0.0]),
            ..Default::default()
        },
    )
    .unwrap();
}

#[test]
fn transform_round_trips() {
    let m = MapTransform {
        origin: (10.0, 40.0),
        pixels_per_metre: 4.0,
        half_extent: 64.0,
    };
    let (px, py) = m.to_pixel(12.25, -3.5);
    let (x, y) = m.to_world(px, py);
    assert!((x - 12.25).abs() < 1e-12 && (y + 3.5).abs() < 1e-12);
    // north-east is up-right
    assert!(m.to_pixel(10.0, 10.0).0 > m.to_pixel(0.0, 0.0).0);
    assert!(m.to_pixel(10.0, 10.0).1 < m.to_pixel(0.0, 0.0).1);
    assert_eq!(m.pixel_of(100.0, 0.0), None);
}
