//! What both kinodynamic trainers share: the settings, provenance and results of a training
//! run, and the helpers that gather mini-batch rows and export a trained network. `kino`
//! trains the MLP models and hands attentive ones to `tal`, which needs these too; kept in
//! `kino`, they made `kino` and `tal` import each other. `kino` re-exports the public ones.

use crate::card::KinoKind;
use crate::features::INPUT_DIM;
use burn::tensor::{Device, Tensor, TensorData};
use std::sync::Arc;
use verti_nn::train::seq::{SeqNet, mlp_layers};
use verti_nn::{LayerSpec, ModelCard, Network, TrainingInfo};

/// Training settings.
#[derive(Clone, Debug, PartialEq)]
pub struct KinoConfig {
    pub kind: KinoKind,
    /// Ensemble members (1 for a single network).
    pub members: usize,
    /// Hidden layer widths (ReLU between layers).
    pub hidden: Vec<usize>,
    pub steps: usize,
    pub batch: usize,
    pub lr: f64,
    pub lr_final: f64,
    pub seed: u64,
    pub eval_every: usize,
}

impl KinoConfig {
    pub fn validate(&self) -> Result<(), String> {
        if self.members == 0 || self.steps == 0 || self.batch == 0 || self.eval_every == 0 {
            return Err("members, steps, batch and eval_every must be at least 1".into());
        }
        if self.hidden.is_empty() || self.hidden.contains(&0) {
            return Err(format!(
                "hidden widths {:?} must be non-empty and positive",
                self.hidden
            ));
        }
        if !(self.lr > 0.0 && self.lr_final > 0.0 && self.lr_final <= self.lr) {
            return Err(format!(
                "learning rates must satisfy 0 < lr_final <= lr, got {} and {}",
                self.lr, self.lr_final
            ));
        }
        Ok(())
    }

    pub fn lr_at(&self, step: usize) -> f64 {
        let progress = step as f64 / self.steps.max(1) as f64;
        self.lr_final
            + 0.5 * (self.lr - self.lr_final) * (1.0 + (std::f64::consts::PI * progress).cos())
    }

    /// The network's layers: inputs → hidden (ReLU) → outputs.
    pub fn layers(&self) -> Vec<LayerSpec> {
        mlp_layers(
            INPUT_DIM,
            &self.hidden,
            self.kind.network_outputs(),
            LayerSpec::Relu,
        )
    }
}

/// One point of the learning curve.
#[derive(Clone, Debug, PartialEq)]
pub struct KinoCurvePoint {
    pub member: usize,
    pub step: usize,
    pub train_loss: f64,
    pub val_loss: f64,
}

/// What training produced besides the model.
#[derive(Clone, Debug)]
pub struct KinoReport {
    pub curve: Vec<KinoCurvePoint>,
    pub wall_time_s: f64,
    /// Final validation MSE of the ensemble mean, standardised units.
    pub val_loss: f64,
}

/// Provenance recorded in the card.
pub struct KinoProvenance {
    pub name: String,
    pub summary: String,
    pub vehicle: String,
    pub dt: f64,
    pub data: String,
    pub worlds: String,
    pub command: String,
}

/// A trained burn network as a verti-nn network named `file` (its card records provenance;
/// the normalisation lives in the kinodynamic card).
pub(crate) fn export_network(
    net: &SeqNet,
    file: &str,
    summary: &str,
    cfg: &KinoConfig,
    prov: &KinoProvenance,
    wall: f64,
) -> Result<Arc<Network>, String> {
    let card = ModelCard {
        summary: summary.to_string(),
        normalisation: format!("see {}.yaml", prov.name),
        training: TrainingInfo {
            data: prov.data.clone(),
            command: prov.command.clone(),
            seed: cfg.seed,
            steps: cfg.steps as u64,
            wall_time_s: wall,
            verti_version: format!("verti {}", env!("CARGO_PKG_VERSION")),
            settings: String::new(),
        },
        ..ModelCard::new(file, net.input_shape(), net.layers().to_vec())
    };
    Network::from_params(card, &net.export_params())
        .map(Arc::new)
        .map_err(|e| e.to_string())
}

pub(crate) fn rows(data: &[f32], dim: usize, idx: &[usize], device: &Device) -> Tensor<2> {
    let mut v = Vec::with_capacity(idx.len() * dim);
    for &i in idx {
        v.extend_from_slice(&data[i * dim..(i + 1) * dim]);
    }
    Tensor::from_data(TensorData::new(v, [idx.len(), dim]), device)
}
