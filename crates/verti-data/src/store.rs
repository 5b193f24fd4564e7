//! Writing a dataset directory: Parquet step tables in trial order, then `manifest.yaml`.

use crate::generate::{GenerateConfig, Source, generate};
use crate::manifest::{FORMAT, MANIFEST, Manifest, WorldsInfo, checksum};
use crate::table::{Table, TrialRecord, write_table};
use crate::{DataError, Kind, Result};
use std::path::Path;
use verti_world::WorldSource;

/// Trials per Parquet file (at least; a file closes at the first batch that reaches it).
pub const FILE_TRIALS: usize = 64;

/// File name of the `n`-th step table.
pub fn file_name(n: usize) -> String {
    format!("steps-{n:05}.parquet")
}

/// What the manifest records beyond the generation settings.
#[derive(Clone, Debug)]
pub struct WriteInfo {
    /// The world set as given (`verti-100-s1`, a directory).
    pub set: String,
    /// The set's resolved name.
    pub set_name: String,
    /// The command line that made the data.
    pub command: String,
    /// Recorded on evaluation worlds (allowed with `--allow-eval-worlds`).
    pub eval_worlds: bool,
    /// Replace the dataset files in a non-empty directory.
    pub force: bool,
}

/// Refuses a non-empty `dir` unless `force` (then removes the dataset files in it).
fn prepare_dir(dir: &Path, force: bool) -> Result<()> {
    if dir.exists() {
        let entries: Vec<_> = std::fs::read_dir(dir)
            .map_err(|e| DataError::file(dir, e))?
            .flatten()
            .collect();
        if !entries.is_empty() && !force {
            return Err(DataError::Argument(format!(
                "--out {} exists and is not empty; choose another directory or pass --force to replace its dataset",
                dir.display()
            )));
        }
        for e in entries {
            let name = e.file_name().to_string_lossy().to_string();
            let ours = name == MANIFEST
                || (name.starts_with("steps-")
                    && (name.ends_with(".parquet") || name.ends_with(".parquet.partial")));
            if ours {
                std::fs::remove_file(e.path()).map_err(|err| DataError::file(&e.path(), err))?;
            }
        }
    } else {
        std::fs::create_dir(dir).map_err(|e| DataError::file(dir, e))?;
    }
    Ok(())
}

/// Writes trials recorded elsewhere (human demonstrations from `verti drive`) as a dataset in
/// `dir`: the same Parquet tables and manifest as generated data, so both load and mix alike.
/// `manifest` gives the identity fields; files, checksums, counts and hours are filled here.
pub fn write_trials(
    dir: &Path,
    trials: &[TrialRecord],
    mut manifest: Manifest,
    force: bool,
) -> Result<Manifest> {
    prepare_dir(dir, force)?;
    let mut files = Vec::new();
    for (n, chunk) in trials.chunks(FILE_TRIALS).enumerate() {
        let name = file_name(n);
        let path = dir.join(&name);
        write_table(&path, &Table::from_trials(chunk, manifest.wheels))?;
        let bytes = std::fs::read(&path).map_err(|e| DataError::file(&path, e))?;
        files.push((name, checksum(&bytes)));
    }
    let seconds: f64 = trials.iter().map(TrialRecord::duration).sum();
    manifest.format = FORMAT.to_string();
    manifest.trials = trials.len();
    manifest.rows = trials.iter().map(|t| t.rows.len()).sum();
    manifest.hours = seconds / 3600.0;
    manifest.hours_simulated = seconds / 3600.0;
    manifest.outcomes.clear();
    for t in trials {
        *manifest
            .outcomes
            .entry(t.outcome.name().to_string())
            .or_insert(0) += 1;
    }
    let mut indices: Vec<u32> = trials.iter().map(|t| t.world).collect();
    indices.sort_unstable();
    indices.dedup();
    manifest.worlds.indices = indices;
    manifest.checksums = files.iter().cloned().collect();
    manifest.files = files.into_iter().map(|f| f.0).collect();
    manifest.write(dir)?;
    Ok(manifest)
}

/// Generates the dataset `cfg` describes into `dir` and writes its manifest (last, so a
/// directory without one is an unfinished run). `progress` gets budget seconds as they pass.
pub fn write_dataset(
    dir: &Path,
    cfg: &GenerateConfig,
    info: &WriteInfo,
    progress: &dyn Fn(f64),
) -> Result<Manifest> {
    cfg.validate()?;
    prepare_dir(dir, info.force)?;
    let wheels = cfg.vehicle.wheel_count();
    let mut files: Vec<(String, String)> = Vec::new();
    let mut pending: Vec<TrialRecord> = Vec::new();
    let flush = |pending: &mut Vec<TrialRecord>, files: &mut Vec<(String, String)>| -> Result<()> {
        if pending.is_empty() {
            return Ok(());
        }
        let name = file_name(files.len());
        let path = dir.join(&name);
        write_table(&path, &Table::from_trials(pending, wheels))?;
        let bytes = std::fs::read(&path).map_err(|e| DataError::file(&path, e))?;
        files.push((name, checksum(&bytes)));
        pending.clear();
        Ok(())
    };
    let totals = generate(
        cfg,
        &mut |batch| {
            pending.extend(batch);
            if pending.len() >= FILE_TRIALS {
                flush(&mut pending, &mut files)?;
            }
            Ok(())
        },
        progress,
    )?;
    flush(&mut pending, &mut files)?;
    // a dataset with no trial is no data (its reader refuses it): say so instead of writing it
    if totals.trials == 0 || totals.rows == 0 {
        let outcomes: Vec<String> = totals
            .outcomes
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        return Err(DataError::Run(format!(
            "{}: no trial was kept from {:.2} h of simulated driving (outcomes: {}), so no dataset was written{}",
            dir.display(),
            totals.seconds_simulated / 3600.0,
            if outcomes.is_empty() {
                "none".to_string()
            } else {
                outcomes.join(", ")
            },
            match cfg.kind {
                Kind::Expert =>
                    "; an expert dataset keeps successful trials only: use a stronger system, a longer --max-trial-seconds or more worlds",
                _ => "",
            }
        )));
    }
    let first = &cfg.worlds[0].meta;
    let (seed, generator) = match &first.source {
        WorldSource::Generated {
            set_seed,
            generator,
        } => (Some(*set_seed), generator.clone()),
        WorldSource::VertiBench { .. } => (None, "verti-bench-import".to_string()),
    };
    let manifest = Manifest {
        format: FORMAT.to_string(),
        kind: cfg.kind,
        profile: match cfg.source {
            Source::Random(p) => Some(p),
            Source::System { .. } => None,
        },
        source: cfg.source.name().to_string(),
        worlds: WorldsInfo {
            set: info.set.clone(),
            name: info.set_name.clone(),
            seed,
            generator,
            scale: first.scale,
            indices: totals.world_indices.clone(),
        },
        vehicle: cfg.vehicle.name.clone(),
        wheels,
        rate: cfg.rate,
        max_trial_seconds: cfg.max_trial_seconds,
        seed: cfg.seed,
        hours_requested: cfg.hours,
        hours: totals.seconds / 3600.0,
        hours_simulated: totals.seconds_simulated / 3600.0,
        trials: totals.trials,
        rows: totals.rows,
        outcomes: totals.outcomes.clone(),
        eval_worlds: info.eval_worlds,
        checksums: files.iter().cloned().collect(),
        files: files.into_iter().map(|f| f.0).collect(),
        command: info.command.clone(),
        verti_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    manifest.write(dir)?;
    Ok(manifest)
}
