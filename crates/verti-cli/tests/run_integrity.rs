//! No trial can poison a run; shards and loaded files are part of a run's identity (issue 33,
//! items 1-4). Each test here failed before its fix.

mod common;

use common::{fails, ok, run_json, s, tmp, verti};
use std::path::{Path, PathBuf};

fn lines(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Item 1: a vehicle so light that its simulation blows up at once makes every trial an
/// `error` (no final distance); the run stays readable by every command.
#[test]
fn an_error_trial_does_not_poison_the_run() {
    let root = tmp("integrity", "error");
    let vehicle = root.join("feather.yaml");
    let yaml = ok(&["vehicle", "show", "hmmwv", "--yaml"]);
    let yaml: String = yaml
        .lines()
        .map(|l| match l {
            l if l.starts_with("name:") => "name: feather".to_string(),
            l if l.starts_with("  mass:") => "  mass: 1.0e-6".to_string(),
            l => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&vehicle, yaml).unwrap();
    let run = root.join("run");
    let eval = |tasks: &str, extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--worlds",
            "verti-1",
            "--vehicle",
            s(&vehicle),
            "--tasks",
            tasks,
            "--max-time",
            "3",
            "--jobs",
            "1",
            "--out",
            s(&run),
        ];
        args.extend_from_slice(extra);
        ok(&args)
    };
    let text = eval("1-2", &[]);
    assert!(text.contains("error 100.0%"), "{text}");
    assert!(
        lines(&run.join("results.jsonl"))
            .iter()
            .all(|l| l.contains("\"final_distance\":null")),
        "an error trial has no final distance"
    );
    ok(&["report", s(&run), "--out", s(&root.join("report"))]);
    let text = eval("1-3", &["--resume"]);
    assert!(text.contains("3 tasks"), "{text}");
    let merged = root.join("merged");
    ok(&["merge", "--out", s(&merged), s(&run)]);
    let png = root.join("replay.png");
    let text = ok(&["replay", s(&run), "--task", "1", "--out", s(&png)]);
    assert!(text.contains("error"), "{text}");
    let html = root.join("replay.html");
    ok(&["replay", s(&run), "--task", "1", "--3d", "--out", s(&html)]);
    let _ = std::fs::remove_dir_all(&root);
}

/// Items 2 and 4: a merge must have every shard of one split (or say which tasks are missing,
/// with `--allow-partial`), and keeps the shards' step logs.
#[test]
fn a_merge_needs_every_shard_and_keeps_their_step_logs() {
    let root = tmp("integrity", "merge");
    let eval = |out: &Path, shard: &str| {
        ok(&[
            "eval",
            "--worlds",
            "verti-1",
            "--tasks",
            "1-6",
            "--max-time",
            "3",
            "--jobs",
            "1",
            "--log-steps",
            "all",
            "--shard",
            shard,
            "--out",
            s(out),
        ])
    };
    let shards: Vec<PathBuf> = (0..3).map(|i| root.join(format!("s{i}"))).collect();
    for (i, dir) in shards.iter().enumerate() {
        eval(dir, &format!("{i}/3"));
        let split = &run_json(dir)["shard"];
        assert_eq!(split["index"], i);
        assert_eq!(split["count"], 3);
        assert_eq!(split["of"], "1-6");
    }
    let merged = root.join("merged");
    // a shard missing: refused, naming it and the tasks
    let text = fails(&["merge", "--out", s(&merged), s(&shards[0]), s(&shards[1])]);
    assert!(
        text.contains("2/3") && text.contains("3, 6") && text.contains("--allow-partial"),
        "{text}"
    );
    assert!(!merged.join("results.jsonl").exists());
    // with --allow-partial: merged, the missing tasks said and recorded
    let text = ok(&[
        "merge",
        "--allow-partial",
        "--out",
        s(&merged),
        s(&shards[0]),
        s(&shards[1]),
    ]);
    assert!(
        text.contains("2 task(s) missing") && text.contains("3, 6"),
        "{text}"
    );
    let record = run_json(&merged);
    assert_eq!(record["missing"], "3,6");
    assert_eq!(record["tasks"], "1-6");
    assert!(record.get("shard").is_none());
    // its step logs came along, one per result
    assert_eq!(std::fs::read_dir(merged.join("steps")).unwrap().count(), 4);
    // resuming the partial merge runs the missing tasks (with their logs)
    ok(&[
        "eval",
        "--worlds",
        "verti-1",
        "--max-time",
        "3",
        "--jobs",
        "1",
        "--log-steps",
        "all",
        "--resume",
        "--out",
        s(&merged),
    ]);
    assert_eq!(lines(&merged.join("results.jsonl")).len(), 6);
    assert_eq!(std::fs::read_dir(merged.join("steps")).unwrap().count(), 6);

    // a whole merge with --force replaces the earlier output and its logs entirely
    std::fs::write(merged.join("steps").join("task-99999.parquet"), "stale").unwrap();
    let all: Vec<&str> = shards.iter().map(|p| s(p)).collect();
    let mut args = vec!["merge", "--force", "--out", s(&merged)];
    args.extend(&all);
    let text = ok(&args);
    assert!(
        text.contains("6 results") && !text.contains("missing"),
        "{text}"
    );
    assert_eq!(std::fs::read_dir(merged.join("steps")).unwrap().count(), 6);
    assert!(run_json(&merged).get("missing").is_none());
    // the output may not be one of the shards
    let mut args = vec!["merge", "--force", "--out", s(&shards[0])];
    args.extend(&all);
    let text = fails(&args);
    assert!(text.contains("is one of the shards"), "{text}");

    // shards of splits of different sizes do not merge
    let other = root.join("half");
    eval(&other, "1/2");
    let text = fails(&[
        "merge",
        "--allow-partial",
        "--out",
        s(&root.join("x")),
        s(&shards[0]),
        s(&other),
    ]);
    assert!(text.contains("not shards of one split"), "{text}");
    // and a shard does not resume as another shard
    let text = fails(&[
        "eval",
        "--worlds",
        "verti-1",
        "--tasks",
        "1-6",
        "--max-time",
        "3",
        "--log-steps",
        "all",
        "--shard",
        "1/3",
        "--resume",
        "--out",
        s(&shards[0]),
    ]);
    assert!(text.contains("split"), "{text}");
    let _ = std::fs::remove_dir_all(&root);
}

/// Item 3: the files a system loads are recorded by content; a resume with another file under
/// the same path is refused, and a card missing for a selected world is refused up front.
#[test]
fn a_resume_checks_the_model_files_by_content() {
    let root = tmp("integrity", "models");
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../verti-policy/models");
    let copy = |card: &str| {
        for ext in ["yaml", "bin"] {
            std::fs::copy(
                models.join(format!("{card}.{ext}")),
                root.join(format!("{card}.{ext}")),
            )
            .unwrap();
        }
    };
    copy("rl-v1");
    copy("acl-v1");
    let card = root.join("policy.yaml");
    std::fs::copy(root.join("rl-v1.yaml"), &card).unwrap();
    let model = format!("model={}", s(&card));
    let run = root.join("run");
    let eval = |tasks: &str, extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--system",
            "rl",
            "--param",
            &model,
            "--worlds",
            "verti-1",
            "--tasks",
            tasks,
            "--max-time",
            "2",
            "--jobs",
            "1",
            "--out",
            s(&run),
        ];
        args.extend_from_slice(extra);
        verti(&args)
    };
    let (success, text) = eval("1", &[]);
    assert!(success, "{text}");
    let inputs = run_json(&run)["inputs"].clone();
    let paths: Vec<&str> = inputs
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["path"].as_str().unwrap())
        .collect();
    assert!(
        paths.iter().any(|p| p.ends_with("policy.yaml"))
            && paths.iter().any(|p| p.ends_with("rl-v1.bin")),
        "{paths:?}"
    );
    // the same path now holds another model: the resume is refused, naming the file
    std::fs::copy(root.join("acl-v1.yaml"), &card).unwrap();
    let (success, text) = eval("1-2", &["--resume"]);
    assert!(!success, "{text}");
    assert!(
        text.contains("policy.yaml") && text.contains("contents changed"),
        "{text}"
    );
    // back to the recorded model: it resumes
    std::fs::copy(root.join("rl-v1.yaml"), &card).unwrap();
    let (success, text) = eval("1-2", &["--resume"]);
    assert!(success, "{text}");

    // per-world cards: one missing for a selected world is refused before the run
    let text = fails(&[
        "eval",
        "--system",
        "va",
        "--param",
        &format!("model_per_world={}/va_w{{world}}.yaml", s(&root)),
        "--worlds",
        "verti-1",
        "--tasks",
        "1",
        "--out",
        s(&root.join("va")),
    ]);
    assert!(
        text.contains("no card for world 1") && text.contains("va_w001.yaml"),
        "{text}"
    );
    assert!(!root.join("va").join("results.jsonl").exists());
    let _ = std::fs::remove_dir_all(&root);
}
