//! Evaluation of the classical systems: determinism across job counts, resume, bad input.

use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::EpisodeConfig;
use verti_bench::episode::{Outcome, Rules};
use verti_bench::eval::{EvalSetup, RESULTS_FILE, RunInfo, evaluate, parse_tasks, read_results};
use verti_sim::vehicles;
use verti_world::World;
use verti_world::generate::{SetConfig, generate_set};

fn worlds(n: u32) -> Vec<Arc<World>> {
    generate_set(
        &SetConfig {
            count: n,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap()
    .into_iter()
    .map(Arc::new)
    .collect()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-eval-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn setup<'a>(
    worlds: &'a [Arc<World>],
    vehicle: &'a verti_sim::VehicleSpec,
    out: PathBuf,
    jobs: usize,
    system: &str,
) -> EvalSetup<'a> {
    EvalSetup {
        worlds,
        whole_set: true,
        vehicle,
        episode: EpisodeConfig {
            max_time: 30.0,
            ..Default::default()
        },
        jobs,
        out,
        resume: false,
        force: true,
        run: RunInfo {
            system: system.into(),
            params: verti_systems::builtin().resolve(system, &[]).unwrap(),
            vehicle: vehicle.name.clone(),
            worlds: "verti-2".into(),
            scale: 1.0,
            rules: Rules::Paper,
            seed: 0,
            max_time: 30.0,
        },
        inputs: None,
        shard: None,
        step_log: None,
        cancel: None,
        warn: None,
    }
}

fn without_wall_time(mut rs: Vec<verti_bench::TrialResult>) -> Vec<verti_bench::TrialResult> {
    for r in &mut rs {
        r.wall_time = 0.0;
    }
    rs
}

/// Compares result lists, reporting the first differing task rather than both lists.
fn assert_same(a: Vec<verti_bench::TrialResult>, b: Vec<verti_bench::TrialResult>, what: &str) {
    let (a, b) = (without_wall_time(a), without_wall_time(b));
    assert_eq!(a.len(), b.len(), "{what}: different numbers of results");
    for (x, y) in a.iter().zip(&b) {
        assert!(x == y, "{what}: task {} differs:\n{x:?}\n{y:?}", x.task);
    }
}

#[test]
fn results_are_identical_for_any_number_of_jobs() {
    let ws = worlds(2);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    for system in ["pid", "mppi"] {
        // MPPI draws random samples: its per-task seed makes it deterministic too
        let params: Vec<(String, verti_bench::ParamValue)> = if system == "mppi" {
            vec![("samples".into(), 64.into()), ("horizon".into(), 20.into())]
        } else {
            vec![]
        };
        let make = || verti_systems::create(system, &params).unwrap();
        let tasks = if system == "mppi" {
            parse_tasks("1-3").unwrap()
        } else {
            Vec::new()
        };
        let a = evaluate(
            &setup(&ws, &hmmwv, tmp(&format!("{system}-j1")), 1, system),
            &tasks,
            &make,
            &|_| {},
        )
        .unwrap();
        let b = evaluate(
            &setup(&ws, &hmmwv, tmp(&format!("{system}-j2")), 2, system),
            &tasks,
            &make,
            &|_| {},
        )
        .unwrap();
        assert_eq!(a.len(), if system == "mppi" { 3 } else { 20 });
        assert!(a.iter().all(|r| r.outcome != Outcome::Error), "{a:?}");
        assert_same(a, b, &format!("{system} with 1 and 2 jobs"));
    }
}

#[test]
fn a_torn_results_file_resumes_without_losing_or_repeating_trials() {
    let ws = worlds(2);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let make = || verti_systems::create("pid", &[]).unwrap();
    let full = evaluate(
        &setup(&ws, &hmmwv, tmp("full"), 2, "pid"),
        &[],
        &make,
        &|_| {},
    )
    .unwrap();

    // a run killed after 7 trials, in the middle of writing the 8th line
    let out = tmp("torn");
    let first = evaluate(
        &setup(&ws, &hmmwv, out.clone(), 2, "pid"),
        &parse_tasks("1-7").unwrap(),
        &make,
        &|_| {},
    )
    .unwrap();
    assert_eq!(first.len(), 7);
    let path = out.join(RESULTS_FILE);
    let mut text = std::fs::read_to_string(&path).unwrap();
    let torn_line = serde_json::to_string(&full[9]).unwrap();
    text.push_str(&torn_line[..torn_line.len() / 2]);
    std::fs::write(&path, text).unwrap();
    let (before, clean) = read_results(&path).unwrap();
    assert_eq!((before.len(), clean), (7, false));

    // without --resume the run refuses to touch the file
    let mut s = setup(&ws, &hmmwv, out.clone(), 2, "pid");
    s.force = false;
    let e = evaluate(&s, &[], &make, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("--resume"), "{e}");
    // resuming with different settings is refused
    s.resume = true;
    s.run.seed = 1;
    let e = evaluate(&s, &[], &make, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("seed: 0 recorded, 1 now"), "{e}");
    s.run.seed = 0;
    // the killed run covered tasks 1-7; extend it to the whole set
    let resumed = evaluate(&s, &parse_tasks("1-20").unwrap(), &make, &|_| {}).unwrap();
    assert_same(
        resumed,
        full.clone(),
        "resumed run against an uninterrupted one",
    );
    let (on_disk, clean) = read_results(&path).unwrap();
    assert!(clean);
    let mut tasks: Vec<u32> = on_disk.iter().map(|r| r.task).collect();
    tasks.sort();
    assert_eq!(
        tasks,
        (1..=20).collect::<Vec<_>>(),
        "each task exactly once"
    );
}

#[test]
fn a_set_holding_one_world_twice_is_refused() {
    let ws = worlds(2);
    let twice = vec![ws[0].clone(), ws[1].clone(), ws[0].clone()];
    let e = verti_bench::eval::select_tasks(&twice, &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("both have index 1"), "{e}");
}

#[test]
fn bad_task_selections_are_rejected() {
    for bad in ["0", "5-1", "abc", "1,,2", "3-x", ""] {
        let e = parse_tasks(bad).unwrap_err().to_string();
        assert!(e.contains("bad task range"), "{bad}: {e}");
    }
    assert_eq!(parse_tasks("3,1-2, 10").unwrap(), vec![1, 2, 3, 10]);
    let ws = worlds(2);
    let e = verti_bench::eval::select_tasks(&ws, &parse_tasks("15-25").unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("not in this world set") && e.contains("1..=20"),
        "{e}"
    );
}

#[test]
fn pid_reaches_goals_on_the_built_in_set() {
    // a sanity check of the whole stack on a few real tasks: PID must succeed on some and
    // every trial must end cleanly
    let ws = worlds(3);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let make = || verti_systems::create("pid", &[]).unwrap();
    let mut s = setup(&ws, &hmmwv, tmp("pid-sanity"), 2, "pid");
    s.episode.max_time = 60.0;
    let rs = evaluate(&s, &[], &make, &|_| {}).unwrap();
    assert_eq!(rs.len(), 30);
    assert!(rs.iter().all(|r| r.outcome != Outcome::Error));
    assert!(rs.iter().filter(|r| r.outcome == Outcome::Success).count() >= 5);
}

#[test]
fn a_last_line_without_its_newline_is_not_glued_to_the_next_result_and_torn_lines_are_reported() {
    let ws = worlds(1);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let make = || verti_systems::create("pid", &[]).unwrap();
    let out = tmp("no-newline");
    evaluate(
        &setup(&ws, &hmmwv, out.clone(), 1, "pid"),
        &parse_tasks("1-3").unwrap(),
        &make,
        &|_| {},
    )
    .unwrap();
    // a complete last line whose newline was lost
    let path = out.join(RESULTS_FILE);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.trim_end()).unwrap();
    let warnings = std::sync::Mutex::new(Vec::<String>::new());
    let warn = |m: &str| warnings.lock().unwrap().push(m.to_string());
    let mut s = setup(&ws, &hmmwv, out.clone(), 1, "pid");
    s.force = false;
    s.resume = true;
    s.warn = Some(&warn);
    let all = evaluate(&s, &parse_tasks("1-5").unwrap(), &make, &|_| {}).unwrap();
    assert_eq!(all.len(), 5);
    let (on_disk, clean) = read_results(&path).unwrap();
    assert!(clean && on_disk.len() == 5, "{} results", on_disk.len());
    assert!(warnings.lock().unwrap().is_empty(), "nothing was torn");

    // a torn line is dropped, and said so
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str("{\"task\": 9");
    std::fs::write(&path, text).unwrap();
    evaluate(&s, &parse_tasks("1-5").unwrap(), &make, &|_| {}).unwrap();
    let said = warnings.lock().unwrap().join("\n");
    assert!(said.contains("torn last line"), "{said}");
}

#[test]
fn two_runs_never_share_a_results_directory() {
    let ws = worlds(1);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let make = || verti_systems::create("pid", &[]).unwrap();
    let out = tmp("locked");
    std::fs::create_dir_all(&out).unwrap();
    // another run holds the directory
    let other = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(out.join(verti_bench::eval::LOCK_FILE))
        .unwrap();
    other.lock().unwrap();
    let e = evaluate(
        &setup(&ws, &hmmwv, out.clone(), 1, "pid"),
        &parse_tasks("1").unwrap(),
        &make,
        &|_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("in use by another running evaluation"), "{e}");
    assert!(!out.join(RESULTS_FILE).exists(), "nothing was written");
    // once it is gone (finished or killed), the directory is free
    drop(other);
    let r = evaluate(
        &setup(&ws, &hmmwv, out.clone(), 1, "pid"),
        &parse_tasks("1").unwrap(),
        &make,
        &|_| {},
    )
    .unwrap();
    assert_eq!(r.len(), 1);
}

#[test]
fn absurd_worker_counts_are_refused() {
    let ws = worlds(1);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let make = || verti_systems::create("pid", &[]).unwrap();
    let e = evaluate(
        &setup(&ws, &hmmwv, tmp("jobs"), 10_000, "pid"),
        &parse_tasks("1").unwrap(),
        &make,
        &|_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("--jobs 10000 is too many"), "{e}");
    assert!(verti_bench::eval::check_jobs(verti_bench::eval::max_jobs(), "--jobs").is_ok());
    assert!(verti_bench::eval::check_jobs(0, "--jobs").is_err());
}

#[test]
fn a_resume_continues_the_recorded_selection() {
    let ws = worlds(2);
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let make = || verti_systems::create("pid", &[]).unwrap();
    let out = tmp("selection");
    let recorded = || {
        let text = std::fs::read_to_string(out.join("run.json")).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["tasks"].as_str().unwrap().to_string()
    };
    evaluate(
        &setup(&ws, &hmmwv, out.clone(), 1, "pid"),
        &parse_tasks("1-3").unwrap(),
        &make,
        &|_| {},
    )
    .unwrap();
    assert_eq!(recorded(), "1-3");
    let mut s = setup(&ws, &hmmwv, out.clone(), 1, "pid");
    s.force = false;
    s.resume = true;
    // no --tasks: the recorded three, not the whole set
    let all = evaluate(&s, &[], &make, &|_| {}).unwrap();
    assert_eq!(all.len(), 3);
    // told otherwise: those run too, and the run now covers both
    let all = evaluate(&s, &parse_tasks("5,12").unwrap(), &make, &|_| {}).unwrap();
    assert_eq!(
        all.iter().map(|r| r.task).collect::<Vec<_>>(),
        vec![1, 2, 3, 5, 12]
    );
    assert_eq!(recorded(), "1-3,5,12");
    assert_eq!(verti_bench::eval::format_tasks(&[]), "all");
    assert_eq!(parse_tasks("all").unwrap(), Vec::<u32>::new());
}
