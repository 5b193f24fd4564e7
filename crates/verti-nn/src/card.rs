//! The model card: a small YAML file beside each weight file that says what the network is
//! (layers, input and output), how to feed it, what it was trained on, with which seed and
//! command, how long it took and how well it did. The weights file is raw little-endian f32,
//! layer by layer (weights, then biases), checked against the card's count and digest.

use crate::error::ModelError;
use crate::layer::{LayerSpec, Shape};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Format version written by this crate.
pub const CARD_FORMAT: u32 = 1;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelCard {
    /// Name used on the command line and in world manifests, e.g. `swae-v1`.
    pub name: String,
    pub format: u32,
    /// One paragraph: what the network does and where it is used.
    pub summary: String,
    /// Shape of one input.
    pub input: Shape,
    pub layers: Vec<LayerSpec>,
    /// How inputs are prepared and outputs read (units, scaling, crop geometry).
    pub normalisation: String,
    pub weights: WeightsInfo,
    pub training: TrainingInfo,
    /// Final metrics, by name (e.g. `val_mse`).
    #[serde(default)]
    pub metrics: BTreeMap<String, f64>,
    /// Named constant vectors the model needs besides its layers (e.g. latent statistics).
    #[serde(default)]
    pub constants: BTreeMap<String, Vec<f64>>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsInfo {
    /// File name, relative to the card.
    pub file: String,
    /// Number of f32 values.
    pub floats: usize,
    /// FNV-1a 64 of the file's bytes, hexadecimal.
    pub fnv1a64: String,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingInfo {
    /// What the model saw (files, world sets and their seeds).
    pub data: String,
    /// The one command that reproduces the weights.
    pub command: String,
    pub seed: u64,
    pub steps: u64,
    pub wall_time_s: f64,
    /// verti version (and commit when known) that trained it.
    pub verti_version: String,
    /// Optimiser, learning rate, batch size and the like, as text.
    pub settings: String,
}

impl ModelCard {
    /// A card for a network of `layers` on `input`, weights in `NAME.bin`, with this verti's
    /// version and nothing else said yet: trainers fill in what they know (struct update
    /// syntax), tests use it as it is.
    pub fn new(name: &str, input: Shape, layers: Vec<LayerSpec>) -> ModelCard {
        ModelCard {
            name: name.to_string(),
            format: CARD_FORMAT,
            summary: String::new(),
            input,
            layers,
            normalisation: String::new(),
            weights: WeightsInfo {
                file: format!("{name}.bin"),
                floats: 0,
                fnv1a64: String::new(),
            },
            training: TrainingInfo {
                verti_version: format!("verti {}", env!("CARGO_PKG_VERSION")),
                ..TrainingInfo::default()
            },
            metrics: BTreeMap::new(),
            constants: BTreeMap::new(),
        }
    }
}

impl WeightsInfo {
    /// Checks that `bytes` are the weights this record describes: [`WeightsInfo::floats`]
    /// little-endian f32 values whose digest is [`WeightsInfo::fnv1a64`]. `origin` names the
    /// card in errors, which also name the field whose record the bytes do not match. Every
    /// model's weights pass this check, whichever card they come with and whether they come
    /// from a file or are compiled in.
    pub fn check(&self, bytes: &[u8], origin: &Path) -> Result<(), ModelError> {
        if self.floats.checked_mul(4) != Some(bytes.len()) {
            return Err(ModelError::invalid(
                origin,
                format!(
                    "field weights.floats: weights file {} has {} bytes, expected {} ({} f32 values): truncated or not this model's",
                    self.file,
                    bytes.len(),
                    // in u128: a count from the card may be near usize::MAX
                    4 * self.floats as u128,
                    self.floats,
                ),
            ));
        }
        let digest = format!("{:016x}", fnv1a64(bytes));
        if digest != self.fnv1a64 {
            return Err(ModelError::invalid(
                origin,
                format!(
                    "field weights.fnv1a64: weights file {} has digest {digest}, the card says {}: the file does not belong to this card",
                    self.file, self.fnv1a64
                ),
            ));
        }
        Ok(())
    }
}

/// A card that names one weights file: verti-nn's [`ModelCard`], and the cards of models that
/// are not plain networks (VertiAdaptor's) but keep their weights the same way.
pub trait WeightsCard: DeserializeOwned {
    fn weights_info(&self) -> &WeightsInfo;
}

impl WeightsCard for ModelCard {
    fn weights_info(&self) -> &WeightsInfo {
        &self.weights
    }
}

/// Parses a card's YAML (any card type), naming the file and the problem.
pub fn parse<C: DeserializeOwned>(text: &str, path: &Path) -> Result<C, ModelError> {
    serde_norway::from_str(text)
        .map_err(|e| ModelError::invalid(path, format!("not a model card: {e}")))
}

/// FNV-1a, 64 bit: a dependency-free digest to catch truncated or swapped weight files.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}
