//! `verti sim compare` end to end on two tasks of the Chrono reference in ../shared, and its
//! errors (the data is not part of the repository; the tests say so and pass when it is absent).

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn shared() -> Option<PathBuf> {
    let dir = repo_root().join("../shared");
    let ok = dir.join("chrono-reference").is_dir() && dir.join("verti-bench-data/worlds").is_dir();
    if !ok {
        eprintln!(
            "SKIPPED: {} lacks chrono-reference or verti-bench-data; comparison checks not run",
            dir.display()
        );
    }
    ok.then_some(dir)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-compare-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs `verti` in `cwd`; (success, stdout, stderr).
fn verti(cwd: &Path, args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_verti"))
        .current_dir(cwd)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn two_tasks_compare_with_pages_and_summary() {
    let Some(shared) = shared() else { return };
    let out = tmp("two");
    let reference = shared.join("chrono-reference");
    // from the repository root, so the default --vb-worlds (../shared/...) is found
    let (ok, stdout, stderr) = verti(
        &repo_root(),
        &[
            "sim",
            "compare",
            reference.to_str().unwrap(),
            "--tasks",
            "9:0,2:4",
            "--jobs",
            "2",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(ok, "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["engine"], "chrono-9.0.1");
    assert_eq!(summary["groups"][0]["tasks"], 2);
    assert_eq!(summary["setup"]["kp"], 0.5276);
    let tasks = summary["tasks"].as_array().unwrap();
    assert_eq!(
        (
            tasks[0]["world_index"].as_u64(),
            tasks[1]["world_index"].as_u64()
        ),
        (Some(2), Some(9)),
        "in the order of the outcomes file"
    );
    for f in ["world-002_p4.png", "world-009_p0.png"] {
        let img = image::open(out.join(f)).unwrap();
        assert!(img.width() > 1000 && img.height() > 500, "{f}");
    }
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("| all tasks | 2 |"), "{md}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json, summary);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bad_references_and_options_get_clear_errors() {
    let Some(shared) = shared() else { return };
    let root = repo_root();
    let reference = shared.join("chrono-reference");
    let r = reference.to_str().unwrap();
    let err = |args: &[&str]| {
        let (ok, _, stderr) = verti(&root, args);
        assert!(!ok, "verti {args:?} should fail");
        stderr
    };
    let e = err(&["sim", "compare", r, "--vb-worlds", "/no/such/worlds"]);
    assert!(
        e.contains("/no/such/worlds: no such folder of Verti-Bench worlds")
            && e.contains("--vb-worlds"),
        "{e}"
    );
    let e = err(&["sim", "compare", r, "--tasks", "9:9"]);
    assert!(e.contains("--tasks item `9:9`: selects no task"), "{e}");
    let e = err(&["sim", "compare", r, "--driver", "mpc"]);
    assert!(e.contains("unknown driver `mpc`"), "{e}");
    let e = err(&["sim", "compare", r, "--inner-dt", "5"]);
    assert!(e.contains("inner_dt = 5"), "{e}");

    // a copy of one task whose trajectory has a bad number on its third line
    let bad = tmp("bad");
    std::fs::create_dir_all(bad.join("trajectories")).unwrap();
    let outcomes = std::fs::read_to_string(reference.join("outcomes.jsonl")).unwrap();
    let line = outcomes
        .lines()
        .find(|l| l.contains("\"world_index\": 9,") && l.contains("\"pair\": 0,"))
        .unwrap();
    std::fs::write(bad.join("outcomes.jsonl"), format!("{line}\n")).unwrap();
    let csv = std::fs::read_to_string(reference.join("trajectories/world-009_p0.csv")).unwrap();
    let mut rows: Vec<String> = csv.lines().map(String::from).collect();
    rows[2] = rows[2].replacen(',', ",oops", 1);
    let csv_path = bad.join("trajectories/world-009_p0.csv");
    std::fs::write(&csv_path, rows.join("\n")).unwrap();
    let e = err(&["sim", "compare", bad.to_str().unwrap()]);
    assert!(
        e.contains(&format!("{}:3: column `x`", csv_path.display())),
        "{e}"
    );
    std::fs::remove_file(&csv_path).unwrap();
    let e = err(&["sim", "compare", bad.to_str().unwrap()]);
    assert!(e.contains("world-009_p0.csv"), "{e}");
    let _ = std::fs::remove_dir_all(&bad);
}

/// The snow trial whose reference chassis falls through the soil is left out and listed, unless
/// asked for; `--csv` writes verti's trajectory in the reference's columns, readable back.
#[test]
fn a_fall_through_is_left_out_and_csv_trajectories_are_written() {
    let Some(shared) = shared() else { return };
    let soil = shared.join("chrono-reference/soil");
    let out = tmp("artifact");
    let o = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "sim",
            "compare",
            soil.to_str().unwrap(),
            "--tasks",
            "83:3,83:2",
        ];
        args.extend_from_slice(&["--json", "--out", o]);
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = verti(&repo_root(), &args);
        assert!(ok, "{stderr}");
        let summary: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        (summary, stderr)
    };
    let (summary, stderr) = run(&["--csv"]);
    assert!(
        stderr.contains("left out vb/config83_mid pair 3 (snow): the chassis falls through"),
        "{stderr}"
    );
    assert_eq!(summary["groups"][0]["tasks"], 1);
    assert_eq!(summary["excluded"][0]["pair"], 3);
    assert_eq!(summary["excluded"][0]["reference_outcome"], "rollover");
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("## Left out: 1 reference trial"), "{md}");
    let csv = std::fs::read_to_string(out.join("verti-world-083_p2.csv")).unwrap();
    assert!(
        csv.starts_with("t,x,y,z,roll,pitch,yaw,v,steer,throttle,brake,agl\n"),
        "{}",
        &csv[..80]
    );
    let samples = verti_compare::reference::parse_trajectory(&csv, &out).unwrap();
    assert!(samples.len() > 100 && samples.iter().all(|s| s.agl.is_finite()));
    assert!(
        !out.join("verti-world-083_p3.csv").exists(),
        "left out, not run"
    );
    // each wheel at the trajectory's sample times, in the harness's per-wheel columns
    let wheels = std::fs::read_to_string(out.join("verti-world-083_p2-wheels.csv")).unwrap();
    let mut lines = wheels.lines();
    assert_eq!(lines.next(), Some("t,v,wheel,omega,fx,fy,fz,gear,rpm"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 4 * samples.len(), "four wheels per sample");
    assert!(rows.iter().all(|r| r.len() == 9 && r[2] < 4.0));
    assert!(
        rows.iter().any(|r| r[6] > 1000.0),
        "wheels carry the vehicle"
    );

    let (summary, _) = run(&["--keep-artifacts"]);
    assert_eq!(summary["groups"][0]["tasks"], 2);
    assert_eq!(summary["excluded"].as_array().unwrap().len(), 0);
    let _ = std::fs::remove_dir_all(&out);
}
