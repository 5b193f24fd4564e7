//! The shipped kinodynamic models: save/load round trip, rollout shape and determinism, and
//! accuracy against the bicycle on trajectories driven on worlds none of them trained on.

use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::observation::{Pose6, test_observation};
use verti_bench::{SystemRegistry, task_info};
use verti_core::params::ParamValue;
use verti_data::generate::Source;
use verti_data::{GenerateConfig, Kind, Profile, WriteInfo, write_dataset};
use verti_kino::eval::{Predictor, evaluate};
use verti_kino::features::KinoState;
use verti_kino::model::bicycle_step;
use verti_kino::rollout::LearnedRollout;
use verti_kino::samples::KinoData;
use verti_kino::{Geometry, KinoFile, KinoModel, Units, shipped};
use verti_systems::rollout::{ControlSamples, PlanContext, RolloutModel, Rollouts};
use verti_world::World;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verti-kino-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn world(set: &str) -> Arc<World> {
    let set = verti_world::sets::resolve_set(set, 1.0, &|| {}).unwrap();
    Arc::new(set.worlds.into_iter().next().unwrap())
}

/// A few open-loop steps of `model` from a pose on `world`, with varied commands.
fn drive(model: &KinoModel, world: &World) -> Vec<Pose6> {
    let units = Units::new(1.0);
    let mut scratch = model.scratch();
    let start = Pose6 {
        x: 3.0,
        y: -2.0,
        z: world.terrain.height_at(3.0, -2.0) + 0.9,
        yaw: 0.4,
        ..Default::default()
    };
    model.begin(&start, &world.terrain, units, &mut scratch);
    let mut state = KinoState {
        pose: start,
        last_delta: [0.4, 0.0, 0.0, 0.0, 0.0, 0.0],
    };
    (0..12)
        .map(|k| {
            let command = (2.0 + 0.1 * k as f64, (k as f64 * 0.7).sin());
            state = model.step(
                &state,
                command,
                &world.terrain,
                units,
                Geometry::default(),
                &mut scratch,
            );
            state.pose
        })
        .collect()
}

#[test]
fn shipped_models_survive_a_save_and_load_bit_for_bit() {
    let w = world("verti-1-s2");
    let dir = temp_dir("round-trip");
    for file in shipped::all().unwrap() {
        let path = dir.join(format!("{}.yaml", file.card.name));
        file.save(&path).unwrap();
        let back = KinoFile::load(&path).unwrap();
        assert_eq!(back.card, file.card);
        let (a, b) = (
            drive(&KinoModel::new(file.clone()), &w),
            drive(&KinoModel::new(Arc::new(back)), &w),
        );
        assert_eq!(a, b, "{}", file.card.name);
        assert!(a.iter().all(|p| p.x.is_finite() && p.roll.is_finite()));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_card_naming_a_missing_network_is_refused_by_field() {
    let dir = temp_dir("missing");
    let file = shipped::model("wmvct-v1").unwrap();
    let path = dir.join("m.yaml");
    file.save(&path).unwrap();
    // a network card given where the model card belongs is named for what it is
    let err = KinoFile::load(&dir.join(&file.card.networks[0]))
        .unwrap_err()
        .to_string();
    assert!(err.contains("this is a network card"), "{err}");
    std::fs::remove_file(dir.join(&file.card.networks[0])).unwrap();
    let err = KinoFile::load(&path).unwrap_err().to_string();
    assert!(err.contains("m.yaml") && err.contains("networks"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rollouts_have_the_samples_shape_and_repeat_exactly() {
    let w = world("verti-1-s2");
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let info = task_info(&w, &spec, 0, &Default::default()).unwrap();
    let obs = test_observation(&w, info.start, 0.3, info.goal, &info.global_path);
    let (samples, horizon) = (7, 5);
    let controls: Vec<(f64, f64)> = (0..samples * horizon)
        .map(|i| (1.0 + (i % 4) as f64, ((i * 3) % 5) as f64 * 0.4 - 0.8))
        .collect();
    let nominal = vec![(0.0, 0.0); horizon];
    let controls = ControlSamples {
        samples,
        horizon,
        controls: &controls,
        nominal: &nominal,
        noise: &controls,
    };
    let ctx = PlanContext {
        start: obs.pose,
        local_goal: info.goal,
        samples,
        horizon,
        step: 0.2,
        nominal_speed: 3.0,
        speed_range: (0.0, 5.0),
        lambda: 0.1,
        sigma: (0.5, 0.5),
        scale: 1.0,
    };
    for file in shipped::all().unwrap() {
        let mut runs = Vec::new();
        for _ in 0..2 {
            let mut r = LearnedRollout::new(KinoModel::new(file.clone()));
            r.reset(&info);
            r.prepare(&obs, &ctx);
            let mut out = Rollouts::default();
            out.resize(samples, horizon);
            r.rollout(&ctx, &controls, &mut out);
            assert_eq!(out.poses.len(), samples * horizon);
            assert!(
                out.poses
                    .iter()
                    .all(|p| p.z.is_finite() && p.pitch.is_finite())
            );
            runs.push(out.poses);
        }
        assert_eq!(runs[0], runs[1], "{}", file.card.name);
        // different controls, different futures
        assert_ne!(runs[0][horizon - 1], runs[0][2 * horizon - 1]);
        // samples are rolled out in pairs (7: three pairs and one alone); each must be what
        // rolling it out on its own (one sample: no pair) gives, bit for bit
        let bits = |p: &Pose6| [p.x, p.y, p.z, p.roll, p.pitch, p.yaw].map(f64::to_bits);
        for s in 0..samples {
            let mine = &controls.controls[s * horizon..(s + 1) * horizon];
            let one = ControlSamples {
                samples: 1,
                horizon,
                controls: mine,
                nominal: &nominal,
                noise: mine,
            };
            let mut r = LearnedRollout::new(KinoModel::new(file.clone()));
            r.reset(&info);
            r.prepare(&obs, &ctx);
            let mut out = Rollouts::default();
            out.resize(1, horizon);
            r.rollout(&ctx, &one, &mut out);
            for t in 0..horizon {
                assert_eq!(
                    bits(&out.poses[t]),
                    bits(&runs[0][s * horizon + t]),
                    "{} sample {s} step {t}",
                    file.card.name
                );
            }
        }
    }
}

#[test]
fn learned_planners_act_the_same_twice() {
    let w = world("verti-1-s2");
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let mut registry = SystemRegistry::new();
    verti_systems::register(&mut registry);
    verti_kino::systems::register(&mut registry, shipped::systems()).unwrap();
    let info = task_info(&w, &spec, 1, &Default::default()).unwrap();
    let obs = test_observation(&w, info.start, 0.0, info.goal, &info.global_path);
    let given = [("samples".to_string(), ParamValue::Int(64))];
    for name in ["wmvct", "mppi6", "tal", "tnt"] {
        let act = || {
            let mut s = registry.create(name, &given).unwrap();
            s.reset(&info);
            (0..3).map(|_| s.act(&obs)).collect::<Vec<_>>()
        };
        assert_eq!(format!("{:?}", act()), format!("{:?}", act()), "{name}");
    }
}

/// Two minutes of exploration on worlds of seed 2 (the models trained on seed 1).
fn held_out() -> KinoData {
    let dir = temp_dir("held-out");
    let worlds: Vec<Arc<World>> = verti_world::sets::resolve_set("verti-2-s2", 1.0, &|| {})
        .unwrap()
        .worlds
        .into_iter()
        .map(Arc::new)
        .collect();
    let cfg = GenerateConfig {
        kind: Kind::Random,
        source: Source::Random(Profile::VertiAdaptor),
        worlds,
        vehicle: verti_sim::vehicles::builtin("hmmwv").unwrap(),
        hours: 2.0 / 60.0,
        rate: 10.0,
        seed: 11,
        max_trial_seconds: 30.0,
    };
    let info = WriteInfo {
        set: "verti-2-s2".into(),
        set_name: "verti-2-s2".into(),
        command: "test".into(),
        eval_worlds: false,
        force: true,
    };
    write_dataset(&dir, &cfg, &info, &|_| {}).unwrap();
    let data = KinoData::load(&dir, 0.2).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    data
}

#[test]
fn learned_models_predict_one_step_better_than_the_bicycle_on_held_out_worlds() {
    let data = held_out();
    let g = Geometry::default();
    let bicycle = evaluate(&data, &Predictor::Bicycle, g, 5);
    assert!(
        bicycle.one_step[0].count > 100,
        "{}",
        bicycle.one_step[0].count
    );
    let b = bicycle.one_step[0].rmse();
    for file in shipped::all().unwrap() {
        let acc = evaluate(&data, &Predictor::Model(KinoModel::new(file.clone())), g, 5);
        let m = acc.one_step[0].rmse();
        // roll and pitch: every model predicts them better than the bicycle; forward motion
        // too where the network predicts it (WMVCT's comes from the bicycle itself)
        let mut dims = vec![(4, "roll"), (5, "pitch")];
        if file.card.kind != verti_kino::KinoKind::Decomposed {
            dims.push((0, "forward"));
        }
        for (i, what) in dims {
            assert!(
                m[i] < b[i],
                "{} {what}: {:.4} vs bicycle {:.4}",
                file.card.name,
                m[i],
                b[i]
            );
        }
    }
    // and the bicycle's own step is what the evaluation calls it
    let tr = &data.trajectories[0];
    let s = KinoState {
        pose: tr.poses[1],
        last_delta: [0.0; 6],
    };
    let next = bicycle_step(
        &s,
        tr.commands[1],
        &data.worlds[tr.world].terrain,
        g,
        data.dt_world,
    );
    assert!(next.pose.x.is_finite());
}
