//! Training data of the local-patch encoder: heading-aligned elevation crops under random
//! poses of training worlds, computed on the fly with the same crop geometry systems see
//! (`verti_bench::Observation::elevation_crop`).

use crate::patch::{PATCH_RESOLUTION, normalise_patch};
use crate::train::swae::BatchSource;
use verti_bench::observation::{CropSpec, test_observation};
use verti_core::Rng;
use verti_world::World;
use verti_world::world::WorldSource;

/// Which worlds, and how crops are scaled.
#[derive(Clone, Debug)]
pub struct PatchSettings {
    /// World set the training crops come from (e.g. `verti-100-s1`).
    pub train_worlds: String,
    /// World set of the validation crops (e.g. `verti-100-s2`).
    pub val_worlds: String,
    pub validation_patches: usize,
    /// Metres of height difference mapped to ±1.
    pub height_scale: f64,
    pub seed: u64,
}

/// Refuses the evaluation worlds (the default set `verti-100` and imported Verti-Bench
/// worlds): no model may be trained on what the benchmark evaluates.
pub fn refuse_evaluation_worlds(spec: &str, worlds: &[World]) -> Result<(), String> {
    for w in worlds {
        let evaluation = match &w.meta.source {
            WorldSource::Generated { set_seed, .. } => {
                *set_seed == 0 && w.meta.name.starts_with("verti-100/")
            }
            WorldSource::VertiBench { .. } => true,
        };
        if evaluation {
            return Err(format!(
                "`{spec}` holds evaluation world {}: models are never trained on verti-100 or \
                 on the original Verti-Bench worlds; use another seed, e.g. verti-100-s1",
                w.meta.name
            ));
        }
    }
    Ok(())
}

fn load_worlds(spec: &str) -> Result<Vec<World>, String> {
    let set = verti_world::sets::resolve_set(spec, 1.0, &|| {}).map_err(|e| e.to_string())?;
    refuse_evaluation_worlds(spec, &set.worlds)?;
    if set.worlds.is_empty() {
        return Err(format!("`{spec}` has no worlds"));
    }
    Ok(set.worlds)
}

/// Draws crops from random poses (uniform over the map, 8 m from its edge; uniform heading).
pub struct PatchSampler {
    train: Vec<World>,
    settings: PatchSettings,
    side: usize,
}

impl PatchSampler {
    pub fn new(settings: &PatchSettings, side: usize) -> Result<PatchSampler, String> {
        if !(settings.height_scale > 0.0 && settings.height_scale.is_finite()) {
            return Err(format!(
                "height scale {} must be a positive number of metres",
                settings.height_scale
            ));
        }
        Ok(PatchSampler {
            train: load_worlds(&settings.train_worlds)?,
            settings: settings.clone(),
            side,
        })
    }

    fn crop(&self, world: &World, rng: &mut Rng) -> Vec<f32> {
        let h = world.terrain.half_extent() - 8.0 * world.meta.scale;
        let xy = [rng.range(-h, h), rng.range(-h, h)];
        let yaw = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
        let obs = test_observation(world, xy, yaw, xy, &[]);
        let crop = obs.elevation_crop(CropSpec {
            size: self.side,
            resolution: PATCH_RESOLUTION * world.meta.scale,
        });
        normalise_patch(&crop.data, self.settings.height_scale)
    }

    /// A fixed validation set from the validation worlds (seeded, independent of training).
    pub fn validation(&self, count: usize) -> Result<Vec<f32>, String> {
        let worlds = load_worlds(&self.settings.val_worlds)?;
        let mut rng = Rng::derive(self.settings.seed, "patch-validation", 0);
        let mut out = Vec::with_capacity(count * self.side * self.side);
        for i in 0..count {
            out.extend(self.crop(&worlds[i % worlds.len()], &mut rng));
        }
        Ok(out)
    }
}

impl BatchSource for PatchSampler {
    fn sample(&mut self, rng: &mut Rng, batch: usize) -> Vec<f32> {
        let mut out = Vec::with_capacity(batch * self.side * self.side);
        for _ in 0..batch {
            let w = &self.train[(rng.next_u64() % self.train.len() as u64) as usize];
            out.extend(self.crop(w, rng));
        }
        out
    }
}
