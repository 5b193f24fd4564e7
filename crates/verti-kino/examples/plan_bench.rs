//! Planning time per call of the learned planners (and plain MPPI at the same size), median
//! and p90 over repeated plans from the start of every task of a few worlds, one thread.
//!
//! `cargo run --release -p verti-kino --example plan_bench [samples] [horizon]`

use std::sync::Arc;
use verti_bench::observation::test_observation;
use verti_bench::{SystemRegistry, task_info};
use verti_core::params::ParamValue;
use verti_world::generate::{SetConfig, generate_set};

fn main() {
    let args: Vec<i64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let samples = args.first().copied().unwrap_or(800);
    let horizon = args.get(1).copied().unwrap_or(20);
    let mut registry = SystemRegistry::new();
    verti_systems::register(&mut registry);
    verti_kino::systems::register(&mut registry, verti_kino::shipped::systems()).unwrap();
    let worlds: Vec<_> = generate_set(
        &SetConfig {
            count: 5,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap()
    .into_iter()
    .map(Arc::new)
    .collect();
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    for name in ["mppi", "wmvct", "mppi6", "tal", "tnt"] {
        let given = [
            ("samples".to_string(), ParamValue::Int(samples)),
            ("horizon".to_string(), ParamValue::Int(horizon)),
        ];
        let mut times = Vec::new();
        for w in &worlds {
            for pair in 0..10 {
                let info = task_info(w, &spec, pair, &Default::default()).unwrap();
                let mut system = registry.create(name, &given).unwrap();
                system.reset(&info);
                let obs = test_observation(
                    w,
                    info.start,
                    (info.goal[1] - info.start[1]).atan2(info.goal[0] - info.start[0]),
                    info.goal,
                    &info.global_path,
                );
                for _ in 0..10 {
                    let t0 = std::time::Instant::now();
                    std::hint::black_box(system.act(&obs));
                    times.push(t0.elapsed().as_secs_f64() * 1e3);
                }
            }
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{name:>6} {samples} rollouts x {horizon} steps: median {:.2} ms per plan (p10 {:.2}, p90 {:.2}, {} plans)",
            times[times.len() / 2],
            times[times.len() / 10],
            times[times.len() * 9 / 10],
            times.len()
        );
    }
}
