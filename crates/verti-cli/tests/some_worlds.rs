//! A run of selected tasks builds only the worlds its tasks are on (`verti eval --tasks 11-12`
//! generates one world of verti-100, not a hundred), records each world's digest instead of
//! the set's, and ends exactly as the same tasks of a run over the whole set; resume, merge,
//! report and replay check it world by world.

mod common;

use common::{fails, ok, results, run_json, s, tmp};
use std::path::Path;
use std::process::Command;

/// The worlds whose digests `run.json` records one by one.
fn recorded_worlds(dir: &Path) -> Vec<String> {
    run_json(dir)["world_digests"]
        .as_object()
        .map(|m| m.keys().cloned().collect())
        .unwrap_or_default()
}

/// `verti eval` of PID on verti-3's `tasks` into `out`, with `extra` arguments.
fn eval_args<'a>(out: &'a Path, tasks: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "eval",
        "--system",
        "pid",
        "--worlds",
        "verti-3",
        "--tasks",
        tasks,
        "--max-time",
        "20",
        "--jobs",
        "1",
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    args
}

fn eval(out: &Path, tasks: &str, extra: &[&str]) -> String {
    ok(&eval_args(out, tasks, extra))
}

#[test]
fn selected_tasks_build_only_their_worlds_and_end_as_in_the_whole_set() {
    let root = tmp("some-worlds", "alike");
    let (whole, some) = (root.join("whole"), root.join("some"));
    eval(&whole, "all", &[]);
    let whole_record = run_json(&whole);
    assert!(whole_record["worlds_digest"].is_string());
    assert!(whole_record.get("world_digests").is_none());
    let same_tasks = |tasks: &[u64]| -> Vec<serde_json::Value> {
        results(&whole)
            .into_iter()
            .filter(|r| tasks.contains(&r["task"].as_u64().unwrap()))
            .collect()
    };

    // tasks 11 and 12 lie on world 2: only it is built and recorded
    eval(&some, "11-12", &[]);
    assert!(run_json(&some).get("worlds_digest").is_none());
    assert_eq!(recorded_worlds(&some), ["2"]);
    assert_eq!(results(&some), same_tasks(&[11, 12]));

    // a resume that widens the selection builds the new task's world and keeps the old digest
    eval(&some, "21", &["--resume"]);
    assert_eq!(recorded_worlds(&some), ["2", "3"]);
    // a resume with no selection continues the recorded one, on its worlds
    let said = eval(&some, "all", &["--resume"]);
    assert!(said.contains("3 tasks"), "{said}");
    assert_eq!(recorded_worlds(&some), ["2", "3"]);
    // ... and one over every task ends as the whole run did
    eval(&some, "1-30", &["--resume"]);
    assert_eq!(recorded_worlds(&some), ["1", "2", "3"]);
    assert_eq!(results(&some), results(&whole));

    // a run recorded over the whole set is resumed over the whole set, so it is still checked
    // by the set's digest
    eval(&whole, "1-2", &["--resume"]);
    assert_eq!(
        run_json(&whole)["worlds_digest"],
        whole_record["worlds_digest"]
    );

    // a world whose contents changed is refused by name
    let mut tampered = run_json(&some);
    tampered["world_digests"]["2"] = "0123456789abcdef".into();
    std::fs::write(
        some.join("run.json"),
        serde_json::to_string_pretty(&tampered).unwrap(),
    )
    .unwrap();
    let e = fails(&eval_args(&some, "11", &["--resume"]));
    assert!(
        e.contains("cannot resume") && e.contains("its contents differ (world(s) 2 of"),
        "{e}"
    );
}

#[test]
fn shards_reports_and_replays_of_selected_tasks() {
    let root = tmp("some-worlds", "joined");
    // two shards of tasks 1-20: each records the worlds of its own tasks
    let shards: Vec<_> = (0..2).map(|i| root.join(format!("shard{i}"))).collect();
    for (i, dir) in shards.iter().enumerate() {
        eval(dir, "1-20", &["--shard", &format!("{i}/2")]);
    }
    let merged = root.join("merged");
    ok(&["merge", "--out", s(&merged), s(&shards[0]), s(&shards[1])]);
    assert_eq!(recorded_worlds(&merged), ["1", "2"]);
    let one = root.join("one");
    eval(&one, "1-20", &[]);
    assert_eq!(results(&merged), results(&one));
    assert_eq!(
        run_json(&merged)["world_digests"],
        run_json(&one)["world_digests"]
    );

    // runs of one system with the same settings on different tasks report as one column
    let other = root.join("other");
    eval(&other, "21-22", &[]);
    let text = ok(&["report", "--json", s(&one), s(&other)]);
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    let systems = summary["systems"].as_array().unwrap();
    assert_eq!(systems.len(), 1, "{text}");
    assert_eq!(systems[0]["name"], "pid");

    // replay builds the task's world alone and checks it against the recorded digest
    let png = root.join("t12.png");
    let said = ok(&["replay", s(&one), "--task", "12", "--out", s(&png)]);
    assert!(said.contains("trajectory written"), "{said}");
}

#[test]
fn runs_on_different_contents_of_one_set_name_stay_apart() {
    let root = tmp("some-worlds", "apart");
    let run_in = |dir: &Path, seed: &str| {
        std::fs::create_dir_all(dir).unwrap();
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_verti"));
        cmd.current_dir(dir);
        let made = cmd
            .args(["world", "generate", "--count", "2", "--seed", seed])
            .args(["--out", "w"])
            .output()
            .unwrap();
        assert!(made.status.success(), "{made:?}");
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_verti"));
        cmd.current_dir(dir);
        let run = cmd
            .args(["eval", "--worlds", "w", "--tasks", "1-2", "--max-time", "3"])
            .args(["--jobs", "1", "--out", "run"])
            .output()
            .unwrap();
        assert!(run.status.success(), "{run:?}");
        dir.join("run")
    };
    let a = run_in(&root.join("a"), "1");
    let b = run_in(&root.join("b"), "2");
    // both ran `w`, tasks 1-2, on a world 1 that differs: two columns, told apart by content
    let text = ok(&["report", "--json", s(&a), s(&b)]);
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    let names: Vec<&str> = summary["systems"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 2, "{text}");
    assert!(
        names.iter().all(|n| n.starts_with("pid [worlds=w#")),
        "{names:?}"
    );
}
