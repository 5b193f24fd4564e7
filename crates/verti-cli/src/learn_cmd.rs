//! `verti learn`: trains the models that ship in `models/`. Training needs burn, which only
//! builds with the `learn` feature (`cargo build --release -p verti-cli --features learn`), so
//! the classical benchmark never pays for it; without the feature these commands explain how
//! to get it.

use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum LearnCommand {
    /// Train the SWAE terrain generator (`swae-v1`) on Verti-Bench's 1000 elevation maps.
    Swae(SwaeArgs),
    /// Train the local-patch terrain encoder (`patch-v1`) on crops from training worlds.
    Patch(PatchArgs),
    /// Train a learned kinodynamic model (`mppi6`, `wmvct`, `tal`) or TNT's traversability network (`tnt`) on random-exploration data.
    Kino(KinoArgs),
    /// Train a driving policy with PPO (`rl`, `mcl` or `acl` by curriculum) on training worlds.
    Rl(RlArgs),
    /// PIETRA's learning benchmark (`--benchmark`): the paper's Tables I-II and Fig. 6 on the
    /// 30 PIETRA maps, every method over its hyper-parameter grid and seeds.
    Pietra(PietraArgs),
    /// VertiAdaptor (`va`) or one of its baselines (`node`, `mlp`, `maml`) on random-exploration
    /// data; `--benchmark` reproduces the paper's Tables II-III and Fig. 3 on unseen worlds.
    Va(VaArgs),
    /// Compare learning curves of `verti learn rl` runs (their `-log.csv` files), grouped by
    /// name: `none-s1-log.csv` and `none-s2-log.csv` are two seeds of group `none`.
    Curves(CurvesArgs),
}

#[derive(Args)]
pub struct VaArgs {
    /// va (function encoder), node (neural ODE), mlp or maml (first-order MAML).
    #[arg(long, default_value = "va")]
    pub method: String,
    /// Training data (random exploration, VertiAdaptor profile, on training worlds).
    #[arg(long, default_value = "data/random-s1")]
    pub data: PathBuf,
    /// Validation data (other worlds).
    #[arg(long, default_value = "data/random-s2")]
    pub val: PathBuf,
    /// Basis functions k (va only; paper 24).
    #[arg(long, default_value_t = 24)]
    pub bases: usize,
    /// Hidden widths of each field (paper: 313 x 4, i.e. floor(64 sqrt(k)); verti ships 64 x 4).
    #[arg(long, value_delimiter = ',', default_value = "64,64,64,64")]
    pub hidden: Vec<usize>,
    /// Drop the elevation embedding (ablation).
    #[arg(long)]
    pub no_elevation: bool,
    /// Drop the semantic embedding (ablation).
    #[arg(long)]
    pub no_semantics: bool,
    /// Training steps (paper 1000) and Adam's learning rate, annealed to --lr-final (cosine).
    #[arg(long, default_value_t = 1000)]
    pub steps: usize,
    #[arg(long, default_value_t = 1e-3)]
    pub lr: f64,
    #[arg(long, default_value_t = 1e-5)]
    pub lr_final: f64,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Model card to write (default models/METHOD-v1.yaml; weights, log and curve beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Validation every this many steps.
    #[arg(long, default_value_t = 50)]
    pub eval_every: usize,
    /// Run the accuracy benchmark (Tables II-III, Fig. 3) instead of training: adapt every
    /// model of --models to each test world and score it there.
    #[arg(long)]
    pub benchmark: bool,
    /// Benchmark: test data (random exploration on unseen worlds, several trials per world).
    #[arg(long, default_value = "data/va-test-s3")]
    pub test: PathBuf,
    /// Benchmark: LABEL=CARD pairs, comma-separated (default: va, node, maml, mlp from models/
    /// and the three ablations from results/va-bench/models/).
    #[arg(long, value_delimiter = ',')]
    pub models: Vec<String>,
    /// Benchmark: adaptation trajectories per world (the rest are scored).
    #[arg(long, default_value_t = 4)]
    pub examples: usize,
    /// Benchmark: rollout length (steps of 0.1 s) and start spacing.
    #[arg(long, default_value_t = 20)]
    pub horizon: usize,
    #[arg(long, default_value_t = 5)]
    pub stride: usize,
    /// Benchmark: multiplies the baselines' adaptation steps (1 = the paper's protocol).
    #[arg(long, default_value_t = 1.0)]
    pub adapt_scale: f64,
    /// Benchmark: output folder (rows-*.jsonl, table.md, fig3-*.png).
    #[arg(long, default_value = "results/va-bench")]
    pub bench_out: PathBuf,
    /// Adapt --adapt-model once to each world of this set (navigation's MAML*: the same
    /// exploration drives as `va adapt=once`), writing DIR/wNNN.yaml for `--param model_per_world=DIR/w{world}.yaml`.
    #[arg(long)]
    pub adapt_to: Option<String>,
    /// World indices of --adapt-to (e.g. 1,2,4), default all.
    #[arg(long, value_delimiter = ',')]
    pub adapt_worlds: Vec<u32>,
    #[arg(long, default_value = "models/maml-v1.yaml")]
    pub adapt_model: PathBuf,
    #[arg(long, default_value = "results/va-nav/maml")]
    pub adapt_out: PathBuf,
    /// Exploration drives per world and their length (s), as `va`'s explore_trials and
    /// explore_seconds.
    #[arg(long, default_value_t = 4)]
    pub explore_trials: usize,
    #[arg(long, default_value_t = 20.0)]
    pub explore_seconds: f64,
}

#[derive(Args)]
pub struct PietraArgs {
    /// Run the learning benchmark (drive the maps, sweep, write the tables). Without it, train
    /// one model for the planner (`--method`) and write it to `--model-out`.
    #[arg(long)]
    pub benchmark: bool,
    /// The model to train without --benchmark: pietra, evora, vanilla, pi, upi-only, pp-only.
    #[arg(long, default_value = "pietra")]
    pub method: String,
    /// Learning rate, physics-loss weight κ and entropy weight of the model (default: what the
    /// benchmark chose for the method on validation).
    #[arg(long)]
    pub lr: Option<f64>,
    #[arg(long)]
    pub kappa: Option<f64>,
    #[arg(long)]
    pub entropy: Option<f64>,
    /// Training seed of the model.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Model card to write (default models/METHOD-v1.yaml; networks beside it).
    #[arg(long)]
    pub model_out: Option<PathBuf>,
    /// Methods to train: all, or a list of pietra, pi, vanilla, evora, upi-only, pp-only.
    #[arg(long, default_value = "all")]
    pub methods: String,
    /// Training seeds per configuration (paper: 5).
    #[arg(long, default_value_t = 5)]
    pub seeds: usize,
    /// Adam steps per run (batch 256).
    #[arg(long, default_value_t = 1500)]
    pub steps: usize,
    /// Exploration trials per map (paper: 20).
    #[arg(long, default_value_t = 20)]
    pub trials_per_map: u32,
    /// Seed of the exploration trials.
    #[arg(long, default_value_t = 0)]
    pub data_seed: u64,
    #[arg(long, default_value = "hmmwv")]
    pub vehicle: String,
    /// Worker processes training runs at once (default: one per core). Results do not depend
    /// on it. Processes, not threads: burn's autodiff graph registry is one lock per process.
    #[arg(long)]
    pub workers: Option<usize>,
    /// Keep the runs already finished in --out (a killed benchmark continues where it was).
    #[arg(long)]
    pub resume: bool,
    /// Folder for tables.md, runs.csv, fig6.png and the finished runs (runs/).
    #[arg(long, default_value = "results/pietra-bench")]
    pub out: PathBuf,
    /// Internal: this process is worker K of N (`K/N`), started by the benchmark itself.
    #[arg(long, hide = true)]
    pub worker: Option<String>,
}

#[derive(Args)]
pub struct CurvesArgs {
    /// `-log.csv` files of `verti learn rl` runs, named GROUP-sSEED-log.csv.
    #[arg(required = true)]
    pub logs: Vec<PathBuf>,
    /// Chart to write.
    #[arg(long, default_value = "curricula.png")]
    pub out: PathBuf,
    #[arg(long, default_value = "validation success of the three curricula")]
    pub title: String,
}

#[derive(Args)]
pub struct RlArgs {
    /// Which tasks episodes drive: none (uniform: the `rl` system), manual (stages over
    /// elevation, ground and obstacles: `mcl`) or auto (prioritised replay by TD error: `acl`).
    #[arg(long, value_parser = ["none", "manual", "auto"], default_value = "none")]
    pub curriculum: String,
    /// Wall-clock budget, minutes (training stops after the update that spends it).
    #[arg(long, default_value_t = 60.0)]
    pub budget: f64,
    /// Stop after this many updates (a reproducible length; the card records the count).
    #[arg(long)]
    pub updates: Option<u64>,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Training worlds (never verti-100).
    #[arg(long, default_value = "verti-100-s1")]
    pub worlds: String,
    /// Validation worlds for the learning curve.
    #[arg(long, default_value = "verti-100-s2")]
    pub val_worlds: String,
    /// Validation tasks, spread evenly over the validation worlds.
    #[arg(long, default_value_t = 50)]
    pub val_tasks: usize,
    /// Validate every this many updates.
    #[arg(long, default_value_t = 40)]
    pub eval_every: u64,
    #[arg(long, default_value = "hmmwv")]
    pub vehicle: String,
    /// Policy card to write (default models/SYSTEM-v1.yaml; weights, curve and log beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Parallel environments.
    #[arg(long, default_value_t = 16)]
    pub envs: usize,
    /// Control steps per environment per update.
    #[arg(long, default_value_t = 256)]
    pub steps: usize,
    #[arg(long, default_value_t = 5)]
    pub epochs: usize,
    #[arg(long, default_value_t = 1024)]
    pub minibatch: usize,
    #[arg(long, default_value_t = 5e-4)]
    pub lr: f64,
    #[arg(long, default_value_t = 0.0)]
    pub ent_coef: f64,
    /// Threads stepping the environments (results depend on the seed, not on this count).
    #[arg(long, default_value_t = 2)]
    pub threads: usize,
    /// Continue from the checkpoint beside --out (`<stem>.ckpt/`, written at every
    /// validation), counting the time already spent toward --budget.
    #[arg(long)]
    pub resume: bool,
}

#[derive(Args)]
pub struct KinoArgs {
    /// Which model: mppi6 (an ensemble predicting the full 6-DoF change), wmvct (bicycle
    /// for x/y/yaw, terrain for z, a network for roll and pitch) or tal (an elevation map
    /// encoded once per plan, gated by the vehicle's offset within it); tnt trains TNT's
    /// traversability network (its dynamics are tal's).
    #[arg(long, value_parser = ["mppi6", "wmvct", "tal", "tnt"])]
    pub model: String,
    /// Training dataset (`verti data generate random --worlds verti-100-s1 ...`).
    #[arg(long, default_value = "data/random-s1")]
    pub data: PathBuf,
    /// Validation dataset, driven on other worlds (e.g. verti-100-s2).
    #[arg(long, default_value = "data/random-s2")]
    pub val: PathBuf,
    /// Model card to write (default models/MODEL-v1.yaml; networks and curve beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Model step, full-scale seconds (a multiple of the data's row period).
    #[arg(long, default_value_t = 0.2)]
    pub dt: f64,
    /// Ensemble members (default: 2 for mppi6, 1 otherwise).
    #[arg(long)]
    pub members: Option<usize>,
    /// Hidden layer widths, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "32,32")]
    pub hidden: Vec<usize>,
    /// Optimiser steps per member.
    #[arg(long, default_value_t = 6000)]
    pub steps: usize,
    #[arg(long, default_value_t = 256)]
    pub batch: usize,
    #[arg(long, default_value_t = 3e-3)]
    pub lr: f64,
    #[arg(long, default_value_t = 1e-5)]
    pub lr_final: f64,
    /// Open-loop horizon of the multi-step validation metric, model steps.
    #[arg(long, default_value_t = 10)]
    pub horizon: usize,
    #[arg(long, default_value_t = 250)]
    pub eval_every: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

/// Settings shared by the autoencoders (defaults depend on the model).
#[derive(Args, Clone)]
pub struct AutoencoderArgs {
    /// Optimiser steps.
    #[arg(long)]
    pub steps: Option<usize>,
    /// Mini-batch size.
    #[arg(long)]
    pub batch: Option<usize>,
    /// Adam learning rate at the start (cosine decay to --lr-final).
    #[arg(long)]
    pub lr: Option<f64>,
    #[arg(long)]
    pub lr_final: Option<f64>,
    /// Channels of the stride-2 convolutions, comma-separated (e.g. 8,16,32,64,128).
    #[arg(long, value_delimiter = ',')]
    pub widths: Option<Vec<usize>>,
    /// Latent dimension.
    #[arg(long, default_value_t = 64)]
    pub latent: usize,
    /// Random projections of the sliced-Wasserstein term.
    #[arg(long, default_value_t = 200)]
    pub projections: usize,
    /// Weight of the sliced-Wasserstein term.
    #[arg(long)]
    pub swd_weight: Option<f64>,
    /// Validate every this many steps.
    #[arg(long, default_value_t = 100)]
    pub eval_every: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

#[derive(Args)]
pub struct SwaeArgs {
    /// Directory of Verti-Bench's elevation maps (`N.bmp`, 128 x 128).
    #[arg(long, default_value = "../shared/verti-bench-data/elev_maps")]
    pub data: PathBuf,
    /// Model card to write (weights and learning curve beside it).
    #[arg(long, default_value = "models/swae-v1.yaml")]
    pub out: PathBuf,
    /// Share of the maps held out for validation.
    #[arg(long, default_value_t = 0.1)]
    pub val_fraction: f64,
    #[command(flatten)]
    pub train: AutoencoderArgs,
}

#[derive(Args)]
pub struct PatchArgs {
    /// World set of the training crops (never verti-100).
    #[arg(long, default_value = "verti-100-s1")]
    pub worlds: String,
    /// World set of the validation crops.
    #[arg(long, default_value = "verti-100-s2")]
    pub val_worlds: String,
    /// Validation crops.
    #[arg(long, default_value_t = 512)]
    pub val_patches: usize,
    /// Metres of height difference that map to ±1 at the encoder's input.
    #[arg(long, default_value_t = 2.0)]
    pub height_scale: f64,
    /// Model card to write (weights and learning curve beside it).
    #[arg(long, default_value = "models/patch-v1.yaml")]
    pub out: PathBuf,
    #[command(flatten)]
    pub train: AutoencoderArgs,
}

#[cfg(not(feature = "learn"))]
pub fn run(_cmd: LearnCommand) -> Result<(), String> {
    Err("this verti was built without training support; rebuild with the `learn` feature: \
         cargo build --release -p verti-cli --features learn (adds burn, about 7 minutes on 2 cores)"
        .into())
}

#[cfg(feature = "learn")]
pub use with_burn::run;

#[cfg(feature = "learn")]
mod with_burn {
    use super::*;
    use crate::progress::bar;
    use verti_learn::commands::{RunSettings, Trained, learn_patch, learn_swae};
    use verti_learn::patches::PatchSettings;
    use verti_learn::swae::SwaeConfig;

    fn config(a: &AutoencoderArgs, side: usize, defaults: SwaeConfig) -> SwaeConfig {
        SwaeConfig {
            side,
            widths: a.widths.clone().unwrap_or(defaults.widths),
            latent: a.latent,
            steps: a.steps.unwrap_or(defaults.steps),
            batch: a.batch.unwrap_or(defaults.batch),
            lr: a.lr.unwrap_or(defaults.lr),
            lr_final: a.lr_final.unwrap_or(defaults.lr_final),
            projections: a.projections,
            swd_weight: a.swd_weight.unwrap_or(defaults.swd_weight),
            seed: a.seed,
            eval_every: a.eval_every,
        }
    }

    fn command_line() -> String {
        let args: Vec<String> = std::env::args().skip(1).collect();
        format!("verti {}", args.join(" "))
    }

    fn name_of(out: &std::path::Path) -> String {
        out.file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("model")
            .to_string()
    }

    fn report(t: &Trained) {
        println!("{}", t.network.describe());
        if let Some(p) = t.report.curve.last() {
            println!(
                "final: train loss {:.4}, validation MSE {:.4}, validation sliced W2^2 {:.4}",
                p.train_loss, p.val_mse, p.val_swd
            );
        }
        for (k, v) in &t.network.card().metrics {
            println!("  {k}: {v}");
        }
        println!(
            "wrote {} (+ {}), learning curve {}; {:.0} s",
            t.card_path.display(),
            t.network.card().weights.file,
            t.curve_png.display(),
            t.report.wall_time_s
        );
    }

    pub fn run(cmd: LearnCommand) -> Result<(), String> {
        let device = verti_learn::training_device();
        match cmd {
            LearnCommand::Kino(a) => crate::learn_kino::run(&a, &command_line(), &device),
            LearnCommand::Rl(a) => crate::learn_rl::run(&a, &command_line(), &device),
            LearnCommand::Curves(a) => crate::learn_rl::curves(&a),
            LearnCommand::Pietra(a) => crate::learn_pietra::run(&a, &command_line(), &device),
            LearnCommand::Va(a) => crate::learn_va::run(&a, &command_line(), &device),
            LearnCommand::Swae(a) => run_autoencoder(Autoencoder::Swae(a), &device),
            LearnCommand::Patch(a) => run_autoencoder(Autoencoder::Patch(a), &device),
        }
    }

    /// The two trainings that share the SWAE code.
    enum Autoencoder {
        Swae(SwaeArgs),
        Patch(PatchArgs),
    }

    fn run_autoencoder(cmd: Autoencoder, device: &verti_learn::Device) -> Result<(), String> {
        let (run, data) = match &cmd {
            Autoencoder::Swae(a) => (
                config(
                    &a.train,
                    128,
                    SwaeConfig {
                        side: 128,
                        widths: vec![8, 16, 32, 64, 128],
                        latent: 64,
                        steps: 3000,
                        batch: 32,
                        lr: 1e-3,
                        lr_final: 1e-5,
                        projections: 200,
                        swd_weight: 1.0,
                        seed: 0,
                        eval_every: 100,
                    },
                ),
                &a.out,
            ),
            Autoencoder::Patch(a) => (
                config(
                    &a.train,
                    64,
                    SwaeConfig {
                        side: 64,
                        widths: vec![8, 16, 32, 64],
                        latent: 64,
                        steps: 3000,
                        batch: 64,
                        lr: 1e-3,
                        lr_final: 1e-5,
                        projections: 200,
                        swd_weight: 1.0,
                        seed: 0,
                        eval_every: 100,
                    },
                ),
                &a.out,
            ),
        };
        let settings = RunSettings {
            config: run.clone(),
            name: name_of(data),
            out: data.clone(),
            command: command_line(),
        };
        let pb = bar(run.steps as u64, "training");
        // without a terminal (logs, CI) the bar is hidden: print a line now and then instead
        let quiet = !std::io::IsTerminal::is_terminal(&std::io::stderr());
        let started = std::time::Instant::now();
        let mut progress = |step: usize, loss: f64| {
            pb.set_position(step as u64);
            if step.is_multiple_of(10) {
                pb.set_message(format!("loss {loss:.4}"));
            }
            if quiet && (step.is_multiple_of(run.eval_every) || step == run.steps) {
                eprintln!(
                    "step {step}/{}: loss {loss:.4} ({:.0} s)",
                    run.steps,
                    started.elapsed().as_secs_f64()
                );
            }
        };
        let trained = match cmd {
            Autoencoder::Swae(a) => {
                learn_swae(&settings, &a.data, a.val_fraction, device, &mut progress)?
            }
            Autoencoder::Patch(a) => learn_patch(
                &settings,
                &PatchSettings {
                    train_worlds: a.worlds,
                    val_worlds: a.val_worlds,
                    validation_patches: a.val_patches,
                    height_scale: a.height_scale,
                    seed: a.train.seed,
                },
                device,
                &mut progress,
            )?,
        };
        pb.finish_and_clear();
        report(&trained);
        Ok(())
    }
}
