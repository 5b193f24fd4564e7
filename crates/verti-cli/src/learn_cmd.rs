//! `verti learn`: trains the models that ship in the family crates' `models/` folders.
//! Training needs burn, which only
//! builds with the `learn` feature (`cargo build --release -p verti-cli --features learn`), so
//! the classical benchmark never pays for it; without the feature these commands explain how
//! to get it.

use crate::learn_args::{CurvesArgs, KinoArgs, PatchArgs, PietraArgs, RlArgs, SwaeArgs, VaArgs};
use clap::Subcommand;

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
    use crate::learn_args::AutoencoderArgs;
    use crate::progress::bar;
    use verti_nn::train::commands::{RunSettings, Trained, learn_patch, learn_swae};
    use verti_nn::train::patches::PatchSettings;
    use verti_nn::train::swae::SwaeConfig;

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
        let device = verti_nn::train::device();
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

    fn run_autoencoder(cmd: Autoencoder, device: &verti_nn::train::Device) -> Result<(), String> {
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
