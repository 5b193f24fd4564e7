//! `verti vehicle ...` and `verti sim ...`

use crate::cli_common::{CmdResult, load_set_with_progress, load_vehicle};
use crate::progress::bar;
use crate::sim_tools::{self, BenchWorlds};
use clap::{Args, Subcommand};
use std::sync::Arc;
use verti_sim::{VehicleSpec, vehicles};

#[derive(Subcommand)]
pub enum VehicleCommand {
    /// List the built-in vehicles.
    List,
    /// Show a vehicle's parameters (a built-in name or a vehicle YAML file). `--yaml` prints the
    /// file itself, a template for your own vehicles.
    Show {
        name: String,
        #[arg(long)]
        yaml: bool,
    },
}

pub fn run_vehicle(cmd: VehicleCommand) -> CmdResult {
    match cmd {
        VehicleCommand::List => {
            println!(
                "{:<11} {:>7} {:>9} {:>7} {:>6}  description",
                "name", "scale", "mass kg", "wheels", "track"
            );
            for spec in vehicles::all_builtin() {
                let wheels: usize = spec.axles.len() * 2;
                println!(
                    "{:<11} {:>7} {:>9.1} {:>7} {:>6}  {}",
                    spec.name,
                    verti_world::scale::scale_label(spec.scale),
                    spec.total_mass(),
                    wheels,
                    if spec.is_tracked() { "yes" } else { "no" },
                    spec.description
                );
            }
            Ok(())
        }
        VehicleCommand::Show { name, yaml } => {
            if yaml {
                match vehicles::builtin_yaml(&name) {
                    Some(t) => print!("{t}"),
                    // the same size cap and path errors as loading it
                    None => print!(
                        "{}",
                        verti_world::yaml::read_yaml_bounded(
                            std::path::Path::new(&name),
                            &verti_world::yaml::YamlLimits::DEFAULT,
                            "a vehicle file",
                        )?
                    ),
                }
                return Ok(());
            }
            let spec = load_vehicle(&name)?;
            print!("{}", spec.summary());
            Ok(())
        }
    }
}

#[derive(Subcommand)]
pub enum SimCommand {
    /// Real-time factor of every (or one) vehicle on a high-elevation rigid world with dense
    /// obstacles and on a deformable world of verti-100 (at the vehicle's scale), single-threaded.
    Bench(BenchArgs),
    /// Random inputs through every world of a set; reports NaNs and blow-ups.
    Soak(SoakArgs),
    /// Fidelity: re-run a reference engine's tasks (e.g. ../shared/chrono-reference) in verti
    /// and compare outcomes, attitudes, times and trajectories; a PNG per task and a summary.
    Compare(crate::compare_cmd::CompareArgs),
}

#[derive(Args)]
pub struct BenchArgs {
    /// Only this vehicle (default: all built-in vehicles).
    #[arg(long)]
    vehicle: Option<String>,
    /// Simulated seconds per run.
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// Runs per case (the median is reported).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
pub struct SoakArgs {
    /// Control steps (10 ms each) in total.
    #[arg(long, default_value_t = 1_000_000)]
    steps: u64,
    /// World set to drive through.
    #[arg(long, default_value = "verti-100")]
    worlds: String,
    /// Only this vehicle (default: all built-in vehicles, each on worlds of its scale, or all).
    #[arg(long)]
    vehicle: Option<String>,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    #[arg(long)]
    json: bool,
}

fn vehicles_arg(v: &Option<String>) -> Result<Vec<VehicleSpec>, Box<dyn std::error::Error>> {
    Ok(match v {
        Some(name) => vec![load_vehicle(name)?],
        None => vehicles::all_builtin(),
    })
}

pub fn run_sim(cmd: SimCommand) -> CmdResult {
    match cmd {
        SimCommand::Bench(a) => {
            if !(a.seconds.is_finite() && a.seconds > 0.0) || a.runs == 0 {
                return Err("--seconds must be positive and --runs at least 1".into());
            }
            let specs = vehicles_arg(&a.vehicle)?;
            let worlds = BenchWorlds::generated_for(&specs)?;
            let report = sim_tools::bench(&worlds, &specs, a.seconds, a.runs);
            if a.json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print!("{report}");
            }
            Ok(())
        }
        SimCommand::Compare(a) => crate::compare_cmd::compare(a),
        SimCommand::Soak(a) => {
            let specs = vehicles_arg(&a.vehicle)?;
            let set = load_set_with_progress(&a.worlds, 1.0)?;
            let mut worlds: Vec<Arc<verti_world::World>> =
                set.worlds.into_iter().map(Arc::new).collect();
            // smaller vehicles get the set regenerated at their scale when it is the built-in one
            for spec in &specs {
                if (spec.scale - 1.0).abs() > 1e-9
                    && verti_world::sets::builtin_config(&a.worlds, spec.scale).is_some()
                {
                    let scaled = load_set_with_progress(&a.worlds, spec.scale)?;
                    worlds.extend(scaled.worlds.into_iter().map(Arc::new));
                }
            }
            let pb = bar(a.steps, "soak");
            let report = sim_tools::soak(&worlds, &specs, a.steps, a.seed, |done| {
                pb.set_position(done)
            });
            pb.finish_and_clear();
            if a.json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print!("{report}");
            }
            if report.failures.is_empty() {
                Ok(())
            } else {
                Err(format!("{} episodes failed", report.failures.len()).into())
            }
        }
    }
}
