//! `verti data generate` and `verti data stats`: the datasets of Verti-Bench §III-G.

use crate::cli_common::{CmdResult, ScaleArg, load_set_checked, load_vehicle};
use crate::progress::bar;
use clap::{Args, Subcommand};
use std::path::PathBuf;
use std::sync::Arc;
use verti_data::generate::{MAX_TRIAL_SECONDS, Source, eval_world_reason};
use verti_data::stats::{Stats, stats};
use verti_data::{Dataset, GenerateConfig, Kind, Profile, WriteInfo, write_dataset};
use verti_render::{Panel, Series};
use verti_world::World;

#[derive(Subcommand)]
pub enum DataCommand {
    /// Generate a dataset: random exploration, failure cases or expert demonstrations.
    Generate(Box<GenerateArgs>),
    /// Summarise a dataset: hours, trials, outcomes, speed/roll/pitch (and a PNG of histograms).
    Stats(StatsArgs),
}

#[derive(Args)]
pub struct GenerateArgs {
    /// random (exploration), failures (last 10 s before rollover or stuck) or expert (a
    /// system's successful trials).
    kind: String,
    /// Simulated hours: of exploration (random; default 10), of driving to harvest failures
    /// from (default 10), of kept successful driving (expert; default 4).
    #[arg(long, allow_negative_numbers = true)]
    hours: Option<f64>,
    /// World set (evaluation worlds, verti-100 and the original Verti-Bench worlds, are refused).
    #[arg(long, default_value = "verti-100-s1")]
    worlds: String,
    /// Vehicle: a built-in name or a vehicle YAML file (default: hmmwv at full scale).
    #[arg(long)]
    vehicle: Option<String>,
    #[command(flatten)]
    scale: ScaleArg,
    /// Output directory (new, or empty unless --force).
    #[arg(long)]
    out: PathBuf,
    /// Replace the dataset files in a non-empty --out.
    #[arg(long)]
    force: bool,
    /// Seed of starts, worlds and command profiles (and of the systems' randomness).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Rows per simulated second (the random driver also commands at this rate).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    rate: f64,
    /// Exploration command profile: paper (sinusoidal steering, 2 m/s) or vertiadaptor.
    #[arg(long, default_value = "paper")]
    profile: String,
    /// Failures: harvest from random exploration (default) or from runs of this system.
    #[arg(long = "from", default_value = "random")]
    from: String,
    /// Expert: the system whose successful trials are kept.
    #[arg(long, default_value = "oracle")]
    system: String,
    /// System parameter override, name=value (repeatable).
    #[arg(long = "param", value_parser = crate::cli_common::assignment)]
    params: Vec<String>,
    /// Length cap of an exploration trial, simulated seconds.
    #[arg(long, default_value_t = MAX_TRIAL_SECONDS)]
    max_trial_seconds: f64,
    /// Allow evaluation worlds; the manifest then says eval_worlds: true.
    #[arg(long)]
    allow_eval_worlds: bool,
}

#[derive(Args)]
pub struct StatsArgs {
    /// A dataset directory.
    dir: PathBuf,
    /// Histogram PNG (default: DIR/stats.png).
    #[arg(long, value_parser = crate::outputs::png_file)]
    png: Option<PathBuf>,
}

pub fn run(cmd: DataCommand) -> CmdResult {
    match cmd {
        DataCommand::Generate(a) => generate(*a),
        DataCommand::Stats(a) => print_stats(a),
    }
}

/// A system of the registry as a data source (checked by building one now).
fn system_source(name: &str, params: &[String]) -> Result<Source, Box<dyn std::error::Error>> {
    let registry = crate::registries::systems();
    let given = params
        .iter()
        .map(|p| registry.parse_param(name, p))
        .collect::<Result<Vec<_>, _>>()?;
    let resolved = registry.resolve(name, &given)?;
    registry.build(name, &resolved)?;
    let owned = name.to_string();
    let make = move || {
        registry
            .build(&owned, &resolved)
            .expect("the system was built once already")
    };
    Ok(Source::System {
        name: name.to_string(),
        make: Arc::new(make),
    })
}

fn generate(a: GenerateArgs) -> CmdResult {
    let kind = Kind::from_name(&a.kind)?;
    let hours = a.hours.unwrap_or(kind.default_hours());
    if !(hours.is_finite() && hours > 0.0) {
        return Err(format!("--hours must be a positive number of hours, not {hours}").into());
    }
    if !(a.rate.is_finite() && (1.0..=100.0).contains(&a.rate)) {
        return Err(format!("--rate must be in [1, 100] Hz, not {}", a.rate).into());
    }
    let profile = Profile::from_name(&a.profile).ok_or_else(|| {
        format!(
            "unknown --profile `{}`: use paper or vertiadaptor",
            a.profile
        )
    })?;
    let source = match kind {
        Kind::Random => Source::Random(profile),
        Kind::Failures if a.from == "random" => Source::Random(profile),
        Kind::Failures => system_source(&a.from, &a.params)?,
        Kind::Expert => system_source(&a.system, &a.params)?,
    };
    verti_core::output::check_output_dir(&a.out).map_err(|p| format!("--out: {p}"))?;
    let (set, scale) = load_set_checked(&a.worlds, &a.scale, None)?;
    let vehicle_name = a
        .vehicle
        .clone()
        .unwrap_or_else(|| verti_sim::vehicles::default_for_scale(scale).to_string());
    let vehicle =
        load_vehicle(&vehicle_name).map_err(|e| format!("--vehicle {vehicle_name}: {e}"))?;
    let worlds: Vec<Arc<World>> = set.worlds.into_iter().map(Arc::new).collect();
    if let Some(reason) = eval_world_reason(&worlds) {
        if !a.allow_eval_worlds {
            return Err(format!("--worlds {}: {reason}", a.worlds).into());
        }
        eprintln!("warning: {reason}; marking the data eval_worlds: true");
    }
    let cfg = GenerateConfig {
        kind,
        source,
        worlds,
        vehicle,
        hours,
        rate: a.rate,
        seed: a.seed,
        max_trial_seconds: a.max_trial_seconds,
    };
    let info = WriteInfo {
        set: a.worlds.clone(),
        set_name: set.name.clone(),
        command: std::env::args().collect::<Vec<_>>().join(" "),
        eval_worlds: a.allow_eval_worlds && eval_world_reason(&cfg.worlds).is_some(),
        force: a.force,
    };
    let pb = bar((hours * 3600.0).round() as u64, kind.name());
    let done = std::sync::Mutex::new(0.0f64);
    let t0 = std::time::Instant::now();
    let m = write_dataset(&a.out, &cfg, &info, &|s| {
        let mut d = done.lock().expect("not poisoned");
        *d += s;
        pb.set_position(d.round() as u64);
    })?;
    pb.finish_and_clear();
    let wall = t0.elapsed().as_secs_f64();
    let outcomes: Vec<String> = m.outcomes.iter().map(|(k, v)| format!("{k} {v}")).collect();
    println!(
        "{} data from {} on {} with {}: {} trials, {} rows, {:.2} h kept of {:.2} h simulated in {:.1} s ({:.0}x real time); outcomes: {}",
        kind.name(),
        m.source,
        set.name,
        m.vehicle,
        m.trials,
        m.rows,
        m.hours,
        m.hours_simulated,
        wall,
        m.hours_simulated * 3600.0 / wall.max(1e-9),
        outcomes.join(", ")
    );
    if kind == Kind::Expert && m.hours < hours {
        eprintln!(
            "warning: the set's tasks gave only {:.2} h of successful driving (asked for {hours} h); use a larger set (e.g. verti-300-s1) for more",
            m.hours
        );
    }
    println!("dataset in {}", a.out.display());
    Ok(())
}

fn print_stats(a: StatsArgs) -> CmdResult {
    let data = Dataset::load(&a.dir)?;
    let s = stats(&data);
    println!(
        "{} dataset ({}): {:.2} h, {} trials (mean {:.1} s), {} rows{}",
        s.kind,
        s.source,
        s.hours,
        s.trials,
        s.mean_trial_seconds,
        s.rows,
        if data.manifest.eval_worlds {
            ", ON EVALUATION WORLDS"
        } else {
            ""
        }
    );
    for (k, v) in &s.outcomes {
        println!(
            "  {k:<9} {v:>6}  {:5.1}%",
            100.0 * *v as f64 / s.trials.max(1) as f64
        );
    }
    for h in &s.histograms {
        println!(
            "  {:<14} mean {:7.2} {}  std {:6.2}  min {:7.2}  max {:7.2}",
            h.name, h.mean, h.unit, h.std, h.min, h.max
        );
    }
    let png = a.png.unwrap_or_else(|| a.dir.join("stats.png"));
    verti_render::grouped_bars_png(&panels(&s), 3, &png)?;
    println!("histograms in {}", png.display());
    Ok(())
}

/// One panel per histogram: bins as groups, the share of steps (%) as bars.
fn panels(s: &Stats) -> Vec<Panel> {
    s.histograms
        .iter()
        .map(|h| {
            let n: usize = h.counts.iter().sum();
            Panel {
                title: format!("{} ({})", h.name, h.unit),
                y_label: "% of steps".into(),
                y_max: None,
                // label every fourth bin by its lower edge, so the labels do not overlap
                groups: (0..h.counts.len())
                    .map(|i| {
                        if i % 4 == 0 {
                            format!("{}", h.edges[i])
                        } else {
                            String::new()
                        }
                    })
                    .collect(),
                series: vec![Series {
                    name: format!("{} ({})", s.kind, s.source),
                    values: h
                        .counts
                        .iter()
                        .map(|c| 100.0 * *c as f64 / n.max(1) as f64)
                        .collect(),
                    errors: None,
                }],
            }
        })
        .collect()
}
