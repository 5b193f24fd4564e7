//! Training TAL's terrain-attentive model (`crate::attentive`): an elevation-map encoder,
//! a gate on its features from the vehicle's offset within the map, and a dynamics network,
//! trained end to end on one-step examples whose map was seen up to a horizon earlier.
//!
//! The algorithm, in order: standardise every input column and the targets with training
//! statistics; build the three networks; for each step draw a mini-batch, run
//! encoder → squash(gate) ⊙ features → dynamics, minimise the mean squared error of the
//! standardised change with Adam on a cosine schedule; record validation loss now and then;
//! export the three networks and one kinodynamic card.

use crate::attentive::{ATTENTIVE_INPUT_DIM, HEAD_DIM, MAP_DIM, OFFSET_DIM, attentive_input_names};
use crate::card::{KINO_FORMAT, KinoCard, KinoFile, KinoTraining};
use crate::features::{OUTPUT_DIM, Standardiser};
use crate::samples::Examples;
use crate::train::kino_shared::{
    KinoConfig, KinoCurvePoint, KinoProvenance, KinoReport, export_network, rows,
};
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor};
use std::collections::BTreeMap;
use std::time::Instant;
use verti_core::Rng;
use verti_nn::train::seq::{Act, SeqNet, mlp_layers, values};
use verti_nn::{LayerSpec, Shape};

/// Map features the encoder produces (and the gate weighs).
pub const FEATURES: usize = 32;
/// Hidden width of the encoder (run once per plan).
const ENCODER_HIDDEN: usize = 64;
/// Hidden width of the gate (run every rollout step, so kept narrow).
const GATE_HIDDEN: usize = 32;

/// The three networks, trained together.
#[derive(Module, Debug)]
pub struct TalNet {
    encoder: SeqNet,
    gate: SeqNet,
    dynamics: SeqNet,
}

fn mlp(inputs: usize, hidden: &[usize], outputs: usize, last_relu: bool) -> Vec<LayerSpec> {
    let mut layers = mlp_layers(inputs, hidden, outputs, LayerSpec::Relu);
    if last_relu {
        layers.push(LayerSpec::Relu);
    }
    layers
}

impl TalNet {
    pub fn new(cfg: &KinoConfig, device: &Device) -> Result<TalNet, String> {
        Ok(TalNet {
            encoder: SeqNet::new(
                Shape::Flat(MAP_DIM),
                &mlp(MAP_DIM, &[ENCODER_HIDDEN], FEATURES, true),
                device,
            )?,
            gate: SeqNet::new(
                Shape::Flat(OFFSET_DIM),
                &mlp(OFFSET_DIM, &[GATE_HIDDEN], FEATURES, false),
                device,
            )?,
            dynamics: SeqNet::new(
                Shape::Flat(FEATURES + HEAD_DIM),
                &mlp(FEATURES + HEAD_DIM, &cfg.hidden, OUTPUT_DIM, false),
                device,
            )?,
        })
    }

    /// Standardised change from standardised map, offset and head columns.
    pub fn forward(&self, map: Tensor<2>, offset: Tensor<2>, head: Tensor<2>) -> Tensor<2> {
        let features = self.encoder.forward(Act::Flat(map)).flat();
        // crate::attentive::squash: ½ + ½·g/(1 + |g|)
        let g = self.gate.forward(Act::Flat(offset)).flat();
        let gate = (g.clone() / (g.abs() + 1.0)) * 0.5 + 0.5;
        let x = Tensor::cat(vec![features * gate, head], 1);
        self.dynamics.forward(Act::Flat(x)).flat()
    }
}

/// Columns `from..to` of the rows `idx` of a row-major table `dim` wide.
fn columns(
    data: &[f32],
    dim: usize,
    (from, to): (usize, usize),
    idx: &[usize],
    device: &Device,
) -> Tensor<2> {
    let mut v = Vec::with_capacity(idx.len() * (to - from));
    for &i in idx {
        v.extend_from_slice(&data[i * dim + from..i * dim + to]);
    }
    Tensor::from_data(
        burn::tensor::TensorData::new(v, [idx.len(), to - from]),
        device,
    )
}

const MAP: (usize, usize) = (0, MAP_DIM);
const OFFSET: (usize, usize) = (MAP_DIM, MAP_DIM + OFFSET_DIM);
const HEAD: (usize, usize) = (MAP_DIM + OFFSET_DIM, ATTENTIVE_INPUT_DIM);

fn batch_loss(net: &TalNet, x: &[f32], y: &[f32], idx: &[usize], device: &Device) -> Tensor<1> {
    let d = ATTENTIVE_INPUT_DIM;
    let pred = net.forward(
        columns(x, d, MAP, idx, device),
        columns(x, d, OFFSET, idx, device),
        columns(x, d, HEAD, idx, device),
    );
    (pred - rows(y, OUTPUT_DIM, idx, device))
        .powi_scalar(2)
        .mean()
}

fn set_loss(net: &TalNet, x: &[f32], y: &[f32], device: &Device) -> f64 {
    let n = y.len() / OUTPUT_DIM;
    let all: Vec<usize> = (0..n).collect();
    let mut sum = 0.0;
    for chunk in all.chunks(4096) {
        sum += f64::from(values(batch_loss(net, x, y, chunk, device))[0]) * chunk.len() as f64;
    }
    sum / n.max(1) as f64
}

fn standardised(ex: &Examples, s: &Standardiser, width: usize, rows: &[f32]) -> Vec<f32> {
    debug_assert_eq!(ex.dim, ATTENTIVE_INPUT_DIM);
    let mut v = rows.to_vec();
    for row in v.chunks_exact_mut(width) {
        s.apply(row);
    }
    v
}

/// Trains an attentive model (one network set; `cfg.members` must be 1).
pub fn train(
    cfg: &KinoConfig,
    train_set: &Examples,
    val_set: &Examples,
    prov: &KinoProvenance,
    device: &Device,
    progress: &mut dyn FnMut(usize, usize, f64),
) -> Result<(KinoFile, KinoReport), String> {
    if cfg.members != 1 {
        return Err(format!(
            "an attentive model trains one network set, not {} members",
            cfg.members
        ));
    }
    for (what, ex) in [("training", train_set), ("validation", val_set)] {
        if ex.dim != ATTENTIVE_INPUT_DIM {
            return Err(format!(
                "{what} examples have {} inputs per row, an attentive model reads {ATTENTIVE_INPUT_DIM}",
                ex.dim
            ));
        }
    }
    let started = Instant::now();
    // 1. standardisation from the training set only
    let xs = Standardiser::fit(&train_set.inputs, ATTENTIVE_INPUT_DIM);
    let ys = Standardiser::fit(&train_set.targets, OUTPUT_DIM);
    let (tx, ty) = (
        standardised(train_set, &xs, ATTENTIVE_INPUT_DIM, &train_set.inputs),
        standardised(train_set, &ys, OUTPUT_DIM, &train_set.targets),
    );
    let (vx, vy) = (
        standardised(val_set, &xs, ATTENTIVE_INPUT_DIM, &val_set.inputs),
        standardised(val_set, &ys, OUTPUT_DIM, &val_set.targets),
    );
    // 2. the three networks
    device.seed(cfg.seed);
    let mut net = TalNet::new(cfg, device)?;
    let mut optim = AdamConfig::new().init();
    let mut rng = Rng::derive(cfg.seed, "tal-batches", 0);
    let n = train_set.len();
    let (mut curve, mut loss_sum, mut loss_steps) = (Vec::new(), 0.0, 0);
    for step in 1..=cfg.steps {
        // 3. a mini-batch, its squared error, one Adam step
        let idx: Vec<usize> = (0..cfg.batch)
            .map(|_| rng.below(n as u64) as usize)
            .collect();
        let loss = batch_loss(&net, &tx, &ty, &idx, device);
        let value = f64::from(values(loss.clone())[0]);
        if !value.is_finite() {
            return Err(format!("training diverged at step {step} (loss {value})"));
        }
        let grads = GradientsParams::from_grads(loss.backward(), &net);
        net = optim.step(cfg.lr_at(step - 1), net, grads);
        loss_sum += value;
        loss_steps += 1;
        progress(0, step, value);
        // 4. validation now and then
        if step % cfg.eval_every == 0 || step == cfg.steps {
            curve.push(KinoCurvePoint {
                member: 0,
                step,
                train_loss: loss_sum / loss_steps as f64,
                val_loss: set_loss(&net, &vx, &vy, device),
            });
            (loss_sum, loss_steps) = (0.0, 0);
        }
    }
    // 5. export: encoder, gate, dynamics, and the card
    let wall = started.elapsed().as_secs_f64();
    let mut networks = Vec::new();
    let mut files = Vec::new();
    for (part, seq) in [
        ("encoder", &net.encoder),
        ("gate", &net.gate),
        ("dynamics", &net.dynamics),
    ] {
        let file = format!("{}.{part}", prov.name);
        let summary = format!("the {part} of the terrain-attentive model {}", prov.name);
        networks.push(export_network(seq, &file, &summary, cfg, prov, wall)?);
        files.push(format!("{file}.yaml"));
    }
    let val_loss = set_loss(&net, &vx, &vy, device);
    let card = KinoCard {
        name: prov.name.clone(),
        format: KINO_FORMAT,
        summary: prov.summary.clone(),
        kind: cfg.kind,
        vehicle: prov.vehicle.clone(),
        dt: prov.dt,
        inputs: attentive_input_names(),
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
                "encoder [{MAP_DIM}-{ENCODER_HIDDEN}-{FEATURES}] ReLU, gate [{OFFSET_DIM}-{GATE_HIDDEN}-{FEATURES}] \
                 softsign squash, dynamics hidden {:?} ReLU; Adam lr {} cosine to {}, batch {}, {} steps",
                cfg.hidden, cfg.lr, cfg.lr_final, cfg.batch, cfg.steps
            ),
        },
        metrics: BTreeMap::new(),
    };
    let file = KinoFile::new(card, networks, std::path::Path::new("<trained>"))
        .map_err(|e| e.to_string())?;
    Ok((
        file,
        KinoReport {
            curve,
            wall_time_s: wall,
            val_loss,
        },
    ))
}
