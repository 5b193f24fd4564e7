//! Speed benchmark: `cargo run -p verti-sim --release --example bench -- [SECONDS] [RUNS] [VEHICLE...]`
//! (the CLI's `verti sim bench` calls the same `verti_sim::tools::bench`).
use verti_sim::tools::{BenchWorlds, bench};
use verti_sim::vehicles;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seconds: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let specs = if args.len() > 3 {
        args[3..]
            .iter()
            .map(|n| vehicles::builtin(n).unwrap())
            .collect()
    } else {
        vehicles::all_builtin()
    };
    let worlds = if std::env::var("SYNTHETIC").is_ok() {
        BenchWorlds::synthetic_for(&specs)
    } else {
        BenchWorlds::generated_for(&specs).expect("generated worlds")
    };
    for p in &worlds.pairs {
        eprintln!(
            "scale {}: rigid {} ({} obstacles, relief {:.1} m), soil {}",
            p.scale,
            p.rigid.meta.name,
            p.rigid.obstacles.len(),
            p.rigid.terrain.max_height() - p.rigid.terrain.min_height(),
            p.soil.meta.name
        );
    }
    let report = bench(&worlds, &specs, seconds, runs);
    print!("{report}");
    if std::env::var("JSON").is_ok() {
        println!("{}", serde_json::to_string_pretty(&report).unwrap());
    }
}
