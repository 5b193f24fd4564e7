//! A trained network as a `verti_va` model card (plain Rust: adapts and predicts without burn),
//! with the coefficient prior fitted by least squares on training data.

use super::net::VaNet;
use crate::data::VaData;
use crate::model::{VA_FORMAT, VaCard, VaTraining, WeightsRef};
use crate::{Method, VaModel};
use std::collections::BTreeMap;
use std::path::Path;

/// Example points for the coefficient prior: every `stride`-th step of the training data.
pub const PRIOR_STRIDE: usize = 10;

/// The plain-Rust model of `net`. For `va` the prior coefficients are the least-squares fit
/// on every tenth training step (what the bases give before any adaptation); the baselines
/// have α = 1.
pub fn to_model(
    net: &VaNet,
    name: &str,
    summary: &str,
    lambda: f64,
    data: &VaData,
    training: VaTraining,
    metrics: BTreeMap<String, f64>,
) -> Result<VaModel, String> {
    let spec = &net.spec;
    let params = net.export_params();
    let card = VaCard {
        name: name.to_string(),
        format: VA_FORMAT,
        summary: summary.to_string(),
        method: spec.method,
        vehicle: data.vehicle.clone(),
        dt: spec.dt,
        bases: spec.bases,
        hidden: spec.hidden.clone(),
        elevation: spec.elevation,
        semantics: spec.semantics,
        lambda,
        alpha_prior: vec![1.0; spec.bases],
        weights: WeightsRef {
            file: format!("{name}.bin"),
            floats: params.len(),
            fnv1a64: String::new(),
        },
        training,
        metrics,
    };
    let mut model = VaModel::new(card, &params, Path::new(name)).map_err(|e| e.to_string())?;
    if spec.method == Method::Va {
        let all: Vec<usize> = (0..data.trajectories.len()).collect();
        let examples: Vec<_> = data
            .examples(&model, &all)
            .into_iter()
            .step_by(PRIOR_STRIDE)
            .collect();
        model.card.alpha_prior = model.adapt(&examples).map_err(|e| e.to_string())?;
    }
    Ok(model)
}
