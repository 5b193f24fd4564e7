//! VertiAdaptor's plain-Rust side: model files, online adaptation while driving, and the
//! `va` system running tasks with every adaptation mode.

use std::path::Path;
use std::sync::Arc;
use verti_bench::observation::Pose6;
use verti_bench::{EpisodeConfig, MobilitySystem, run_episode};
use verti_core::params::{ParamValue, Params};
use verti_core::{Factory, Rng};
use verti_va::adapter::{AdaptMode, Adapter};
use verti_va::model::{POSE_DIM, VA_FORMAT, VaCard, VaTraining, WeightsRef};
use verti_va::system::VaSystem;
use verti_va::{Method, VaModel};
use verti_world::World;

/// A small model with random weights (the mechanics do not need trained ones).
fn tiny(method: Method, bases: usize, seed: u64) -> VaModel {
    let card = VaCard {
        name: "tiny".into(),
        format: VA_FORMAT,
        summary: "test".into(),
        method,
        vehicle: "hmmwv".into(),
        dt: 0.1,
        bases,
        hidden: vec![8, 8],
        elevation: true,
        semantics: true,
        lambda: 1e-3,
        alpha_prior: vec![1.0 / bases as f64; bases],
        weights: WeightsRef {
            file: "tiny.bin".into(),
            floats: 0,
            fnv1a64: String::new(),
        },
        training: VaTraining {
            data: "none".into(),
            worlds: "none".into(),
            command: "test".into(),
            seed,
            steps: 0,
            wall_time_s: 0.0,
            verti_version: "test".into(),
            settings: String::new(),
        },
        metrics: Default::default(),
    };
    let n = card.float_count();
    let mut rng = Rng::new(seed);
    let params: Vec<f32> = (0..n).map(|_| rng.range(-0.3, 0.3) as f32).collect();
    let card = VaCard {
        weights: WeightsRef {
            floats: n,
            ..card.weights.clone()
        },
        ..card
    };
    VaModel::new(card, &params, Path::new("tiny")).unwrap()
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("verti-va-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn models_save_and_load_bit_for_bit() {
    let dir = temp_dir("save");
    let mut model = tiny(Method::Va, 3, 1);
    let path = dir.join("tiny.yaml");
    model.save(&path).unwrap();
    let back = VaModel::load(&path).unwrap();
    assert_eq!(back.params(), model.params());
    assert_eq!(back.card, model.card);
    let e = [0.1f32; 16];
    assert_eq!(
        back.predict(&[0.5, -1.0, 2.0], 0.1, -0.05, &e, (2.0, 0.3)),
        model.predict(&[0.5, -1.0, 2.0], 0.1, -0.05, &e, (2.0, 0.3))
    );
    // a damaged weights file is named with the field that caught it
    let bin = dir.join("tiny.bin");
    let mut bytes = std::fs::read(&bin).unwrap();
    bytes[10] ^= 0xff;
    std::fs::write(&bin, bytes).unwrap();
    let err = VaModel::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("tiny.yaml") && err.contains("fnv1a64"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn least_squares_adaptation_recovers_coefficients_the_data_were_made_with() {
    // targets made by the model's own bases with known coefficients: one solve finds them
    let mut model = tiny(Method::Va, 4, 2);
    // random small weights give basis changes of ~1e-2, whose Gram entries λ = 1e-3 would
    // dominate; the recovery itself is what is tested here
    model.card.lambda = 1e-12;
    let truth = [0.7, -0.2, 1.3, 0.4];
    let mut rng = Rng::new(3);
    let examples: Vec<_> = (0..400)
        .map(|_| {
            let embedding: [f32; 16] = std::array::from_fn(|_| rng.range(-1.0, 1.0) as f32);
            let (roll, pitch) = (rng.range(-0.3, 0.3), rng.range(-0.3, 0.3));
            let command = (rng.range(0.0, 3.0), rng.range(-1.0, 1.0));
            let delta = model.predict(&truth, roll, pitch, &embedding, command);
            verti_va::Example {
                roll,
                pitch,
                embedding,
                command,
                delta,
            }
        })
        .collect();
    let alpha = model.adapt(&examples).unwrap();
    for (a, t) in alpha.iter().zip(truth) {
        assert!((a - t).abs() < 0.05, "{alpha:?} vs {truth:?}");
    }
}

/// Drives the adapter along a straight line at 2 m/s for `seconds`, observed at 10 Hz.
fn drive(adapter: &mut Adapter, seconds: f64) {
    adapter.reset(1.0);
    let steps = (seconds * 10.0).round() as usize;
    for i in 0..=steps {
        let t = i as f64 * 0.1;
        let pose = Pose6 {
            x: 2.0 * t,
            pitch: 0.05 * (t).sin(),
            ..Pose6::default()
        };
        adapter.observe(t, pose, (2.0, 0.0), &mut |_| [0.0; 16]);
    }
}

#[test]
fn adaptation_modes_update_when_they_should() {
    let model = Arc::new(tiny(Method::Va, 3, 4));
    let prior = model.card.alpha_prior.clone();
    let mut none = Adapter::new(model.clone(), AdaptMode::None);
    drive(&mut none, 12.0);
    assert_eq!(none.alpha(), prior.as_slice());
    assert_eq!(none.solves, 0);
    let mut every = Adapter::new(
        model.clone(),
        AdaptMode::Every {
            period: 5.0,
            window: 5.0,
        },
    );
    drive(&mut every, 12.0);
    // examples every 0.1 s from t = 0.1; solves at 5 s and 10 s
    assert_eq!(every.examples, 120);
    assert_eq!(every.solves, 2);
    assert_ne!(every.alpha(), prior.as_slice());
    let mut rls = Adapter::new(model, AdaptMode::Rls { forgetting: 0.98 });
    drive(&mut rls, 3.0);
    assert_eq!((rls.examples, rls.solves), (30, 30));
    assert_ne!(rls.alpha(), prior.as_slice());
    assert_eq!(POSE_DIM, 6);
}

fn tiny_source() -> Result<Arc<VaModel>, String> {
    Ok(Arc::new(tiny(Method::Va, 3, 5)))
}

#[test]
fn the_va_system_drives_with_every_adaptation_mode() {
    let world: Arc<World> = Arc::new(
        verti_world::sets::resolve_set("verti-1-s2", 1.0, &|| {})
            .unwrap()
            .worlds
            .remove(0),
    );
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let factory = VaSystem::new(tiny_source);
    for adapt in ["none", "once", "every", "rls"] {
        let given = vec![
            ("adapt".to_string(), ParamValue::Str(adapt.into())),
            ("samples".to_string(), ParamValue::Int(16)),
            ("explore_trials".to_string(), ParamValue::Int(1)),
            ("explore_seconds".to_string(), ParamValue::Float(3.0)),
            ("period".to_string(), ParamValue::Float(1.0)),
        ];
        let params = Params::resolve("va", factory.info().params, &given).unwrap();
        let mut system: Box<dyn MobilitySystem> = factory.build(&params).unwrap();
        let r = run_episode(
            &world,
            &spec,
            0,
            system.as_mut(),
            &EpisodeConfig {
                max_time: 4.0,
                ..Default::default()
            },
            None,
        );
        assert!(r.error.is_none(), "adapt={adapt}: {r:?}");
        assert!(
            r.time > 3.9 || r.outcome != verti_bench::Outcome::Timeout,
            "adapt={adapt}: {r:?}"
        );
    }
}

/// A straight 3 s drive over made-up terrain latents, as a dataset.
fn synthetic_data() -> verti_va::data::VaData {
    let mut rng = Rng::new(8);
    let n = 30;
    let poses: Vec<Pose6> = (0..n)
        .map(|i| Pose6 {
            x: 0.2 * i as f64,
            roll: 0.02 * (i as f64).sin(),
            ..Pose6::default()
        })
        .collect();
    let terrain: Vec<f32> = (0..n * verti_va::terrain::TERRAIN_DIM)
        .map(|_| rng.range(-1.0, 1.0) as f32)
        .collect();
    verti_va::data::VaData {
        worlds: Vec::new(),
        trajectories: vec![verti_va::data::VaTrajectory {
            world: 0,
            level: verti_world::ElevationLevel::Low,
            poses,
            commands: vec![(2.0, 0.1); n],
            terrain,
        }],
        units: verti_kino::features::Units::new(1.0),
        dt: 0.1,
        vehicle: "hmmwv".into(),
        set: "synthetic".into(),
        eval_worlds: false,
        hours: 0.0,
        dir: std::path::PathBuf::new(),
    }
}

#[test]
fn online_scoring_without_adaptation_matches_offline_scoring() {
    let model = Arc::new(tiny(Method::Va, 3, 6));
    let data = synthetic_data();
    let prior = model.card.alpha_prior.clone();
    let offline = verti_va::eval::errors(&model, &prior, &data, &[0], 8, 5);
    let online = verti_va::eval::online_errors(&model, AdaptMode::None, &prior, &data, &[0], 8, 5);
    assert_eq!(offline, online);
    assert_eq!((offline.one_step_count, offline.rollouts), (29, 5));
    // adapting online changes the scores
    let rls = verti_va::eval::online_errors(
        &model,
        AdaptMode::Rls { forgetting: 0.98 },
        &prior,
        &data,
        &[0],
        8,
        5,
    );
    assert_ne!(rls, offline);
}

#[test]
fn recursive_least_squares_continues_from_coefficients_set_outright() {
    let model = Arc::new(tiny(Method::Va, 3, 9));
    let start = vec![5.0, -5.0, 5.0];
    let mut rls = Adapter::new(model, AdaptMode::Rls { forgetting: 0.98 });
    rls.reset(1.0);
    rls.set_alpha(start.clone());
    for i in 0..=1 {
        let pose = Pose6 {
            x: 0.2 * i as f64,
            ..Pose6::default()
        };
        rls.observe(0.1 * i as f64, pose, (2.0, 0.0), &mut |_| [0.0; 16]);
    }
    assert_eq!(rls.examples, 1);
    // one example moves the coefficients only within its 6-dimensional span: they stay far
    // nearer the start than the prior (1/3 each)
    let dist = |a: &[f64], b: &[f64]| -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let prior = vec![1.0 / 3.0; 3];
    assert!(
        dist(rls.alpha(), &start) < dist(rls.alpha(), &prior),
        "{:?}",
        rls.alpha()
    );
}
