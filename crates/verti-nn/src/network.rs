//! A feed-forward network built from a model card and its weights.

use crate::card::{CARD_FORMAT, ModelCard, WeightsInfo, fnv1a64};
pub use crate::error::ModelError;
use crate::layer::{LayerSpec, Shape};
use std::path::Path;

/// A network ready for inference: the card, and each layer's parameters and input shape.
#[derive(Clone, Debug)]
pub struct Network {
    card: ModelCard,
    /// Parameters of every layer, concatenated in layer order.
    params: Vec<f32>,
    /// (offset into `params`, input shape) per layer.
    layout: Vec<(usize, Shape)>,
    output: Shape,
}

impl Network {
    /// Builds a network from a card and the bytes of its weight file. `origin` names the card
    /// in error messages.
    pub fn from_bytes(
        card: ModelCard,
        weights: &[u8],
        origin: &Path,
    ) -> Result<Network, ModelError> {
        let bad = |message: String| ModelError::Invalid {
            path: origin.to_path_buf(),
            message,
        };
        if card.format != CARD_FORMAT {
            return Err(bad(format!(
                "field format: version {} is not supported (this verti reads {CARD_FORMAT})",
                card.format
            )));
        }
        // Every size below comes from the file: arithmetic on them is checked, and every
        // activation is bounded, so that a loaded network runs without overflow or an
        // allocation that cannot succeed (a wrapped count could match a small weight file).
        check_size(card.input.checked_len(), "the input", card.input)
            .map_err(|e| bad(format!("field input: {e}")))?;
        let mut layout = Vec::with_capacity(card.layers.len());
        let mut shape = card.input;
        let mut offset: usize = 0;
        for (i, layer) in card.layers.iter().enumerate() {
            let field = |e: String| bad(format!("field layers[{i}]: {e}"));
            layout.push((offset, shape));
            offset = layer
                .checked_parameter_count()
                .and_then(|n| offset.checked_add(n))
                .ok_or_else(|| {
                    field(format!(
                        "the parameter count overflows at this {} layer (sizes too large)",
                        layer.kind()
                    ))
                })?;
            let scratch = layer.scratch_len(shape);
            if scratch.is_none_or(|n| n > MAX_VALUES) {
                return Err(field(format!(
                    "the {} layer on {shape} needs a work buffer of more than {MAX_VALUES} values (stride too large)",
                    layer.kind()
                )));
            }
            shape = layer.output_shape(shape).map_err(field)?;
            check_size(shape.checked_len(), "the output", shape).map_err(field)?;
        }
        if offset != card.weights.floats {
            return Err(bad(format!(
                "field weights.floats: the layers have {offset} parameters, the card says {}",
                card.weights.floats
            )));
        }
        card.weights.check(weights, origin)?;
        let params: Vec<f32> = weights
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        if let Some(k) = params.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!(
                "weights file {} holds a non-finite value at index {k}",
                card.weights.file
            )));
        }
        Ok(Network {
            card,
            params,
            layout,
            output: shape,
        })
    }

    /// Loads `card_path` (YAML) and the weight file it names (relative to the card).
    pub fn load(card_path: &Path) -> Result<Network, ModelError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| ModelError::Io { path, source }
        };
        let text = std::fs::read_to_string(card_path).map_err(io(card_path))?;
        let card = parse_card(&text, card_path)?;
        let weights_path = card_path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&card.weights.file);
        let bytes = std::fs::read(&weights_path).map_err(io(&weights_path))?;
        Network::from_bytes(card, &bytes, card_path)
    }

    /// Builds a network from parameters in memory (training code exports this way), filling
    /// in the card's weight count and digest.
    pub fn from_params(mut card: ModelCard, params: &[f32]) -> Result<Network, ModelError> {
        let bytes = params_to_bytes(params);
        card.weights = WeightsInfo {
            file: card.weights.file.clone(),
            floats: params.len(),
            fnv1a64: format!("{:016x}", fnv1a64(&bytes)),
        };
        Network::from_bytes(card, &bytes, Path::new("<in memory>"))
    }

    /// Writes the card to `card_path` and the weights beside it under the card's file name.
    pub fn save(&self, card_path: &Path) -> Result<(), ModelError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| ModelError::Io { path, source }
        };
        let dir = card_path.parent().unwrap_or(Path::new("."));
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir).map_err(io(dir))?;
        }
        let weights_path = dir.join(&self.card.weights.file);
        std::fs::write(&weights_path, params_to_bytes(&self.params)).map_err(io(&weights_path))?;
        let text = serde_norway::to_string(&self.card).map_err(|e| ModelError::Invalid {
            path: card_path.to_path_buf(),
            message: e.to_string(),
        })?;
        std::fs::write(card_path, text).map_err(io(card_path))
    }

    pub fn card(&self) -> &ModelCard {
        &self.card
    }
    pub fn card_mut(&mut self) -> &mut ModelCard {
        &mut self.card
    }
    pub fn input_shape(&self) -> Shape {
        self.card.input
    }
    pub fn output_shape(&self) -> Shape {
        self.output
    }
    /// All parameters, layer by layer.
    pub fn params(&self) -> &[f32] {
        &self.params
    }
    /// Size of the weight file, bytes.
    pub fn weight_bytes(&self) -> usize {
        4 * self.params.len()
    }

    /// Runs one input through the network. Panics if `input` does not have the card's input
    /// length (a programming error: callers build inputs of the declared shape).
    pub fn forward(&self, input: &[f32]) -> Vec<f32> {
        assert_eq!(
            input.len(),
            self.card.input.len(),
            "{} takes {} inputs",
            self.card.name,
            self.card.input
        );
        let mut x = input.to_vec();
        for (layer, &(offset, shape)) in self.card.layers.iter().zip(&self.layout) {
            let n = layer.parameter_count();
            x = layer.forward(&self.params[offset..offset + n], shape, x);
        }
        x
    }

    /// The parameters of layer `index` (weights, then biases).
    pub fn layer_params(&self, index: usize) -> &[f32] {
        let (offset, _) = self.layout[index];
        &self.params[offset..offset + self.card.layers[index].parameter_count()]
    }

    /// Number of layers of each kind, for summaries.
    pub fn describe(&self) -> String {
        let convs = self
            .card
            .layers
            .iter()
            .filter(|l| {
                matches!(
                    l,
                    LayerSpec::Conv2d { .. } | LayerSpec::ConvTranspose2d { .. }
                )
            })
            .count();
        format!(
            "{}: {} -> {}, {} layers ({convs} convolutional), {} parameters ({:.1} KiB)",
            self.card.name,
            self.card.input,
            self.output,
            self.card.layers.len(),
            self.params.len(),
            self.weight_bytes() as f64 / 1024.0
        )
    }
}

/// Most values one activation (a layer's input or output, or a work buffer) may hold: 2^28
/// f32 values, 1 GiB. The shipped models stay below 2^19; the bound refuses cards whose sizes
/// would make [`Network::forward`] allocate without limit.
pub const MAX_VALUES: usize = 1 << 28;

/// Checks the length of `shape` (`len`: None when it overflows): not empty, not above
/// [`MAX_VALUES`].
fn check_size(len: Option<usize>, what: &str, shape: Shape) -> Result<(), String> {
    match len {
        Some(1..=MAX_VALUES) => Ok(()),
        Some(0) => Err(format!("{what} {shape} is empty")),
        _ => Err(format!(
            "{what} {shape} has more than {MAX_VALUES} values (sizes too large)"
        )),
    }
}

/// Parses a network's card, naming the file and the problem.
pub fn parse_card(text: &str, path: &Path) -> Result<ModelCard, ModelError> {
    crate::card::parse(text, path)
}

fn params_to_bytes(params: &[f32]) -> Vec<u8> {
    params.iter().flat_map(|v| v.to_le_bytes()).collect()
}
