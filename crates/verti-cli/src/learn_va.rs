//! `verti learn va` (with the `learn` feature): trains VertiAdaptor or one of its baselines.

use crate::learn_args::VaArgs;
use crate::progress::bar;
use std::path::PathBuf;
use verti_nn::train::Device;
use verti_va::Method;
use verti_va::lsq::LAMBDA;
use verti_va::train::batch::Sampling;
use verti_va::train::bench::{self, BenchConfig};
use verti_va::train::command::{VaRun, learn_va};
use verti_va::train::fit::TrainConfig;
use verti_va::train::net::NetSpec;
use verti_va::train::report;

/// The model step (paper: RK4 over Δt = 0.1 s), full-scale seconds.
pub const DT: f64 = 0.1;

pub fn config_of(a: &VaArgs) -> Result<TrainConfig, String> {
    let method = Method::parse(&a.method)
        .ok_or_else(|| format!("--method {}: expected va, node, mlp or maml", a.method))?;
    Ok(TrainConfig {
        spec: NetSpec {
            method,
            bases: if method == Method::Va { a.bases } else { 1 },
            hidden: a.hidden.clone(),
            elevation: !a.no_elevation,
            semantics: !a.no_semantics,
            dt: DT,
        },
        sampling: Sampling::default(),
        steps: a.steps,
        lr: a.lr,
        lr_final: a.lr_final,
        lambda: LAMBDA,
        maml_inner_lr: 0.01,
        seed: a.seed,
        eval_every: a.eval_every,
    })
}

/// The models the benchmark runs by default: the shipped cards, then the ablations and, as
/// their control, a full VA trained the same way (`verti learn va --out
/// results/va-bench/models/va-retrained.yaml`): the shipped cards' training data may predate a
/// change of the engine, and an ablation is only compared with a model trained on the same.
const DEFAULT_MODELS: [(&str, &str); 9] = [
    ("va", "crates/verti-va/models/va-v1.yaml"),
    ("node", "crates/verti-va/models/node-v1.yaml"),
    ("maml", "crates/verti-va/models/maml-v1.yaml"),
    ("mlp", "crates/verti-va/models/mlp-v1.yaml"),
    ("va-small", "crates/verti-va/models/va-small-v1.yaml"),
    ("va-retrained", "results/va-bench/models/va-retrained.yaml"),
    (
        "va-no-semantics",
        "results/va-bench/models/va-no-semantics.yaml",
    ),
    (
        "va-no-elevation",
        "results/va-bench/models/va-no-elevation.yaml",
    ),
    ("va-no-both", "results/va-bench/models/va-no-both.yaml"),
];

fn benchmark(a: &VaArgs, device: &Device) -> Result<(), String> {
    let models: Vec<(String, PathBuf)> = if a.models.is_empty() {
        DEFAULT_MODELS
            .iter()
            .map(|(l, p)| (l.to_string(), PathBuf::from(p)))
            .collect()
    } else {
        a.models
            .iter()
            .map(|m| {
                m.split_once('=')
                    .map(|(l, p)| (l.to_string(), PathBuf::from(p)))
                    .ok_or_else(|| format!("--models {m}: expected LABEL=CARD"))
            })
            .collect::<Result<_, _>>()?
    };
    let cfg = BenchConfig {
        test: a.test.clone(),
        models,
        examples: a.examples,
        horizon: a.horizon,
        mse_steps: 8.min(a.horizon),
        stride: a.stride.max(1),
        adapt_scale: a.adapt_scale,
        online: true,
        out: a.bench_out.clone(),
    };
    let loading_bar = bar(0, "terrain latents");
    let loading = |done: usize, total: usize| {
        loading_bar.set_length(total as u64);
        loading_bar.set_position(done as u64);
    };
    let pb = bar(0, "worlds x models");
    let quiet = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let mut progress = |done: usize, total: usize, label: &str| {
        loading_bar.finish_and_clear();
        pb.set_length(total as u64);
        pb.set_position(done as u64);
        pb.set_message(label.to_string());
        if quiet {
            eprintln!("{done}/{total} {label}");
        }
    };
    bench::run(&cfg, device, &mut progress, &loading)?;
    pb.finish_and_clear();
    let md = report::write(&cfg.out, cfg.mse_steps)?;
    println!("{md}");
    println!(
        "wrote {}/table.md, fig3-one-step.png, fig3-steps.png",
        cfg.out.display()
    );
    Ok(())
}

/// `--adapt-to`: one adapted card per world.
fn adapt_to_worlds(a: &VaArgs, set: &str, device: &Device) -> Result<(), String> {
    let model = verti_va::VaModel::load(&a.adapt_model).map_err(|e| e.to_string())?;
    let resolved = verti_world::sets::resolve_set(set, 1.0, &|| {}).map_err(|e| e.to_string())?;
    let worlds: Vec<_> = resolved
        .worlds
        .into_iter()
        .filter(|w| a.adapt_worlds.is_empty() || a.adapt_worlds.contains(&w.meta.index))
        .map(std::sync::Arc::new)
        .collect();
    if worlds.is_empty() {
        return Err(format!("{set} has none of the worlds {:?}", a.adapt_worlds));
    }
    let spec = verti_sim::vehicles::builtin(&model.card.vehicle).map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&a.adapt_out).map_err(|e| format!("{}: {e}", a.adapt_out.display()))?;
    let pb = bar(worlds.len() as u64, "adapting");
    for w in &worlds {
        let name = format!("w{:03}", w.meta.index);
        let started = std::time::Instant::now();
        let sim = verti_sim::Sim::new(w, &spec).map_err(|e| format!("{}: {e}", w.meta.name))?;
        let mut adapted = verti_va::train::adapt::adapt_to_world(
            &model,
            w,
            std::sync::Arc::new(sim),
            a.explore_trials,
            a.explore_seconds,
            a.adapt_scale,
            &name,
            device,
        )?;
        adapted
            .card
            .metrics
            .insert("adapt_s".into(), started.elapsed().as_secs_f64());
        adapted
            .save(&a.adapt_out.join(format!("{name}.yaml")))
            .map_err(|e| e.to_string())?;
        pb.inc(1);
        // the bar hides itself without a terminal (logs): say it on stderr then
        let line = format!(
            "{}: adapted in {:.1} s",
            w.meta.name,
            started.elapsed().as_secs_f64()
        );
        if pb.is_hidden() {
            eprintln!("{line}");
        } else {
            pb.println(line);
        }
    }
    pb.finish_and_clear();
    println!(
        "wrote {} cards to {} (use --param model_per_world={}/w{{world}}.yaml --param adapt=none)",
        worlds.len(),
        a.adapt_out.display(),
        a.adapt_out.display()
    );
    Ok(())
}

pub fn run(a: &VaArgs, command: &str, device: &Device) -> Result<(), String> {
    if a.benchmark {
        return benchmark(a, device);
    }
    if let Some(set) = &a.adapt_to {
        return adapt_to_worlds(a, set, device);
    }
    let config = config_of(a)?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("crates/verti-va/models/{}-v1.yaml", a.method)));
    let run = VaRun {
        data: a.data.clone(),
        val: a.val.clone(),
        out,
        config: config.clone(),
        command: command.to_string(),
    };
    let quiet = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let loading_bar = bar(0, "terrain latents");
    let loading = |done: usize, total: usize| {
        loading_bar.set_length(total as u64);
        loading_bar.set_position(done as u64);
    };
    let pb = bar(config.steps as u64, "training");
    pb.set_position(0);
    let started = std::time::Instant::now();
    let mut progress = |step: usize, loss: f64| {
        loading_bar.finish_and_clear();
        pb.set_position(step as u64);
        pb.set_message(format!("loss {loss:.4}"));
        if quiet && (step.is_multiple_of(config.eval_every) || step == config.steps) {
            eprintln!(
                "step {step}/{}: loss {loss:.4} ({:.0} s)",
                config.steps,
                started.elapsed().as_secs_f64()
            );
        }
    };
    let trained = learn_va(&run, device, &mut progress, &loading)?;
    pb.finish_and_clear();
    let card = &trained.model.card;
    if let Some(l) = trained.log.last() {
        println!(
            "final: train loss {:.5}, validation loss {:.5}",
            l.train_loss, l.val_loss
        );
    }
    println!(
        "wrote {} (+ {}, {} KiB), learning curve {}; {:.0} s",
        run.out.display(),
        card.weights.file,
        card.weights.floats * 4 / 1024,
        trained.curve_png.display(),
        trained.wall_s
    );
    Ok(())
}
