//! The kinodynamic model file: one YAML card naming the model's kind, step, normalisation and
//! training record, plus one verti-nn network file per network it is made of (ensemble
//! members, heads).

use crate::Result;
use crate::attentive::{ATTENTIVE_INPUT_DIM, HEAD_DIM, MAP_DIM, OFFSET_DIM};
use crate::features::{INPUT_DIM, OUTPUT_DIM};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use verti_nn::{Mlp, ModelError, Network};

/// Current card format.
pub const KINO_FORMAT: u32 = 1;

/// How a model turns its networks into a 6-DoF step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KinoKind {
    /// MPPI-6 (KrModel's spirit): an ensemble of MLPs predicts the full 6-DoF change; members
    /// are averaged.
    Ensemble,
    /// WMVCT: a kinematic bicycle for forward/left/yaw, the terrain height for z, and a
    /// network for the next roll and pitch (absolute, not a change).
    Decomposed,
    /// TAL: an elevation-map encoder run once per plan, a gate on its features from the
    /// vehicle's offset within the map, and a dynamics network (networks in that order; see
    /// [`crate::attentive`]).
    Attentive,
}

impl KinoKind {
    /// Outputs each network predicts.
    pub fn network_outputs(self) -> usize {
        match self {
            KinoKind::Ensemble | KinoKind::Attentive => OUTPUT_DIM,
            KinoKind::Decomposed => 2,
        }
    }
    /// Raw input columns the card standardises.
    pub fn input_dim(self) -> usize {
        match self {
            KinoKind::Ensemble | KinoKind::Decomposed => INPUT_DIM,
            KinoKind::Attentive => ATTENTIVE_INPUT_DIM,
        }
    }
}

/// What training did (mirrors verti-nn's card so a reader finds the same fields).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KinoTraining {
    pub data: String,
    pub worlds: String,
    pub command: String,
    pub seed: u64,
    pub steps: usize,
    pub wall_time_s: f64,
    pub verti_version: String,
    pub settings: String,
}

/// The model card of a kinodynamic model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KinoCard {
    pub name: String,
    pub format: u32,
    pub summary: String,
    pub kind: KinoKind,
    /// Vehicle the training data were driven with, and the model step (full-scale seconds).
    pub vehicle: String,
    pub dt: f64,
    pub inputs: Vec<String>,
    pub input_mean: Vec<f64>,
    pub input_std: Vec<f64>,
    /// Standardisation of what the networks predict (`kind.network_outputs()` values).
    pub output_mean: Vec<f64>,
    pub output_std: Vec<f64>,
    /// Network card files, relative to this card.
    pub networks: Vec<String>,
    pub training: KinoTraining,
    pub metrics: BTreeMap<String, f64>,
}

/// A loaded model: card and networks, checked against each other.
#[derive(Clone, Debug)]
pub struct KinoFile {
    pub card: KinoCard,
    pub networks: Vec<Arc<Network>>,
    /// The networks as MLPs on raw inputs and raw outputs (the standardisation folded into
    /// their first and last layers).
    pub mlps: Vec<Mlp>,
}

impl KinoFile {
    /// Checks a card and its networks: dimensions, step, formats.
    pub fn new(card: KinoCard, networks: Vec<Arc<Network>>, origin: &Path) -> Result<KinoFile> {
        let bad = |field: &str, why: String| ModelError::card(origin, field, why);
        if card.format != KINO_FORMAT {
            return Err(bad(
                "format",
                format!(
                    "{} is not supported (this verti reads {KINO_FORMAT})",
                    card.format
                ),
            ));
        }
        if !(card.dt.is_finite() && card.dt > 0.0) {
            return Err(bad("dt", format!("{} must be a positive time", card.dt)));
        }
        let outputs = card.kind.network_outputs();
        for (field, v, n) in [
            ("input_mean", &card.input_mean, card.kind.input_dim()),
            ("input_std", &card.input_std, card.kind.input_dim()),
            ("output_mean", &card.output_mean, outputs),
            ("output_std", &card.output_std, outputs),
        ] {
            if v.len() != n {
                return Err(bad(field, format!("{} values, expected {n}", v.len())));
            }
            if v.iter().any(|x| !x.is_finite()) || (field.ends_with("std") && v.contains(&0.0)) {
                return Err(bad(
                    field,
                    "values must be finite (and non-zero for std)".into(),
                ));
            }
        }
        if networks.is_empty() || networks.len() != card.networks.len() {
            return Err(bad(
                "networks",
                format!("{} listed, {} loaded", card.networks.len(), networks.len()),
            ));
        }
        let mlps = match card.kind {
            KinoKind::Ensemble | KinoKind::Decomposed => {
                let mut mlps = Vec::new();
                for (file, net) in card.networks.iter().zip(&networks) {
                    let mlp = as_mlp(file, net, INPUT_DIM, Some(outputs), card.kind)
                        .map_err(|e| bad("networks", e))?;
                    let folded = mlp
                        .fold_standardisation(
                            &card.input_mean,
                            &card.input_std,
                            &card.output_mean,
                            &card.output_std,
                        )
                        .map_err(|e| bad("networks", format!("{file}: {e}")))?;
                    mlps.push(folded);
                }
                mlps
            }
            KinoKind::Attentive => {
                fold_attentive(&card, &networks).map_err(|e| bad("networks", e))?
            }
        };
        Ok(KinoFile {
            card,
            networks,
            mlps,
        })
    }

    /// Reads a card and the networks it lists (beside it).
    pub fn load(path: &Path) -> Result<KinoFile> {
        let text = std::fs::read_to_string(path).map_err(|e| ModelError::io(path, e))?;
        let card = parse_card(&text, path)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let networks = card
            .networks
            .iter()
            .map(|f| {
                Network::load(&dir.join(f))
                    .map(Arc::new)
                    .map_err(|e| ModelError::card(path, "networks", e))
            })
            .collect::<Result<Vec<_>>>()?;
        KinoFile::new(card, networks, path)
    }

    /// Writes the card to `path` and each network beside it under its listed name.
    pub fn save(&self, path: &Path) -> Result<()> {
        let dir = path.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|e| ModelError::io(dir, e))?;
        for (file, net) in self.card.networks.iter().zip(&self.networks) {
            net.save(&dir.join(file))
                .map_err(|e| ModelError::card(&dir.join(file), "networks", e))?;
        }
        let text =
            serde_norway::to_string(&self.card).map_err(|e| ModelError::card(path, "card", e))?;
        std::fs::write(path, text).map_err(|e| ModelError::io(path, e))
    }
}

/// A network as an MLP with the given input (and output) width.
fn as_mlp(
    file: &str,
    net: &Network,
    inputs: usize,
    outputs: Option<usize>,
    kind: KinoKind,
) -> std::result::Result<Mlp, String> {
    let mlp = Mlp::from_network(net).map_err(|e| format!("{file}: {e}"))?;
    if mlp.inputs() != inputs || outputs.is_some_and(|o| mlp.outputs() != o) {
        return Err(format!(
            "{file} maps {} inputs to {}, a {kind:?} model needs {inputs} to {}",
            mlp.inputs(),
            mlp.outputs(),
            outputs.map_or("its features".to_string(), |o| o.to_string())
        ));
    }
    Ok(mlp)
}

/// TAL's three networks with the card's standardisation folded in: the map columns into the
/// encoder, the offset columns into the gate, the head columns (and the outputs) into the
/// dynamics network, whose gated-feature inputs are not standardised.
fn fold_attentive(
    card: &KinoCard,
    networks: &[Arc<Network>],
) -> std::result::Result<Vec<Mlp>, String> {
    let [enc, gate, dynamics] = networks else {
        return Err(format!(
            "an attentive model has 3 networks (encoder, gate, dynamics), not {}",
            networks.len()
        ));
    };
    let files = &card.networks;
    let kind = card.kind;
    let enc = as_mlp(&files[0], enc, MAP_DIM, None, kind)?;
    let features = enc.outputs();
    let gate = as_mlp(&files[1], gate, OFFSET_DIM, Some(features), kind)?;
    let dynamics = as_mlp(
        &files[2],
        dynamics,
        features + HEAD_DIM,
        Some(OUTPUT_DIM),
        kind,
    )?;
    let (m, s) = (&card.input_mean, &card.input_std);
    let head = MAP_DIM + OFFSET_DIM..;
    let mut dyn_mean = vec![0.0; features];
    dyn_mean.extend_from_slice(&m[head.clone()]);
    let mut dyn_std = vec![1.0; features];
    dyn_std.extend_from_slice(&s[head]);
    Ok(vec![
        enc.fold_inputs(&m[..MAP_DIM], &s[..MAP_DIM])?,
        gate.fold_inputs(
            &m[MAP_DIM..MAP_DIM + OFFSET_DIM],
            &s[MAP_DIM..MAP_DIM + OFFSET_DIM],
        )?,
        dynamics.fold_standardisation(&dyn_mean, &dyn_std, &card.output_mean, &card.output_std)?,
    ])
}

/// Parses a card's YAML, naming the file in errors.
pub fn parse_card(text: &str, path: &Path) -> Result<KinoCard> {
    // a common slip: one of the model's network cards instead of the model card
    if text.lines().any(|l| l.starts_with("layers:")) && !text.contains("\nnetworks:") {
        return Err(ModelError::card(
            path,
            "card",
            "this is a network card (one of a model's networks); pass the model's own card \
             (e.g. crates/verti-kino/models/mppi6-v1.yaml), which lists its networks",
        ));
    }
    serde_norway::from_str(text).map_err(|e| {
        let field = e
            .location()
            .map(|l| format!("line {}", l.line()))
            .unwrap_or_else(|| "card".into());
        ModelError::card(path, &field, e)
    })
}
