//! PIETRA's speed, one thread: CVaR-map generation at the paper's map size (81 x 96 cells x 13
//! headings, 101 088 footprints) with the shipped model and with the physics prior alone, and
//! one risk-aware MPPI plan (1024 rollouts x 50 steps) from the start of every test-map task.
//! Medians and p90 over repeats.
//!
//! `cargo run --release -p verti-pietra --example pietra_bench`

use std::sync::Arc;
use verti_bench::observation::test_observation;
use verti_bench::{SystemRegistry, task_info};
use verti_pietra::bins::param_bins;
use verti_pietra::cvar_map::{CvarMap, MapSpec, Region, Source};
use verti_pietra::dataset::WheelLayout;
use verti_pietra::maps::{Split, split_maps};
use verti_pietra::prior::PriorConfig;

fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[(v.len() * 9) / 10])
}

fn main() {
    // one thread throughout: the planner's map build would otherwise use every core
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .expect("first pool");
    let model = verti_pietra::shipped::pietra_v1().expect("shipped model");
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let worlds = split_maps(Split::Test);
    let map_spec = MapSpec {
        layout: WheelLayout::of(&spec),
        prior: PriorConfig::default(),
        bins: param_bins(),
        alpha: 0.5,
        surface: None,
    };
    for (name, source) in [
        ("model", Source::Model(&model)),
        ("physics prior", Source::Physics),
    ] {
        let mut times = Vec::new();
        for w in worlds.iter().take(5) {
            let region = Region::around(0.0, 0.0, 0.5, 96, 81);
            let t0 = std::time::Instant::now();
            std::hint::black_box(CvarMap::build(&w.terrain, &map_spec, source, region));
            times.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        let (med, p90) = stats(times);
        println!(
            "CVaR map 96 x 81 x 13 ({name}): median {med:.1} ms ({:.1} Hz), p90 {p90:.1} ms",
            1e3 / med
        );
    }
    let mut registry = SystemRegistry::new();
    verti_pietra::system::register(&mut registry, verti_pietra::shipped::pietra_v1).unwrap();
    let mut times = Vec::new();
    let mut first = Vec::new();
    for w in worlds.iter() {
        for pair in 0..10 {
            let info = task_info(w, &spec, pair, &Default::default()).unwrap();
            let mut system = registry.create("pietra", &[]).unwrap();
            system.reset(&info);
            let obs = test_observation(
                w,
                info.start,
                (info.goal[1] - info.start[1]).atan2(info.goal[0] - info.start[0]),
                info.goal,
                &info.global_path,
            );
            for i in 0..6 {
                let t0 = std::time::Instant::now();
                std::hint::black_box(system.act(&obs));
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                // the first plan of a trial also builds the whole map's CVaR (once per trial)
                if i == 0 {
                    first.push(ms)
                } else {
                    times.push(ms)
                }
            }
        }
    }
    let (med, p90) = stats(times);
    let (fmed, _) = stats(first);
    println!(
        "risk-aware MPPI plan, 1024 x 50: median {med:.2} ms, p90 {p90:.2} ms; first plan of a trial (with the 50 m map's CVaR, 129 x 129 x 13 at 0.39 m): median {fmed:.0} ms"
    );
    let _ = Arc::new(());
}
