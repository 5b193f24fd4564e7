//! Renders a few worlds of the default set and its elevation histograms into a folder, and
//! prints the set statistics: `cargo run -p verti-render --example render_set -- /tmp/render`.

use std::path::PathBuf;
use verti_render::{
    RenderOptions, TrajectoryStyle, draw_trajectory, elevation_histograms_png, render_world,
};
use verti_world::generate::{SetConfig, generate_set};
use verti_world::stats::set_stats;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "render-out".into()),
    );
    std::fs::create_dir_all(&out)?;
    let worlds = generate_set(&SetConfig::default(), &|| {})?;
    let stats = set_stats(&worlds);
    println!("{stats}");
    elevation_histograms_png(&stats, &out.join("elevation_histograms.png"))?;
    // One world of each level and each terrain type, then a grid view and a single pair.
    let mut picked = Vec::new();
    for w in &worlds {
        let new_level = !picked
            .iter()
            .any(|p: &&verti_world::World| p.meta.level == w.meta.level);
        let new_type = !picked
            .iter()
            .any(|p: &&verti_world::World| p.meta.terrain_type == w.meta.terrain_type);
        if new_level || new_type {
            picked.push(w);
        }
    }
    for w in &picked {
        let name = format!(
            "world_{:03}_{}_{}_{}.png",
            w.meta.index, w.meta.level, w.meta.terrain_type, w.meta.density
        );
        render_world(w, &RenderOptions::default())?.save_png(&out.join(name))?;
    }
    let w = picked[0];
    let opts = RenderOptions {
        pairs: Some(vec![3]),
        show_grid: true,
        ..Default::default()
    };
    let mut img = render_world(w, &opts)?;
    // A fake drive along the global path with speed rising then falling, failing near the end.
    let path = &w.paths[3].points;
    let pts = verti_world::paths::resample(path, 0.5);
    let n = pts.len();
    let speeds: Vec<f64> = (0..n)
        .map(|i| 4.0 * (std::f64::consts::PI * i as f64 / n as f64).sin())
        .collect();
    let cut = n * 4 / 5;
    let style = TrajectoryStyle {
        failure: Some(pts[cut - 1]),
        ..Default::default()
    };
    draw_trajectory(&mut img, &pts[..cut], &speeds[..cut], &style)?;
    img.save_png(&out.join("trajectory_demo.png"))?;
    let small = RenderOptions {
        pixels_per_cell: 1,
        ..Default::default()
    };
    render_world(w, &small)?.save_png(&out.join("small_ppc1.png"))?;
    let big = RenderOptions {
        pixels_per_cell: 8,
        ..Default::default()
    };
    render_world(worlds.last().unwrap(), &big)?.save_png(&out.join("big_ppc8.png"))?;
    // A 1/6-scale world: metres shrink, pixels per cell do not.
    let sixth = generate_set(
        &SetConfig {
            count: 1,
            scale: 1.0 / 6.0,
            ..Default::default()
        },
        &|| {},
    )?;
    render_world(&sixth[0], &RenderOptions::default())?.save_png(&out.join("scale_sixth.png"))?;
    // Original Verti-Bench worlds, when a folder of them is given as the second argument.
    if let Some(vb) = std::env::args().nth(2) {
        use verti_world::import_vb::{ImportOptions, import_vb, scan_vb_dir};
        let mut vb_worlds = Vec::new();
        for f in scan_vb_dir(std::path::Path::new(&vb))? {
            vb_worlds.push(import_vb(
                &f.config,
                &f.heightmap,
                f.labels.as_deref(),
                &ImportOptions::default(),
            )?);
        }
        let vb_stats = set_stats(&vb_worlds);
        println!("\nVerti-Bench worlds\n{vb_stats}");
        elevation_histograms_png(&vb_stats, &out.join("vb_elevation_histograms.png"))?;
        for w in vb_worlds.iter().take(3) {
            let name = format!(
                "vb_{:03}_{}_{}.png",
                w.meta.index, w.meta.level, w.meta.density
            );
            render_world(w, &RenderOptions::default())?.save_png(&out.join(name))?;
        }
    }
    println!("wrote {}", out.display());
    Ok(())
}
