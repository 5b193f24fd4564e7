//! Every line the results writer produces is read back by every reader (issue 33, item 1).
//!
//! An `error` trial has no final distance (NaN), and a diverged trial can leave any statistic
//! undefined. JSON has no NaN: such numbers are written as `null`. Before this was handled, one
//! such line made `report`, `--resume`, `merge` and `replay` fail on the whole run. The property
//! below draws results of every outcome with arbitrary numbers (NaN, ±infinity, subnormals,
//! extremes) and strings, writes them with the writer `verti eval` uses, and reads them back
//! through the readers: the results file reader (resume, replay), the report loader with its
//! tables, and the shard joiner (merge).

use proptest::prelude::*;
use std::path::PathBuf;
use verti_bench::eval::{RESULTS_FILE, RUN_FILE, read_results, result_line};
use verti_bench::identity::RunRecord;
use verti_bench::metrics::{AngleStats, SignalStats, Stats};
use verti_bench::{Outcome, Rules, TrialResult};
use verti_world::{ElevationLevel, ObstacleDensity, TerrainType};

/// Any f64, with the awkward classes drawn often.
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(f64::MAX),
        Just(f64::MIN_POSITIVE / 4.0),
        Just(-0.0),
        any::<f64>(),
        -1e3..1e3f64,
    ]
}

fn stats() -> impl Strategy<Value = Stats> {
    (any::<u64>(), number(), number(), number()).prop_map(|(count, mean, var, max)| Stats {
        count,
        mean,
        var,
        max,
    })
}

fn signal() -> impl Strategy<Value = SignalStats> {
    (any::<u64>(), number(), number(), number()).prop_map(
        |(samples, mean_abs, total_variation, last)| SignalStats {
            samples,
            mean_abs,
            total_variation,
            last,
        },
    )
}

fn angle() -> impl Strategy<Value = AngleStats> {
    (stats(), stats()).prop_map(|(raw, abs)| AngleStats { raw, abs })
}

fn result() -> impl Strategy<Value = TrialResult> {
    let ids = (1..=100_000u32, 0..10u32, ".{0,12}", ".{0,12}", ".{0,12}");
    let kinds = (0..5usize, 0..3usize, 0..3usize, 0..3usize, any::<bool>());
    let numbers = (number(), prop::option::of(number()), number(), number());
    let more = (number(), number(), prop::option::of(".{0,40}"));
    let stats = (angle(), angle(), signal(), signal());
    (ids, kinds, numbers, more, stats).prop_map(
        |(
            (task, pair, world_name, system, vehicle),
            (outcome, level, terrain, density, reference_rules),
            (time, traversal_time, path_length, final_distance),
            (final_roll, wall_time, error),
            (roll, pitch, throttle, steering),
        )| TrialResult {
            task,
            world: task.div_ceil(10),
            pair,
            world_name,
            level: [
                ElevationLevel::Low,
                ElevationLevel::Mid,
                ElevationLevel::High,
            ][level],
            terrain_type: TerrainType::ALL[terrain],
            density: ObstacleDensity::ALL[density],
            system,
            vehicle,
            rules: if reference_rules {
                Rules::VertiBench
            } else {
                Rules::Paper
            },
            outcome: Outcome::ALL[outcome],
            time,
            traversal_time,
            roll,
            pitch,
            throttle,
            steering,
            path_length,
            final_distance,
            final_roll,
            error,
            wall_time,
        },
    )
}

/// What a result reads back as: every non-finite number becomes NaN, an undefined traversal
/// time none. Compared through the writer, since NaN != NaN.
fn expected(r: &TrialResult) -> String {
    result_line(r)
}

fn case_dir(tag: &str) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("verti-lines-{tag}-{}-{k}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run_record() -> RunRecord {
    let json = r#"{"system": "pid", "params": {}, "vehicle": "hmmwv", "worlds": "w",
        "scale": 1.0, "rules": "paper", "seed": 0, "max_time": 60.0, "tasks": "all"}"#;
    serde_json::from_str(json).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn every_written_line_is_read_by_every_reader(results in prop::collection::vec(result(), 1..6)) {
        // one run: distinct tasks, as a writer of one run produces them
        let mut results = results;
        results.sort_by_key(|r| r.task);
        results.dedup_by_key(|r| r.task);
        let dir = case_dir("run");
        let text: String = results.iter().map(|r| result_line(r) + "\n").collect();
        std::fs::write(dir.join(RESULTS_FILE), &text).unwrap();
        std::fs::write(dir.join(RUN_FILE), serde_json::to_string(&run_record()).unwrap()).unwrap();

        // the results file reader (resume, replay)
        let (read, clean) = read_results(&dir.join(RESULTS_FILE)).unwrap();
        prop_assert!(clean);
        prop_assert_eq!(
            read.iter().map(expected).collect::<Vec<_>>(),
            results.iter().map(expected).collect::<Vec<_>>()
        );
        for (back, written) in read.iter().zip(&results) {
            // an undefined number reads back undefined, a defined one exactly
            prop_assert_eq!(back.final_distance.is_nan(), !written.final_distance.is_finite());
            if written.final_distance.is_finite() {
                prop_assert_eq!(back.final_distance.to_bits(), written.final_distance.to_bits());
            }
        }

        // the report: loading, then the tables
        let loaded = verti_bench::report::load_results(std::slice::from_ref(&dir)).unwrap();
        prop_assert_eq!(loaded.len(), results.len());
        let summary = verti_bench::report::summarize(&loaded);
        let _ = verti_bench::report::markdown(&summary);

        // merge: the run as its only shard
        let joined = verti_bench::shard::join(std::slice::from_ref(&dir)).unwrap();
        prop_assert_eq!(joined.results().len(), results.len());
        let out = case_dir("merged");
        joined.write(&out, true, &|t| format!("task-{t}")).unwrap();
        let (merged, _) = read_results(&out.join(RESULTS_FILE)).unwrap();
        prop_assert_eq!(
            merged.iter().map(expected).collect::<Vec<_>>(),
            results.iter().map(expected).collect::<Vec<_>>()
        );
        std::fs::remove_dir_all(&dir).ok();
        std::fs::remove_dir_all(&out).ok();
    }
}

/// The repro of the issue: an `error` trial as `run_episode` writes it (no final distance).
#[test]
fn an_error_trial_line_reads_back() {
    let line = r#"{"task":1,"world":1,"pair":0,"world_name":"w001","level":"low","terrain_type":"rigid","density":"sparse","system":"pid","vehicle":"v","rules":"paper","outcome":"error","time":0.0,"traversal_time":null,"roll":{"raw":{"count":0,"mean":0.0,"var":0.0,"max":0.0},"abs":{"count":0,"mean":0.0,"var":0.0,"max":0.0}},"pitch":{"raw":{"count":0,"mean":0.0,"var":0.0,"max":0.0},"abs":{"count":0,"mean":0.0,"var":0.0,"max":0.0}},"throttle":{"samples":0,"mean_abs":0.0,"total_variation":0.0,"last":0.0},"steering":{"samples":0,"mean_abs":0.0,"total_variation":0.0,"last":0.0},"path_length":0.0,"final_distance":null,"final_roll":0.0,"error":"non-finite state","wall_time":0.0}"#;
    let r: TrialResult = serde_json::from_str(line).unwrap();
    assert!(r.final_distance.is_nan());
    assert_eq!(r.outcome, Outcome::Error);
    assert_eq!(result_line(&r), line);
}
