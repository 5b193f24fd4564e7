//! Adaptation data gathered in a task's world before the task (the environment data of the
//! paper's VA* and MAML*): VertiAdaptor's sinusoidal exploration from random starts, the same
//! drives for every task of a world (seeded by the world's index), so every method adapted
//! "once per environment" sees the same data.

use crate::model::{Example, VaModel};
use crate::terrain::{TERRAIN_DIM, terrain_latent};
use std::sync::Arc;
use verti_core::rng::mix_seed;
use verti_data::Profile;
use verti_data::generate::{DriveRows, explore_poses};
use verti_kino::features::{Units, heading_delta};
use verti_nn::patch::PatchEncoder;
use verti_sim::Sim;
use verti_world::World;

/// `trials` drives of `seconds` (full scale) on `world`, recorded every model step `dt`.
pub fn explore_world(
    world: &Arc<World>,
    sim: Arc<Sim>,
    dt: f64,
    trials: usize,
    seconds: f64,
) -> Result<Vec<DriveRows>, String> {
    let scale = world.meta.scale;
    let rate = 1.0 / (dt * scale.sqrt());
    (0..trials)
        .map(|i| {
            let seed = mix_seed(&[u64::from(world.meta.index), i as u64, 0x7661]);
            explore_poses(
                world,
                sim.clone(),
                Profile::VertiAdaptor,
                seed,
                seconds * scale.sqrt(),
                rate,
            )
        })
        .collect()
}

/// One example per step of each drive: the model's inputs at a pose and the change to the
/// next (full-scale units).
pub fn drives_to_examples(
    drives: &[DriveRows],
    world: &World,
    model: &VaModel,
    encoder: &PatchEncoder,
) -> Vec<Example> {
    drives_to_rows(drives, world, encoder)
        .into_iter()
        .map(|(latent, roll, pitch, command, delta)| Example {
            roll,
            pitch,
            embedding: model.embed(&latent),
            command,
            delta,
        })
        .collect()
}

/// One step's raw inputs and target: terrain latent, roll, pitch, full-scale command, change.
pub type RawStep = ([f32; TERRAIN_DIM], f64, f64, (f64, f64), [f64; 6]);

/// The raw inputs of each step for training code that embeds with its own networks.
pub fn drives_to_rows(drives: &[DriveRows], world: &World, encoder: &PatchEncoder) -> Vec<RawStep> {
    let scale = world.meta.scale;
    let units = Units::new(scale);
    let mut out = Vec::new();
    for drive in drives {
        for w in drive.windows(2) {
            let (p, (v, s)) = w[0];
            let mut latent = [0f32; TERRAIN_DIM];
            terrain_latent(world, &p, scale, encoder, &mut latent);
            out.push((
                latent,
                p.roll,
                p.pitch,
                (v / scale.sqrt(), s),
                units.delta_to_model(&heading_delta(&p, &w[1].0)),
            ));
        }
    }
    out
}
