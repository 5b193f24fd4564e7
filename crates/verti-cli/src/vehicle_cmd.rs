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
    /// obstacles, a deformable and a mixed world of verti-100 (at the vehicle's scale),
    /// single-threaded.
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
    /// Trace the benchmark's drive on this world instead (`SET:N`, e.g. verti-100:3, or a world
    /// directory; needs --vehicle): a line of state every --every control steps of 20 ms.
    #[arg(long, requires = "vehicle", conflicts_with = "json")]
    trace: Option<String>,
    /// With --trace: print every N-th control step.
    #[arg(long, default_value_t = 50, requires = "trace")]
    every: u64,
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
    /// Trace one episode instead: the episode seed a failure reports (needs --world and
    /// --vehicle; the world is generated at the vehicle's scale, as the soak does).
    #[arg(long, requires_all = ["world", "vehicle"], conflicts_with = "json")]
    replay: Option<u64>,
    /// With --replay: the failure's world, `SET:N` (e.g. verti-100:17) or a world directory.
    #[arg(long, requires = "replay")]
    world: Option<String>,
    /// With --replay: print every N-th control step of 10 ms.
    #[arg(long, default_value_t = 10, requires = "replay")]
    every: u64,
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
            if let Some(world) = &a.trace {
                let spec = &specs[0];
                let world = sim_tools::traced_world(world, spec.scale)?;
                return Ok(sim_tools::bench_trace(
                    &world,
                    spec,
                    a.seconds,
                    a.every,
                    |line| println!("{line}"),
                )?);
            }
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
            if let (Some(seed), Some(world)) = (a.replay, &a.world) {
                let spec = vehicles_arg(&a.vehicle)?.remove(0);
                let world = sim_tools::traced_world(world, spec.scale)?;
                let episode =
                    sim_tools::replay(&world, &spec, seed, a.every, |line| println!("{line}"));
                return match episode.error {
                    None => Ok(()),
                    Some((t, e)) => Err(format!("the episode fails at t = {t:.3} s: {e}").into()),
                };
            }
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
