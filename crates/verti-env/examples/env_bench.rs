//! Throughput of the environment core without Python: env steps per second (0.1 s each) for
//! one environment stepped in a loop and for a `VecCore` batch, on the rigid worlds of the
//! built-in set. The Python figures (`python -m verti.bench`) add the binding overhead.
//!
//!     cargo run --release -p verti-env --example env_bench [-- ENVS THREADS SECONDS]

use std::sync::Arc;
use std::time::Instant;
use verti_core::Rng;
use verti_env::{EnvConfig, EnvCore, TaskFilter, VecCore};
use verti_world::TerrainType;
use verti_world::generate::{SetConfig, generate_set};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let envs: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(64);
    let threads: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3.0);
    let worlds: Vec<_> = generate_set(&SetConfig::default(), &|| {})
        .expect("the built-in set generates")
        .into_iter()
        .map(Arc::new)
        .collect();
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let filter = TaskFilter {
        terrain_types: vec![TerrainType::Rigid],
        ..Default::default()
    };
    let core = EnvCore::new(worlds, spec, EnvConfig::default(), &filter, 0).unwrap();
    let mut rng = Rng::new(1);

    // one environment
    let mut env = core.sibling(0);
    env.reset(Some(0), None).unwrap();
    let (mut steps, t0) = (0u64, Instant::now());
    while t0.elapsed().as_secs_f64() < seconds {
        let a = env
            .action_from_normalized(&[1.0, rng.range(-1.0, 1.0)])
            .unwrap();
        let r = env.step(a).unwrap();
        steps += 1;
        if r.terminated || r.truncated {
            env.reset(None, None).unwrap();
        }
    }
    let single = steps as f64 / t0.elapsed().as_secs_f64();
    println!("single env (no observation copy): {single:.0} steps/s");

    // a batch
    let mut v = VecCore::new(core, envs, threads).unwrap();
    let seeds: Vec<u64> = (0..envs as u64).collect();
    v.reset(Some(&seeds)).unwrap();
    let (mut steps, t0) = (0u64, Instant::now());
    while t0.elapsed().as_secs_f64() < seconds {
        let actions: Vec<f64> = (0..envs)
            .flat_map(|_| [1.0, rng.range(-1.0, 1.0)])
            .collect();
        v.step(&actions).unwrap();
        steps += envs as u64;
    }
    let rate = steps as f64 / t0.elapsed().as_secs_f64();
    println!(
        "vector env, {envs} envs on {threads} thread(s): {rate:.0} steps/s ({:.0} per thread)",
        rate / threads as f64
    );
}
