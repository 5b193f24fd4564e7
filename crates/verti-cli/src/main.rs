//! `verti`: the command line of the verti off-road mobility benchmark.

mod progress;
mod world_cmd;

use clap::{Parser, Subcommand};
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        if n == 0 {
            eprintln!("error: --threads must be at least 1");
            return ExitCode::from(2);
        }
        // The global pool can only be built once; failing here means it already exists.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    let result = match cli.command {
        Command::World(cmd) => world_cmd::run(cmd),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
