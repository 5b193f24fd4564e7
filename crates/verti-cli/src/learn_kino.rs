//! `verti learn kino` (with the `learn` feature): trains a learned kinodynamic model.

use crate::learn_args::KinoArgs;
use crate::progress::bar;
use std::path::PathBuf;
use verti_kino::KinoKind;
use verti_kino::features::OUTPUT_NAMES;
use verti_kino::train::kino::KinoConfig;
use verti_kino::train::kino_command::{KinoRun, draw_curve, learn_kino};
use verti_kino::train::trav::{TravRun, learn_trav};
use verti_nn::train::Device;

/// Progress of a training run: the bar, and plain lines every `eval_every` steps where
/// stderr is not a terminal (logs of long runs).
fn reporter<'a>(
    pb: &'a indicatif::ProgressBar,
    config: &'a KinoConfig,
) -> impl FnMut(usize, usize, f64) + 'a {
    let quiet = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let started = std::time::Instant::now();
    move |member: usize, step: usize, loss: f64| {
        pb.set_position((member * config.steps + step) as u64);
        if step.is_multiple_of(10) {
            pb.set_message(format!("member {member} loss {loss:.4}"));
        }
        if quiet && (step.is_multiple_of(config.eval_every) || step == config.steps) {
            eprintln!(
                "member {member} step {step}/{}: loss {loss:.4} ({:.0} s)",
                config.steps,
                started.elapsed().as_secs_f64()
            );
        }
    }
}

fn config_of(a: &KinoArgs, kind: KinoKind, members: usize) -> KinoConfig {
    KinoConfig {
        kind,
        members: a.members.unwrap_or(members),
        hidden: a.hidden.clone(),
        steps: a.steps,
        batch: a.batch,
        lr: a.lr,
        lr_final: a.lr_final,
        seed: a.seed,
        eval_every: a.eval_every,
    }
}

/// `--model tnt`: TNT's traversability network (its dynamics are TAL's model, tal-v1).
fn run_trav(a: &KinoArgs, command: &str, device: &Device) -> Result<(), String> {
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("crates/verti-kino/models/tnt-v1.yaml"));
    let name = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("tnt-v1")
        .to_string();
    let config = config_of(a, KinoKind::Ensemble, 1);
    let run = TravRun {
        config: config.clone(),
        name,
        out,
        data: a.data.clone(),
        val: a.val.clone(),
        dt: a.dt,
        command: command.into(),
    };
    let pb = bar(config.steps as u64, "training");
    let t = learn_trav(&run, device, &mut reporter(&pb, &config))?;
    pb.finish_and_clear();
    println!(
        "{}: {} training / {} validation patches; validation MSE {:.4} (predicting the \
         training mean: {:.4}); {:.0} s",
        t.network.card().name,
        t.train_examples,
        t.val_examples,
        t.val_loss,
        t.baseline_loss,
        t.wall_time_s
    );
    let curve = run
        .out
        .with_file_name(format!("{}-curve.png", t.network.card().name));
    draw_curve(&t.curve, &t.network.card().name, &curve)?;
    println!(
        "wrote {}, learning curve {}",
        run.out.display(),
        curve.display()
    );
    Ok(())
}

pub fn run(a: &KinoArgs, command: &str, device: &Device) -> Result<(), String> {
    if a.model == "tnt" {
        return run_trav(a, command, device);
    }
    let (kind, members, summary) = match a.model.as_str() {
        "mppi6" => (
            KinoKind::Ensemble,
            // two members of 32 cost what three of 24 do and predict better (README)
            2,
            "MPPI-6's model: an ensemble of MLPs predicting the full 6-DoF pose change over one \
             step from attitude, pose rates, command and the terrain under and ahead",
        ),
        "tal" => (
            KinoKind::Attentive,
            1,
            "TAL's model: a heading-aligned elevation map around the vehicle encoded once per \
             plan, its features gated by the vehicle's offset within the map, and a dynamics \
             network predicting the 6-DoF change from gated features, attitude, rates and command",
        ),
        _ => (
            KinoKind::Decomposed,
            1,
            "WMVCT's model: a kinematic bicycle for forward, left and yaw, the terrain height \
             for z, and an MLP for the next roll and pitch",
        ),
    };
    let name = format!("{}-v1", a.model);
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("crates/verti-kino/models/{name}.yaml")));
    let name = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or(&name)
        .to_string();
    let config = config_of(a, kind, members);
    let run = KinoRun {
        geometry: crate::kino_cmd::geometry_of(&a.data)?,
        config: config.clone(),
        name,
        out,
        data: a.data.clone(),
        val: a.val.clone(),
        dt: a.dt,
        horizon: a.horizon,
        summary: summary.into(),
        command: command.into(),
    };
    let pb = bar((config.steps * config.members) as u64, "training");
    let mut progress = reporter(&pb, &config);
    let t = learn_kino(&run, device, &mut progress)?;
    pb.finish_and_clear();
    println!(
        "{}: {} training / {} validation examples; validation MSE (standardised) {:.4}",
        t.file.card.name, t.train_examples, t.val_examples, t.report.val_loss
    );
    for acc in &t.accuracy {
        for (label, e) in [("1 step", &acc.one_step[0]), ("multi", &acc.multi_step[0])] {
            let r = e.rmse();
            let cells: Vec<String> = OUTPUT_NAMES
                .iter()
                .zip(r)
                .map(|(n, v)| format!("{n} {v:.3}"))
                .collect();
            println!("  {:>10} {label:>6}: {}", acc.predictor, cells.join(", "));
        }
    }
    println!(
        "wrote {} (+ {} network(s)), learning curve {}; {:.0} s",
        run.out.display(),
        t.file.networks.len(),
        t.curve_png.display(),
        t.report.wall_time_s
    );
    Ok(())
}
