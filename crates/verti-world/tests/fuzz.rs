//! Bounded property tests (issue 10): no input may panic. Real files written by the generator
//! are mutated (bytes flipped, inserted, deleted, the file cut short, numbers swapped for
//! extreme ones) and loaded; every load must return `Ok` or `Err`. Generation is driven with
//! arbitrary scales and seeds. Case counts are capped so the whole file runs in seconds in a
//! debug build; a failing case is shrunk and printed by proptest.

use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use verti_testkit::mutate::{
    EXTREMES, Edit, edit_strategy, edited, number_edit, text_edit_strategy,
};
use verti_world::format::{ELEVATION, LABELS, MANIFEST, load_world, save_world};
use verti_world::generate::elevation::ProceduralRock;
use verti_world::generate::{SetConfig, composition, generate_world, one_default_world};
use verti_world::import_vb::read_grey_bmp;
use verti_world::scale::{MAX_SCALE, MIN_SCALE, parse_scale};

/// The files of one real generated world: (name, bytes).
fn real_world_files() -> &'static Vec<(&'static str, Vec<u8>)> {
    static FILES: OnceLock<Vec<(&'static str, Vec<u8>)>> = OnceLock::new();
    FILES.get_or_init(|| {
        let w = one_default_world().unwrap();
        let dir = case_dir("source");
        save_world(&w, &dir).unwrap();
        let files = [MANIFEST, ELEVATION, LABELS]
            .into_iter()
            .map(|f| (f, std::fs::read(dir.join(f)).unwrap()))
            .collect();
        std::fs::remove_dir_all(&dir).ok();
        files
    })
}

/// Writes the real world with `file` replaced by `bytes` and loads it.
fn load_with(file: &str, bytes: &[u8]) {
    let dir = case_dir("load");
    for (name, real) in real_world_files() {
        let content: &[u8] = if *name == file { bytes } else { real };
        std::fs::write(dir.join(name), content).unwrap();
    }
    // Ok or Err are both fine; a panic fails the test
    let _ = load_world(&dir);
    std::fs::remove_dir_all(&dir).ok();
}

fn mutated(file: &str, edits: &[Edit]) -> Vec<u8> {
    let real = &real_world_files()
        .iter()
        .find(|(n, _)| *n == file)
        .unwrap()
        .1;
    edited(real, edits)
}

/// Edits of a binary file: any byte values, and numbers swapped for extreme ones (one edit in
/// five), which reach the shape written in an `.npy` header.
fn binary_edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![4 => edit_strategy(), 1 => number_edit(EXTREMES)]
}

/// A fresh directory per call (cases may run on several threads of one process).
fn case_dir(tag: &str) -> PathBuf {
    verti_testkit::case_dir("verti-fuzz", tag)
}

/// A 129 x 129 8-bit palettised grey BMP, laid out like the Verti-Bench heightmaps.
fn grey_bmp() -> Vec<u8> {
    let (n, row) = (129u32, 132u32);
    let offset = 14 + 40 + 1024;
    let mut b = Vec::new();
    b.extend_from_slice(b"BM");
    b.extend_from_slice(&(offset + row * n).to_le_bytes());
    b.extend_from_slice(&[0; 4]);
    b.extend_from_slice(&offset.to_le_bytes());
    for v in [40u32, n, n] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&1u16.to_le_bytes());
    b.extend_from_slice(&8u16.to_le_bytes());
    b.extend_from_slice(&[0; 16]);
    b.extend_from_slice(&256u32.to_le_bytes());
    b.extend_from_slice(&256u32.to_le_bytes());
    for g in 0..=255u8 {
        b.extend_from_slice(&[g, g, g, 0]);
    }
    for r in 0..n {
        for c in 0..row {
            b.push(((r * 7 + c * 3) % 256) as u8);
        }
    }
    b
}

fn bmp_path(dir: &Path) -> PathBuf {
    dir.join("world1.bmp")
}

proptest! {
    #![proptest_config(verti_testkit::config(64))]

    #[test]
    fn mutated_manifests_never_panic(edits in prop::collection::vec(text_edit_strategy(), 1..6)) {
        load_with(MANIFEST, &mutated(MANIFEST, &edits));
    }

    #[test]
    fn random_manifests_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        load_with(MANIFEST, &bytes);
    }

    #[test]
    fn mutated_arrays_never_panic(
        which in prop::bool::ANY,
        edits in prop::collection::vec(binary_edit_strategy(), 1..6),
    ) {
        let file = if which { ELEVATION } else { LABELS };
        load_with(file, &mutated(file, &edits));
    }

    #[test]
    fn mutated_heightmaps_never_panic(edits in prop::collection::vec(binary_edit_strategy(), 1..6)) {
        let bytes = edited(&grey_bmp(), &edits);
        let dir = case_dir("bmp");
        std::fs::write(bmp_path(&dir), &bytes).unwrap();
        let _ = read_grey_bmp(&bmp_path(&dir));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn scale_text_never_panics(
        chars in prop::collection::vec(prop::sample::select(b"0123456789./e+- ".to_vec()), 0..12),
    ) {
        let text = String::from_utf8(chars).unwrap();
        if let Ok(s) = parse_scale(&text) {
            prop_assert!((MIN_SCALE..=MAX_SCALE).contains(&s));
        }
    }
}

/// Scales from everywhere: any bit pattern, the range's edges, and values inside it.
fn scale_strategy() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        Just(0.0),
        Just(1e-8),
        Just(MIN_SCALE),
        Just(MIN_SCALE * (1.0 - 1e-12)),
        Just(MAX_SCALE),
        Just(MAX_SCALE * (1.0 + 1e-12)),
        (MIN_SCALE..=MAX_SCALE),
        (-3.0f64..1.0).prop_map(|e| 10f64.powf(e)),
    ]
}

proptest! {
    // generation is the expensive case (a world with its paths): fewer cases
    #![proptest_config(verti_testkit::config(16))]

    #[test]
    fn generation_never_panics_and_refuses_only_out_of_range_scales(
        scale in scale_strategy(),
        seed in any::<u64>(),
        index in 1u32..=100,
    ) {
        let config = SetConfig { seed, count: 100, scale, ..Default::default() };
        let (level, ty, density) = composition(&SetConfig { seed, ..Default::default() })
            [index as usize - 1];
        let r = generate_world(&config, index, level, ty, density, &ProceduralRock::default());
        let in_range = scale.is_finite() && (MIN_SCALE..=MAX_SCALE).contains(&scale);
        match r {
            Ok(w) => prop_assert!(in_range && w.meta.scale == scale),
            Err(e) => {
                prop_assert!(!in_range, "scale {scale} is in range but failed: {e}");
                prop_assert!(e.to_string().contains("scale"), "{e}");
            }
        }
    }
}
