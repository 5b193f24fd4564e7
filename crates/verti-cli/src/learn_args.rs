//! The arguments of `verti learn`'s subcommands. They live apart from the dispatch in
//! `learn_cmd` because each training module (`learn_kino`, `learn_rl`, ...) reads its own
//! arguments while `learn_cmd` calls those modules: keeping the structs here lets both import
//! them without importing each other. Built with or without the `learn` feature, as the
//! command line lists these commands either way.

use clap::Args;
use std::path::PathBuf;

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
    /// Model card to write (default crates/verti-va/models/METHOD-v1.yaml; weights, log and curve beside it).
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
    /// Benchmark: LABEL=CARD pairs, comma-separated (default: va, node, maml, mlp and va-small
    /// from crates/verti-va/models/, and va-retrained with the three ablations from
    /// results/va-bench/models/).
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
    #[arg(long, default_value = "crates/verti-va/models/maml-v1.yaml")]
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
    /// Model card to write (default crates/verti-pietra/models/METHOD-v1.yaml; networks beside it).
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
    /// Policy card to write (default crates/verti-policy/models/SYSTEM-v1.yaml; weights, curve and log beside it).
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
    /// Model card to write (default crates/verti-kino/models/MODEL-v1.yaml; networks and curve beside it).
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
    #[arg(long, default_value = "crates/verti-nn/models/swae-v1.yaml")]
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
    #[arg(long, default_value = "crates/verti-nn/models/patch-v1.yaml")]
    pub out: PathBuf,
    #[command(flatten)]
    pub train: AutoencoderArgs,
}
