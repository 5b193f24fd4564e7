//! Dataset tests on tiny configurations: schema round trip, determinism across thread counts,
//! bad inputs, and the window sampler's patch alignment.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_bench::features::Feature;
use verti_bench::observation::CropSpec;
use verti_core::rng::Rng;
use verti_data::generate::{Source, eval_world_reason};
use verti_data::manifest::{FORMAT, Manifest, WorldsInfo};
use verti_data::table::{
    FEATURES, Row, Table, TrialRecord, WheelGround, read_table, schema, write_table,
};
use verti_data::{
    DataError, DataOutcome, Dataset, GenerateConfig, Kind, Profile, WindowSampler, WriteInfo,
    write_dataset,
};
use verti_world::World;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verti-data-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Two small worlds of a training seed (generated once per test binary).
fn worlds() -> Vec<Arc<World>> {
    static SET: std::sync::OnceLock<Vec<Arc<World>>> = std::sync::OnceLock::new();
    SET.get_or_init(|| {
        verti_world::sets::resolve_set("verti-2-s1", 1.0, &|| {})
            .unwrap()
            .worlds
            .into_iter()
            .map(Arc::new)
            .collect()
    })
    .clone()
}

fn config(kind: Kind, hours: f64) -> GenerateConfig {
    GenerateConfig {
        kind,
        source: Source::Random(Profile::VertiAdaptor),
        worlds: worlds(),
        vehicle: verti_sim::vehicles::builtin("hmmwv").unwrap(),
        hours,
        rate: 10.0,
        seed: 3,
        max_trial_seconds: 40.0,
    }
}

fn info(force: bool) -> WriteInfo {
    WriteInfo {
        set: "verti-2-s1".into(),
        set_name: "verti-2-s1".into(),
        command: "test".into(),
        eval_worlds: false,
        force,
    }
}

/// A hand-made trial with distinctive values in every column.
fn hand_trial(trial: u32, world: u32, n: usize, outcome: DataOutcome) -> TrialRecord {
    let rows = (0..n)
        .map(|k| {
            let mut features = [0.0; FEATURES];
            for (i, f) in features.iter_mut().enumerate() {
                *f = trial as f64 * 1000.0 + k as f64 + i as f64 * 0.001;
            }
            features[0] = k as f64 * 0.1;
            Row {
                features,
                steering: (k as f64).sin(),
                speed: 2.0 + k as f64 * 0.01,
                wheels: (0..4)
                    .map(|w| WheelGround {
                        class: (k + w) as u8 % 10,
                        friction: 0.5 + w as f64 * 0.1,
                        soil: (k + w) % 3 == 0,
                    })
                    .collect(),
            }
        })
        .collect();
    TrialRecord {
        trial,
        world,
        first_step: 5,
        rows,
        outcome,
    }
}

#[test]
fn schema_round_trip() {
    let dir = temp_dir("roundtrip");
    std::fs::create_dir_all(&dir).unwrap();
    let trials = vec![
        hand_trial(0, 1, 7, DataOutcome::Rollover),
        hand_trial(9, 2, 3, DataOutcome::Edge),
    ];
    let table = Table::from_trials(&trials, 4);
    let path = dir.join("t.parquet");
    write_table(&path, &table).unwrap();
    let back = read_table(&path, &schema(4)).unwrap();
    assert_eq!(back, table);
    assert_eq!(back.rows(), 10);
    assert_eq!(back.i32("step").unwrap()[..3], [5, 6, 7]);
    let outcome = back.outcomes().unwrap();
    assert_eq!(outcome[6].as_deref(), Some("rollover"));
    assert_eq!(outcome[5], None);
    assert_eq!(outcome[9].as_deref(), Some("edge"));
    // every feature of the schema is a column
    for f in Feature::ALL {
        assert!(back.f64(f.name()).is_some(), "{}", f.name());
    }
    // a file of another vehicle's schema is refused, naming the file
    let e = read_table(&path, &schema(6)).unwrap_err().to_string();
    assert!(e.contains("t.parquet") && e.contains("wheel4_class"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn generated_data_load_back_and_are_deterministic_across_threads() {
    let cfg = config(Kind::Random, 0.05);
    let run = |threads: usize, name: &str| -> (PathBuf, Manifest) {
        let dir = temp_dir(name);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let m = pool
            .install(|| write_dataset(&dir, &cfg, &info(false), &|_| {}))
            .unwrap();
        (dir, m)
    };
    let (a, ma) = run(1, "det1");
    let (b, mb) = run(3, "det3");
    assert_eq!(ma, mb);
    assert!(ma.hours >= 0.05 && ma.trials >= 1, "{ma:?}");
    for f in &ma.files {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f} differs between 1 and 3 threads"
        );
    }
    let data = Dataset::load(&a).unwrap();
    assert_eq!(data.trial_count(), ma.trials);
    assert_eq!(data.table.rows(), ma.rows);
    let mut seconds = 0.0;
    for t in data.trials() {
        seconds += t.duration();
        // 10 Hz rows from t = 0; the last one at the end, which may fall between two
        let time = t.f64("t").unwrap();
        assert_eq!(time[0], 0.0);
        for w in time[..time.len() - 1].windows(2) {
            assert!((w[1] - w[0] - 0.1).abs() < 1e-6, "{w:?}");
        }
        assert!(matches!(
            t.outcome,
            DataOutcome::Rollover | DataOutcome::Stuck | DataOutcome::Timeout | DataOutcome::Edge
        ));
        let speed = t.f64("cmd_speed").unwrap();
        assert!(speed.iter().all(|v| (0.0..=3.0).contains(v)));
        let class = t.i32("wheel0_class").unwrap();
        assert!(class.iter().all(|c| (0..10).contains(c)));
    }
    assert!((seconds / 3600.0 - ma.hours).abs() < 1e-9);
    // an existing non-empty directory is refused without --force, replaced with it
    let e = write_dataset(&a, &cfg, &info(false), &|_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--force") && e.contains(&a.display().to_string()),
        "{e}"
    );
    write_dataset(&a, &cfg, &info(true), &|_| {}).unwrap();
    for d in [a, b] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn failures_are_last_ten_seconds_of_rollovers_and_stucks() {
    let dir = temp_dir("failures");
    let m = write_dataset(&dir, &config(Kind::Failures, 0.1), &info(false), &|_| {}).unwrap();
    assert!(m.hours_simulated >= 0.1);
    let data = Dataset::load(&dir).unwrap();
    for t in data.trials() {
        assert!(matches!(
            t.outcome,
            DataOutcome::Rollover | DataOutcome::Stuck
        ));
        assert!(t.duration() <= 10.0 + 1e-6, "{}", t.duration());
        let roll = t.f64("roll").unwrap().last().unwrap().to_degrees().abs();
        assert_eq!(t.outcome == DataOutcome::Rollover, roll > 30.0);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn expert_keeps_only_successes() {
    let dir = temp_dir("expert");
    let mut cfg = config(Kind::Expert, 0.01);
    let registry = {
        let mut r = verti_bench::SystemRegistry::new();
        verti_systems::register(&mut r);
        r
    };
    let params = registry.resolve("pid", &[]).unwrap();
    cfg.source = Source::System {
        name: "pid".into(),
        make: Arc::new(move || registry.build("pid", &params).unwrap()),
    };
    let m = write_dataset(&dir, &cfg, &info(false), &|_| {}).unwrap();
    let data = Dataset::load(&dir).unwrap();
    assert!(m.hours >= 0.01 || m.trials == 20, "{m:?}");
    for t in data.trials() {
        assert_eq!(t.outcome, DataOutcome::Success);
        // trial ids are task numbers
        assert!((1..=20).contains(&t.trial));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_inputs_are_clear_errors() {
    let e = Kind::from_name("randomm").unwrap_err().to_string();
    assert!(e.contains("randomm") && e.contains("failures"), "{e}");
    for hours in [0.0, -1.0, f64::NAN] {
        let e = config(Kind::Random, hours)
            .validate()
            .unwrap_err()
            .to_string();
        assert!(e.contains("--hours"), "{e}");
    }
    let mut cfg = config(Kind::Random, 1.0);
    cfg.rate = 0.0;
    assert!(cfg.validate().unwrap_err().to_string().contains("--rate"));
    // the evaluation set (seed 0) is refused with the reason, a training seed is not
    let eval: Vec<Arc<World>> = verti_world::sets::resolve_set("verti-1", 1.0, &|| {})
        .unwrap()
        .worlds
        .into_iter()
        .map(Arc::new)
        .collect();
    let reason = eval_world_reason(&eval).unwrap();
    assert!(
        reason.contains("evaluation") && reason.contains("--allow-eval-worlds"),
        "{reason}"
    );
    assert!(eval_world_reason(&worlds()).is_none());
    // a truncated Parquet file is an error naming it
    let dir = temp_dir("corrupt");
    let m = write_dataset(&dir, &config(Kind::Random, 0.01), &info(false), &|_| {}).unwrap();
    let file = dir.join(&m.files[0]);
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
    let Err(e) = Dataset::load(&dir) else {
        panic!("a truncated file loaded")
    };
    assert!(matches!(e, DataError::File { .. }));
    assert!(e.to_string().contains(&m.files[0]), "{e}");
    // garbage in the middle of a page is caught too
    let mut bad = bytes.clone();
    for b in &mut bad[200..400] {
        *b ^= 0x5A;
    }
    std::fs::write(&file, &bad).unwrap();
    let Err(e) = Dataset::load(&dir) else {
        panic!("a damaged file loaded")
    };
    let e = e.to_string();
    assert!(e.contains(&m.files[0]) && e.contains("checksum"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
    let Err(e) = Dataset::load(Path::new("/no/such/dataset")) else {
        panic!("nothing loaded")
    };
    let e = e.to_string();
    assert!(e.contains("manifest.yaml"), "{e}");
}

/// Writes `trials` as a one-file dataset recorded on world index `world` (for hand-made data).
fn hand_dataset(dir: &Path, trials: &[TrialRecord], world: u32) {
    std::fs::create_dir_all(dir).unwrap();
    write_table(
        &dir.join("steps-00000.parquet"),
        &Table::from_trials(trials, 4),
    )
    .unwrap();
    let m = Manifest {
        format: FORMAT.into(),
        kind: Kind::Random,
        profile: Some(Profile::Paper),
        source: "hand".into(),
        worlds: WorldsInfo {
            set: "none".into(),
            name: "none".into(),
            seed: None,
            generator: "test".into(),
            scale: 1.0,
            indices: vec![world],
        },
        vehicle: "hmmwv".into(),
        wheels: 4,
        rate: 10.0,
        max_trial_seconds: 300.0,
        seed: 0,
        hours_requested: 0.0,
        hours: 0.0,
        hours_simulated: 0.0,
        trials: trials.len(),
        rows: trials.iter().map(|t| t.rows.len()).sum(),
        outcomes: Default::default(),
        eval_worlds: false,
        files: vec!["steps-00000.parquet".into()],
        checksums: Default::default(),
        command: String::new(),
        verti_version: String::new(),
    };
    m.write(dir).unwrap();
}

#[test]
fn window_patches_follow_the_heading_on_a_tilted_plane() {
    // z = 0.1 x: facing east (yaw 0) the ground rises ahead; facing north it rises to the right
    let world = Arc::new(verti_sim::testing::plane_world(
        1.0,
        0.1f64.atan(),
        0.0,
        0.8,
    ));
    let index = world.meta.index;
    let mut trial = hand_trial(0, index, 6, DataOutcome::Stuck);
    let (x, y, z, yaw) = (1, 2, 3, 6); // Feature::ALL positions
    assert_eq!(Feature::ALL[yaw], Feature::Yaw);
    for (k, r) in trial.rows.iter_mut().enumerate() {
        r.features[x] = 2.0;
        r.features[y] = -1.0;
        r.features[z] = 0.2 + 1.5; // ground at x = 2 plus the chassis height
        r.features[yaw] = if k < 3 {
            0.0
        } else {
            std::f64::consts::FRAC_PI_2
        };
    }
    let dir = temp_dir("sampler");
    hand_dataset(&dir, &[trial], index);
    let data = Dataset::load(&dir).unwrap();
    let crop = CropSpec {
        size: 5,
        resolution: 0.5,
    };
    let sampler =
        WindowSampler::new(&data, vec![world], 3, crop, vec![Feature::Yaw, Feature::X]).unwrap();
    assert_eq!(sampler.windows(), 4);
    let b = sampler.batch(&[0, 3]).unwrap();
    assert_eq!((b.windows, b.steps), (2, 3));
    assert_eq!(b.state.len(), 2 * 3 * 2);
    assert_eq!(b.state[6], std::f64::consts::FRAC_PI_2); // window 1, step 0, yaw
    let cell = |w: usize, s: usize, r: usize, c: usize| b.elevation[((w * 3 + s) * 5 + r) * 5 + c];
    // centre: the ground under the vehicle relative to its height
    assert!((cell(0, 0, 2, 2) + 1.5).abs() < 1e-5);
    // facing east: rows ahead (row 0, 1 m ahead) higher by 0.1 m, columns flat
    assert!((cell(0, 0, 0, 2) - cell(0, 0, 2, 2) - 0.1).abs() < 1e-5);
    assert!((cell(0, 0, 2, 0) - cell(0, 0, 2, 4)).abs() < 1e-5);
    // facing north: rows flat, column 4 (the vehicle's right = east) higher
    assert!((cell(1, 0, 0, 2) - cell(1, 0, 4, 2)).abs() < 1e-5);
    assert!((cell(1, 0, 2, 4) - cell(1, 0, 2, 0) - 0.2).abs() < 1e-5);
    assert!(b.semantic.iter().all(|&c| c == b.semantic[0]));
    // random batches are deterministic for a seed
    let s1 = sampler.sample(&mut Rng::new(5), 8).unwrap();
    let s2 = sampler.sample(&mut Rng::new(5), 8).unwrap();
    assert_eq!(s1, s2);
    assert!(
        sampler.batch(&[4]).is_err(),
        "a window may not run past its trial"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
