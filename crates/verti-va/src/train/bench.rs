//! VertiAdaptor's accuracy benchmark (paper §V-A/B): on every world of an unseen test set,
//! adapt each model to the first trajectories driven there and score it on the rest.
//!
//! Per world ("environment") and model, in order:
//! 1. the first `examples` trajectories are the adaptation data, the others the queries;
//! 2. adapt: one least-squares solve for `va`, the paper's gradient protocol for the
//!    baselines (`adapt::Protocol`), timed; and, as a reference row, no adaptation at all;
//! 3. score every one-step prediction of the queries and open-loop rollouts of `horizon`
//!    steps from every `stride`-th pose (true commands and terrain along the way).
//!
//! Rows (one per world and model) go to `OUT/rows-LABEL.jsonl` as they finish, so models can
//! run in separate processes and a killed run keeps what it did; the tables read every rows
//! file in OUT.

use super::adapt::{Protocol, adapt_gradient};
use super::batch::Points;
use super::command::load_data;
use crate::adapter::AdaptMode;
use crate::data::VaData;
use crate::eval::{ErrorSums, errors, online_errors};
use crate::{Method, VaModel};
use burn::tensor::Device;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to run.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    pub test: PathBuf,
    /// (label, model card).
    pub models: Vec<(String, PathBuf)>,
    pub examples: usize,
    pub horizon: usize,
    /// Rollout steps of the MSE in the tables (the training horizon, 8).
    pub mse_steps: usize,
    pub stride: usize,
    /// Multiplies the baselines' adaptation steps (1 = the paper's protocol).
    pub adapt_scale: f64,
    /// Also score VertiAdaptor adapting online along the queries (every 5 s, and RLS).
    pub online: bool,
    pub out: PathBuf,
}

/// One world and model.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    pub label: String,
    pub method: Method,
    pub adapted: bool,
    pub world: usize,
    pub level: String,
    pub adapt_s: f64,
    pub example_points: usize,
    pub sums: ErrorSums,
}

fn rows_path(out: &Path, label: &str) -> PathBuf {
    out.join(format!("rows-{label}.jsonl"))
}

fn append(path: &Path, row: &Row) -> Result<(), String> {
    use std::io::Write;
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let line = serde_json::to_string(row).map_err(|e| e.to_string())?;
    writeln!(f, "{line}").map_err(|e| format!("{}: {e}", path.display()))
}

/// Every row in `out`'s rows files.
pub fn read_rows(out: &Path) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    let dir = std::fs::read_dir(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut files: Vec<PathBuf> = dir
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("rows-") && n.ends_with(".jsonl"))
        })
        .collect();
    files.sort();
    for f in files {
        let text = std::fs::read_to_string(&f).map_err(|e| format!("{}: {e}", f.display()))?;
        for (i, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
        {
            rows.push(
                serde_json::from_str(line)
                    .map_err(|e| format!("{} line {}: {e}", f.display(), i + 1))?,
            );
        }
    }
    Ok(rows)
}

/// Adaptation examples of `trajs` as burn points.
fn points(data: &VaData, trajs: &[usize]) -> Points {
    let mut p = Points::default();
    for &i in trajs {
        let t = &data.trajectories[i];
        for s in 0..t.len() - 1 {
            p.push(data, t, s);
        }
    }
    p
}

/// Runs the models of `cfg` over the test worlds; `progress` hears (done, total, label).
pub fn run(
    cfg: &BenchConfig,
    device: &Device,
    progress: &mut dyn FnMut(usize, usize, &str),
    loading: &(dyn Fn(usize, usize) + Sync),
) -> Result<(), String> {
    std::fs::create_dir_all(&cfg.out).map_err(|e| format!("{}: {e}", cfg.out.display()))?;
    let mut models = Vec::new();
    for (label, path) in &cfg.models {
        models.push((
            label.clone(),
            VaModel::load(path).map_err(|e| e.to_string())?,
        ));
    }
    let dt = models.first().map_or(0.1, |(_, m)| m.card.dt);
    if let Some((l, m)) = models.iter().find(|(_, m)| m.card.dt != dt) {
        return Err(format!("{l} steps {} s, the others {dt} s", m.card.dt));
    }
    let data = load_data(&cfg.test, dt, "test", loading)?;
    let envs: Vec<(usize, Vec<usize>)> = data
        .by_world(2)
        .into_iter()
        .filter(|(_, t)| t.len() > cfg.examples)
        .collect();
    if envs.is_empty() {
        return Err(format!(
            "{}: no world has more than {} trajectories",
            cfg.test.display(),
            cfg.examples
        ));
    }
    let total = envs.len() * models.len();
    let mut done = 0;
    for (label, model) in &models {
        let path = rows_path(&cfg.out, label);
        let rows_so_far = if cfg.out.exists() {
            read_rows(&cfg.out)?
        } else {
            Vec::new()
        };
        let finished = |l: &str| -> Vec<usize> {
            rows_so_far
                .iter()
                .filter(|r| r.label == l && r.adapted)
                .map(|r| r.world)
                .collect()
        };
        let (main_done, online_done) = (finished(label), finished(&format!("{label}-slide")));
        let online = cfg.online && model.card.method == Method::Va;
        for (world, trajs) in &envs {
            done += 1;
            progress(done, total, label);
            let world_id = data.worlds[*world].meta.index as usize;
            let main_needed = !main_done.contains(&world_id);
            let online_needed = online && !online_done.contains(&world_id);
            if !main_needed && !online_needed {
                continue;
            }
            let (ex, queries) = trajs.split_at(cfg.examples);
            let level = data.worlds[*world].meta.level;
            let score = |m: &VaModel, alpha: &[f64]| {
                errors(m, alpha, &data, queries, cfg.horizon, cfg.stride)
            };
            let examples = data.examples(model, ex);
            let base = Row {
                label: label.clone(),
                method: model.card.method,
                adapted: false,
                world: world_id,
                level: format!("{level:?}").to_lowercase(),
                adapt_s: 0.0,
                example_points: examples.len(),
                sums: if main_needed {
                    score(model, &model.card.alpha_prior)
                } else {
                    ErrorSums::new(cfg.horizon)
                },
            };
            // VertiAdaptor's one solve (timed): the adapted row's coefficients, and where the
            // online rows start from
            let solve = if model.card.method == Method::Va {
                let started = Instant::now();
                let alpha = model.adapt(&examples).map_err(|e| e.to_string())?;
                Some((started.elapsed().as_secs_f64(), alpha))
            } else {
                None
            };
            let sums = match (Protocol::of(model.card.method, cfg.adapt_scale), &solve) {
                _ if !main_needed => (0.0, ErrorSums::new(cfg.horizon)),
                (Some(p), _) => {
                    let started = Instant::now();
                    let adapted = adapt_gradient(model, &points(&data, ex), p, device)?;
                    let s = started.elapsed().as_secs_f64();
                    (s, score(&adapted, &[1.0]))
                }
                (None, Some((s, alpha))) => (*s, score(model, alpha)),
                (None, None) => {
                    return Err(format!("{label}: no adaptation protocol and no solve"));
                }
            };
            if main_needed {
                append(&path, &base)?;
                append(
                    &path,
                    &Row {
                        adapted: true,
                        adapt_s: sums.0,
                        sums: sums.1,
                        ..base.clone()
                    },
                )?;
            }
            if online_needed {
                // online adaptation along the queries, from the adapted (once) coefficients
                // for comparison with them: VA† (every 5 s on the last 5 s), RLS, and a
                // sliding-window solve every step
                let Some((_, once)) = &solve else {
                    return Err(format!("{label}: online rows need a least-squares solve"));
                };
                let shared = std::sync::Arc::new(model.clone());
                for (suffix, mode) in [
                    (
                        "every",
                        AdaptMode::Every {
                            period: 5.0,
                            window: 5.0,
                        },
                    ),
                    ("rls", AdaptMode::Rls { forgetting: 0.98 }),
                    // a least-squares solve every step on the last 5 s: how much of RLS's
                    // gain is the update rate rather than the recursion
                    (
                        "slide",
                        AdaptMode::Every {
                            period: 0.1,
                            window: 5.0,
                        },
                    ),
                ] {
                    if online_done.contains(&world_id)
                        || rows_so_far
                            .iter()
                            .any(|r| r.world == world_id && r.label == format!("{label}-{suffix}"))
                    {
                        continue;
                    }
                    let label = format!("{label}-{suffix}");
                    let sums =
                        online_errors(&shared, mode, once, &data, queries, cfg.horizon, cfg.stride);
                    append(
                        &rows_path(&cfg.out, &label),
                        &Row {
                            label,
                            adapted: true,
                            adapt_s: 0.0,
                            sums,
                            ..base.clone()
                        },
                    )?;
                }
            }
        }
    }
    Ok(())
}

/// Rows pooled by (label, adapted, level).
pub fn pooled(rows: &[Row]) -> BTreeMap<(String, bool, String), (ErrorSums, Vec<f64>)> {
    let mut out: BTreeMap<(String, bool, String), (ErrorSums, Vec<f64>)> = BTreeMap::new();
    for r in rows {
        let e = out
            .entry((r.label.clone(), r.adapted, r.level.clone()))
            .or_insert_with(|| (ErrorSums::new(r.sums.step_sq.len()), Vec::new()));
        e.0.merge(&r.sums);
        e.1.push(r.adapt_s);
    }
    out
}
