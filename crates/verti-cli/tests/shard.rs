//! Sharded evaluation joined by `verti merge`, and `--perception`, end to end.

mod common;

use common::{ok, results, s, tmp, verti};
use std::path::{Path, PathBuf};

#[test]
fn shards_merge_into_what_one_run_writes() {
    let root = tmp("shard", "merge");
    let full = root.join("full");
    let eval = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--system",
            "pid",
            "--worlds",
            "verti-4",
            "--tasks",
            "1-24",
            "--jobs",
            "1",
            "--out",
            s(out),
        ];
        args.extend_from_slice(extra);
        ok(&args)
    };
    eval(&full, &[]);
    let shards: Vec<PathBuf> = (0..3).map(|i| root.join(format!("shard{i}"))).collect();
    for (i, dir) in shards.iter().enumerate() {
        eval(dir, &["--shard", &format!("{i}/3")]);
        // disjoint: each shard has its third
        assert_eq!(results(dir).len(), 8);
    }
    let merged = root.join("merged");
    let mut args = vec!["merge", "--out", s(&merged)];
    args.extend(shards.iter().map(|p| s(p)));
    let text = ok(&args);
    assert!(text.contains("24 results"), "{text}");
    assert_eq!(results(&merged), results(&full));
    // the merged run covers the tasks, and resumes as a finished run
    let again = eval(&merged, &["--resume"]);
    assert!(again.contains("24 tasks"), "{again}");

    // a shard with an unfinished task is refused unless --allow-partial
    let shard0 = std::fs::read_to_string(shards[0].join("results.jsonl")).unwrap();
    let cut: String = shard0.lines().skip(1).map(|l| format!("{l}\n")).collect();
    std::fs::write(shards[0].join("results.jsonl"), cut).unwrap();
    let (success, text) = verti(&[
        "merge",
        "--force",
        "--out",
        s(&merged),
        s(&shards[0]),
        s(&shards[1]),
        s(&shards[2]),
    ]);
    assert!(
        !success && text.contains("--allow-partial") && text.contains("shard0"),
        "{text}"
    );
    let text = ok(&[
        "merge",
        "--force",
        "--allow-partial",
        "--out",
        s(&merged),
        s(&shards[0]),
        s(&shards[1]),
        s(&shards[2]),
    ]);
    assert!(text.contains("23 results"), "{text}");
    // an existing output is not overwritten without --force
    let (success, text) = verti(&[
        "merge",
        "--allow-partial",
        "--out",
        s(&merged),
        s(&shards[1]),
    ]);
    assert!(!success && text.contains("--force"), "{text}");

    // shards of different runs do not merge
    let other = root.join("other");
    eval(&other, &["--shard", "0/3", "--seed", "5"]);
    let (success, text) = verti(&[
        "merge",
        "--out",
        s(&root.join("x")),
        s(&shards[1]),
        s(&other),
    ]);
    assert!(
        !success && text.contains("not shards of one run") && text.contains("seed"),
        "{text}"
    );
    // bad shard specs are named
    let (success, text) = verti(&["eval", "--worlds", "verti-4", "--shard", "3/3"]);
    assert!(!success && text.contains("3/3"), "{text}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn perception_noise_changes_what_systems_see_and_is_recorded() {
    let root = tmp("shard", "perception");
    let eval = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--system",
            "pid",
            "--worlds",
            "verti-4",
            "--tasks",
            "1-6",
            "--out",
            s(out),
        ];
        args.extend_from_slice(extra);
        verti(&args)
    };
    let (clean, noisy, again, none) = (
        root.join("clean"),
        root.join("noisy"),
        root.join("again"),
        root.join("none"),
    );
    assert!(eval(&clean, &[]).0);
    assert!(eval(&none, &["--perception", "none"]).0);
    assert!(eval(&noisy, &["--perception", "high", "--jobs", "2"]).0);
    assert!(eval(&again, &["--perception", "high", "--jobs", "1"]).0);
    // `none` is the default; noise changes the trials; the same seed repeats them exactly
    assert_eq!(results(&none), results(&clean));
    assert_ne!(results(&noisy), results(&clean));
    assert_eq!(results(&noisy), results(&again));
    let run = std::fs::read_to_string(noisy.join("run.json")).unwrap();
    assert!(
        run.contains("\"perception\"") && run.contains("\"high\""),
        "{run}"
    );
    let clean_run = std::fs::read_to_string(clean.join("run.json")).unwrap();
    assert!(!clean_run.contains("perception"), "{clean_run}");
    // noise on the map alone leaves PID (which reads only its pose) exactly as without noise
    let map_only = root.join("map-only.yaml");
    std::fs::write(
        &map_only,
        "elevation: {sigma: 0.15, hole_fraction: 0.15, range: 15.0, latency: 0.2}\n\
         semantics: {confusion: 0.3}\nobstacles: {miss_probability: 0.25, false_per_hectare: 6}\n",
    )
    .unwrap();
    let map_noise = root.join("map-noise");
    assert!(eval(&map_noise, &["--perception", s(&map_only)]).0);
    assert_eq!(results(&map_noise), results(&clean));
    // a resume under other noise is refused, naming both
    let (success, text) = eval(&noisy, &["--perception", "low", "--resume"]);
    assert!(
        !success && text.contains("perception") && text.contains("`high`"),
        "{text}"
    );
    // a custom model from YAML, with its bad field named
    let yaml = root.join("bad.yaml");
    std::fs::write(&yaml, "pose:\n  position_drift: -1\n").unwrap();
    let (success, text) = eval(&root.join("x"), &["--perception", s(&yaml)]);
    assert!(!success && text.contains("pose.position_drift"), "{text}");
    let (success, text) = eval(&root.join("x"), &["--perception", "foggy"]);
    assert!(!success && text.contains("low, medium, high"), "{text}");
    let _ = std::fs::remove_dir_all(&root);
}
