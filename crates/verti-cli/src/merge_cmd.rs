//! `verti merge`: joins the run directories of a sharded evaluation (`verti eval --shard i/N`).

use crate::cli_common::CmdResult;
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
    /// Join even if the shards do not cover the whole selection (a shard not given, or one
    /// with unfinished tasks): the missing tasks are listed here and recorded in the merged
    /// run.json (`missing`), and `verti eval --resume --out DIR` on the merged directory runs
    /// them. By default that fails, so a half-finished cluster run is not mistaken for a
    /// whole one.
    #[arg(long, alias = "partial")]
    allow_partial: bool,
}

pub fn merge(a: MergeArgs) -> CmdResult {
    let joined = verti_bench::shard::join(&a.shards)?;
    if let Some(message) = joined.coverage() {
        if !a.allow_partial {
            return Err(
                format!("{message}; or pass --allow-partial to merge what is there").into(),
            );
        }
        eprintln!("warning: {message}");
    }
    if joined.unchecked {
        eprintln!(
            "warning: these shards were written before verti recorded splits: whether they cover the whole selection cannot be checked (only their own unfinished tasks are known)"
        );
    }
    joined.write(&a.out, a.force, &verti_log::log_file_name)?;
    println!(
        "merged {} shard(s): {} results{}{} -> {}",
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
        if joined.missing.is_empty() {
            String::new()
        } else {
            format!(
                ", {} task(s) missing (listed in run.json)",
                joined.missing.len()
            )
        },
        a.out.join(verti_bench::eval::RESULTS_FILE).display()
    );
    Ok(())
}
