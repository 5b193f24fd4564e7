//! Times VertiAdaptor's adaptation and planning on one CPU core (medians):
//!
//! * one example's basis changes (what each model step of driving costs the adapter);
//! * a least-squares solve from the normal equations of a 5 s window (50 examples);
//! * one recursive-least-squares update;
//! * a whole adaptation from 1000 raw examples (basis evaluation + solve), as the accuracy
//!   benchmark adapts;
//! * one MPPI plan's rollouts (128 samples x 15 steps by default).
//!
//! `cargo run --release -p verti-va --example va_bench -- [CARD] [SAMPLES] [HORIZON]`

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;
use verti_bench::observation::test_observation;
use verti_core::Rng;
use verti_systems::rollout::{ControlSamples, PlanContext, RolloutModel, Rollouts};
use verti_va::adapter::{AdaptMode, Adapter};
use verti_va::lsq::{NormalEquations, Rls};
use verti_va::model::POSE_DIM;
use verti_va::planner::VaRollout;
use verti_va::{Example, VaModel};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(reps: usize, mut f: impl FnMut()) -> f64 {
    let mut v = Vec::with_capacity(reps);
    for _ in 0..reps {
        let t = Instant::now();
        f();
        v.push(t.elapsed().as_secs_f64());
    }
    median(v)
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let card = PathBuf::from(
        args.first()
            .map_or("crates/verti-va/models/va-small-v1.yaml", |s| s.as_str()),
    );
    let samples: usize = args
        .get(1)
        .map_or(Ok(128), |s| s.parse())
        .map_err(|e| format!("{e}"))?;
    let horizon: usize = args
        .get(2)
        .map_or(Ok(15), |s| s.parse())
        .map_err(|e| format!("{e}"))?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .map_err(|e| e.to_string())?;
    let model = Arc::new(VaModel::load(&card).map_err(|e| e.to_string())?);
    let k = model.card.bases;
    println!(
        "{}: k = {k}, fields {:?}, {} multiply-adds per step; one thread",
        model.card.name,
        model.card.hidden,
        model.multiply_adds()
    );
    let mut rng = Rng::new(1);
    let examples: Vec<Example> = (0..1000)
        .map(|_| Example {
            roll: rng.range(-0.3, 0.3),
            pitch: rng.range(-0.3, 0.3),
            embedding: std::array::from_fn(|_| rng.range(-1.0, 1.0) as f32),
            command: (rng.range(0.0, 3.0), rng.range(-1.0, 1.0)),
            delta: std::array::from_fn(|_| rng.range(-0.3, 0.3)),
        })
        .collect();
    let mut phi = vec![0.0; k * POSE_DIM];
    let e = &examples[0];
    let t_basis = time(200, || {
        model.basis_changes(e.roll, e.pitch, &e.embedding, e.command, &mut phi)
    });
    let phis: Vec<Vec<f64>> = examples[..50]
        .iter()
        .map(|e| {
            let mut p = vec![0.0; k * POSE_DIM];
            model.basis_changes(e.roll, e.pitch, &e.embedding, e.command, &mut p);
            p
        })
        .collect();
    let t_solve = time(1000, || {
        let mut ne = NormalEquations::new(k, POSE_DIM);
        for (p, e) in phis.iter().zip(&examples) {
            ne.add(p, &e.delta);
        }
        std::hint::black_box(ne.solve(model.card.lambda).unwrap());
    });
    let mut rls = Rls::new(vec![0.0; k], POSE_DIM, 0.1, 0.98);
    let t_rls = time(1000, || rls.update(&phis[0], &examples[0].delta));
    let t_full = time(5, || {
        std::hint::black_box(model.adapt(&examples).unwrap());
    });
    println!("basis changes of one example: {:.3} ms", 1e3 * t_basis);
    println!(
        "least-squares solve, 5 s window (50 examples, Gram + Cholesky): {:.3} ms",
        1e3 * t_solve
    );
    println!("one RLS update: {:.3} ms", 1e3 * t_rls);
    println!(
        "adaptation from 1000 raw examples (basis evaluation + solve): {:.1} ms",
        1e3 * t_full
    );
    // one plan's rollouts on a verti world
    let world = verti_world::sets::resolve_set("verti-1-s2", 1.0, &|| {})
        .map_err(|e| e.to_string())?
        .worlds
        .remove(0);
    let spec = verti_sim::vehicles::builtin("hmmwv").map_err(|e| e.to_string())?;
    let info = verti_bench::task_info(&Arc::new(world.clone()), &spec, 0, &Default::default())
        .ok_or("no task")?;
    let adapter = Arc::new(Mutex::new(Adapter::new(model.clone(), AdaptMode::None)));
    let mut rollout = VaRollout::new(adapter, verti_nn::shipped::patch_v1()?);
    rollout.reset(&info);
    let obs = test_observation(&world, info.start, 0.0, info.goal, &[]);
    let ctx = PlanContext {
        start: obs.pose,
        local_goal: info.goal,
        samples,
        horizon,
        step: 0.1,
        nominal_speed: 3.0,
        speed_range: (0.9, 3.0),
        lambda: 0.1,
        sigma: (0.5, 0.5),
        scale: 1.0,
    };
    let t_fill = time(1, || rollout.prepare(&obs, &ctx));
    let controls: Vec<(f64, f64)> = (0..samples * horizon)
        .map(|_| (rng.range(0.9, 3.0), rng.range(-1.0, 1.0)))
        .collect();
    let cs = ControlSamples {
        samples,
        horizon,
        controls: &controls,
        nominal: &controls[..horizon],
        noise: &controls,
    };
    let mut out = Rollouts::default();
    out.resize(samples, horizon);
    let t_plan = time(9, || rollout.rollout(&ctx, &cs, &mut out));
    println!(
        "first plan's terrain embeddings (grid around the start): {:.0} ms",
        1e3 * t_fill
    );
    println!(
        "rollouts of one plan ({samples} x {horizon}): {:.1} ms",
        1e3 * t_plan
    );
    Ok(())
}
