//! MPPI planning time per call (1024 rollouts x 50 steps by default), median of repeated plans
//! from the start of every task of a few worlds of the default set.
//!
//! `cargo run --release -p verti-systems --example mppi_bench [samples] [horizon]`

use std::sync::Arc;
use verti_bench::MobilitySystem;
use verti_bench::observation::test_observation;
use verti_bench::task_info;
use verti_systems::mppi::{Mppi, MppiParams};
use verti_world::generate::{SetConfig, generate_set, one_default_world};

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    // the benchmark configuration: 1024 rollouts x 50 steps (evaluation defaults are
    // 800 x 30, see MppiParams)
    let params = MppiParams {
        samples: args.first().copied().unwrap_or(1024),
        horizon: args.get(1).copied().unwrap_or(50),
        ..Default::default()
    };
    let worlds = generate_set(
        &SetConfig {
            count: 5,
            ..Default::default()
        },
        &|| {},
    )
    .unwrap();
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let mut times = Vec::new();
    for w in worlds.into_iter().map(Arc::new) {
        for pair in 0..10 {
            let info = task_info(&w, &spec, pair, &Default::default()).unwrap();
            let mut m = Mppi::new(params.clone());
            m.reset(&info);
            let obs = test_observation(
                &w,
                info.start,
                (info.goal[1] - info.start[1]).atan2(info.goal[0] - info.start[0]),
                info.goal,
                &info.global_path,
            );
            for _ in 0..20 {
                let t0 = std::time::Instant::now();
                std::hint::black_box(m.plan_once(&obs));
                times.push(t0.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    // the obstacle crop alone, as MPPI takes it (radius ~ 1.5 v T + 2 m at 0.4 m)
    let w = Arc::new(one_default_world().unwrap());
    let info = task_info(&w, &spec, 0, &Default::default()).unwrap();
    let obs = test_observation(
        &w,
        info.start,
        std::f64::consts::PI,
        info.goal,
        &info.global_path,
    );
    let reach = 3.0 * 1.5 * params.step * params.horizon as f64 + 2.0;
    let size = ((2.0 * reach / 0.4).ceil() as usize) | 1;
    let t0 = std::time::Instant::now();
    for _ in 0..100 {
        std::hint::black_box(obs.occupancy_crop(verti_bench::CropSpec {
            size,
            resolution: 0.4,
        }));
    }
    println!(
        "occupancy crop {size}x{size}: {:.3} ms",
        t0.elapsed().as_secs_f64() * 10.0
    );
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    println!(
        "MPPI {} rollouts x {} steps: median {:.3} ms per plan (p10 {:.3}, p90 {:.3}, {} plans)",
        params.samples,
        params.horizon,
        median,
        times[times.len() / 10],
        times[times.len() * 9 / 10],
        times.len()
    );
}
