//! A trained driving policy: the actor network of a Gaussian policy, read from a verti-nn
//! model card whose constants hold the Gaussian's log standard deviations.
//!
//! The network maps [`crate::inputs::policy_input`] to the mean action (target speed,
//! steering), both normalised to [-1, 1] as the environment's action space; the benchmark
//! drives the mean (clipped), as Stable-Baselines3's `predict(deterministic=True)` does.

use crate::inputs::INPUT_DIM;
use std::path::Path;
use std::sync::Arc;
use verti_nn::{Mlp, MlpScratch, Network, Shape};

/// Actions: target speed and steering.
pub const ACTION_DIM: usize = 2;

/// Card constant with the Gaussian's log standard deviation per action.
pub const LOG_STD: &str = "log_std";

/// A policy ready to act.
#[derive(Clone, Debug)]
pub struct Policy {
    network: Arc<Network>,
    mlp: Mlp,
    log_std: [f32; ACTION_DIM],
}

impl Policy {
    /// Checks that `network` is a policy for verti's inputs: input [`INPUT_DIM`], two outputs,
    /// linear layers and activations only, constant `log_std` of two values.
    pub fn new(network: Arc<Network>) -> Result<Policy, String> {
        let card = network.card();
        let name = &card.name;
        if network.input_shape() != Shape::Flat(INPUT_DIM) {
            return Err(format!(
                "{name}: field input: a driving policy takes {INPUT_DIM} inputs \
                 (verti_policy::inputs), this network takes {}",
                network.input_shape()
            ));
        }
        if network.output_shape() != Shape::Flat(ACTION_DIM) {
            return Err(format!(
                "{name}: field layers: a driving policy gives {ACTION_DIM} outputs (speed, \
                 steering), this network gives {}",
                network.output_shape()
            ));
        }
        let log_std = match card.constants.get(LOG_STD).map(Vec::as_slice) {
            Some(&[a, b]) if a.is_finite() && b.is_finite() => [a as f32, b as f32],
            Some(other) => {
                return Err(format!(
                    "{name}: field constants.{LOG_STD}: expected 2 finite numbers, got {other:?}"
                ));
            }
            None => return Err(format!("{name}: field constants.{LOG_STD} is missing")),
        };
        let mlp = Mlp::from_network(&network)?;
        Ok(Policy {
            network,
            mlp,
            log_std,
        })
    }

    /// Loads a policy card (YAML) and its weights.
    pub fn load(card: &Path) -> Result<Policy, String> {
        let net = Network::load(card).map_err(|e| e.to_string())?;
        Policy::new(Arc::new(net))
    }

    pub fn network(&self) -> &Network {
        &self.network
    }

    pub fn name(&self) -> &str {
        &self.network.card().name
    }

    /// Log standard deviations of the training-time Gaussian.
    pub fn log_std(&self) -> [f32; ACTION_DIM] {
        self.log_std
    }

    pub fn scratch(&self) -> MlpScratch {
        self.mlp.scratch()
    }

    /// The mean action for an input vector, unclipped.
    pub fn mean(&self, input: &[f32], scratch: &mut MlpScratch) -> [f32; ACTION_DIM] {
        let mut out = [0.0; ACTION_DIM];
        self.mlp.forward_into(input, scratch, &mut out);
        out
    }

    /// The action the benchmark applies: the mean, clipped to [-1, 1].
    pub fn act(&self, input: &[f32], scratch: &mut MlpScratch) -> [f32; ACTION_DIM] {
        self.mean(input, scratch).map(|a| a.clamp(-1.0, 1.0))
    }
}
