//! The baselines' gradient-based adaptation to a new environment (paper §IV-C), on its
//! example points, minimising the one-step mean squared error of the predicted change:
//!
//! * `mlp`: the last layer only, 40,000 Adam steps at 5e-3;
//! * `maml`: every weight from the meta-learned start, 20,000 SGD steps at 5e-3 (the inner
//!   learning rate the paper names);
//! * `node`: every weight, 500 Adam steps (the paper gives no rate; 1e-3, the training rate).
//!
//! VertiAdaptor's adaptation is one least-squares solve (`VaModel::adapt`) and needs none of
//! this. The adapted weights come back as a plain-Rust model, scored like every other.

use super::batch::Points;
use super::fit::one_step_loss;
use super::net::{NetSpec, Stacked, VaNet};
use crate::{Method, VaModel};
use burn::module::{Module, Param};
use burn::optim::{AdamConfig, GradientsParams, SgdConfig};
use burn::tensor::{Device, Tensor};
use std::path::Path;

/// How a baseline adapts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Protocol {
    /// Every weight, with Adam (`sgd` false) or plain SGD.
    AllWeights { steps: usize, lr: f64, sgd: bool },
    /// The last layer only, with Adam, on the frozen features before it.
    LastLayer { steps: usize, lr: f64 },
}

impl Protocol {
    /// The paper's protocol for a method, with its step count multiplied by `scale`; `None`
    /// for VertiAdaptor.
    pub fn of(method: Method, scale: f64) -> Option<Protocol> {
        let steps = |n: f64| ((n * scale).round() as usize).max(1);
        match method {
            Method::Va => None,
            Method::Node => Some(Protocol::AllWeights {
                steps: steps(500.0),
                lr: 1e-3,
                sgd: false,
            }),
            Method::Mlp => Some(Protocol::LastLayer {
                steps: steps(40_000.0),
                lr: 5e-3,
            }),
            Method::Maml => Some(Protocol::AllWeights {
                steps: steps(20_000.0),
                lr: 5e-3,
                sgd: true,
            }),
        }
    }
}

/// The last layer as its own module (so the optimiser only sees it).
#[derive(Module, Debug)]
struct Last {
    layer: Stacked,
}

fn spec_of(model: &VaModel) -> NetSpec {
    let c = &model.card;
    NetSpec {
        method: c.method,
        bases: c.bases,
        hidden: c.hidden.clone(),
        elevation: c.elevation,
        semantics: c.semantics,
        dt: c.dt,
    }
}

/// `model` adapted to `examples` by `protocol`.
pub fn adapt_gradient(
    model: &VaModel,
    examples: &Points,
    protocol: Protocol,
    device: &Device,
) -> Result<VaModel, String> {
    let mut net = VaNet::from_params(spec_of(model), &model.params(), device)?;
    match protocol {
        Protocol::AllWeights { steps, lr, sgd } => {
            let mut optim = if sgd {
                SgdConfig::new().init()
            } else {
                AdamConfig::new().init()
            };
            for _ in 0..steps {
                let loss = one_step_loss(&net, examples, device);
                let grads = GradientsParams::from_grads(loss.backward(), &net);
                net = optim.step(lr, net, grads);
            }
        }
        Protocol::LastLayer { steps, lr } => {
            let t = examples.tensors(device);
            let n = examples.len();
            let features = net
                .last_hidden(t.roll_pitch, net.embed(t.terrain), t.command)
                .detach();
            let [_, width] = features.dims();
            let features = features.reshape([1, n, width]);
            let target = t.delta.reshape([1, n, crate::model::POSE_DIM]);
            let old = net.fields.pop().ok_or("the network has no layers")?;
            let mut last = Last {
                layer: Stacked {
                    w: Param::from_tensor(old.w.val().detach().require_grad()),
                    b: Param::from_tensor(old.b.val().detach().require_grad()),
                },
            };
            let mut optim = AdamConfig::new().init();
            for _ in 0..steps {
                let pred = last.layer.forward(features.clone());
                let loss: Tensor<1> = (pred - target.clone()).powi_scalar(2).mean().reshape([1]);
                let grads = GradientsParams::from_grads(loss.backward(), &last);
                last = optim.step(lr, last, grads);
            }
            net.fields.push(last.layer);
        }
    }
    VaModel::new(
        model.card.clone(),
        &net.export_params(),
        Path::new(&model.card.name),
    )
    .map_err(|e| e.to_string())
}

/// `model` adapted to `world` on the exploration drives every "once per environment" method
/// sees ([`crate::explore`]): the baselines' gradient protocol (steps × `scale`), or
/// VertiAdaptor's least-squares solve written into the card's prior coefficients. The card is
/// renamed `name` (weights `name.bin`).
#[allow(clippy::too_many_arguments)]
pub fn adapt_to_world(
    model: &VaModel,
    world: &std::sync::Arc<verti_world::World>,
    sim: std::sync::Arc<verti_sim::Sim>,
    trials: usize,
    seconds: f64,
    scale: f64,
    name: &str,
    device: &Device,
) -> Result<VaModel, String> {
    let drives = crate::explore::explore_world(world, sim, model.card.dt, trials, seconds)?;
    let encoder = verti_nn::shipped::patch_v1()?;
    let mut adapted = match Protocol::of(model.card.method, scale) {
        None => {
            let ex = crate::explore::drives_to_examples(&drives, world, model, &encoder);
            let mut m = model.clone();
            m.card.alpha_prior = model.adapt(&ex).map_err(|e| e.to_string())?;
            m
        }
        Some(p) => {
            let mut points = Points::default();
            for (latent, roll, pitch, command, delta) in
                crate::explore::drives_to_rows(&drives, world, &encoder)
            {
                points.push_raw(&latent, roll, pitch, command, &delta);
            }
            adapt_gradient(model, &points, p, device)?
        }
    };
    adapted.card.name = name.to_string();
    adapted.card.weights.file = format!("{name}.bin");
    adapted.card.summary = format!(
        "{} adapted to world {} ({} exploration drives of {seconds} s)",
        model.card.name, world.meta.name, trials
    );
    Ok(adapted)
}
