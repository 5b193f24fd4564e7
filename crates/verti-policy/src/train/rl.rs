//! What `verti learn rl` does, as a library function: build the training environments and the
//! curriculum, run PPO updates until the budget is spent, validate the deterministic policy on
//! a fixed set of tasks from other worlds now and then, checkpoint, and write the policy with
//! its card, learning curve (PNG) and a CSV log.

use crate::Policy;
use crate::inputs::{INPUT_DIM, SCALAR_NAMES, env_config, policy_input};
use crate::train::curriculum::{
    Manual, Prioritised, TaskMeta, TaskSampler, Uniform, default_stages,
};
use crate::train::ppo::{PpoConfig, Trainer, UpdateStats};
use burn::tensor::Device;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use verti_bench::episode::Outcome;
use verti_env::{EnvCore, EnvError, ObsBuf, TaskFilter};
use verti_nn::Network;
use verti_render::lines::{LinePanel, LineSeries, line_chart_image};
use verti_sim::VehicleSpec;
use verti_world::World;

/// Which curriculum picks the training tasks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurriculumKind {
    /// Uniform over the training tasks (`rl`).
    None,
    /// Manual stages (`mcl`).
    Manual,
    /// Prioritised level replay (`acl`).
    Auto,
}

impl CurriculumKind {
    pub fn parse(s: &str) -> Result<CurriculumKind, String> {
        match s {
            "none" => Ok(CurriculumKind::None),
            "manual" => Ok(CurriculumKind::Manual),
            "auto" => Ok(CurriculumKind::Auto),
            other => Err(format!(
                "unknown curriculum `{other}` (none, manual or auto)"
            )),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            CurriculumKind::None => "none",
            CurriculumKind::Manual => "manual",
            CurriculumKind::Auto => "auto",
        }
    }
    /// The benchmark system trained with this curriculum.
    pub fn system(self) -> &'static str {
        match self {
            CurriculumKind::None => "rl",
            CurriculumKind::Manual => "mcl",
            CurriculumKind::Auto => "acl",
        }
    }
}

/// Manual curriculum: success rate over this many episodes of a stage ...
pub const MANUAL_WINDOW: usize = 50;
/// ... must reach this to open the next stage.
pub const MANUAL_THRESHOLD: f64 = 0.6;

/// Everything a training run needs.
pub struct RlSettings {
    pub curriculum: CurriculumKind,
    pub ppo: PpoConfig,
    /// Wall-clock budget, minutes.
    pub budget_minutes: f64,
    /// Stop after this many updates even if budget is left (reproducible runs).
    pub max_updates: Option<u64>,
    pub train_worlds: Vec<Arc<World>>,
    pub train_set: String,
    pub val_worlds: Vec<Arc<World>>,
    pub val_set: String,
    /// Validation tasks (evenly spread over the validation set).
    pub val_tasks: usize,
    /// Validate every this many updates.
    pub eval_every: u64,
    pub vehicle: VehicleSpec,
    /// Policy card to write; weights, curve and log beside it.
    pub out: PathBuf,
    pub command: String,
    /// Continue from the checkpoint beside `out` (`<stem>.ckpt/`) where one exists. A resumed
    /// run is deterministic too, but not bit-identical to an uninterrupted one (episodes in
    /// flight restart and Adam's moments are not checkpointed).
    pub resume: bool,
}

/// One validation point of the learning curve.
#[derive(Clone, Debug, PartialEq)]
pub struct CurvePoint {
    pub update: u64,
    pub env_steps: u64,
    pub wall_s: f64,
    /// Success of the deterministic policy on the validation tasks.
    pub val_success: f64,
    /// Success of the training episodes that ended since the previous point.
    pub train_success: f64,
}

/// What a run produced.
pub struct RlReport {
    pub policy: Network,
    pub curve: Vec<CurvePoint>,
    pub updates: Vec<UpdateStats>,
    pub wall_s: f64,
    pub card: PathBuf,
    pub curve_png: PathBuf,
    pub log_csv: PathBuf,
}

/// The tasks of `worlds` with what the curricula sort by.
pub fn task_metas(worlds: &[Arc<World>]) -> Vec<TaskMeta> {
    let mut v = Vec::new();
    for w in worlds {
        for t in &w.tasks {
            v.push(TaskMeta {
                number: w.task_id(t.pair).number(),
                level: w.meta.level,
                density: w.meta.density,
                terrain: w.meta.terrain_type,
            });
        }
    }
    v.sort_by_key(|t| t.number);
    v
}

/// `k` task numbers spread evenly over `worlds`' tasks.
pub fn spread_tasks(worlds: &[Arc<World>], k: usize) -> Vec<u32> {
    let all = task_metas(worlds);
    let k = k.min(all.len()).max(1);
    (0..k).map(|i| all[i * all.len() / k].number).collect()
}

/// Drives `policy` (its mean action) on each task once, `threads` at a time; outcomes in task
/// order. The same encoding as training and as `verti eval`.
pub fn evaluate(
    policy: &Policy,
    template: &EnvCore,
    tasks: &[u32],
    threads: usize,
) -> Result<Vec<Outcome>, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| {
        tasks
            .par_iter()
            .map(|&n| -> Result<Outcome, EnvError> {
                let mut env = template.sibling(u64::from(n));
                env.reset(None, Some(n))?;
                let mut buf = ObsBuf::default();
                let mut x = Vec::with_capacity(INPUT_DIM);
                let mut scratch = policy.scratch();
                loop {
                    env.observe(&mut buf)?;
                    let ep = env.episode().expect("reset above");
                    let scale = env.worlds()[ep.world].meta.scale;
                    policy_input(&buf, scale, &mut x);
                    let a = policy.act(&x, &mut scratch);
                    let action = env.action_from_normalized(&[f64::from(a[0]), f64::from(a[1])])?;
                    if let Some(o) = env.step(action)?.outcome {
                        return Ok(o);
                    }
                }
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| e.to_string())
    })
}

fn sampler(kind: CurriculumKind, tasks: &[TaskMeta]) -> Box<dyn TaskSampler> {
    match kind {
        CurriculumKind::None => Box::new(Uniform::new(tasks.len())),
        CurriculumKind::Manual => Box::new(Manual::new(
            tasks,
            &default_stages(),
            MANUAL_WINDOW,
            MANUAL_THRESHOLD,
        )),
        CurriculumKind::Auto => Box::new(Prioritised::new(tasks.len())),
    }
}

fn stem(out: &Path) -> String {
    out.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("policy")
        .to_string()
}

fn sibling_path(out: &Path, suffix: &str) -> PathBuf {
    out.with_file_name(format!("{}{suffix}", stem(out)))
}

/// The checkpoint directory of a run writing `out`.
pub fn checkpoint_dir(out: &Path) -> PathBuf {
    sibling_path(out, ".ckpt")
}

/// Writes the networks, counters, curve and curriculum state (at every validation point).
fn save_checkpoint(dir: &Path, trainer: &Trainer, curve: &[CurvePoint]) -> Result<(), String> {
    trainer
        .actor_network("actor")
        .save(&dir.join("actor.yaml"))
        .map_err(|e| e.to_string())?;
    trainer
        .critic_network("critic")
        .save(&dir.join("critic.yaml"))
        .map_err(|e| e.to_string())?;
    let state = serde_json::json!({
        "updates": trainer.updates,
        "env_steps": trainer.env_steps,
        "curve": curve
            .iter()
            .map(|p| vec![p.update as f64, p.env_steps as f64, p.wall_s, p.val_success, p.train_success])
            .collect::<Vec<_>>(),
        // NaN (an unscored task) has no JSON form: null
        "sampler": trainer
            .sampler
            .state()
            .iter()
            .map(|v| if v.is_nan() { None } else { Some(*v) })
            .collect::<Vec<_>>(),
    });
    let path = dir.join("state.json");
    // write then rename: a run killed mid-write keeps the previous checkpoint
    let tmp = dir.join("state.json.tmp");
    std::fs::write(&tmp, state.to_string()).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, &path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Loads a checkpoint into `trainer`; returns the curve so far.
fn load_checkpoint(dir: &Path, trainer: &mut Trainer) -> Result<Vec<CurvePoint>, String> {
    let path = dir.join("state.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let bad = |field: &str| format!("{}: field {field} is missing or malformed", path.display());
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let updates = v["updates"].as_u64().ok_or_else(|| bad("updates"))?;
    let env_steps = v["env_steps"].as_u64().ok_or_else(|| bad("env_steps"))?;
    let sampler: Vec<f64> = v["sampler"]
        .as_array()
        .ok_or_else(|| bad("sampler"))?
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect();
    let mut curve = Vec::new();
    for p in v["curve"].as_array().ok_or_else(|| bad("curve"))? {
        let n: Vec<f64> = p
            .as_array()
            .ok_or_else(|| bad("curve"))?
            .iter()
            .filter_map(serde_json::Value::as_f64)
            .collect();
        if n.len() != 5 {
            return Err(bad("curve"));
        }
        curve.push(CurvePoint {
            update: n[0] as u64,
            env_steps: n[1] as u64,
            wall_s: n[2],
            val_success: n[3],
            train_success: n[4],
        });
    }
    let actor = Network::load(&dir.join("actor.yaml")).map_err(|e| e.to_string())?;
    let critic = Network::load(&dir.join("critic.yaml")).map_err(|e| e.to_string())?;
    trainer
        .resume(&actor, &critic, (updates, env_steps), &sampler)
        .map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(curve)
}

/// Trains a policy; `progress(stats, point, status)` after every update (`point` when the
/// update validated).
pub fn learn_rl(
    s: &RlSettings,
    device: &Device,
    progress: &mut dyn FnMut(&UpdateStats, Option<&CurvePoint>, &str),
) -> Result<RlReport, String> {
    if !(s.budget_minutes.is_finite() && s.budget_minutes > 0.0) {
        return Err(format!(
            "budget = {} minutes must be positive",
            s.budget_minutes
        ));
    }
    let cfg = env_config();
    let template = EnvCore::new(
        s.train_worlds.clone(),
        s.vehicle.clone(),
        cfg.clone(),
        &TaskFilter::default(),
        s.ppo.seed,
    )
    .map_err(|e| e.to_string())?;
    let val_template = EnvCore::new(
        s.val_worlds.clone(),
        s.vehicle.clone(),
        cfg,
        &TaskFilter::default(),
        0,
    )
    .map_err(|e| e.to_string())?;
    let val_tasks = spread_tasks(&s.val_worlds, s.val_tasks);
    let tasks = task_metas(&s.train_worlds);
    let sampler = sampler(s.curriculum, &tasks);
    let mut trainer = Trainer::new(s.ppo.clone(), &template, tasks, sampler, device)?;
    let name = stem(&s.out);
    let started = Instant::now();
    let mut curve = Vec::new();
    let mut updates = Vec::new();
    let (mut won, mut ended) = (0usize, 0usize);
    let validate = |trainer: &Trainer| -> Result<f64, String> {
        let policy = Policy::new(Arc::new(trainer.actor_network(&name)))?;
        let outcomes = evaluate(&policy, &val_template, &val_tasks, s.ppo.threads)?;
        Ok(
            outcomes.iter().filter(|o| **o == Outcome::Success).count() as f64
                / outcomes.len() as f64,
        )
    };
    let ckpt = checkpoint_dir(&s.out);
    // wall time spent before a resume counts toward the budget
    let mut earlier_s = 0.0;
    if s.resume && ckpt.join("state.json").exists() {
        curve = load_checkpoint(&ckpt, &mut trainer)?;
        earlier_s = curve.last().map_or(0.0, |p| p.wall_s);
    } else {
        curve.push(CurvePoint {
            update: 0,
            env_steps: 0,
            wall_s: 0.0,
            val_success: validate(&trainer)?,
            train_success: 0.0,
        });
    }
    std::fs::create_dir_all(&ckpt).map_err(|e| format!("{}: {e}", ckpt.display()))?;
    loop {
        let stats = trainer.update()?;
        won += stats
            .episodes
            .iter()
            .filter(|e| e.outcome == Outcome::Success)
            .count();
        ended += stats.episodes.len();
        let spent = earlier_s + started.elapsed().as_secs_f64();
        let out_of_time =
            spent >= s.budget_minutes * 60.0 || s.max_updates.is_some_and(|m| trainer.updates >= m);
        let mut point = None;
        if trainer.updates.is_multiple_of(s.eval_every.max(1)) || out_of_time {
            curve.push(CurvePoint {
                update: trainer.updates,
                env_steps: trainer.env_steps,
                wall_s: spent,
                val_success: validate(&trainer)?,
                train_success: if ended > 0 {
                    won as f64 / ended as f64
                } else {
                    0.0
                },
            });
            (won, ended) = (0, 0);
            save_checkpoint(&ckpt, &trainer, &curve)?;
            point = curve.last();
        }
        progress(&stats, point, &trainer.sampler.status());
        updates.push(stats);
        if out_of_time {
            break;
        }
    }
    let wall = earlier_s + started.elapsed().as_secs_f64();
    let policy = finish_card(s, &trainer, &curve, &updates, wall)?;
    let card = s.out.clone();
    policy.save(&card).map_err(|e| e.to_string())?;
    let curve_png = sibling_path(&s.out, "-curve.png");
    draw_curve(&curve, &name, &curve_png)?;
    let log_csv = sibling_path(&s.out, "-log.csv");
    write_log(&updates, &curve, &log_csv)?;
    Ok(RlReport {
        policy,
        curve,
        updates,
        wall_s: wall,
        card,
        curve_png,
        log_csv,
    })
}

fn finish_card(
    s: &RlSettings,
    trainer: &Trainer,
    curve: &[CurvePoint],
    updates: &[UpdateStats],
    wall: f64,
) -> Result<Network, String> {
    let name = stem(&s.out);
    let mut net = trainer.actor_network(&name);
    let c = net.card_mut();
    let p = &s.ppo;
    c.summary = format!(
        "Driving policy `{}` (PPO, curriculum {}): the actor network, mean action (target speed, \
         steering) in [-1, 1] from a 16 x 16 heading-aligned elevation patch and {} scalars; \
         the first layer is the terrain encoder, trained end to end.",
        s.curriculum.system(),
        s.curriculum.name(),
        SCALAR_NAMES.len()
    );
    c.normalisation = format!(
        "inputs: verti_policy::inputs::policy_input: 256 heights of a 16 x 16 crop at 0.4 m \
         (row 0 ahead, column 0 left) minus the ground under the vehicle, / 2 m, clamped to \
         [-1, 1]; then {}. Outputs: mean action, clipped to [-1, 1] when driving; speed x 4 m/s \
         x sqrt(scale). Constant log_std: the training Gaussian.",
        SCALAR_NAMES.join("; ")
    );
    c.training.data = format!(
        "episodes on the tasks of {} ({} worlds, {} tasks, vehicle {}); validation on {} tasks \
         of {}; never verti-100",
        s.train_set,
        s.train_worlds.len(),
        trainer.tasks.len(),
        s.vehicle.name,
        s.val_tasks,
        s.val_set
    );
    c.training.command = reproducible_command(&s.command, trainer.updates);
    c.training.seed = p.seed;
    c.training.steps = trainer.updates;
    c.training.wall_time_s = (wall * 10.0).round() / 10.0;
    c.training.settings = format!(
        "PPO: {} envs x {} steps per update, {} epochs, minibatch {}, gamma {}, lambda {}, clip \
         {}, ent {}, vf {}, grad norm {}, Adam {} (eps 1e-5), hidden {:?} tanh, init log std {}, \
         reward x {}, {} threads; curriculum {}{}; {} updates, {} env steps",
        p.envs,
        p.steps,
        p.epochs,
        p.minibatch,
        p.gamma,
        p.lambda,
        p.clip,
        p.ent_coef,
        p.vf_coef,
        p.max_grad_norm,
        p.lr,
        p.hidden,
        p.init_log_std,
        p.reward_scale,
        p.threads,
        s.curriculum.name(),
        match s.curriculum {
            CurriculumKind::Manual => format!(
                " (stages promoted at {:.0} % success over {MANUAL_WINDOW} episodes)",
                100.0 * MANUAL_THRESHOLD
            ),
            CurriculumKind::Auto => " (PLR: replay 0.5, beta 0.1, staleness 0.1)".into(),
            CurriculumKind::None => String::new(),
        },
        trainer.updates,
        trainer.env_steps
    );
    let last = curve.last().cloned().ok_or("no validation point")?;
    let best = curve.iter().map(|p| p.val_success).fold(0.0, f64::max);
    let steps: f64 = updates.iter().map(|u| u.collect_s + u.learn_s).sum();
    c.metrics.insert("val_success".into(), last.val_success);
    c.metrics.insert("val_success_best".into(), best);
    c.metrics
        .insert("env_steps".into(), trainer.env_steps as f64);
    c.metrics.insert(
        "env_steps_per_s".into(),
        (trainer.env_steps as f64 / steps.max(1e-9)).round(),
    );
    c.metrics
        .insert("train_success_last".into(), last.train_success);
    Ok(net)
}

/// The command that reproduces a run exactly: a wall-clock budget (and a resume) replaced by
/// the number of updates the run made, since training is deterministic per update count.
pub fn reproducible_command(command: &str, updates: u64) -> String {
    let mut out: Vec<&str> = Vec::new();
    let mut words = command.split_whitespace();
    while let Some(w) = words.next() {
        match w {
            "--budget" | "--updates" => {
                words.next();
            }
            "--resume" => {}
            _ if w.starts_with("--budget=") || w.starts_with("--updates=") => {}
            _ => out.push(w),
        }
    }
    format!("{} --updates {updates}", out.join(" "))
}

fn draw_curve(curve: &[CurvePoint], name: &str, out: &Path) -> Result<(), String> {
    let panel = LinePanel {
        title: format!("{name}: success vs environment steps"),
        x_label: "environment steps (millions)".into(),
        y_label: "success (%)".into(),
        series: vec![
            LineSeries {
                name: "validation tasks (deterministic)".into(),
                points: curve
                    .iter()
                    .map(|p| [p.env_steps as f64 / 1e6, 100.0 * p.val_success])
                    .collect(),
            },
            LineSeries {
                name: "training episodes".into(),
                points: curve
                    .iter()
                    .skip(1)
                    .map(|p| [p.env_steps as f64 / 1e6, 100.0 * p.train_success])
                    .collect(),
            },
        ],
        marks: vec![],
    };
    let img = line_chart_image(&panel, 720, 400).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, out).map_err(|e| e.to_string())
}

fn write_log(updates: &[UpdateStats], curve: &[CurvePoint], out: &Path) -> Result<(), String> {
    let mut text = String::from(
        "update,env_steps,episodes,successes,mean_return,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance,grad_norm,collect_s,learn_s,val_success\n",
    );
    for u in updates {
        let won = u
            .episodes
            .iter()
            .filter(|e| e.outcome == Outcome::Success)
            .count();
        let ret = if u.episodes.is_empty() {
            f64::NAN
        } else {
            u.episodes.iter().map(|e| e.ret).sum::<f64>() / u.episodes.len() as f64
        };
        let val = curve
            .iter()
            .find(|p| p.update == u.update)
            .map_or(String::new(), |p| format!("{:.4}", p.val_success));
        let _ = writeln!(
            text,
            "{},{},{},{},{:.2},{:.5},{:.5},{:.4},{:.5},{:.4},{:.4},{:.4},{:.3},{:.3},{}",
            u.update,
            u.env_steps,
            u.episodes.len(),
            won,
            ret,
            u.policy_loss,
            u.value_loss,
            u.entropy,
            u.approx_kl,
            u.clip_fraction,
            u.explained_variance,
            u.grad_norm,
            u.collect_s,
            u.learn_s,
            val
        );
    }
    std::fs::write(out, text).map_err(|e| format!("{}: {e}", out.display()))
}

/// The validation points of a run's `-log.csv`: (environment steps, success).
pub fn read_log(path: &Path) -> Result<Vec<[f64; 2]>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header.iter().position(|h| *h == name).ok_or_else(|| {
            format!(
                "{}: no column {name} (not a `verti learn rl` log)",
                path.display()
            )
        })
    };
    let (steps, val) = (col("env_steps")?, col("val_success")?);
    let mut points = Vec::new();
    for (i, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let num = |k: usize| f.get(k).and_then(|v| v.parse::<f64>().ok());
        match (num(steps), f.get(val)) {
            (Some(x), Some(v)) if !v.is_empty() => {
                let y = v.parse::<f64>().map_err(|_| {
                    format!("{}: line {}: bad val_success {v}", path.display(), i + 2)
                })?;
                points.push([x, y]);
            }
            (None, _) => {
                return Err(format!("{}: line {}: bad env_steps", path.display(), i + 2));
            }
            _ => {}
        }
    }
    Ok(points)
}

/// Learning curves of several runs grouped by name (e.g. curriculum): per group the mean
/// validation success over its runs at each validation point (runs of one group share the
/// schedule). Returns per group the final mean and the mean over all validation points (the
/// area under the curve, which says how fast a curriculum learns).
pub fn draw_comparison(
    groups: &[(String, Vec<Vec<[f64; 2]>>)],
    title: &str,
    out: &Path,
) -> Result<Vec<(String, f64, f64)>, String> {
    let mut series = Vec::new();
    let mut finals = Vec::new();
    for (name, runs) in groups {
        let n = runs.iter().map(Vec::len).min().unwrap_or(0);
        if n == 0 {
            return Err(format!("group {name} has a run without validation points"));
        }
        let mean: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let x = runs.iter().map(|r| r[i][0]).sum::<f64>() / runs.len() as f64;
                let y = runs.iter().map(|r| r[i][1]).sum::<f64>() / runs.len() as f64;
                [x / 1e6, 100.0 * y]
            })
            .collect();
        let area = mean.iter().map(|p| p[1]).sum::<f64>() / (100.0 * n as f64);
        finals.push((name.clone(), mean[n - 1][1] / 100.0, area));
        series.push(LineSeries {
            name: format!("{name} (mean of {})", runs.len()),
            points: mean,
        });
    }
    let panel = LinePanel {
        title: title.to_string(),
        x_label: "environment steps (millions)".into(),
        y_label: "validation success (%)".into(),
        series,
        marks: vec![],
    };
    let img = line_chart_image(&panel, 720, 400).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, out).map_err(|e| e.to_string())?;
    Ok(finals)
}

#[cfg(test)]
mod tests {
    use super::reproducible_command;

    #[test]
    fn the_card_records_the_update_count_instead_of_the_budget() {
        assert_eq!(
            reproducible_command("verti learn rl --curriculum auto --budget 18 --seed 2", 812),
            "verti learn rl --curriculum auto --seed 2 --updates 812"
        );
        assert_eq!(
            reproducible_command("verti learn rl --budget=5 --updates 9 --resume", 9),
            "verti learn rl --updates 9"
        );
    }
}
