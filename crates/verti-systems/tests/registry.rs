//! A system registered from outside verti-systems (as a learned-systems crate would), built
//! with string and path parameters, run through the evaluation, and its parameters recorded in
//! and resumed from `run.json`; old `run.json` files resume too.

use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::episode::Rules;
use verti_bench::eval::{EvalSetup, RUN_FILE, RunInfo, evaluate, parse_tasks};
use verti_bench::{
    Action, EpisodeConfig, MobilitySystem, Observation, ParamSpec, ParamValue, Params, SystemInfo,
    SystemRegistry, TaskInfo,
};
use verti_core::Factory;
use verti_world::World;
use verti_world::generate::one_default_world;

/// Drives at a fixed speed and a steering read from a "weights" file.
struct Scripted {
    label: String,
    steering: f64,
}

impl MobilitySystem for Scripted {
    fn name(&self) -> &str {
        &self.label
    }
    fn control_rate(&self) -> f64 {
        10.0
    }
    fn reset(&mut self, _task: &TaskInfo) {}
    fn act(&mut self, _obs: &Observation) -> Action {
        Action::HighLevel {
            speed: 2.0,
            steering: self.steering,
        }
    }
}

struct ScriptedFactory;

impl Factory<dyn MobilitySystem> for ScriptedFactory {
    fn info(&self) -> SystemInfo {
        SystemInfo {
            name: "scripted".into(),
            summary: "constant steering from a file".into(),
            params: vec![
                ParamSpec::string("label", "scripted", "name reported in results"),
                ParamSpec::path("weights", "", "file holding the steering"),
                ParamSpec::choice(
                    "mode",
                    "file",
                    &["file", "straight"],
                    "where steering comes from",
                ),
            ],
        }
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        let steering = match (p.str("mode"), p.path("weights")) {
            ("straight", _) => 0.0,
            (_, None) => return Err("mode=file needs weights".into()),
            (_, Some(path)) => std::fs::read_to_string(path)
                .map_err(|e| e.to_string())?
                .trim()
                .parse()
                .map_err(|_| format!("{} holds no number", path.display()))?,
        };
        Ok(Box::new(Scripted {
            label: p.str("label").to_string(),
            steering,
        }))
    }
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-registry-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn registry() -> SystemRegistry {
    let mut r = SystemRegistry::new();
    verti_systems::register(&mut r);
    r.register(ScriptedFactory).unwrap();
    r
}

#[test]
fn an_outside_system_registers_and_builds_with_string_and_path_parameters() {
    let r = registry();
    assert_eq!(r.names(), ["pid", "eh", "mppi", "oracle", "scripted"]);
    let dir = tmp("build");
    let weights = dir.join("steer.txt");
    std::fs::write(&weights, "0.25\n").unwrap();
    let given = vec![
        r.parse_param("scripted", "label=toy").unwrap(),
        r.parse_param("scripted", &format!("weights={}", weights.display()))
            .unwrap(),
    ];
    assert_eq!(given[1].1, ParamValue::Path(weights.clone()));
    let mut sys = r.create("scripted", &given).unwrap();
    assert_eq!(sys.name(), "toy");
    let w = one_default_world().unwrap();
    let obs = verti_bench::observation::test_observation(&w, [0.0, 0.0], 0.0, [10.0, 0.0], &[]);
    assert_eq!(
        sys.act(&obs),
        Action::HighLevel {
            speed: 2.0,
            steering: 0.25
        }
    );

    // errors name the system and the parameter
    let err = |text: &str| r.parse_param("scripted", text).unwrap_err().to_string();
    assert_eq!(
        err("weights=/no/such/weights.bin"),
        "system scripted parameter weights: `/no/such/weights.bin` does not exist"
    );
    assert_eq!(
        err("mode=guess"),
        "system scripted parameter mode: `guess` is not one of file, straight"
    );
    assert!(err("colour=red").contains(
        "system scripted has no parameter `colour`; its parameters: label, weights, mode"
    ));
    let e = r
        .create("scripted", &[("label".into(), ParamValue::Float(1.0))])
        .err()
        .unwrap()
        .to_string();
    assert_eq!(
        e,
        "system scripted parameter label: expected string, got `1`"
    );
    // the factory's own refusal
    let e = r.create("scripted", &[]).err().unwrap().to_string();
    assert_eq!(e, "cannot build system scripted: mode=file needs weights");
}

fn setup<'a>(
    worlds: &'a [Arc<World>],
    vehicle: &'a verti_sim::VehicleSpec,
    out: PathBuf,
    system: &str,
    params: Params,
) -> EvalSetup<'a> {
    EvalSetup {
        worlds,
        whole_set: true,
        vehicle,
        episode: EpisodeConfig {
            max_time: 5.0,
            ..Default::default()
        },
        jobs: 1,
        out,
        resume: false,
        force: true,
        run: RunInfo {
            system: system.into(),
            params,
            vehicle: vehicle.name.clone(),
            worlds: "verti-1".into(),
            scale: 1.0,
            rules: Rules::Paper,
            seed: 0,
            max_time: 5.0,
        },
        inputs: None,
        shard: None,
        step_log: None,
        cancel: None,
        warn: None,
    }
}

#[test]
fn run_json_records_every_parameter_and_resumes_old_and_new_records() {
    let r = registry();
    let ws: Vec<Arc<World>> = vec![Arc::new(one_default_world().unwrap())];
    let hmmwv = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let dir = tmp("eval");
    let weights = dir.join("steer.txt");
    std::fs::write(&weights, "-0.5").unwrap();
    let params = r
        .resolve(
            "scripted",
            &[("weights".into(), ParamValue::Path(weights.clone()))],
        )
        .unwrap();
    let out = dir.join("run");
    let make = || r.build("scripted", &params).unwrap();
    let s = setup(&ws, &hmmwv, out.clone(), "scripted", params.clone());
    let first = evaluate(&s, &parse_tasks("1").unwrap(), &make, &|_| {}).unwrap();
    assert_eq!(first.len(), 1);
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join(RUN_FILE)).unwrap()).unwrap();
    assert_eq!(
        run["params"],
        serde_json::json!({"label": "scripted", "weights": weights.to_str().unwrap(), "mode": "file"})
    );
    // the recorded values rebuild the system (as `verti replay` does)
    let recorded: verti_bench::identity::RunRecord =
        serde_json::from_str(&std::fs::read_to_string(out.join(RUN_FILE)).unwrap()).unwrap();
    assert_eq!(
        r.build("scripted", &recorded.run.params).unwrap().name(),
        "scripted"
    );

    // resuming with the same parameters, however given, continues the run
    let mut again = setup(&ws, &hmmwv, out.clone(), "scripted", params.clone());
    (again.resume, again.force) = (true, false);
    let both = evaluate(&again, &parse_tasks("1-2").unwrap(), &make, &|_| {}).unwrap();
    assert_eq!(both.len(), 2);
    // ... and with others is refused
    let other = r
        .resolve(
            "scripted",
            &[
                ("weights".into(), ParamValue::Path(weights.clone())),
                ("label".into(), "renamed".into()),
            ],
        )
        .unwrap();
    let mut changed = setup(&ws, &hmmwv, out.clone(), "scripted", other);
    (changed.resume, changed.force) = (true, false);
    let e = evaluate(&changed, &[], &make, &|_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a different run")
            && e.contains("parameter `label`: scripted recorded, renamed now"),
        "{e}"
    );

    // a run.json from before typed parameters: only the given ones, as numbers
    let pid = |given: &[(String, ParamValue)]| r.resolve("pid", given).unwrap();
    let make_pid = || r.build("pid", &pid(&[])).unwrap();
    let old = dir.join("old");
    evaluate(
        &setup(&ws, &hmmwv, old.clone(), "pid", pid(&[])),
        &parse_tasks("1").unwrap(),
        &make_pid,
        &|_| {},
    )
    .unwrap();
    let mut legacy: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(old.join(RUN_FILE)).unwrap()).unwrap();
    legacy["params"] = serde_json::json!([["speed", 3.0], ["rate", 20.0]]);
    let write_legacy =
        |v: &serde_json::Value| std::fs::write(old.join(RUN_FILE), v.to_string()).unwrap();
    write_legacy(&legacy);
    let mut resume = setup(&ws, &hmmwv, old.clone(), "pid", pid(&[]));
    (resume.resume, resume.force) = (true, false);
    assert_eq!(
        evaluate(&resume, &parse_tasks("1-2").unwrap(), &make_pid, &|_| {})
            .unwrap()
            .len(),
        2
    );
    // the resumed run rewrote run.json with every parameter
    let now: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(old.join(RUN_FILE)).unwrap()).unwrap();
    assert_eq!(now["params"]["kp"], serde_json::json!(1.0));
    legacy["params"] = serde_json::json!([["speed", 4.0]]);
    write_legacy(&legacy);
    let e = evaluate(&resume, &[], &make_pid, &|_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("parameter `speed`: 4 recorded"), "{e}");
}
