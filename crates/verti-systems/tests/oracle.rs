//! The oracle on a small hand-made world: a tree on the straight line from start to goal.
//! Driving straight ends against the tree; the oracle, rolling candidates out on branches of
//! the true trial, goes around it. Also: determinism (twice, and with 1 or 2 jobs), the
//! error without privileged access, and parameter validation.

use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::episode::{Outcome, Rules};
use verti_bench::eval::{EvalSetup, RunInfo, evaluate};
use verti_bench::observation::test_observation;
use verti_bench::{
    Action, EpisodeConfig, MobilitySystem, Observation, ParamValue, TaskInfo, Trial, TrialResult,
    run_episode,
};
use verti_sim::{testing, vehicles};
use verti_systems::oracle::{Oracle, OracleParams};
use verti_world::{Task, World};

/// Flat rigid ground with a tree (radius 2 m) at the origin, on the straight line of task 0
/// (from x = -30 to x = 30); task 1 runs beside it.
fn tree_world() -> Arc<World> {
    let mut w = testing::tree_world(1.0, 0.8, 0.0, 2.0, 6.0);
    w.meta.index = 1;
    w.tasks = vec![
        Task {
            pair: 0,
            start: [-30.0, 0.0],
            goal: [30.0, 0.0],
        },
        Task {
            pair: 1,
            start: [-30.0, 20.0],
            goal: [20.0, 20.0],
        },
    ];
    Arc::new(w)
}

fn episode() -> EpisodeConfig {
    EpisodeConfig {
        max_time: 40.0,
        ..Default::default()
    }
}

/// Small and quick: the test must take seconds.
fn small() -> OracleParams {
    OracleParams {
        samples: 10,
        horizon: 3.0,
        segments: 3,
        replan: 0.5,
        ..Default::default()
    }
}

/// The trivial baseline: straight ahead at 3 m/s.
struct Straight;

impl MobilitySystem for Straight {
    fn name(&self) -> &str {
        "straight"
    }
    fn control_rate(&self) -> f64 {
        10.0
    }
    fn reset(&mut self, _task: &TaskInfo) {}
    fn act(&mut self, _obs: &Observation) -> Action {
        Action::HighLevel {
            speed: 3.0,
            steering: 0.0,
        }
    }
}

fn run(system: &mut dyn MobilitySystem, pair: u32) -> TrialResult {
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    run_episode(&tree_world(), &hmmwv, pair, system, &episode(), None)
}

fn same(mut a: TrialResult, mut b: TrialResult) {
    a.wall_time = 0.0;
    b.wall_time = 0.0;
    assert_eq!(a, b);
}

#[test]
fn the_oracle_goes_around_the_tree_that_stops_straight_driving() {
    let straight = run(&mut Straight, 0);
    assert_ne!(straight.outcome, Outcome::Success, "{straight:?}");
    let mut oracle = Oracle::new(small()).unwrap();
    let r = run(&mut oracle, 0);
    assert_eq!(r.outcome, Outcome::Success, "{r:?}");
    assert!(oracle.plans > 0 && oracle.rollouts >= oracle.plans);
    // and it is deterministic: the same task twice gives the same result, field by field
    let mut again = Oracle::new(small()).unwrap();
    same(r, run(&mut again, 0));
}

#[test]
fn results_do_not_depend_on_the_number_of_jobs() {
    let worlds = [tree_world()];
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let given: Vec<(String, ParamValue)> = vec![
        ("samples".into(), 10.into()),
        ("horizon".into(), 3.0.into()),
        ("segments".into(), 3.into()),
    ];
    let registry = verti_systems::builtin();
    let params = registry.resolve("oracle", &given).unwrap();
    let make = || registry.build("oracle", &params).unwrap();
    let results = |jobs: usize| {
        let out: PathBuf =
            std::env::temp_dir().join(format!("verti-oracle-j{jobs}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let setup = EvalSetup {
            worlds: &worlds,
            whole_set: true,
            vehicle: &hmmwv,
            episode: episode(),
            jobs,
            out: out.clone(),
            resume: false,
            force: true,
            run: RunInfo {
                system: "oracle".into(),
                params: params.clone(),
                vehicle: "hmmwv".into(),
                worlds: "tree".into(),
                scale: 1.0,
                rules: Rules::Paper,
                seed: 0,
                max_time: 40.0,
            },
            inputs: None,
            shard: None,
            step_log: None,
            cancel: None,
            warn: None,
        };
        let mut r = evaluate(&setup, &[], &make, &|_| {}).unwrap();
        let _ = std::fs::remove_dir_all(&out);
        r.sort_by_key(|r| r.task);
        r
    };
    let (a, b) = (results(1), results(2));
    assert_eq!(a.len(), 2);
    for (x, y) in a.into_iter().zip(b) {
        assert_eq!(x.outcome, Outcome::Success, "{x:?}");
        same(x, y);
    }
}

#[test]
fn without_privileged_access_the_oracle_fails_the_trial_with_a_message() {
    let world = tree_world();
    let hmmwv = vehicles::builtin("hmmwv").unwrap();
    let mut oracle = Oracle::new(small()).unwrap();
    // a hand-built observation has no trial behind it
    let obs = test_observation(&world, [-30.0, 0.0], 0.0, [30.0, 0.0], &[]);
    assert!(obs.trial().is_none());
    let _ = oracle.act(&obs);
    let message = oracle.failure().expect("the oracle says why it cannot act");
    assert!(message.contains("privileged"), "{message}");

    // a driver that withholds the trial: the trial ends as an error with that message
    let mut trial = Trial::start(&world, &hmmwv, 0, &episode(), "oracle").unwrap();
    let mut oracle = Oracle::new(small()).unwrap();
    oracle.reset(trial.info());
    assert!(trial.observation().trial().is_some());
    let _ = oracle.act(&trial.observation().without_trial());
    trial.abort(oracle.failure().unwrap());
    let r = trial.finish();
    assert_eq!(r.outcome, Outcome::Error);
    assert!(r.error.unwrap().contains("privileged access"));
}

#[test]
fn parameters_are_validated() {
    let bad = |p: OracleParams| match Oracle::new(p) {
        Ok(_) => panic!("refused"),
        Err(e) => e,
    };
    let e = bad(OracleParams {
        horizon: 0.25,
        ..Default::default()
    });
    assert!(e.contains("horizon") && e.contains("0.1"), "{e}");
    let e = bad(OracleParams {
        horizon: 4.0,
        segments: 3,
        ..Default::default()
    });
    assert!(e.contains("segments"), "{e}");
    let e = bad(OracleParams {
        replan: 2.0,
        ..Default::default()
    });
    assert!(e.contains("replan"), "{e}");
    let e = bad(OracleParams {
        min_speed: 4.0,
        ..Default::default()
    });
    assert!(e.contains("min_speed"), "{e}");
    // through the registry: ranges and consistency, naming the system and the parameter
    let r = verti_systems::builtin();
    let e = r
        .parse_param("oracle", "samples=0")
        .unwrap_err()
        .to_string();
    assert!(e.contains("oracle") && e.contains("samples"), "{e}");
    let e = verti_systems::create("oracle", &[("replan".into(), 0.15.into())])
        .err()
        .unwrap();
    assert!(e.contains("replan"), "{e}");
    assert!(verti_systems::create("oracle", &[]).is_ok());
}
