//! `verti merge`: joins the run directories of a sharded evaluation (`verti eval --shard i/N`).

use crate::world_cmd::CmdResult;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct MergeArgs {
    /// Run directories written by `verti eval --shard i/N` (any order; shell globs welcome).
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Directory for the joined run (run.json, and results.jsonl sorted by task).
    #[arg(long)]
    out: PathBuf,
    /// Overwrite an existing results file in --out.
    #[arg(long)]
    force: bool,
    /// Join even if some shard has unfinished tasks (they are listed); by default that fails,
    /// so a half-finished cluster run is not mistaken for a whole one.
    #[arg(long)]
    partial: bool,
}

pub fn merge(a: MergeArgs) -> CmdResult {
    let joined = verti_bench::shard::join(&a.shards)?;
    if !joined.unfinished.is_empty() {
        let message = unfinished_message(&joined.unfinished);
        if !a.partial {
            return Err(message.into());
        }
        eprintln!("warning: {message}");
    }
    joined.write(&a.out, a.force)?;
    println!(
        "merged {} shard(s): {} results{} -> {}",
        a.shards.len(),
        joined.results().len(),
        if joined.duplicates > 0 {
            format!(
                " ({} tasks finished twice, identical, kept once)",
                joined.duplicates
            )
        } else {
            String::new()
        },
        a.out.join(verti_bench::eval::RESULTS_FILE).display()
    );
    Ok(())
}

fn unfinished_message(unfinished: &[(u32, PathBuf)]) -> String {
    let mut dirs: Vec<String> = unfinished
        .iter()
        .map(|(_, d)| d.display().to_string())
        .collect();
    dirs.sort();
    dirs.dedup();
    let shown: Vec<String> = unfinished
        .iter()
        .take(8)
        .map(|(n, _)| n.to_string())
        .collect();
    format!(
        "{} selected task(s) have no result (e.g. {}): resume {} with `verti eval ... --resume --out DIR`, or pass --partial to merge what is there",
        unfinished.len(),
        shown.join(", "),
        dirs.join(", ")
    )
}
