//! The environment core: same trials as the benchmark, determinism, errors and the reward.

use std::sync::Arc;
use verti_bench::episode::{EpisodeConfig, run_episode};
use verti_bench::{Action, MobilitySystem, task_info};
use verti_env::*;
use verti_sim::{Controls, VehicleSpec};
use verti_world::generate::{SetConfig, composition, elevation::ProceduralRock, generate_world};
use verti_world::{ElevationLevel, World};

fn world(index: u32) -> Arc<World> {
    let config = SetConfig {
        count: 100,
        ..Default::default()
    };
    let (l, t, d) = composition(&config)[index as usize - 1];
    Arc::new(generate_world(&config, index, l, t, d, &ProceduralRock::default()).unwrap())
}

fn hmmwv() -> VehicleSpec {
    verti_sim::vehicles::builtin("hmmwv").unwrap()
}

/// A PID system driving through the environment gets exactly the benchmark's trial.
#[test]
fn pid_through_the_env_reproduces_run_episode() {
    let w = world(1);
    let spec = hmmwv();
    let pair = 3;
    let cfg = EpisodeConfig {
        max_time: 20.0,
        ..Default::default()
    };
    let mut pid = verti_systems::pid::Pid::new(Default::default());
    let reference = run_episode(&w, &spec, pair, &mut pid, &cfg, None);

    let env_cfg = EnvConfig {
        episode: cfg.clone(),
        control_rate: pid.control_rate(),
        ..Default::default()
    };
    let mut env = EnvCore::new(
        vec![w.clone()],
        spec.clone(),
        env_cfg,
        &TaskFilter::default(),
        0,
    )
    .unwrap();
    env.reset(None, Some(w.task_id(pair).number())).unwrap();
    let mut pid = verti_systems::pid::Pid::new(Default::default());
    pid.reset(&task_info(&w, &spec, pair, &cfg).unwrap());
    let report = loop {
        let action = pid.act(&env.episode().unwrap().trial().observation());
        let r = env.step(action).unwrap();
        if r.terminated || r.truncated {
            break r;
        }
    };
    let mut m = env.episode().unwrap().metrics();
    assert_eq!(report.outcome, Some(reference.outcome));
    // the very record `verti eval` writes, but for the system's name and the wall time
    m.system = reference.system.clone();
    m.wall_time = reference.wall_time;
    assert_eq!(m, reference);
    assert!(
        m.path_length > 5.0,
        "the PID drove somewhere: {}",
        m.path_length
    );
}

#[test]
fn same_seed_same_episode_and_parallel_equals_serial() {
    let w = world(2);
    let mut a = EnvCore::new(
        vec![w.clone()],
        hmmwv(),
        EnvConfig::default(),
        &TaskFilter::default(),
        0,
    )
    .unwrap();
    let mut b = a.sibling(99);
    a.reset(Some(7), None).unwrap();
    b.reset(Some(7), None).unwrap();
    assert_eq!(a.episode().unwrap().id, b.episode().unwrap().id);
    for k in 0..20 {
        let act = a
            .action_from_normalized(&[0.8, (k as f64 * 0.3).sin()])
            .unwrap();
        assert_eq!(a.step(act).unwrap(), b.step(act).unwrap());
    }
    let (mut oa, mut ob) = (ObsBuf::default(), ObsBuf::default());
    a.observe(&mut oa).unwrap();
    b.observe(&mut ob).unwrap();
    assert_eq!(oa, ob);

    // a vector of 3 stepped in parallel equals the same environments stepped one by one
    let mut v = VecCore::new(a.sibling(0), 3, 2).unwrap();
    v.reset(Some(&[5, 6, 7])).unwrap();
    let mut serial: Vec<EnvCore> = (0..3).map(|i| a.sibling(0).tap_reset(5 + i)).collect();
    for k in 0..15 {
        let acts: Vec<f64> = (0..3)
            .flat_map(|i| [1.0, 0.2 * (i as f64 - 1.0) + 0.01 * k as f64])
            .collect();
        v.step(&acts).unwrap();
        for (i, env) in serial.iter_mut().enumerate() {
            let r = env
                .step(env.action_from_normalized(&acts[2 * i..2 * i + 2]).unwrap())
                .unwrap();
            assert_eq!(r, v.reports[i]);
            let mut o = ObsBuf::default();
            env.observe(&mut o).unwrap();
            assert_eq!(o, v.obs[i]);
        }
    }
}

trait TapReset {
    fn tap_reset(self, seed: u64) -> Self;
}
impl TapReset for EnvCore {
    fn tap_reset(mut self, seed: u64) -> Self {
        self.reset(Some(seed), None).unwrap();
        self
    }
}

#[test]
fn rejects_bad_settings_and_actions() {
    let w = world(3);
    let bad = EnvConfig {
        control_rate: 7.0,
        ..Default::default()
    };
    let e = EnvCore::new(vec![w.clone()], hmmwv(), bad, &TaskFilter::default(), 0)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("whole number of inner steps"), "{e}");
    let filter = TaskFilter {
        levels: vec![],
        tasks: vec![5000],
        ..Default::default()
    };
    let e = EnvCore::new(vec![w.clone()], hmmwv(), EnvConfig::default(), &filter, 0)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("not in this world set"), "{e}");
    let other = if w.meta.level == ElevationLevel::Low {
        ElevationLevel::High
    } else {
        ElevationLevel::Low
    };
    let filter = TaskFilter {
        levels: vec![other],
        ..Default::default()
    };
    let e = EnvCore::new(vec![w.clone()], hmmwv(), EnvConfig::default(), &filter, 0)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("no task"), "{e}");
    let mut env = EnvCore::new(
        vec![w],
        hmmwv(),
        EnvConfig::default(),
        &TaskFilter::default(),
        0,
    )
    .unwrap();
    assert!(
        env.step(Action::HighLevel {
            speed: 1.0,
            steering: 0.0
        })
        .unwrap_err()
        .to_string()
        .contains("reset")
    );
    env.reset(Some(1), None).unwrap();
    assert!(env.action_from_normalized(&[f64::NAN, 0.0]).is_err());
    assert!(env.action_from_normalized(&[0.0]).is_err());
    assert!(
        env.step(Action::LowLevel(Controls::new(2.0, 0.0, 0.0)))
            .unwrap_err()
            .to_string()
            .contains("throttle")
    );
}

#[test]
fn progress_reward_is_planar() {
    // a stopped vehicle gains nothing and pays the no-progress penalty; driving toward the
    // local goal earns about 50 per metre
    let w = world(4);
    let mut env = EnvCore::new(
        vec![w],
        hmmwv(),
        EnvConfig::default(),
        &TaskFilter::default(),
        0,
    )
    .unwrap();
    env.reset(Some(3), None).unwrap();
    let r = env
        .step(Action::LowLevel(Controls::new(0.0, 1.0, 0.0)))
        .unwrap();
    assert!(
        r.terms.progress.abs() < 5.0 && r.terms.no_progress == -10.0,
        "{r:?}"
    );
    let mut total = 0.0;
    for _ in 0..40 {
        total += env
            .step(Action::HighLevel {
                speed: 4.0,
                steering: 0.0,
            })
            .unwrap()
            .terms
            .progress;
    }
    let m = env.episode().unwrap().metrics();
    assert!(
        total > 0.0 && total <= 50.0 * m.path_length + 1e-6,
        "progress {total} for {} m",
        m.path_length
    );
}
