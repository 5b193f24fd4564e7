//! Training TNT's traversability network (`crate::traversability`), self-supervised from
//! exploration: every pose's slope patch is labelled with what the next second brought (the
//! largest roll or pitch, the shortfall against the commanded distance).
//!
//! The algorithm, in order: build patches and labels from the training and validation
//! datasets; initialise a three-layer fully convolutional network; for each step draw a
//! mini-batch and take one Adam step on the mean squared error of both labels (cosine
//! schedule); record validation loss now and then; export a verti-nn network whose card
//! records the data, worlds, command and metrics.

use crate::samples::Examples;
use crate::train::kino::{KinoConfig, KinoCurvePoint};
use crate::traversability::{
    CHANNELS, FIELD, LABEL_HORIZON, OUTPUTS, RISK_ANGLE, SPACING, Traversability,
};
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use verti_core::Rng;
use verti_nn::train::seq::{Act, SeqNet, values};
use verti_nn::{LayerSpec, ModelCard, Network, Shape, TrainingInfo};

/// Channels of the two hidden convolutions.
const WIDTH: usize = 8;

/// 9 × 9 slopes → 7 → 5 → 1 cell: valid convolutions only, so the trained network applies
/// unchanged to a whole map.
pub fn layers() -> Vec<LayerSpec> {
    let conv = |i, o, k| LayerSpec::Conv2d {
        in_channels: i,
        out_channels: o,
        kernel: k,
        stride: 1,
        padding: 0,
    };
    vec![
        conv(CHANNELS, WIDTH, 3),
        LayerSpec::Relu,
        conv(WIDTH, WIDTH, 3),
        LayerSpec::Relu,
        conv(WIDTH, OUTPUTS, FIELD - 4),
        LayerSpec::Flatten,
    ]
}

fn batch(ex: &Examples, idx: &[usize], device: &Device) -> (Tensor<4>, Tensor<2>) {
    let mut x = Vec::with_capacity(idx.len() * ex.dim);
    let mut y = Vec::with_capacity(idx.len() * OUTPUTS);
    for &i in idx {
        x.extend_from_slice(&ex.inputs[i * ex.dim..(i + 1) * ex.dim]);
        y.extend_from_slice(&ex.targets[i * OUTPUTS..(i + 1) * OUTPUTS]);
    }
    (
        Tensor::from_data(
            TensorData::new(x, [idx.len(), CHANNELS, FIELD, FIELD]),
            device,
        ),
        Tensor::from_data(TensorData::new(y, [idx.len(), OUTPUTS]), device),
    )
}

fn loss(net: &SeqNet, ex: &Examples, idx: &[usize], device: &Device) -> Tensor<1> {
    let (x, y) = batch(ex, idx, device);
    (net.forward(Act::Image(x)).flat() - y)
        .powi_scalar(2)
        .mean()
}

fn set_loss(net: &SeqNet, ex: &Examples, device: &Device) -> f64 {
    let all: Vec<usize> = (0..ex.len()).collect();
    let mut sum = 0.0;
    for chunk in all.chunks(4096) {
        sum += f64::from(values(loss(net, ex, chunk, device))[0]) * chunk.len() as f64;
    }
    sum / ex.len().max(1) as f64
}

/// Mean squared error of always predicting the training mean (what the network must beat).
fn constant_baseline(train: &Examples, val: &Examples) -> f64 {
    let n = train.len().max(1) as f64;
    let mut mean = [0.0f64; OUTPUTS];
    for row in train.targets.chunks_exact(OUTPUTS) {
        for (m, v) in mean.iter_mut().zip(row) {
            *m += f64::from(*v) / n;
        }
    }
    let mut sq = 0.0;
    for row in val.targets.chunks_exact(OUTPUTS) {
        for (m, v) in mean.iter().zip(row) {
            sq += (f64::from(*v) - m).powi(2);
        }
    }
    sq / (val.len().max(1) * OUTPUTS) as f64
}

/// Where and how to train.
pub struct TravRun {
    pub config: KinoConfig,
    pub name: String,
    pub out: PathBuf,
    pub data: PathBuf,
    pub val: PathBuf,
    pub dt: f64,
    pub command: String,
}

/// What training produced.
pub struct TravTrained {
    pub network: Arc<Network>,
    pub curve: Vec<KinoCurvePoint>,
    pub val_loss: f64,
    pub baseline_loss: f64,
    pub train_examples: usize,
    pub val_examples: usize,
    pub wall_time_s: f64,
}

/// Trains, checks and writes the traversability network.
pub fn learn_trav(
    run: &TravRun,
    device: &Device,
    progress: &mut dyn FnMut(usize, usize, f64),
) -> Result<TravTrained, String> {
    let cfg = &run.config;
    cfg.validate()?;
    let (train_data, val_data) = (
        crate::train::kino_command::load(&run.data, run.dt, "training")?,
        crate::train::kino_command::load(&run.val, run.dt, "validation")?,
    );
    let (train, val) = (
        train_data.traversability_examples(),
        val_data.traversability_examples(),
    );
    if train.is_empty() || val.is_empty() {
        return Err("no pose of the datasets has a full label horizon".into());
    }
    let started = Instant::now();
    // 1. the network
    device.seed(cfg.seed);
    let input = Shape::Image([CHANNELS, FIELD, FIELD]);
    let mut net = SeqNet::new(input, &layers(), device)?;
    let mut optim = AdamConfig::new().init();
    let mut rng = Rng::derive(cfg.seed, "trav-batches", 0);
    let (mut curve, mut loss_sum, mut loss_steps) = (Vec::new(), 0.0, 0);
    for step in 1..=cfg.steps {
        // 2. a mini-batch, its squared error, one Adam step
        let idx: Vec<usize> = (0..cfg.batch)
            .map(|_| rng.below(train.len() as u64) as usize)
            .collect();
        let l = loss(&net, &train, &idx, device);
        let value = f64::from(values(l.clone())[0]);
        if !value.is_finite() {
            return Err(format!("training diverged at step {step} (loss {value})"));
        }
        let grads = GradientsParams::from_grads(l.backward(), &net);
        net = optim.step(cfg.lr_at(step - 1), net, grads);
        (loss_sum, loss_steps) = (loss_sum + value, loss_steps + 1);
        progress(0, step, value);
        // 3. validation now and then
        if step % cfg.eval_every == 0 || step == cfg.steps {
            curve.push(KinoCurvePoint {
                member: 0,
                step,
                train_loss: loss_sum / loss_steps as f64,
                val_loss: set_loss(&net, &val, device),
            });
            (loss_sum, loss_steps) = (0.0, 0);
        }
    }
    let wall = started.elapsed().as_secs_f64();
    // 4. export, with what it was trained on and how well it does
    let val_loss = set_loss(&net, &val, device);
    let baseline_loss = constant_baseline(&train, &val);
    let round = |v: f64| (v * 1e4).round() / 1e4;
    let card = ModelCard {
        summary: format!(
            "TNT's traversability: slopes along and across the heading on a {FIELD} x {FIELD} \
             lattice of {SPACING} m (full scale) → [largest |roll| or |pitch| over the next \
             {LABEL_HORIZON} s / {RISK_ANGLE} rad, 1 − distance made good / commanded]"
        ),
        normalisation: "none: slopes are rise over run at full scale; labels as summarised".into(),
        training: TrainingInfo {
            data: format!(
                "{} ({:.1} h, {}) for training, {} ({:.1} h, {}) for validation: {} and {} \
                 labelled poses; never verti-100",
                run.data.display(),
                train_data.hours,
                train_data.set,
                run.val.display(),
                val_data.hours,
                val_data.set,
                train.len(),
                val.len()
            ),
            command: run.command.clone(),
            seed: cfg.seed,
            steps: cfg.steps as u64,
            wall_time_s: (wall * 10.0).round() / 10.0,
            verti_version: format!("verti {}", env!("CARGO_PKG_VERSION")),
            settings: format!(
                "Adam lr {} cosine to {}, batch {}, {} steps",
                cfg.lr, cfg.lr_final, cfg.batch, cfg.steps
            ),
        },
        metrics: BTreeMap::from([
            ("val_mse".to_string(), round(val_loss)),
            (
                "val_mse_constant_baseline".to_string(),
                round(baseline_loss),
            ),
        ]),
        ..ModelCard::new(&run.name, input, layers())
    };
    let network =
        Arc::new(Network::from_params(card, &net.export_params()).map_err(|e| e.to_string())?);
    // the benchmark's loader accepts it (fully convolutional, right shapes)
    Traversability::new(network.clone())?;
    network.save(&run.out).map_err(|e| e.to_string())?;
    Ok(TravTrained {
        network,
        curve,
        val_loss,
        baseline_loss,
        train_examples: train.len(),
        val_examples: val.len(),
        wall_time_s: wall,
    })
}
