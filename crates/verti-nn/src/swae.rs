//! `swae-v1`: terrain geometry sampled from a trained sliced-Wasserstein autoencoder, as
//! Verti-Bench's BenchGen (paper §III-B): draw z ~ N(0, I), decode to a 128 x 128 map, read it
//! as a fraction of the level's maximum height (the grey level / 255 of Verti-Bench's BMPs; the
//! decoder works in standardised units, so fraction = `fraction_mean` + `fraction_std` · output,
//! constants from the model card), resample to the world's 129 x 129 vertices (bicubic, as
//! Verti-Bench) and clamp to [0, 1]. Unlike Verti-Bench the grey level is not truncated to 8
//! bits.
//!
//! Decoding runs through [`crate::Network`]'s fixed-order loops, so a world generated with this
//! source is byte-identical on every machine and thread count.

use crate::Network;
use crate::resize::bicubic;
use std::sync::Arc;
use verti_core::Rng;
use verti_core::params::{ParamSpec, Params};
use verti_core::registry::{Factory, FactoryInfo};
use verti_world::generate::elevation::ElevationSource;

/// Registry name of the shipped source.
pub const SWAE_SOURCE: &str = "swae-v1";

/// An elevation source decoding latent samples with a trained decoder.
pub struct SwaeSource {
    decoder: Arc<Network>,
    name: String,
    /// fraction = offset + scale · decoder output.
    offset: f64,
    scale: f64,
    /// Standard deviation of the latent samples (1 = the prior).
    latent_scale: f64,
}

impl SwaeSource {
    /// `decoder` maps a flat latent vector to a [1, side, side] map in [-1, 1].
    pub fn new(decoder: Arc<Network>, latent_scale: f64) -> Result<SwaeSource, String> {
        let name = decoder.card().name.clone();
        match decoder.output_shape() {
            crate::Shape::Image([1, h, w]) if h == w => {}
            other => {
                return Err(format!(
                    "{name}: a terrain decoder must output [1, side, side], this one gives {other}"
                ));
            }
        }
        if !(latent_scale.is_finite() && latent_scale >= 0.0) {
            return Err(format!(
                "latent_scale {latent_scale} must be finite and >= 0"
            ));
        }
        let constant = |key: &str| {
            decoder
                .card()
                .constants
                .get(key)
                .and_then(|v| v.first().copied())
                .ok_or_else(|| format!("{name}: model card has no constant {key}"))
        };
        let (offset, scale) = (constant("fraction_mean")?, constant("fraction_std")?);
        let name = if latent_scale == 1.0 {
            name
        } else {
            format!("{name}(latent_scale={latent_scale})")
        };
        Ok(SwaeSource {
            decoder,
            name,
            offset,
            scale,
            latent_scale,
        })
    }

    /// The decoded map before resampling: [side x side] fractions (not yet clamped).
    pub fn decode(&self, z: &[f32]) -> Vec<f64> {
        self.decoder
            .forward(z)
            .iter()
            .map(|&y| self.offset + self.scale * f64::from(y))
            .collect()
    }

    /// A latent sample from the prior (scaled).
    pub fn sample_latent(&self, rng: &mut Rng) -> Vec<f32> {
        (0..self.decoder.input_shape().len())
            .map(|_| (rng.normal() * self.latent_scale) as f32)
            .collect()
    }
}

impl ElevationSource for SwaeSource {
    fn name(&self) -> &str {
        &self.name
    }

    fn generate(&self, rng: &mut Rng, n: usize) -> Vec<f64> {
        let z = self.sample_latent(rng);
        let map = self.decode(&z);
        let side = (map.len() as f64).sqrt() as usize;
        bicubic(&map, side, n)
            .into_iter()
            .map(|v| v.clamp(0.0, 1.0))
            .collect()
    }
}

/// Builds [`SwaeSource`] from the shipped decoder, with its latent scale adjustable.
pub struct SwaeFactory {
    pub decoder: Arc<Network>,
}

impl Factory<dyn ElevationSource> for SwaeFactory {
    fn info(&self) -> FactoryInfo {
        FactoryInfo {
            name: self.decoder.card().name.clone(),
            summary: "terrain sampled from the trained SWAE (Verti-Bench's BenchGen, trained on its 1000 elevation maps)".into(),
            params: vec![ParamSpec::float(
                "latent_scale",
                1.0,
                0.0,
                3.0,
                "standard deviation of the latent samples (1 = the N(0, I) prior; smaller = more typical terrain)",
            )],
        }
    }

    fn build(&self, p: &Params) -> Result<Box<dyn ElevationSource>, String> {
        Ok(Box::new(SwaeSource::new(
            self.decoder.clone(),
            p.float("latent_scale"),
        )?))
    }
}
