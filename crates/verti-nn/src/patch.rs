//! The local-patch terrain encoder: a heading-aligned elevation crop under the vehicle (64 x 64
//! cells at 0.1 m, like Verti-Bench's BenchElev) to a 64-number embedding. Learned systems use
//! it as their terrain input; it was trained as the encoder half of a small SWAE on crops from
//! training worlds (see its card).

use crate::Network;
use std::sync::Arc;

/// Cells per side of the crop the encoder takes.
pub const PATCH_CELLS: usize = 64;
/// Metres per cell.
pub const PATCH_RESOLUTION: f64 = 0.1;

/// Turns a crop of terrain heights (m, row 0 ahead, column 0 left, as
/// `verti_bench::Observation::elevation_crop` returns it) into the encoder's input: heights
/// relative to the crop's centre, divided by `height_scale` metres and clamped to [-1, 1].
pub fn normalise_patch(heights: &[f64], height_scale: f64) -> Vec<f32> {
    let n = (heights.len() as f64).sqrt() as usize;
    // the centre of an even crop lies between four cells: average them
    let centre = if n.is_multiple_of(2) {
        let (a, b) = (n / 2 - 1, n / 2);
        0.25 * (heights[a * n + a] + heights[a * n + b] + heights[b * n + a] + heights[b * n + b])
    } else {
        heights[(n / 2) * n + n / 2]
    };
    heights
        .iter()
        .map(|h| ((h - centre) / height_scale).clamp(-1.0, 1.0) as f32)
        .collect()
}

/// A trained patch encoder with its input scaling.
#[derive(Clone, Debug)]
pub struct PatchEncoder {
    net: Arc<Network>,
    height_scale: f64,
}

impl PatchEncoder {
    /// Wraps an encoder network whose card holds the constant `height_scale` (metres).
    pub fn new(net: Arc<Network>) -> Result<PatchEncoder, String> {
        let card = net.card();
        let height_scale = card
            .constants
            .get("height_scale")
            .and_then(|v| v.first().copied())
            .ok_or_else(|| format!("{}: card has no constant height_scale", card.name))?;
        if net.input_shape() != crate::Shape::Image([1, PATCH_CELLS, PATCH_CELLS]) {
            return Err(format!(
                "{}: a patch encoder takes [1, {PATCH_CELLS}, {PATCH_CELLS}], this one takes {}",
                card.name,
                net.input_shape()
            ));
        }
        Ok(PatchEncoder { net, height_scale })
    }

    pub fn network(&self) -> &Network {
        &self.net
    }

    /// Length of the embedding.
    pub fn dim(&self) -> usize {
        self.net.output_shape().len()
    }

    /// Metres of height difference that map to ±1 at the input.
    pub fn height_scale(&self) -> f64 {
        self.height_scale
    }

    /// Embeds a 64 x 64 crop of terrain heights (m).
    pub fn embed(&self, heights: &[f64]) -> Vec<f32> {
        assert_eq!(
            heights.len(),
            PATCH_CELLS * PATCH_CELLS,
            "patch must be 64 x 64"
        );
        self.net
            .forward(&normalise_patch(heights, self.height_scale))
    }
}
