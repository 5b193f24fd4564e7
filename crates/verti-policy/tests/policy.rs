//! Policies: save/load round trip, refusal of malformed cards by field, and the benchmark
//! system driving exactly as the training environment does.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::episode::{EpisodeConfig, run_episode};
use verti_env::{EnvCore, ObsBuf, TaskFilter};
use verti_nn::{LayerSpec, ModelCard, Network, Shape};
use verti_policy::inputs::{INPUT_DIM, env_config, policy_input};
use verti_policy::system::PolicyDriver;
use verti_policy::{Policy, shipped};
use verti_world::World;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verti-policy-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A small random policy network with the given constants.
fn network(inputs: usize, constants: BTreeMap<String, Vec<f64>>) -> Network {
    let layers = vec![
        LayerSpec::Linear { inputs, outputs: 8 },
        LayerSpec::Tanh,
        LayerSpec::Linear {
            inputs: 8,
            outputs: 2,
        },
    ];
    let n = inputs * 8 + 8 + 8 * 2 + 2;
    let mut rng = verti_core::Rng::new(5);
    let params: Vec<f32> = (0..n).map(|_| rng.range(-0.3, 0.3) as f32).collect();
    let card = ModelCard {
        constants,
        ..ModelCard::new("toy", Shape::Flat(inputs), layers)
    };
    Network::from_params(card, &params).unwrap()
}

fn log_std() -> BTreeMap<String, Vec<f64>> {
    BTreeMap::from([("log_std".to_string(), vec![-0.5, -0.7])])
}

#[test]
fn shipped_policies_survive_a_save_and_load_bit_for_bit() {
    let dir = temp_dir("roundtrip");
    let x: Vec<f32> = (0..INPUT_DIM).map(|i| ((i as f32) * 0.37).sin()).collect();
    for (name, policy) in shipped::all() {
        let policy = policy.unwrap_or_else(|e| panic!("{name}: {e}"));
        let card = dir.join(format!("{name}.yaml"));
        policy.network().save(&card).unwrap();
        let back = Policy::load(&card).unwrap();
        assert_eq!(back.network().params(), policy.network().params(), "{name}");
        assert_eq!(back.log_std(), policy.log_std());
        let (mut s1, mut s2) = (policy.scratch(), back.scratch());
        assert_eq!(policy.mean(&x, &mut s1), back.mean(&x, &mut s2), "{name}");
        let a = policy.act(&x, &mut s1);
        assert!(a.iter().all(|v| (-1.0..=1.0).contains(v)));
    }
}

#[test]
fn malformed_policy_cards_are_refused_by_field() {
    let e = Policy::new(Arc::new(network(INPUT_DIM, BTreeMap::new()))).unwrap_err();
    assert!(
        e.contains("constants.log_std") && e.contains("missing"),
        "{e}"
    );
    let bad = BTreeMap::from([("log_std".to_string(), vec![0.1])]);
    let e = Policy::new(Arc::new(network(INPUT_DIM, bad))).unwrap_err();
    assert!(
        e.contains("constants.log_std") && e.contains("2 finite"),
        "{e}"
    );
    let e = Policy::new(Arc::new(network(10, log_std()))).unwrap_err();
    assert!(
        e.contains("field input") && e.contains(&INPUT_DIM.to_string()),
        "{e}"
    );
    assert!(Policy::new(Arc::new(network(INPUT_DIM, log_std()))).is_ok());
    let missing = temp_dir("missing").join("none.yaml");
    let e = Policy::load(&missing).unwrap_err();
    assert!(e.contains("none.yaml"), "{e}");
}

fn world() -> Arc<World> {
    let set = verti_world::sets::resolve_set("verti-1-s2", 1.0, &|| {}).unwrap();
    Arc::new(set.worlds.into_iter().next().unwrap())
}

/// The benchmark system and the training environment, driven by the same policy on the same
/// task, take the same path to the same outcome: a policy is evaluated on the very inputs it
/// was trained on.
#[test]
fn the_benchmark_system_drives_as_the_training_environment() {
    let w = world();
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let policy = shipped::rl_v1().unwrap();
    let pair = w.tasks[0].pair;
    let number = w.task_id(pair).number();
    let cfg = EpisodeConfig::default();
    let mut driver = PolicyDriver::new("rl", policy.clone());
    let bench = run_episode(&w, &spec, pair, &mut driver, &cfg, None);

    let mut env = EnvCore::new(
        vec![w.clone()],
        spec,
        env_config(),
        &TaskFilter::default(),
        0,
    )
    .unwrap();
    env.reset(None, Some(number)).unwrap();
    let (mut buf, mut x, mut scratch) = (ObsBuf::default(), Vec::new(), policy.scratch());
    let outcome = loop {
        env.observe(&mut buf).unwrap();
        policy_input(&buf, w.meta.scale, &mut x);
        let a = policy.act(&x, &mut scratch);
        let action = env
            .action_from_normalized(&[f64::from(a[0]), f64::from(a[1])])
            .unwrap();
        if let Some(o) = env.step(action).unwrap().outcome {
            break o;
        }
    };
    let ep = env.episode().unwrap().metrics();
    assert_eq!(bench.outcome, outcome);
    assert_eq!(bench.time, ep.time, "same trial length");
    assert_eq!(bench.path_length, ep.path_length, "same path, bit for bit");
}
