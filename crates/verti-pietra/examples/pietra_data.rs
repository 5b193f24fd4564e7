//! Drives the PIETRA maps once and prints what the data look like (trials, endings, samples,
//! unevenness and target spreads per split): a quick look before a benchmark run.
//!
//! `cargo run --release -p verti-pietra --example pietra_data`

use verti_pietra::dataset::{DataConfig, collect};
use verti_pietra::maps::Split;

fn main() -> Result<(), String> {
    let vehicle = verti_sim::vehicles::builtin("hmmwv").map_err(|e| e.to_string())?;
    let cfg = DataConfig::paper(vehicle);
    for split in Split::ALL {
        let t = std::time::Instant::now();
        let d = collect(split, &cfg)?;
        let n = d.samples.len().max(1) as f64;
        let mean = |f: &dyn Fn(&verti_pietra::dataset::Sample) -> f64| {
            d.samples.iter().map(f).sum::<f64>() / n
        };
        let mut u: Vec<f64> = d.samples.iter().map(|s| s.unevenness).collect();
        u.sort_by(f64::total_cmp);
        let q = |p: f64| {
            u.get(((u.len().max(1) - 1) as f64 * p) as usize)
                .copied()
                .unwrap_or(f64::NAN)
        };
        println!(
            "{:<10} {} trials, {:.0} s driven, {} samples, endings {:?} ({:.1} s wall)",
            split.name(),
            d.trials,
            d.seconds,
            d.samples.len(),
            d.endings,
            t.elapsed().as_secs_f64()
        );
        println!(
            "           unevenness p10/p50/p90 {:.3}/{:.3}/{:.3} m; mean ψ: lin {:.2} ang {:.2} |roll| {:.1}° |pitch| {:.1}°",
            q(0.1),
            q(0.5),
            q(0.9),
            mean(&|s| s.targets[0]),
            mean(&|s| s.targets[1]),
            mean(&|s| s.targets[2]).to_degrees(),
            mean(&|s| s.targets[3]).to_degrees()
        );
    }
    Ok(())
}
