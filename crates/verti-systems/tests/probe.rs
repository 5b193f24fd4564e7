use std::sync::Arc;
use verti_bench::{EpisodeConfig, run_episode};
use verti_sim::vehicles;
use verti_world::generate::{SetConfig, generate_set};

#[test]
#[ignore]
fn probe() {
    let worlds = generate_set(&SetConfig { count: 6, ..Default::default() }, &|| {}).unwrap();
    let spec = vehicles::builtin("hmmwv").unwrap();
    for w in worlds {
        let w = Arc::new(w);
        for sys in ["pid", "eh", "mppi"] {
            let mut s = verti_systems::create(sys, &[]).unwrap();
            let t0 = std::time::Instant::now();
            let r = run_episode(&w, &spec, 0, s.as_mut(), &EpisodeConfig::default(), None);
            println!("{} {:?} {:?} {:?} t={:.1} dist={:.1} len={:.1} roll={:.1} err={:?} wall={:.3}", w.meta.name, w.meta.level, w.meta.terrain_type, r.outcome, sys, r.final_distance, r.path_length, r.roll.abs.max, r.error, t0.elapsed().as_secs_f64());
        }
    }
}

#[test]
#[ignore]
fn mppi_plan_time() {
    use verti_bench::MobilitySystem;
    let worlds = generate_set(&SetConfig { count: 1, ..Default::default() }, &|| {}).unwrap();
    let w = Arc::new(worlds.into_iter().next().unwrap());
    let spec = vehicles::builtin("hmmwv").unwrap();
    let mut m = verti_systems::mppi::Mppi::new(Default::default());
    let info = verti_bench::episode::task_info(&w, &spec, 0, 0).unwrap();
    m.reset(&info);
    let obs = verti_bench::observation::test_observation(&w, info.start, 0.0, info.goal, &info.global_path);
    let t0 = std::time::Instant::now();
    for _ in 0..50 { m.plan_once(&obs); }
    println!("plan {:.3} ms", t0.elapsed().as_secs_f64() * 1e3 / 50.0);
}
