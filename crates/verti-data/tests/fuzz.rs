//! Damaged datasets (hardening issue, item 9): no manifest or Parquet file may panic the
//! reader. A tiny real dataset, written by the crate's own writer, is damaged and loaded;
//! every load must return `Ok` or an error naming a file of the dataset.
//!
//! The manifest's checksums catch damage to a Parquet file, so the damaged files here come
//! with a checksum that matches or none at all: the Parquet decoder itself then meets the
//! damage (it used to panic on some, e.g. a dictionary index out of range in `rle.rs`).
//!
//! Case counts are capped so the file runs in seconds in the dev profile; `PROPTEST_CASES`
//! overrides them for a longer run (`PROPTEST_CASES=5000 cargo test --release -p verti-data
//! --test fuzz`). A failing case is shrunk and printed by proptest.

use proptest::prelude::*;
use std::path::PathBuf;
use std::sync::OnceLock;
use verti_core::rng::Rng;
use verti_data::manifest::{FORMAT, MANIFEST, Manifest, WorldsInfo, checksum};
use verti_data::table::{FEATURES, Row, TrialRecord, WheelGround};
use verti_data::{DataOutcome, Dataset, Kind, Profile, write_trials};
use verti_testkit::config;
use verti_testkit::mutate::{Edit, apply, edit_strategy, edited, flip_edit, text_edit_strategy};

/// A fresh, empty directory per call (cases may run on several threads of one process).
fn case_dir(tag: &str) -> PathBuf {
    verti_testkit::case_dir("verti-data-fuzz", tag)
}

/// A trial of `n` rows with distinct values in every column (4 wheels).
fn trial(trial: u32, n: usize, outcome: DataOutcome) -> TrialRecord {
    let rows = (0..n)
        .map(|k| {
            let mut features = [0.0; FEATURES];
            for (i, f) in features.iter_mut().enumerate() {
                *f = trial as f64 * 100.0 + k as f64 + i as f64 * 0.01;
            }
            features[0] = k as f64 * 0.1;
            Row {
                features,
                steering: (k as f64).sin(),
                speed: 1.0 + k as f64 * 0.1,
                wheels: (0..4)
                    .map(|w| WheelGround {
                        class: ((k + w) % 10) as u8,
                        friction: 0.5 + w as f64 * 0.1,
                        soil: (k + w) % 2 == 0,
                    })
                    .collect(),
            }
        })
        .collect();
    TrialRecord {
        trial,
        world: 1,
        first_step: 0,
        rows,
        outcome,
    }
}

/// The files of a tiny dataset written by `write_trials`: (name, bytes), manifest first.
fn real_files() -> &'static Vec<(String, Vec<u8>)> {
    static FILES: OnceLock<Vec<(String, Vec<u8>)>> = OnceLock::new();
    FILES.get_or_init(|| {
        let dir = case_dir("source");
        let template = Manifest {
            format: FORMAT.into(),
            kind: Kind::Random,
            profile: Some(Profile::Paper),
            source: "fuzz".into(),
            worlds: WorldsInfo {
                set: "none".into(),
                name: "none".into(),
                seed: None,
                generator: "test".into(),
                scale: 1.0,
                indices: vec![],
            },
            vehicle: "hmmwv".into(),
            wheels: 4,
            rate: 10.0,
            max_trial_seconds: 60.0,
            seed: 0,
            hours_requested: 0.0,
            hours: 0.0,
            hours_simulated: 0.0,
            trials: 0,
            rows: 0,
            outcomes: Default::default(),
            eval_worlds: false,
            files: vec![],
            checksums: Default::default(),
            command: "fuzz".into(),
            verti_version: "test".into(),
        };
        let trials = [
            trial(0, 60, DataOutcome::Rollover),
            trial(1, 40, DataOutcome::Edge),
        ];
        let m = write_trials(&dir, &trials, template, false).unwrap();
        let mut files = vec![(
            MANIFEST.to_string(),
            std::fs::read(dir.join(MANIFEST)).unwrap(),
        )];
        for f in &m.files {
            files.push((f.clone(), std::fs::read(dir.join(f)).unwrap()));
        }
        std::fs::remove_dir_all(&dir).ok();
        files
    })
}

/// How the manifest vouches for a damaged Parquet file.
#[derive(Clone, Copy, Debug)]
enum Sum {
    /// The checksum is rewritten to match the damaged bytes.
    Matching,
    /// The manifest has no checksums (older datasets, hand-made ones).
    Absent,
    /// The manifest is left as written (its checksum refuses damage).
    Kept,
}

/// The manifest text with its checksums made to vouch for `files` as `sum` says.
fn vouched_manifest(text: &str, files: &[(String, Vec<u8>)], sum: Sum) -> String {
    let mut m: Manifest = serde_norway::from_str(text).unwrap();
    match sum {
        Sum::Matching => {
            for (name, bytes) in files {
                if let Some(c) = m.checksums.get_mut(name) {
                    *c = checksum(bytes);
                }
            }
        }
        Sum::Absent => m.checksums.clear(),
        Sum::Kept => {}
    }
    serde_norway::to_string(&m).unwrap()
}

/// Writes the dataset with `files` replacing the real ones (by name) and loads it: `Ok`, or
/// an error naming a file of the dataset. A panic fails the caller.
fn load_with(replaced: &[(String, Vec<u8>)]) -> Result<(), String> {
    let dir = case_dir("load");
    for (name, real) in real_files() {
        let bytes = replaced
            .iter()
            .find(|(n, _)| n == name)
            .map_or(real, |(_, b)| b);
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let r = Dataset::load(&dir);
    std::fs::remove_dir_all(&dir).ok();
    match r {
        Ok(_) => Ok(()),
        Err(e) => {
            let m = e.to_string();
            if m.contains(&dir.display().to_string()) {
                Err(m)
            } else {
                panic!("the error names no file of the dataset: {m}")
            }
        }
    }
}

/// The Parquet file of the dataset, damaged by `smash`, with the manifest vouching as `sum`
/// says; loaded under `catch_unwind` so a panic is counted, not fatal.
fn smashed(smash: impl Fn(&mut Vec<u8>), sum: Sum) -> std::thread::Result<Result<(), String>> {
    let files = real_files();
    let (name, bytes) = &files[1];
    let mut bad = bytes.clone();
    smash(&mut bad);
    let parquet = vec![(name.clone(), bad)];
    let manifest = vouched_manifest(std::str::from_utf8(&files[0].1).unwrap(), &parquet, sum);
    let mut replaced = parquet;
    replaced.push((MANIFEST.to_string(), manifest.into_bytes()));
    std::panic::catch_unwind(move || load_with(&replaced))
}

/// 80 seeded byte smashes of the Parquet file, half with a matching checksum and half with
/// none: each load is `Ok` or an error naming the file, never a panic. Before the reader
/// caught the decoder's panics, smashes 9, 16, 68 and 70 panicked with parquet 57.3 (a
/// dictionary index out of range, `rle.rs:500`); other seeds also reached panics in the
/// footer's thrift decoding and a negative column-chunk offset.
#[test]
fn smashed_parquet_with_a_matching_or_absent_checksum_is_an_error_naming_the_file() {
    let name = &real_files()[1].0;
    let len = real_files()[1].1.len() as u64;
    let (mut ok, mut err, mut panics) = (0, 0, Vec::new());
    for k in 0..80u64 {
        let smash = |b: &mut Vec<u8>| {
            // a few bytes anywhere (mostly inside pages: the data are most of the file)
            let mut rng = Rng::new(0x5eed_0000 + k);
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(len) as usize;
                b[i] = rng.next_u64() as u8;
            }
        };
        let sum = if k % 2 == 0 {
            Sum::Matching
        } else {
            Sum::Absent
        };
        match smashed(smash, sum) {
            Ok(Ok(())) => ok += 1,
            Ok(Err(m)) => {
                err += 1;
                // damage the decoder finds names the Parquet file; damage it cannot see
                // (changed values) may surface as a later check naming the manifest
                assert!(m.contains(name.as_str()) || m.contains(MANIFEST), "{m}");
            }
            Err(_) => panics.push(k),
        }
    }
    assert!(panics.is_empty(), "smashes {panics:?} panicked");
    assert!(
        err > 0,
        "{ok} loads, {err} errors: the smashes found nothing"
    );
}

/// Edits of a binary file: any byte values, flips four times as likely as each other kind
/// (4 : 1 : 1 : 1), since a flip keeps the file's length and offsets and so reaches further
/// into the Parquet decoder.
fn parquet_edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![3 => flip_edit(), 4 => edit_strategy()]
}

fn sum_strategy() -> impl Strategy<Value = Sum> {
    prop_oneof![
        3 => Just(Sum::Matching),
        2 => Just(Sum::Absent),
        1 => Just(Sum::Kept),
    ]
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn mutated_parquet_never_panics(
        edits in prop::collection::vec(parquet_edit_strategy(), 1..6),
        sum in sum_strategy(),
    ) {
        let r = smashed(|b| edits.iter().for_each(|e| apply(b, e)), sum);
        prop_assert!(r.is_ok(), "the reader panicked");
    }

    #[test]
    fn mutated_manifests_never_panic(edits in prop::collection::vec(text_edit_strategy(), 1..6)) {
        let text = edited(&real_files()[0].1, &edits);
        let _ = load_with(&[(MANIFEST.to_string(), text)]);
    }

    #[test]
    fn random_manifests_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let _ = load_with(&[(MANIFEST.to_string(), bytes)]);
    }
}

/// The reader's error for a missing Parquet file names it.
#[test]
fn a_missing_parquet_file_is_named() {
    let dir = case_dir("missing");
    let (manifest, parquet) = (&real_files()[0], &real_files()[1]);
    std::fs::write(dir.join(&manifest.0), &manifest.1).unwrap();
    let e = Dataset::load(&dir).unwrap_err().to_string();
    assert!(e.contains(&parquet.0), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A wheel count beyond any vehicle's is refused by name: the reader builds the schema's
/// per-wheel column names from it, and 2^32 wheels took minutes and all memory doing so.
#[test]
fn a_wheel_count_beyond_any_vehicle_is_refused() {
    let text = String::from_utf8(real_files()[0].1.clone()).unwrap();
    assert!(text.contains("wheels: 4\n"), "{text}");
    for bad in ["0", "17", "4294967296"] {
        let m = text.replace("wheels: 4\n", &format!("wheels: {bad}\n"));
        let e = load_with(&[(MANIFEST.to_string(), m.into_bytes())]).unwrap_err();
        assert!(
            e.contains(MANIFEST) && e.contains("field wheels") && e.contains(bad),
            "{e}"
        );
    }
}

/// A file holding more rows than its manifest lists is refused, naming the file, before its
/// columns are read: the footer's row count sizes the reader's buffers, so a damaged one must
/// not be believed beyond what the manifest allows.
#[test]
fn a_file_with_more_rows_than_the_manifest_lists_is_refused_by_name() {
    let text = String::from_utf8(real_files()[0].1.clone()).unwrap();
    assert!(text.contains("rows: 100\n"), "{text}");
    let m = text.replace("rows: 100\n", "rows: 3\n");
    let e = load_with(&[(MANIFEST.to_string(), m.into_bytes())]).unwrap_err();
    assert!(
        e.contains(&real_files()[1].0) && e.contains("claims 100 rows, more than the 3"),
        "{e}"
    );
}
