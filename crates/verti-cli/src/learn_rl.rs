//! `verti learn rl` (with the `learn` feature): trains a driving policy with PPO.

use crate::cli_common::{load_set_with_progress, load_vehicle};
use crate::learn_args::{CurvesArgs, RlArgs};
use crate::progress::bar;
use std::path::PathBuf;
use std::sync::Arc;
use verti_nn::train::Device;
use verti_policy::train::ppo::PpoConfig;
use verti_policy::train::rl::{CurriculumKind, RlSettings, learn_rl};

/// Refuses the evaluation set: policies train and validate on other seeds.
fn check_not_evaluation(set: &str, flag: &str) -> Result<(), String> {
    let base = set.split(':').next().unwrap_or(set);
    if base == "verti-100" || base.ends_with("verti-bench-data/worlds") {
        return Err(format!(
            "{flag} {set}: that is the evaluation set; train and validate on other seeds \
             (verti-100-s1, verti-100-s2, ...)"
        ));
    }
    Ok(())
}

pub fn run(a: &RlArgs, command: &str, device: &Device) -> Result<(), String> {
    let curriculum = CurriculumKind::parse(&a.curriculum)?;
    check_not_evaluation(&a.worlds, "--worlds")?;
    check_not_evaluation(&a.val_worlds, "--val-worlds")?;
    if a.worlds == a.val_worlds {
        return Err(
            "--worlds and --val-worlds must differ (validation needs unseen worlds)".into(),
        );
    }
    let out = a.out.clone().unwrap_or_else(|| {
        PathBuf::from(format!(
            "crates/verti-policy/models/{}-v1.yaml",
            curriculum.system()
        ))
    });
    let vehicle = load_vehicle(&a.vehicle).map_err(|e| e.to_string())?;
    let train = load_set_with_progress(&a.worlds, 1.0).map_err(|e| e.to_string())?;
    let val = load_set_with_progress(&a.val_worlds, 1.0).map_err(|e| e.to_string())?;
    let settings = RlSettings {
        curriculum,
        ppo: PpoConfig {
            envs: a.envs,
            steps: a.steps,
            epochs: a.epochs,
            minibatch: a.minibatch,
            lr: a.lr,
            ent_coef: a.ent_coef,
            seed: a.seed,
            threads: a.threads,
            ..PpoConfig::default()
        },
        budget_minutes: a.budget,
        max_updates: a.updates,
        train_worlds: train.worlds.into_iter().map(Arc::new).collect(),
        train_set: a.worlds.clone(),
        val_worlds: val.worlds.into_iter().map(Arc::new).collect(),
        val_set: a.val_worlds.clone(),
        val_tasks: a.val_tasks,
        eval_every: a.eval_every,
        vehicle,
        out: out.clone(),
        command: command.to_string(),
        resume: a.resume,
    };
    if let Some(dir) = out.parent()
        && !dir.as_os_str().is_empty()
    {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let budget_s = (a.budget * 60.0).round() as u64;
    let pb = bar(budget_s, "training (s of budget)");
    let quiet = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let started = std::time::Instant::now();
    let mut last_val = f64::NAN;
    let mut progress = |u: &verti_policy::train::ppo::UpdateStats,
                        point: Option<&verti_policy::train::rl::CurvePoint>,
                        status: &str| {
        let t = started.elapsed().as_secs_f64();
        pb.set_position((t as u64).min(budget_s));
        if let Some(p) = point {
            last_val = p.val_success;
        }
        let won = u
            .episodes
            .iter()
            .filter(|e| e.outcome == verti_bench::episode::Outcome::Success)
            .count();
        let line = format!(
            "update {} | {:.2} M steps | {} episodes, {} won | val {} | kl {:.4} clip {:.2} \
             ev {:.2} | std {:.2}/{:.2} | {:.0} steps/s | {status}",
            u.update,
            u.env_steps as f64 / 1e6,
            u.episodes.len(),
            won,
            if last_val.is_nan() {
                "not yet".to_string()
            } else {
                format!("{:.0} %", 100.0 * last_val)
            },
            u.approx_kl,
            u.clip_fraction,
            u.explained_variance,
            u.log_std[0].exp(),
            u.log_std[1].exp(),
            u.env_steps as f64 / t.max(1e-9),
        );
        pb.set_message(line.clone());
        if quiet && (point.is_some() || u.update <= 3) {
            eprintln!("{line} ({t:.0} s)");
        }
    };
    let report = learn_rl(&settings, device, &mut progress)?;
    pb.finish_and_clear();
    println!("{}", report.policy.describe());
    for (k, v) in &report.policy.card().metrics {
        println!("  {k}: {v}");
    }
    println!(
        "wrote {} (+ {}), learning curve {}, log {}; {:.0} s",
        report.card.display(),
        report.policy.card().weights.file,
        report.curve_png.display(),
        report.log_csv.display(),
        report.wall_s
    );
    Ok(())
}

/// `verti learn curves`: groups logs by the part of their name before `-s<seed>`.
pub fn curves(a: &CurvesArgs) -> Result<(), String> {
    let mut groups: Vec<(String, Vec<Vec<[f64; 2]>>)> = Vec::new();
    for path in &a.logs {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or_else(|| format!("{}: not a file name", path.display()))?;
        let group = name
            .rfind("-s")
            .map_or(name.trim_end_matches("-log.csv"), |i| &name[..i])
            .to_string();
        let points = verti_policy::train::rl::read_log(path)?;
        match groups.iter_mut().find(|(g, _)| *g == group) {
            Some((_, runs)) => runs.push(points),
            None => groups.push((group, vec![points])),
        }
    }
    let finals = verti_policy::train::rl::draw_comparison(&groups, &a.title, &a.out)?;
    for ((name, runs), (_, last, area)) in groups.iter().zip(&finals) {
        let each: Vec<String> = runs
            .iter()
            .map(|r| format!("{:.0}", 100.0 * r.last().map_or(0.0, |p| p[1])))
            .collect();
        println!(
            "{name}: final validation success {:.1} % (mean of {} runs: {} %); mean over the run {:.1} %",
            100.0 * last,
            runs.len(),
            each.join(", "),
            100.0 * area
        );
    }
    println!("wrote {}", a.out.display());
    Ok(())
}
