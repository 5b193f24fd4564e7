//! Sliced-Wasserstein autoencoder training (Kolouri et al.; Verti-Bench's BenchGen and
//! BenchElev), as one readable loop.
//!
//! Loss per mini-batch of M inputs x_m with codes z_m = enc(x_m):
//!
//!   MSE(dec(z), x) + L1(dec(z), x) + λ · (1 / (L M)) Σ_l Σ_m (sort(θ_l·z)_m − sort(θ_l·z̃)_m)²
//!
//! with z̃_m ~ N(0, I) and L random unit directions θ_l: the Monte-Carlo sliced W₂² between the
//! codes and the prior (in one dimension optimal transport matches sorted samples). Sampling
//! z ~ N(0, I) and decoding then generates new inputs.

use crate::train::seq::{Act, SeqNet, values};
use crate::{LayerSpec, Shape};
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use std::time::Instant;
use verti_core::Rng;

/// Settings of one training run.
#[derive(Clone, Debug)]
pub struct SwaeConfig {
    /// Side of the square single-channel inputs (a power of two).
    pub side: usize,
    /// Channels of the stride-2 convolutions, first to last; each halves the side.
    pub widths: Vec<usize>,
    pub latent: usize,
    pub steps: usize,
    pub batch: usize,
    /// Adam learning rate at the start; it decays along a cosine to `lr_final`.
    pub lr: f64,
    pub lr_final: f64,
    /// Random projections of the sliced-Wasserstein term.
    pub projections: usize,
    /// λ, the weight of the sliced-Wasserstein term.
    pub swd_weight: f64,
    pub seed: u64,
    /// Validation every this many steps (and at the end).
    pub eval_every: usize,
}

/// Slope of the LeakyReLUs (PyTorch's default, as Verti-Bench).
pub const SLOPE: f32 = 0.01;

impl SwaeConfig {
    /// Checks the settings, naming the bad one.
    pub fn validate(&self) -> Result<(), String> {
        let down = 1usize << self.widths.len();
        if self.widths.is_empty() || !self.side.is_power_of_two() || self.side < 2 * down {
            return Err(format!(
                "side {} must be a power of two at least 2^{} for {} stride-2 layers",
                self.side,
                self.widths.len() + 1,
                self.widths.len()
            ));
        }
        for (name, v) in [
            ("latent", self.latent),
            ("steps", self.steps),
            ("batch", self.batch),
            ("projections", self.projections),
            ("eval_every", self.eval_every),
        ] {
            if v == 0 {
                return Err(format!("{name} must be at least 1"));
            }
        }
        if self.batch < 2 {
            return Err("batch must be at least 2 (the Wasserstein term compares samples)".into());
        }
        if !(self.lr > 0.0 && self.lr_final > 0.0 && self.lr_final <= self.lr) {
            return Err(format!(
                "learning rates must satisfy 0 < lr_final <= lr, got lr {} lr_final {}",
                self.lr, self.lr_final
            ));
        }
        if !(self.swd_weight >= 0.0 && self.swd_weight.is_finite()) {
            return Err(format!("swd_weight {} must be >= 0", self.swd_weight));
        }
        Ok(())
    }

    /// Encoder: stride-2 3x3 convolutions with LeakyReLU, flatten, linear to the latent.
    pub fn encoder_layers(&self) -> Vec<LayerSpec> {
        let mut layers = Vec::new();
        let mut channels = 1;
        for &w in &self.widths {
            layers.push(LayerSpec::Conv2d {
                in_channels: channels,
                out_channels: w,
                kernel: 3,
                stride: 2,
                padding: 1,
            });
            layers.push(LayerSpec::LeakyRelu { slope: SLOPE });
            channels = w;
        }
        let k = self.side >> self.widths.len();
        layers.push(LayerSpec::Flatten);
        layers.push(LayerSpec::Linear {
            inputs: channels * k * k,
            outputs: self.latent,
        });
        layers
    }

    /// Decoder: linear to the smallest feature map, transposed stride-2 convolutions back to
    /// the input side, and a last 3x3 convolution to one channel with a linear output (inputs
    /// are standardised, so no squashing is needed).
    pub fn decoder_layers(&self) -> Vec<LayerSpec> {
        let k = self.side >> self.widths.len();
        let last = *self.widths.last().expect("validated: widths not empty");
        let mut layers = vec![
            LayerSpec::Linear {
                inputs: self.latent,
                outputs: last * k * k,
            },
            LayerSpec::LeakyRelu { slope: SLOPE },
            LayerSpec::Reshape {
                shape: [last, k, k],
            },
        ];
        let mut channels = last;
        let mut outs: Vec<usize> = self.widths.iter().rev().skip(1).copied().collect();
        outs.push(self.widths[0]);
        for w in outs {
            layers.push(LayerSpec::ConvTranspose2d {
                in_channels: channels,
                out_channels: w,
                kernel: 3,
                stride: 2,
                padding: 1,
                output_padding: 1,
            });
            layers.push(LayerSpec::LeakyRelu { slope: SLOPE });
            channels = w;
        }
        layers.push(LayerSpec::Conv2d {
            in_channels: channels,
            out_channels: 1,
            kernel: 3,
            stride: 1,
            padding: 1,
        });
        layers
    }

    pub fn input_shape(&self) -> Shape {
        Shape::Image([1, self.side, self.side])
    }

    /// Learning rate at `step` (cosine decay from `lr` to `lr_final`).
    pub fn lr_at(&self, step: usize) -> f64 {
        let progress = step as f64 / self.steps.max(1) as f64;
        self.lr_final
            + 0.5 * (self.lr - self.lr_final) * (1.0 + (std::f64::consts::PI * progress).cos())
    }
}

/// The two halves, trained together.
#[derive(Module, Debug)]
pub struct Swae {
    pub encoder: SeqNet,
    pub decoder: SeqNet,
}

/// Where training batches come from: `batch` standardised inputs of side x side, flattened.
pub trait BatchSource {
    fn sample(&mut self, rng: &mut Rng, batch: usize) -> Vec<f32>;
}

/// One point of the learning curve.
#[derive(Clone, Copy, Debug)]
pub struct CurvePoint {
    pub step: usize,
    /// Training loss (mean over the steps since the previous point).
    pub train_loss: f64,
    /// Validation reconstruction MSE (standardised units).
    pub val_mse: f64,
    /// Sliced W₂² between validation codes and the prior.
    pub val_swd: f64,
}

/// What a run produced besides the weights.
#[derive(Clone, Debug)]
pub struct SwaeReport {
    pub curve: Vec<CurvePoint>,
    pub wall_time_s: f64,
    /// Mean and standard deviation of each latent dimension over the validation codes.
    pub latent_mean: Vec<f64>,
    pub latent_std: Vec<f64>,
}

/// A batch of flattened inputs as a tensor [n, 1, side, side].
fn images(data: Vec<f32>, side: usize, device: &Device) -> Tensor<4> {
    let n = data.len() / (side * side);
    Tensor::from_data(TensorData::new(data, [n, 1, side, side]), device)
}

fn gaussian(rng: &mut Rng, shape: [usize; 2], device: &Device) -> Tensor<2> {
    let v: Vec<f32> = (0..shape[0] * shape[1])
        .map(|_| rng.normal() as f32)
        .collect();
    Tensor::from_data(TensorData::new(v, shape), device)
}

/// L random unit directions in the latent space, as the columns of a [latent, L] matrix.
fn directions(rng: &mut Rng, latent: usize, count: usize, device: &Device) -> Tensor<2> {
    let mut v = vec![0f32; latent * count];
    for l in 0..count {
        let d: Vec<f64> = (0..latent).map(|_| rng.normal()).collect();
        let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
        for (i, x) in d.iter().enumerate() {
            v[i * count + l] = (x / norm) as f32;
        }
    }
    Tensor::from_data(TensorData::new(v, [latent, count]), device)
}

/// Monte-Carlo sliced W₂² between two equally sized sample sets [M, latent].
pub fn sliced_w2(a: Tensor<2>, b: Tensor<2>, dirs: Tensor<2>) -> Tensor<1> {
    let pa = a.matmul(dirs.clone()).sort(0);
    let pb = b.matmul(dirs).sort(0);
    (pa - pb).powi_scalar(2).mean()
}

/// Trains a SWAE on batches from `train`, validating on `val` (flattened standardised inputs).
/// `progress(step, loss)` is called after every step.
pub fn train(
    cfg: &SwaeConfig,
    train_data: &mut dyn BatchSource,
    val: &[f32],
    device: &Device,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<(Swae, SwaeReport), String> {
    cfg.validate()?;
    let started = Instant::now();
    let mut rng = Rng::derive(cfg.seed, "swae-train", 0);
    device.seed(cfg.seed);
    let mut model = Swae {
        encoder: SeqNet::new(cfg.input_shape(), &cfg.encoder_layers(), device)?,
        decoder: SeqNet::new(Shape::Flat(cfg.latent), &cfg.decoder_layers(), device)?,
    };
    let mut optim = AdamConfig::new().init();
    let mut curve = Vec::new();
    let mut loss_sum = 0.0;
    let mut loss_steps = 0;
    for step in 1..=cfg.steps {
        // 1. a mini-batch and its reconstruction
        let x = images(train_data.sample(&mut rng, cfg.batch), cfg.side, device);
        let z = model.encoder.forward(Act::Image(x.clone())).flat();
        let x_hat = model.decoder.forward(Act::Flat(z.clone())).image();
        // 2. reconstruction: MSE + L1
        let diff = x_hat - x;
        let recon = diff.clone().powi_scalar(2).mean() + diff.abs().mean();
        // 3. sliced Wasserstein distance from the codes to N(0, I) samples
        let prior = gaussian(&mut rng, [cfg.batch, cfg.latent], device);
        let dirs = directions(&mut rng, cfg.latent, cfg.projections, device);
        let swd = sliced_w2(z, prior, dirs);
        let loss = recon + swd.mul_scalar(cfg.swd_weight);
        // 4. one Adam step at the scheduled rate
        let loss_value = f64::from(values(loss.clone())[0]);
        if !loss_value.is_finite() {
            return Err(format!(
                "training diverged at step {step} (loss {loss_value})"
            ));
        }
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optim.step(cfg.lr_at(step - 1), model, grads);
        loss_sum += loss_value;
        loss_steps += 1;
        progress(step, loss_value);
        // 5. validation now and then
        if step % cfg.eval_every == 0 || step == cfg.steps {
            let (val_mse, val_swd, _) = evaluate(&model, cfg, val, device);
            curve.push(CurvePoint {
                step,
                train_loss: loss_sum / loss_steps as f64,
                val_mse,
                val_swd,
            });
            loss_sum = 0.0;
            loss_steps = 0;
        }
    }
    let (_, _, codes) = evaluate(&model, cfg, val, device);
    let (latent_mean, latent_std) = column_stats(&codes, cfg.latent);
    Ok((
        model,
        SwaeReport {
            curve,
            wall_time_s: started.elapsed().as_secs_f64(),
            latent_mean,
            latent_std,
        },
    ))
}

/// Validation reconstruction MSE, sliced W₂² of the codes against prior samples (fixed seed),
/// and the codes themselves (row-major [n, latent]).
pub fn evaluate(
    model: &Swae,
    cfg: &SwaeConfig,
    val: &[f32],
    device: &Device,
) -> (f64, f64, Vec<f32>) {
    let per = cfg.side * cfg.side;
    let n = val.len() / per;
    let (mut se, mut codes) = (0.0, Vec::with_capacity(n * cfg.latent));
    for chunk in val.chunks(per * 64) {
        let x = images(chunk.to_vec(), cfg.side, device);
        let z = model.encoder.forward(Act::Image(x.clone())).flat();
        let x_hat = model.decoder.forward(Act::Flat(z.clone())).image();
        se += f64::from(values((x_hat - x).powi_scalar(2).sum())[0]);
        codes.extend(values(z));
    }
    let mut rng = Rng::derive(cfg.seed, "swae-validation", 0);
    let z = Tensor::from_data(TensorData::new(codes.clone(), [n, cfg.latent]), device);
    let prior = gaussian(&mut rng, [n, cfg.latent], device);
    let dirs = directions(&mut rng, cfg.latent, 200, device);
    let swd = f64::from(values(sliced_w2(z, prior, dirs))[0]);
    (se / (n * per) as f64, swd, codes)
}

fn column_stats(rows: &[f32], cols: usize) -> (Vec<f64>, Vec<f64>) {
    let n = (rows.len() / cols) as f64;
    let mut mean = vec![0.0; cols];
    for r in rows.chunks_exact(cols) {
        for (m, v) in mean.iter_mut().zip(r) {
            *m += f64::from(*v) / n;
        }
    }
    let mut var = vec![0.0; cols];
    for r in rows.chunks_exact(cols) {
        for ((s, v), m) in var.iter_mut().zip(r).zip(&mean) {
            *s += (f64::from(*v) - m).powi(2) / n;
        }
    }
    (mean, var.into_iter().map(f64::sqrt).collect())
}
