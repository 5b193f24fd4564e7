//! End-to-end tests of the `verti` executable.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn verti() -> Command {
    Command::new(env!("CARGO_BIN_EXE_verti"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run_ok(args: &[&str]) -> String {
    let out = verti().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "verti {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn run_err(args: &[&str]) -> String {
    let out = verti().args(args).output().unwrap();
    assert!(!out.status.success(), "verti {args:?} should fail");
    String::from_utf8(out.stderr).unwrap()
}

fn lines(path: &PathBuf) -> Vec<serde_json::Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn a_killed_evaluation_resumes_and_loses_nothing() {
    let out = tmp("kill");
    let out_s = out.to_str().unwrap();
    let args = [
        "eval", "--system", "pid", "--worlds", "verti-4", "--jobs", "2", "--out", out_s,
    ];
    let mut child = verti()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // kill it once some results are on disk
    let results = out.join("results.jsonl");
    let t0 = Instant::now();
    loop {
        let n = std::fs::read_to_string(&results)
            .map(|t| t.lines().count())
            .unwrap_or(0);
        if n >= 3 || t0.elapsed() > Duration::from_secs(120) {
            break;
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    let partial = lines(&results).len();
    assert!(
        partial < 40,
        "the run finished before it could be killed ({partial} results)"
    );

    // without --resume it refuses; with it, it completes the set
    let e = run_err(&args);
    assert!(e.contains("--resume"), "{e}");
    let mut resume_args = args.to_vec();
    resume_args.push("--resume");
    run_ok(&resume_args);
    let done = lines(&results);
    let mut tasks: Vec<u64> = done.iter().map(|r| r["task"].as_u64().unwrap()).collect();
    tasks.sort();
    assert_eq!(
        tasks,
        (1..=40).collect::<Vec<_>>(),
        "every task exactly once after resuming"
    );

    // and the results equal those of an uninterrupted run (but for wall time)
    let clean = tmp("clean");
    run_ok(&[
        "eval",
        "--system",
        "pid",
        "--worlds",
        "verti-4",
        "--jobs",
        "1",
        "--out",
        clean.to_str().unwrap(),
    ]);
    let strip = |mut v: Vec<serde_json::Value>| {
        v.sort_by_key(|r| r["task"].as_u64());
        for r in &mut v {
            r.as_object_mut().unwrap().remove("wall_time");
        }
        v
    };
    assert_eq!(strip(done), strip(lines(&clean.join("results.jsonl"))));
}

#[test]
fn bad_input_gets_clear_errors() {
    let e = run_err(&["eval", "--system", "teleport", "--worlds", "verti-1"]);
    assert!(
        e.contains("unknown system `teleport`") && e.contains("pid"),
        "{e}"
    );
    let e = run_err(&[
        "eval", "--system", "pid", "--tasks", "9-3", "--worlds", "verti-1",
    ]);
    assert!(e.contains("bad task range"), "{e}");
    let e = run_err(&[
        "eval",
        "--system",
        "pid",
        "--tasks",
        "11-20",
        "--worlds",
        "verti-1",
        "--out",
        tmp("range").to_str().unwrap(),
    ]);
    assert!(e.contains("not in this world set"), "{e}");
    let e = run_err(&[
        "eval",
        "--system",
        "pid",
        "--vehicle",
        "hovercraft",
        "--worlds",
        "verti-1",
    ]);
    assert!(e.contains("hovercraft") && e.contains("hmmwv"), "{e}");
    // a vehicle file that is not there is a missing file, not an unknown vehicle name
    let e = run_err(&[
        "eval",
        "--system",
        "pid",
        "--vehicle",
        "/nonexistent/rover.yaml",
        "--worlds",
        "verti-1",
    ]);
    assert!(
        e.contains("rover.yaml") && !e.contains("unknown vehicle"),
        "{e}"
    );
    let e = run_err(&["eval", "--param", "speed=fast"]);
    assert!(
        e.contains("system pid parameter speed: `fast` is not a number"),
        "{e}"
    );
    let e = run_err(&["eval", "--system", "mppi", "--param", "samples=0"]);
    assert!(
        e.contains("system mppi parameter samples: 0 is outside [1, 65536]"),
        "{e}"
    );
    let e = run_err(&["eval", "--param", "speed"]);
    assert!(e.contains("must look like name=value"), "{e}");
    let e = run_err(&["world", "generate", "--elevation", "swae"]);
    assert!(
        e.contains("unknown elevation source `swae`; known: procedural-rock"),
        "{e}"
    );
    let e = run_err(&["world", "generate", "--elevation-param", "pits_min=many"]);
    assert!(
        e.contains("parameter pits_min: `many` is not an integer"),
        "{e}"
    );
    // the listings show each parameter's type, default and accepted values
    let list = run_ok(&["systems", "list"]);
    assert!(
        list.lines()
            .any(|l| l.contains("samples") && l.contains("int") && l.contains("800")),
        "{list}"
    );
    let list = run_ok(&["world", "sources"]);
    assert!(
        list.contains("procedural-rock") && list.contains("coverage"),
        "{list}"
    );
    // a source with other settings records them in each world's generator name
    let dir = tmp("custom-source");
    run_ok(&[
        "world",
        "generate",
        "--count",
        "1",
        "--elevation-param",
        "coverage=1.25",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let manifest = std::fs::read_to_string(dir.join("world-001/world.yaml")).unwrap();
    assert!(
        manifest.contains("procedural-rock-v1(coverage=1.25)"),
        "{manifest}"
    );
    let e = run_err(&[
        "world",
        "generate",
        "--scale",
        "0",
        "--out",
        tmp("scale").to_str().unwrap(),
    ]);
    assert!(e.contains("scale"), "{e}");

    // a corrupt world on disk: the error names the file and the field
    let dir = tmp("corrupt");
    run_ok(&[
        "world",
        "generate",
        "--count",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let manifest = dir.join("world-001/world.yaml");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("level: ", "level: extreme-")).unwrap();
    let e = run_err(&[
        "eval",
        "--worlds",
        dir.to_str().unwrap(),
        "--out",
        tmp("corrupt-out").to_str().unwrap(),
    ]);
    assert!(e.contains("world.yaml") && e.contains("extreme-"), "{e}");
}

#[test]
fn world_commands_work_end_to_end() {
    let dir = tmp("worlds");
    let out = run_ok(&[
        "world",
        "generate",
        "--count",
        "3",
        "--seed",
        "5",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(out.contains("3 worlds, 30 tasks"), "{out}");
    let show = run_ok(&["world", "show", dir.join("world-002").to_str().unwrap()]);
    assert!(show.contains("pair 9"), "{show}");
    let png = dir.join("w.png");
    run_ok(&[
        "world",
        "render",
        "verti-3-s5:2",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    let json = run_ok(&["world", "stats", dir.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["worlds"], 3);
    let e = run_err(&[
        "world",
        "generate",
        "--count",
        "3",
        "--seed",
        "5",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(e.contains("not empty") && e.contains("--force"), "{e}");
    let listed = run_ok(&["vehicle", "list"]);
    assert!(listed.contains("hmmwv") && listed.contains("m113"));
}

#[test]
fn tiny_scales_are_errors_and_empty_folders_do_not_hide_built_in_sets() {
    // a scale below the range used to panic with a backtrace inside rock generation
    for args in [
        vec!["world", "generate", "--count", "1", "--scale", "1e-8"],
        vec!["eval", "--worlds", "verti-1", "--scale", "1e-8"],
        vec!["world", "show", "verti-1:1", "--scale", "1/100000"],
    ] {
        let e = run_err(&args);
        assert!(
            e.contains("scale") && e.contains("[1/1000, 10]") && !e.contains("panicked"),
            "{args:?}: {e}"
        );
    }
    // an empty ./verti-2 is not a set: the built-in verti-2 is used, with a note
    let cwd = tmp("shadow");
    std::fs::create_dir_all(cwd.join("verti-2")).unwrap();
    let out = verti()
        .args(["world", "stats", "verti-2", "--json"])
        .current_dir(&cwd)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("note:")
            && err.contains("built-in set `verti-2`")
            && err.contains("./verti-2"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["worlds"], 2);
    // ./verti-2 names the directory, which says what it lacks
    let out = verti()
        .args(["world", "stats", "./verti-2"])
        .current_dir(&cwd)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not a world set"),
        "{err}"
    );
    std::fs::remove_dir_all(cwd).ok();
}

#[test]
fn outputs_must_be_png_files_in_existing_directories() {
    let dir = tmp("outputs");
    std::fs::create_dir_all(&dir).unwrap();
    let d = |p: &str| dir.join(p).to_str().unwrap().to_string();
    // pictures: another extension is refused, with the formats that are supported
    for args in [
        vec!["world", "render", "verti-1:1", "--out", &d("w.jpg")],
        vec!["world", "stats", "verti-1", "--histograms", &d("h.bmp")],
        vec!["replay", &d("run"), "--task", "1", "--out", &d("t.jpeg")],
    ] {
        let e = run_err(&args);
        assert!(
            e.contains("is not a supported format; supported: .png"),
            "{args:?}: {e}"
        );
    }
    let e = run_err(&["world", "render", "verti-1:1", "--out", &d("w")]);
    assert!(e.contains("no extension; supported: .png"), "{e}");
    // no command creates a missing parent directory
    let typo = dir.join("typo");
    for args in [
        vec!["world", "render", "verti-1:1", "--out", &d("typo/a/w.png")],
        vec![
            "world",
            "stats",
            "verti-1",
            "--histograms",
            &d("typo/a/h.png"),
        ],
        vec![
            "replay",
            &d("run"),
            "--task",
            "1",
            "--out",
            &d("typo/a/t.png"),
        ],
        vec!["report", &d("run"), "--out", &d("typo/a/report")],
        vec!["eval", "--worlds", "verti-1", "--out", &d("typo/a/run")],
        vec![
            "world",
            "generate",
            "--count",
            "1",
            "--out",
            &d("typo/a/set"),
        ],
        vec![
            "world",
            "import-vb",
            "--dir",
            &d("vb"),
            "--out",
            &d("typo/a/vb"),
        ],
    ] {
        let e = run_err(&args);
        assert!(
            e.contains(&format!(
                "directory {} does not exist",
                typo.join("a").display()
            )),
            "{args:?}: {e}"
        );
    }
    assert!(!typo.exists(), "a directory was created");
    // an output directory itself may be new when its parent exists
    run_ok(&["world", "render", "verti-1:1", "--out", &d("w.PNG")]);
    assert!(dir.join("w.PNG").is_file());
}

#[test]
fn several_systems_evaluate_in_sequence_into_their_own_folders() {
    let out = tmp("several");
    let out_s = out.to_str().unwrap();
    let stdout = run_ok(&[
        "eval",
        "--system",
        "pid,tal",
        "--worlds",
        "verti-1",
        "--tasks",
        "1-2",
        "--max-time",
        "2",
        "--param",
        "samples=16",
        "--out",
        out_s,
    ]);
    // `samples` is tal's parameter only; pid ran with its own defaults
    for system in ["pid", "tal"] {
        let rs = lines(&out.join(system).join("results.jsonl"));
        assert_eq!(rs.len(), 2, "{system}");
        assert!(rs.iter().all(|r| r["system"] == system));
        assert!(stdout.contains(&format!("{system} on verti-1")), "{stdout}");
    }
    let e = run_err(&[
        "eval",
        "--system",
        "pid,eh",
        "--param",
        "samples=16",
        "--tasks",
        "1",
    ]);
    assert!(
        e.contains("none of pid, eh has a parameter `samples`"),
        "{e}"
    );
    let e = run_err(&["eval", "--system", "pid,nobody", "--tasks", "1"]);
    assert!(e.contains("nobody"), "{e}");
    let _ = std::fs::remove_dir_all(&out);
}
