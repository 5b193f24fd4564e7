//! Training the learned kinodynamic models of `verti-kino` (MPPI-6's ensemble, WMVCT's
//! roll/pitch network) on one-step examples from random-exploration datasets.
//!
//! The algorithm, in order: standardise inputs and targets with training statistics; for each
//! ensemble member, draw its own mini-batches (members differ by initialisation and data
//! order), minimise the mean squared error of the standardised targets with Adam on a cosine
//! schedule, and record the validation loss now and then; export every member as a verti-nn
//! network and the whole as a kinodynamic model card.

// the settings and results live in `kino_shared` (shared with `tal`); `kino::` stays their path
use crate::card::{KINO_FORMAT, KinoCard, KinoFile, KinoKind, KinoTraining};
use crate::features::{INPUT_DIM, OUTPUT_DIM, Standardiser, input_names};
use crate::samples::Examples;
pub use crate::train::kino_shared::{KinoConfig, KinoCurvePoint, KinoProvenance, KinoReport};
use crate::train::kino_shared::{export_network, rows};
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::Device;
use std::collections::BTreeMap;
use std::time::Instant;
use verti_core::Rng;
use verti_nn::Shape;
use verti_nn::train::seq::{Act, SeqNet, values};

/// What a network of this kind learns from one example (raw inputs, 6 target deltas): the
/// whole change for the ensemble; the *next* roll and pitch themselves for the decomposed
/// model (attitude follows from where the wheels stand, so predicting it outright does not
/// accumulate the drift that integrating predicted changes does).
fn pick_targets(kind: KinoKind, input: &[f32], delta: &[f32]) -> Vec<f32> {
    match kind {
        KinoKind::Ensemble | KinoKind::Attentive => delta.to_vec(),
        KinoKind::Decomposed => vec![input[0] + delta[4], input[1] + delta[5]],
    }
}

/// Inputs and chosen target columns, standardised.
struct Standardised {
    x: Vec<f32>,
    y: Vec<f32>,
    n: usize,
}

fn targets(kind: KinoKind, ex: &Examples) -> Vec<f32> {
    ex.inputs
        .chunks_exact(INPUT_DIM)
        .zip(ex.targets.chunks_exact(OUTPUT_DIM))
        .flat_map(|(x, d)| pick_targets(kind, x, d))
        .collect()
}

fn standardise(
    ex: &Examples,
    kind: KinoKind,
    xs: &Standardiser,
    ys: &Standardiser,
) -> Standardised {
    let mut x = ex.inputs.clone();
    for row in x.chunks_exact_mut(INPUT_DIM) {
        xs.apply(row);
    }
    let mut y = targets(kind, ex);
    for row in y.chunks_exact_mut(kind.network_outputs()) {
        ys.apply(row);
    }
    Standardised { x, y, n: ex.len() }
}

/// Mean squared error (standardised units) of a network over a whole set, in chunks.
fn set_loss(net: &SeqNet, set: &Standardised, outputs: usize, device: &Device) -> f64 {
    let mut sum = 0.0;
    let all: Vec<usize> = (0..set.n).collect();
    for chunk in all.chunks(4096) {
        let x = rows(&set.x, INPUT_DIM, chunk, device);
        let y = rows(&set.y, outputs, chunk, device);
        let d = net.forward(Act::Flat(x)).flat() - y;
        sum += f64::from(values(d.powi_scalar(2).sum())[0]);
    }
    sum / (set.n.max(1) * outputs) as f64
}

/// Trains a model on `train`, validating on `val`; `progress(member, step, loss)` after every
/// step. Attentive models (TAL) train in [`crate::train::tal`].
pub fn train(
    cfg: &KinoConfig,
    train_set: &Examples,
    val_set: &Examples,
    prov: &KinoProvenance,
    device: &Device,
    progress: &mut dyn FnMut(usize, usize, f64),
) -> Result<(KinoFile, KinoReport), String> {
    cfg.validate()?;
    if train_set.is_empty() || val_set.is_empty() {
        return Err("training and validation sets must both hold examples".into());
    }
    if cfg.kind == KinoKind::Attentive {
        return crate::train::tal::train(cfg, train_set, val_set, prov, device, progress);
    }
    let started = Instant::now();
    let outputs = cfg.kind.network_outputs();
    // 1. standardisation from the training set only
    let xs = Standardiser::fit(&train_set.inputs, INPUT_DIM);
    let ys = Standardiser::fit(&targets(cfg.kind, train_set), outputs);
    let tr = standardise(train_set, cfg.kind, &xs, &ys);
    let va = standardise(val_set, cfg.kind, &xs, &ys);
    device.seed(cfg.seed);
    let layers = cfg.layers();
    let mut members = Vec::new();
    let mut curve = Vec::new();
    for m in 0..cfg.members {
        // 2. each member: its own initialisation and batch order
        let mut rng = Rng::derive(cfg.seed, "kino-member", m as u64);
        let mut net = SeqNet::new(Shape::Flat(INPUT_DIM), &layers, device)?;
        let mut optim = AdamConfig::new().init();
        let (mut loss_sum, mut loss_steps) = (0.0, 0);
        for step in 1..=cfg.steps {
            // 3. a mini-batch, its squared error, one Adam step
            let idx: Vec<usize> = (0..cfg.batch)
                .map(|_| rng.below(tr.n as u64) as usize)
                .collect();
            let x = rows(&tr.x, INPUT_DIM, &idx, device);
            let y = rows(&tr.y, outputs, &idx, device);
            let loss = (net.forward(Act::Flat(x)).flat() - y).powi_scalar(2).mean();
            let value = f64::from(values(loss.clone())[0]);
            if !value.is_finite() {
                return Err(format!("member {m} diverged at step {step} (loss {value})"));
            }
            let grads = GradientsParams::from_grads(loss.backward(), &net);
            net = optim.step(cfg.lr_at(step - 1), net, grads);
            loss_sum += value;
            loss_steps += 1;
            progress(m, step, value);
            // 4. validation now and then
            if step % cfg.eval_every == 0 || step == cfg.steps {
                curve.push(KinoCurvePoint {
                    member: m,
                    step,
                    train_loss: loss_sum / loss_steps as f64,
                    val_loss: set_loss(&net, &va, outputs, device),
                });
                (loss_sum, loss_steps) = (0.0, 0);
            }
        }
        members.push(net);
    }
    // 5. export: one verti-nn network per member, one card for the model
    let wall = started.elapsed().as_secs_f64();
    let mut networks = Vec::new();
    let mut files = Vec::new();
    for (m, net) in members.iter().enumerate() {
        let file = format!("{}.net{m}", prov.name);
        let summary = format!("network {m} of the kinodynamic model {}", prov.name);
        networks.push(export_network(net, &file, &summary, cfg, prov, wall)?);
        files.push(format!("{file}.yaml"));
    }
    let card = KinoCard {
        name: prov.name.clone(),
        format: KINO_FORMAT,
        summary: prov.summary.clone(),
        kind: cfg.kind,
        vehicle: prov.vehicle.clone(),
        dt: prov.dt,
        inputs: input_names(),
        input_mean: xs.mean.clone(),
        input_std: xs.std.clone(),
        output_mean: ys.mean.clone(),
        output_std: ys.std.clone(),
        networks: files,
        training: KinoTraining {
            data: prov.data.clone(),
            worlds: prov.worlds.clone(),
            command: prov.command.clone(),
            seed: cfg.seed,
            steps: cfg.steps,
            wall_time_s: wall,
            verti_version: format!("verti {}", env!("CARGO_PKG_VERSION")),
            settings: format!(
                "{} member(s), hidden {:?} ReLU, Adam lr {} cosine to {}, batch {}, {} steps each",
                cfg.members, cfg.hidden, cfg.lr, cfg.lr_final, cfg.batch, cfg.steps
            ),
        },
        metrics: BTreeMap::new(),
    };
    let file = KinoFile::new(card, networks, std::path::Path::new("<trained>"))
        .map_err(|e| e.to_string())?;
    // ensemble validation loss, through the exported (verti-nn) networks on standardised data
    let exported = file
        .networks
        .iter()
        .map(|n| verti_nn::Mlp::from_network(n))
        .collect::<Result<Vec<_>, String>>()?;
    let mut sq = 0.0;
    let mut out = vec![0.0f32; outputs];
    let mut scratch = exported[0].scratch();
    for (x, y) in va.x.chunks_exact(INPUT_DIM).zip(va.y.chunks_exact(outputs)) {
        let mut mean = vec![0.0f32; outputs];
        for mlp in &exported {
            mlp.forward_into(x, &mut scratch, &mut out);
            mean.iter_mut().zip(&out).for_each(|(a, b)| *a += b);
        }
        for (a, b) in mean.iter().zip(y) {
            let e = f64::from(a / exported.len() as f32 - b);
            sq += e * e;
        }
    }
    let val_loss = sq / (va.n * outputs) as f64;
    Ok((
        file,
        KinoReport {
            curve,
            wall_time_s: wall,
            val_loss,
        },
    ))
}
