//! Every original Verti-Bench world in ../shared imports and renders (the data is not part of
//! the repository; the test says so and passes when it is absent).

use std::path::PathBuf;
use verti_render::{RenderOptions, render_world};
use verti_world::import_vb::{ImportOptions, import_vb, scan_vb_dir};

#[test]
fn all_shared_verti_bench_worlds_render() {
    let dir =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/verti-bench-data/worlds");
    if !dir.is_dir() {
        eprintln!(
            "SKIPPED: {} is absent; Verti-Bench render checks not run",
            dir.display()
        );
        return;
    }
    let files = scan_vb_dir(&dir).unwrap();
    assert_eq!(files.len(), 80);
    let options = RenderOptions {
        pixels_per_cell: 2,
        ..Default::default()
    };
    for f in &files {
        let w = import_vb(
            &f.config,
            &f.heightmap,
            f.labels.as_deref(),
            &ImportOptions::default(),
        )
        .unwrap();
        let img = render_world(&w, &options).unwrap_or_else(|e| panic!("{}: {e}", w.meta.name));
        // the map area is (n - 1) cells at 2 px each, plus the title and legend around it
        assert!(
            img.image.width() >= 256 && img.image.height() >= 256,
            "{}",
            w.meta.name
        );
        // every obstacle centre lands on a dark pixel (obstacles are drawn filled, near-black)
        for o in &w.obstacles {
            let p = o.position();
            if let Some((px, py)) = img.map.pixel_of(p.x, p.y) {
                let c = img.image.get_pixel(px, py);
                assert!(
                    c[0] < 110 && c[2] < 110,
                    "{}: obstacle at ({:.1}, {:.1}) drawn as {:?}",
                    w.meta.name,
                    p.x,
                    p.y,
                    c
                );
            }
        }
    }
}
