//! Training VertiAdaptor (Algorithm 1) and its baselines, each step visible in order.
//!
//! Per step, for `va`:
//! 1. draw F environments and N trajectories in each (the first N_ex examples, the rest
//!    queries), 256 one-step example points per environment, S rollout starts per query;
//! 2. per environment, the basis changes at its example points and the least-squares
//!    coefficients α^(f) = (G + λI)⁻¹F (gradients flow through the solve);
//! 3. roll every query out T_pred steps from its true start with the true commands and
//!    terrain, x̂_t = x̂_{t−1} ⊕ Σ_i α_i G_i(x̂_{t−1}), and average ‖x̂_t − x_t‖² (the
//!    paper sums; the mean only rescales the learning rate);
//! 4. one Adam step (gradient norm clipped to 1, as the function-encoder libraries do), the
//!    learning rate annealed from 1e-3 to 1e-5 over the run (cosine).
//!
//! `node` is the same with one field and α = 1; `mlp` minimises the one-step error of one
//! network predicting the change; `maml` is first-order MAML of that network (one inner SGD
//! step on an environment's examples, the query loss at the adapted weights, the gradients
//! of all environments averaged into one Adam step of the initial weights).

use super::batch::{Draw, Rollouts, Sampling, draw, environments};
use super::net::{NetSpec, VaNet, coefficients, combine};
use crate::Method;
use crate::data::VaData;
use crate::model::{EMBED, POSE_DIM};
use crate::terrain::TERRAIN_DIM;
use burn::grad_clipping::GradientClippingConfig;
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsAccumulator, GradientsParams, SgdConfig};
use burn::tensor::{Device, Tensor, TensorData};
use std::time::Instant;
use verti_core::Rng;
use verti_nn::train::seq::values;

/// Training settings (defaults: the paper's Table I).
#[derive(Clone, Debug, PartialEq)]
pub struct TrainConfig {
    pub spec: NetSpec,
    pub sampling: Sampling,
    pub steps: usize,
    pub lr: f64,
    pub lr_final: f64,
    pub lambda: f64,
    /// First-order MAML's inner learning rate (one SGD step).
    pub maml_inner_lr: f64,
    pub seed: u64,
    /// Validation every this many steps (and at the end).
    pub eval_every: usize,
}

impl TrainConfig {
    pub fn lr_at(&self, step: usize) -> f64 {
        let progress = step as f64 / self.steps.max(1) as f64;
        self.lr_final
            + 0.5 * (self.lr - self.lr_final) * (1.0 + (std::f64::consts::PI * progress).cos())
    }
    pub fn validate(&self) -> Result<(), String> {
        let s = &self.sampling;
        if self.steps == 0
            || s.envs == 0
            || s.horizon == 0
            || s.rollouts == 0
            || s.example_points == 0
        {
            return Err(
                "steps, environments, horizon, rollouts and example points must be at least 1"
                    .into(),
            );
        }
        if s.examples == 0 || s.examples >= s.trajectories {
            return Err(format!(
                "{} example trajectories of {}: need at least one example and one query",
                s.examples, s.trajectories
            ));
        }
        if !(self.lr > 0.0 && self.lr_final > 0.0 && self.lr_final <= self.lr) {
            return Err(format!(
                "learning rates must satisfy 0 < lr_final <= lr, got {} and {}",
                self.lr, self.lr_final
            ));
        }
        if self.spec.method != Method::Va && self.spec.bases != 1 {
            return Err(format!(
                "{} has one network; --bases {} applies to va only",
                self.spec.method.name(),
                self.spec.bases
            ));
        }
        Ok(())
    }
}

/// A row of the training log.
#[derive(Clone, Debug, PartialEq)]
pub struct LogRow {
    pub step: usize,
    pub train_loss: f64,
    /// The method's own loss on a fixed draw from the validation data.
    pub val_loss: f64,
}

pub struct Trained {
    pub net: VaNet,
    pub log: Vec<LogRow>,
    pub wall_s: f64,
}

fn tensor2(v: &[f32], dims: [usize; 2], device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(v.to_vec(), dims), device)
}

/// Mean squared error of open-loop rollouts; `alpha` [B, k] holds each rollout's coefficients.
pub fn rollout_loss(net: &VaNet, r: &Rollouts, alpha: Tensor<2>, device: &Device) -> Tensor<1> {
    let (b, horizon) = (r.count, r.horizon);
    let embedding = net
        .embed(tensor2(&r.terrain, [b * horizon, TERRAIN_DIM], device))
        .reshape([b, horizon, 2 * EMBED]);
    let command = tensor2(&r.command, [b * horizon, 2], device).reshape([b, horizon, 2]);
    let target =
        tensor2(&r.target, [b * horizon, POSE_DIM], device).reshape([b, horizon, POSE_DIM]);
    let start = tensor2(&r.start_roll_pitch, [b, 2], device);
    // the predicted pose relative to the start: x, y, z, yaw, roll and pitch changes
    let zeros = || Tensor::<2>::zeros([b, 1], device);
    let (mut x, mut y, mut z, mut yaw) = (zeros(), zeros(), zeros(), zeros());
    let mut attitude = Tensor::<2>::zeros([b, 2], device);
    let mut loss = Tensor::<1>::zeros([1], device);
    for t in 0..horizon {
        let at = |v: &Tensor<3>, w: usize| v.clone().narrow(1, t, 1).reshape([b, w]);
        let g = net.basis_changes(
            start.clone() + attitude.clone(),
            at(&embedding, 2 * EMBED),
            at(&command, 2),
        );
        let d = combine(g, alpha.clone());
        let col = |i: usize| d.clone().narrow(1, i, 1);
        let (c, s) = (yaw.clone().cos(), yaw.clone().sin());
        x = x + c.clone() * col(0) - s.clone() * col(1);
        y = y + s * col(0) + c * col(1);
        z = z + col(2);
        yaw = yaw + col(3);
        attitude = attitude + d.clone().narrow(1, 4, 2);
        let pred = Tensor::cat(
            vec![
                x.clone(),
                y.clone(),
                z.clone(),
                yaw.clone(),
                attitude.clone(),
            ],
            1,
        );
        loss = loss
            + (pred - at(&target, POSE_DIM))
                .powi_scalar(2)
                .mean()
                .reshape([1]);
    }
    loss / horizon as f64
}

/// Mean squared one-step error of a network (its single basis, α = 1) on points.
pub fn one_step_loss(net: &VaNet, p: &super::batch::Points, device: &Device) -> Tensor<1> {
    let t = p.tensors(device);
    let n = p.len();
    let g = net.basis_changes(t.roll_pitch, net.embed(t.terrain), t.command);
    let ones = Tensor::<2>::ones([n, net.spec.bases], device);
    (combine(g, ones) - t.delta)
        .powi_scalar(2)
        .mean()
        .reshape([1])
}

/// Each query's coefficients [B, k]: least squares on its environment's examples for `va`,
/// 1 for `node`.
fn query_coefficients(
    net: &VaNet,
    d: &Draw,
    lambda: f64,
    device: &Device,
) -> Result<Tensor<2>, String> {
    let k = net.spec.bases;
    if net.spec.method != Method::Va {
        return Ok(Tensor::ones([d.queries.count, k], device));
    }
    let mut per_env = Vec::with_capacity(d.examples.len());
    for ex in &d.examples {
        let t = ex.tensors(device);
        let g = net.basis_changes(t.roll_pitch, net.embed(t.terrain), t.command);
        per_env.push(coefficients(g, t.delta, lambda)?.reshape([1, k]));
    }
    let rows: Vec<Tensor<2>> = d.env_of_query.iter().map(|&f| per_env[f].clone()).collect();
    Ok(Tensor::cat(rows, 0))
}

/// The method's loss on one draw (for `maml`, the query loss without adaptation; its
/// training step is `maml_step`).
pub fn draw_loss(net: &VaNet, d: &Draw, lambda: f64, device: &Device) -> Result<Tensor<1>, String> {
    match net.spec.method {
        Method::Va | Method::Node => {
            let alpha = query_coefficients(net, d, lambda, device)?;
            Ok(rollout_loss(net, &d.queries, alpha, device))
        }
        Method::Mlp | Method::Maml => {
            let mut all = d.query_points.clone();
            for ex in &d.examples {
                all.extend(ex);
            }
            Ok(one_step_loss(net, &all, device))
        }
    }
}

/// First-order MAML: per environment, one SGD step on its examples, then the gradient of the
/// query loss at the adapted weights; the environments' gradients are averaged.
fn maml_step(net: &VaNet, d: &Draw, inner_lr: f64, device: &Device) -> (f64, GradientsParams) {
    let mut acc = GradientsAccumulator::<VaNet>::new();
    let mut total = 0.0;
    let envs = d.examples.len();
    let horizon = d.queries.horizon;
    for (f, ex) in d.examples.iter().enumerate() {
        let inner = one_step_loss(net, ex, device);
        let grads = GradientsParams::from_grads(inner.backward(), net);
        let mut sgd = SgdConfig::new().init();
        // the adapted weights start a new graph: first-order MAML ignores second derivatives
        let adapted = sgd.step(inner_lr, net.clone(), grads);
        let mut q = super::batch::Points::default();
        for (j, &e) in d.env_of_query.iter().enumerate() {
            if e == f {
                q.extend(&d.query_points.slice(j * horizon, (j + 1) * horizon));
            }
        }
        let outer = one_step_loss(&adapted, &q, device) / envs as f64;
        total += f64::from(values(outer.clone())[0]);
        acc.accumulate(
            &adapted,
            GradientsParams::from_grads(outer.backward(), &adapted),
        );
    }
    (total, acc.grads())
}

/// Trains `cfg.spec` on `data`; `val` (other worlds) is scored every `eval_every` steps.
/// `progress` hears (step, training loss).
pub fn train(
    data: &VaData,
    val: &VaData,
    cfg: &TrainConfig,
    device: &Device,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<Trained, String> {
    cfg.validate()?;
    let started = Instant::now();
    let envs = environments(data, cfg.sampling.horizon);
    let val_envs = environments(val, cfg.sampling.horizon);
    if envs.is_empty() || val_envs.is_empty() {
        return Err(format!(
            "no trajectory of {} steps or more in the {} data",
            cfg.sampling.horizon + 1,
            if envs.is_empty() {
                "training"
            } else {
                "validation"
            }
        ));
    }
    let mut rng = Rng::derive(cfg.seed, "va-batches", 0);
    let val_draws: Vec<Draw> = {
        let mut vr = Rng::derive(cfg.seed, "va-validation", 0);
        (0..4)
            .map(|_| draw(val, &val_envs, &cfg.sampling, &mut vr))
            .collect()
    };
    let mut net = VaNet::new(cfg.spec.clone(), cfg.seed, device);
    let mut optim = AdamConfig::new()
        .with_grad_clipping(Some(GradientClippingConfig::Norm(1.0)))
        .init();
    let mut log = Vec::new();
    let mut recent = Vec::new();
    for step in 0..cfg.steps {
        // 1. the draw; 2.–3. the method's loss; 4. one Adam step
        let d = draw(data, &envs, &cfg.sampling, &mut rng);
        let (loss, grads) = if cfg.spec.method == Method::Maml {
            maml_step(&net, &d, cfg.maml_inner_lr, device)
        } else {
            let l = draw_loss(&net, &d, cfg.lambda, device)?;
            let v = f64::from(values(l.clone())[0]);
            (v, GradientsParams::from_grads(l.backward(), &net))
        };
        if !loss.is_finite() {
            return Err(format!(
                "{} diverged at step {step} (loss {loss})",
                cfg.spec.method.name()
            ));
        }
        net = optim.step(cfg.lr_at(step), net, grads);
        recent.push(loss);
        progress(step + 1, loss);
        if (step + 1) % cfg.eval_every == 0 || step + 1 == cfg.steps {
            let mut val_loss = 0.0;
            for vd in &val_draws {
                let l = draw_loss(&net.clone().no_grad(), vd, cfg.lambda, device)?;
                val_loss += f64::from(values(l)[0]) / val_draws.len() as f64;
            }
            log.push(LogRow {
                step: step + 1,
                train_loss: recent.iter().sum::<f64>() / recent.len() as f64,
                val_loss,
            });
            recent.clear();
        }
    }
    Ok(Trained {
        net,
        log,
        wall_s: started.elapsed().as_secs_f64(),
    })
}
