//! `verti`: the command line of the verti off-road mobility benchmark.

mod cli_common;
mod compare_cmd;
mod data_cmd;
mod drive_cmd;
mod eval_cmd;
mod kino_cmd;
mod learn_args;
mod learn_cmd;
#[cfg(feature = "learn")]
mod learn_kino;
#[cfg(feature = "learn")]
mod learn_pietra;
#[cfg(feature = "learn")]
mod learn_rl;
#[cfg(feature = "learn")]
mod learn_va;
mod merge_cmd;
mod outputs;
mod pietra_cmd;
mod progress;
mod registries;
mod sim_tools;
mod vehicle_cmd;
mod world_cmd;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "verti", version, about = "verti: a fast off-road mobility benchmark for vertically challenging terrain", long_about = None)]
struct Cli {
    /// Worker threads for parallel work (default: all cores). Results never depend on it.
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Generate, import, inspect and render worlds.
    #[command(subcommand)]
    World(world_cmd::WorldCommand),
    /// List and inspect vehicles.
    #[command(subcommand)]
    Vehicle(vehicle_cmd::VehicleCommand),
    /// Simulator speed benchmark, robustness soak, and comparison with a reference engine.
    #[command(subcommand)]
    Sim(vehicle_cmd::SimCommand),
    /// List the mobility systems and their parameters.
    #[command(subcommand)]
    Systems(SystemsCommand),
    /// Evaluate a mobility system on a world set (parallel, resumable).
    Eval(eval_cmd::EvalArgs),
    /// Drive a task yourself in real time, watching it live in the browser (or watch a
    /// system drive); recorded as a demonstration dataset.
    Drive(drive_cmd::DriveArgs),
    /// Join the run directories of a sharded evaluation (`verti eval --shard i/N`) into one.
    Merge(merge_cmd::MergeArgs),
    /// Draw one evaluated trial's trajectory over its world.
    Replay(eval_cmd::ReplayArgs),
    /// Table I and Fig. 6 (Markdown, HTML, PNG, JSON) from evaluation results.
    Report(eval_cmd::ReportArgs),
    /// Train the shipped models (needs the `learn` feature: `--features learn`).
    #[command(subcommand)]
    Learn(learn_cmd::LearnCommand),
    /// Learned kinodynamic models: accuracy against the bicycle model.
    #[command(subcommand)]
    Kino(kino_cmd::KinoCommand),
    /// Datasets: random exploration, failure cases and expert demonstrations (Parquet).
    #[command(subcommand)]
    Data(data_cmd::DataCommand),
    /// PIETRA: the 30 PIETRA maps, and the navigation benchmark (paper §V-D, Fig. 7).
    #[command(subcommand)]
    Pietra(pietra_cmd::PietraCommand),
}

#[derive(Subcommand)]
enum SystemsCommand {
    /// Every system with its parameters, defaults and ranges.
    List,
}

fn main() -> ExitCode {
    // Behave like other Unix tools when output goes to a closed pipe (`verti ... | head`):
    // terminate quietly instead of panicking on the failed write.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let matches = outputs::check_outputs(Cli::command()).get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Some(n) = cli.threads {
        if let Err(e) = verti_bench::eval::check_jobs(n, "--threads") {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
        // The global pool can only be built once; failing here means it already exists.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    let result = match cli.command {
        Command::World(cmd) => world_cmd::run(cmd),
        Command::Vehicle(cmd) => vehicle_cmd::run_vehicle(cmd),
        Command::Sim(cmd) => vehicle_cmd::run_sim(cmd),
        Command::Systems(SystemsCommand::List) => eval_cmd::systems_list(),
        Command::Eval(a) => eval_cmd::eval(a),
        Command::Drive(a) => drive_cmd::drive(a),
        Command::Merge(a) => merge_cmd::merge(a),
        Command::Replay(a) => eval_cmd::replay(a),
        Command::Report(a) => eval_cmd::report(a),
        Command::Learn(cmd) => learn_cmd::run(cmd).map_err(Into::into),
        Command::Data(cmd) => data_cmd::run(cmd),
        Command::Kino(cmd) => kino_cmd::run(cmd),
        Command::Pietra(cmd) => pietra_cmd::run(cmd).map_err(Into::into),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
