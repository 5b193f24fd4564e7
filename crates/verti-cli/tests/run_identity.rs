//! A run knows what it ran, by content: resume, report and replay check it (issue 10, items
//! 1, 5, 6, 7, 11 and 15). Each test here failed before run identities existed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn verti(args: &[&str], cwd: Option<&Path>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_verti"));
    c.args(args);
    if let Some(d) = cwd {
        c.current_dir(d);
    }
    c.output().unwrap()
}

fn ok(args: &[&str], cwd: Option<&Path>) -> (String, String) {
    let out = verti(args, cwd);
    assert!(
        out.status.success(),
        "verti {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn err(args: &[&str], cwd: Option<&Path>) -> String {
    let out = verti(args, cwd);
    assert!(!out.status.success(), "verti {args:?} should fail");
    String::from_utf8(out.stderr).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-identity-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn generate(dir: &Path, seed: &str, extra: &[&str]) {
    let mut args = vec![
        "world",
        "generate",
        "--count",
        "1",
        "--seed",
        seed,
        "--out",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ok(&args, None);
}

const SHORT: [&str; 6] = ["--tasks", "1-2", "--max-time", "3", "--jobs", "1"];

fn eval_args<'a>(worlds: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["eval", "--worlds", worlds, "--out", out];
    a.extend_from_slice(&SHORT);
    a.extend_from_slice(extra);
    a
}

#[test]
fn a_resume_checks_worlds_and_vehicle_by_content() {
    let root = tmp("content");
    // `w` in one directory and `w` in another are different sets
    let (a, b) = (root.join("a"), root.join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    generate(&a.join("w"), "1", &[]);
    generate(&b.join("w"), "2", &[]);
    let out = root.join("run");
    let out_s = out.to_str().unwrap();
    ok(&eval_args("w", out_s, &[]), Some(&a));
    let e = err(&eval_args("w", out_s, &["--resume"]), Some(&b));
    assert!(
        e.contains("cannot resume") && e.contains("world set: its contents differ"),
        "{e}"
    );
    // the same set named by another path resumes
    let abs = a.join("w");
    ok(
        &eval_args(abs.to_str().unwrap(), out_s, &["--resume"]),
        Some(&b),
    );

    // a vehicle file edited between two calls is another vehicle, though its name is the same
    let car = root.join("car.yaml");
    let (spec, _) = ok(&["vehicle", "show", "artcar", "--yaml"], None);
    std::fs::write(&car, spec.replace("name: artcar", "name: mycar")).unwrap();
    let out2 = root.join("run2");
    let out2_s = out2.to_str().unwrap();
    let car_s = car.to_str().unwrap();
    ok(&eval_args("w", out2_s, &["--vehicle", car_s]), Some(&a));
    let edited = std::fs::read_to_string(&car).unwrap();
    let mass_line = edited
        .lines()
        .find(|l| l.trim_start().starts_with("mass:"))
        .expect("a mass line")
        .to_string();
    std::fs::write(&car, edited.replace(&mass_line, "  mass: 99.0")).unwrap();
    let e = err(
        &eval_args("w", out2_s, &["--vehicle", car_s, "--resume"]),
        Some(&a),
    );
    assert!(e.contains("vehicle: `mycar` (digest"), "{e}");
    // replay drives the vehicle the run recorded, not what the file says now
    let png = root.join("t1.png");
    let (said, _) = ok(
        &[
            "replay",
            out2_s,
            "--task",
            "1",
            "--out",
            png.to_str().unwrap(),
        ],
        Some(&a),
    );
    assert!(said.contains("trajectory written"), "{said}");

    // replay checks the worlds are still those of the run: regenerate them with another seed
    generate(&a.join("w"), "2", &["--force"]);
    let e = err(
        &[
            "replay",
            out_s,
            "--task",
            "1",
            "--out",
            png.to_str().unwrap(),
        ],
        Some(&b),
    );
    assert!(e.contains("no longer holds the worlds"), "{e}");
    // --worlds hands replay the set itself, checked by content: the same worlds elsewhere replay
    let c = root.join("c");
    std::fs::create_dir_all(&c).unwrap();
    generate(&c.join("w"), "1", &[]);
    let replay = |worlds: &Path| {
        vec![
            "replay".to_string(),
            out_s.to_string(),
            "--task".into(),
            "1".into(),
            "--out".into(),
            png.to_str().unwrap().into(),
            "--worlds".into(),
            worlds.to_str().unwrap().into(),
        ]
    };
    let args = replay(&c.join("w"));
    let (said, _) = ok(&args.iter().map(String::as_str).collect::<Vec<_>>(), None);
    assert!(said.contains("trajectory written"), "{said}");
    let args = replay(&b.join("w"));
    let e = err(&args.iter().map(String::as_str).collect::<Vec<_>>(), None);
    assert!(e.contains("the worlds given are not those the run"), "{e}");
}

#[test]
fn step_logs_belong_to_the_run() {
    let root = tmp("steps");
    let out = root.join("run");
    let out_s = out.to_str().unwrap();
    ok(
        &eval_args("verti-1", out_s, &["--log-steps", "last10"]),
        None,
    );
    assert_eq!(std::fs::read_dir(out.join("steps")).unwrap().count(), 2);
    // resuming without the logs would leave some tasks logged and some not
    let e = err(&eval_args("verti-1", out_s, &["--resume"]), None);
    assert!(e.contains("step logs: last10 recorded, none now"), "{e}");
    // a fresh start keeps no stale logs
    ok(&eval_args("verti-1", out_s, &["--force"]), None);
    assert!(!out.join("steps").exists());
    // how trials start is part of the run too
    let e = err(
        &eval_args("verti-1", out_s, &["--resume", "--start", "drop"]),
        None,
    );
    assert!(e.contains("start: settled recorded, drop now"), "{e}");
}

#[test]
fn a_saved_set_keeps_its_scale_and_the_vehicle_scale_is_checked() {
    let root = tmp("scale");
    let set = root.join("small");
    generate(&set, "3", &["--scale", "1/6"]);
    let set_s = set.to_str().unwrap();
    let out = root.join("run");
    let out_s = out.to_str().unwrap();
    let e = err(&eval_args(set_s, out_s, &["--scale", "1/10"]), None);
    assert!(
        e.contains("--scale 1/10 does not apply") && e.contains("saved at scale 1/6"),
        "{e}"
    );
    // without --scale the set's own scale is used and recorded, with its default vehicle
    ok(&eval_args(set_s, out_s, &[]), None);
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert!((run["scale"].as_f64().unwrap() - 1.0 / 6.0).abs() < 1e-12);
    assert_eq!(run["vehicle"], "artcar");
    let e = err(&["world", "stats", set_s, "--scale", "1"], None);
    assert!(e.contains("does not apply"), "{e}");
    // a full-scale vehicle on 1/6-scale worlds runs, with a warning
    let (_, warned) = ok(
        &eval_args(set_s, out_s, &["--force", "--vehicle", "hmmwv"]),
        None,
    );
    assert!(
        warned.contains(
            "warning: vehicle hmmwv is built for scale 1 but the worlds are at scale 1/6"
        ),
        "{warned}"
    );
}

#[test]
fn a_report_keeps_runs_apart_and_counts_each_trial_once() {
    let root = tmp("report");
    let run = |name: &str, extra: &[&str]| {
        let out = root.join(name);
        ok(&eval_args("verti-1", out.to_str().unwrap(), extra), None);
        out
    };
    let slow = run("slow", &["--param", "speed=2"]);
    let fast = run("fast", &["--param", "speed=4"]);
    let report = |paths: &[&Path]| {
        let mut args = vec!["report", "--json"];
        args.extend(paths.iter().map(|p| p.to_str().unwrap()));
        verti(&args, None)
    };
    let out = report(&[&slow, &fast]);
    assert!(out.status.success());
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = summary["systems"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["pid [speed=2]", "pid [speed=4]"]);
    // the same run twice, or a copy of it, would count its trials twice
    let out = report(&[&slow, &slow.join("results.jsonl")]);
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success() && e.contains("given twice"), "{e}");
    let copy = root.join("copy");
    std::fs::create_dir_all(&copy).unwrap();
    for f in ["results.jsonl", "run.json"] {
        std::fs::copy(slow.join(f), copy.join(f)).unwrap();
    }
    let out = report(&[&slow, &copy]);
    let e = String::from_utf8(out.stderr).unwrap();
    assert!(
        !out.status.success() && e.contains("with the same settings"),
        "{e}"
    );
    // one run split over two directories (disjoint tasks) is one column
    let rest = root.join("rest");
    ok(
        &[
            "eval",
            "--worlds",
            "verti-1",
            "--out",
            rest.to_str().unwrap(),
            "--tasks",
            "3-4",
            "--max-time",
            "3",
            "--jobs",
            "1",
            "--param",
            "speed=2",
        ],
        None,
    );
    let out = report(&[&slow, &rest]);
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let systems = summary["systems"].as_array().unwrap();
    assert_eq!(systems.len(), 1);
    assert_eq!(systems[0]["outcomes"]["trials"], 4, "{}", systems[0]);
}
