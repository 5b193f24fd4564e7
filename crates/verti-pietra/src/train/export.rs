//! Trains one traversability model for the planner and writes it as a `verti_pietra` model
//! card with its six networks, so planning needs no learning framework.

use super::data::PietraData;
use super::fit::{RunConfig, train, train_log_density_min};
use super::model::{
    FLOW_LAYERS, LATENT, LOG_EVIDENCE_CLAMP, PRIOR_EVIDENCE, TravNet, decoder_layers,
    encoder_layers, log_budget, scaler_layers,
};
use crate::bins::PARAMS;
use crate::dataset::FEATURES;
use crate::model::{TRAV_FORMAT, TravCard, TravModel};
use burn::tensor::Device;
use std::collections::BTreeMap;
use std::sync::Arc;
use verti_nn::train::seq::{SeqNet, values};
use verti_nn::{LayerSpec, ModelCard, Network, Shape, TrainingInfo};

/// What the exported model's card records about its training.
pub struct ExportInfo {
    pub name: String,
    pub command: String,
    pub data: String,
}

fn network(
    name: String,
    input: usize,
    layers: Vec<LayerSpec>,
    net: &SeqNet,
    summary: &str,
) -> Result<Arc<Network>, String> {
    let card = ModelCard {
        summary: summary.to_string(),
        normalisation: "see the PIETRA card that lists this network".into(),
        ..ModelCard::new(&name, Shape::Flat(input), layers)
    };
    Network::from_params(card, &net.export_params())
        .map(Arc::new)
        .map_err(|e| e.to_string())
}

fn f64s(t: burn::tensor::Tensor<1>) -> Vec<f64> {
    values(t).into_iter().map(f64::from).collect()
}

/// The networks and flow of a trained `net` as a plain-Rust model.
pub fn to_model(
    net: &TravNet,
    data: &PietraData,
    ood_log_density: f64,
    training: TrainingInfo,
    metrics: BTreeMap<String, f64>,
    name: &str,
) -> Result<TravModel, String> {
    let m = net.method;
    let mut networks = vec![network(
        format!("{name}.encoder"),
        FEATURES,
        encoder_layers(),
        &net.encoder,
        "PIETRA footprint encoder: 12 x 7 heights (m, divided by the card's input_scale) → latent",
    )?];
    for (k, d) in net.decoders.iter().enumerate() {
        networks.push(network(
            format!("{name}.decoder{}", k + 1),
            LATENT,
            decoder_layers(),
            d,
            "PIETRA decoder: latent → logits of one traversability parameter's 12 bins",
        )?);
    }
    networks.push(network(
        format!("{name}.scaler"),
        LATENT,
        scaler_layers(),
        &net.scaler,
        "PIETRA evidence scaler: latent → logit of each parameter's evidence scale",
    )?);
    let card = TravCard {
        name: name.to_string(),
        format: TRAV_FORMAT,
        summary: format!(
            "{} traversability on the PIETRA maps: a footprint's yaw-aligned elevation patch → \
             PMFs over 12 bins of linear and angular traction, |roll| and |pitch|",
            m.name()
        ),
        method: m.name().to_string(),
        evidential: m.evidential(),
        physics_in_posterior: m.physics_in_posterior(),
        scales_evidence: m.scales_evidence(),
        input_scale: f64::from(net.input_scale),
        log_budget: log_budget(),
        log_evidence_clamp: LOG_EVIDENCE_CLAMP,
        prior_evidence: PRIOR_EVIDENCE,
        prior: data.prior.clone(),
        bins: data.bins.to_vec(),
        latent: LATENT,
        flow_z0: f64s(net.flow.z0.val().reshape([FLOW_LAYERS * LATENT])),
        flow_alpha: f64s(net.flow.alpha.val()),
        flow_beta: f64s(net.flow.beta.val()),
        ood_log_density,
        networks: networks
            .iter()
            .map(|n| format!("{}.yaml", n.card().name))
            .collect(),
        training,
        metrics,
    };
    debug_assert_eq!(card.networks.len(), 2 + PARAMS);
    TravModel::new(card, networks, std::path::Path::new(name))
}

/// Trains `cfg` on the benchmark's data and returns the plain-Rust model with its card.
pub fn train_model(
    data: &PietraData,
    cfg: &RunConfig,
    info: &ExportInfo,
    device: &Device,
) -> Result<TravModel, String> {
    let t = train(data, cfg, device)?;
    let ood = if cfg.method.evidential() {
        train_log_density_min(&t.net, data, device)
    } else {
        f64::NEG_INFINITY
    };
    let scores = t.test.scores(&data.test, data.threshold);
    let round = |v: f64| (v * 1e4).round() / 1e4;
    let metrics = BTreeMap::from([
        (
            "val_emd2".to_string(),
            round(t.val.scores(&data.val, data.threshold).overall),
        ),
        ("test_emd2".to_string(), round(scores.overall)),
        ("test_emd2_id".to_string(), round(scores.id)),
        ("test_emd2_ood".to_string(), round(scores.ood)),
    ]);
    let training = TrainingInfo {
        data: info.data.clone(),
        command: info.command.clone(),
        seed: cfg.seed,
        steps: cfg.steps as u64,
        wall_time_s: (t.wall_s * 10.0).round() / 10.0,
        verti_version: format!("verti {}", env!("CARGO_PKG_VERSION")),
        settings: format!(
            "Adam lr {}, batch {}, physics weight {}, entropy weight {}",
            cfg.lr, cfg.batch, cfg.weights.physics, cfg.weights.entropy
        ),
    };
    to_model(
        &t.net,
        data,
        if ood.is_finite() { ood } else { -1e30 },
        training,
        metrics,
        &info.name,
    )
}
