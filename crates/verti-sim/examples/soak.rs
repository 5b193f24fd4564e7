//! Random-input soak: `cargo run -p verti-sim --release --example soak -- [STEPS] [SEED]`
//! (the CLI's `verti sim soak` calls the same `verti_sim::tools::soak`).
use std::sync::Arc;
use verti_sim::testing::{self, RoughSurface};
use verti_sim::tools::soak;
use verti_sim::vehicles;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let steps: u64 = args
        .get(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let specs = vehicles::all_builtin();
    let mut worlds = Vec::new();
    for scale in [1.0, 1.0 / 6.0, 0.1] {
        for (i, surface) in [RoughSurface::Rigid, RoughSurface::Soil, RoughSurface::Mixed]
            .into_iter()
            .enumerate()
        {
            worlds.push(Arc::new(testing::rough_world(
                scale,
                10 + i as u64,
                16.0,
                surface,
            )));
        }
    }
    let report = soak(&worlds, &specs, steps, seed, |done| {
        eprint!("\r{done} steps")
    });
    eprintln!();
    print!("{report}");
}
