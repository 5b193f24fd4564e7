//! A dataset's trajectories at the model step, with the terrain latent under every pose,
//! grouped by world: VertiAdaptor's "environments" (Algorithm 1 samples environments, then
//! trajectories within each).
//!
//! The latents take the patch encoder over every row, so they are computed once (on all
//! cores, the same bits on any thread count) and cached beside the dataset in
//! `va-terrain-<digest>.bin`, keyed by the encoder's weights, the step and the dataset's
//! checksums.

use crate::model::{Example, VaModel};
use crate::terrain::{TERRAIN_DIM, terrain_latent};
use crate::{Result, VaError};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_bench::observation::Pose6;
use verti_kino::features::{Units, heading_delta};
use verti_kino::samples::KinoData;
use verti_nn::patch::PatchEncoder;
use verti_world::{ElevationLevel, World};

/// One trial at the model step.
#[derive(Clone, Debug)]
pub struct VaTrajectory {
    /// Index into [`VaData::worlds`].
    pub world: usize,
    pub level: ElevationLevel,
    pub poses: Vec<Pose6>,
    /// Full-scale target speed (m/s) and steering, held from each pose to the next.
    pub commands: Vec<(f64, f64)>,
    /// [`TERRAIN_DIM`] values per pose.
    pub terrain: Vec<f32>,
}

impl VaTrajectory {
    pub fn len(&self) -> usize {
        self.poses.len()
    }
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }
    pub fn terrain_at(&self, t: usize) -> &[f32] {
        &self.terrain[t * TERRAIN_DIM..(t + 1) * TERRAIN_DIM]
    }
    /// The full-scale heading-frame change from pose `t` to `t + 1`.
    pub fn delta(&self, t: usize, units: Units) -> [f64; 6] {
        units.delta_to_model(&heading_delta(&self.poses[t], &self.poses[t + 1]))
    }
}

/// A dataset ready for VertiAdaptor.
pub struct VaData {
    pub worlds: Vec<Arc<World>>,
    pub trajectories: Vec<VaTrajectory>,
    pub units: Units,
    /// Model step, full-scale seconds.
    pub dt: f64,
    pub vehicle: String,
    pub set: String,
    pub eval_worlds: bool,
    pub hours: f64,
    pub dir: PathBuf,
}

impl VaData {
    /// Loads `dir` at step `dt` (full-scale seconds) and the terrain latent of every pose.
    pub fn load(
        dir: &Path,
        dt: f64,
        encoder: &PatchEncoder,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<VaData> {
        let kino = KinoData::load(dir, dt).map_err(|e| VaError::Data(e.to_string()))?;
        // one trajectory per trial: a step of one row keeps them whole
        let rows: usize = kino.trajectories.iter().map(|t| t.poses.len()).sum();
        let key = cache_key(dir, dt, encoder, rows)?;
        let cache = dir.join(format!("va-terrain-{key:016x}.bin"));
        let scale = kino.units.scale;
        let latents: Vec<f32> = match std::fs::read(&cache) {
            Ok(bytes) if bytes.len() == rows * TERRAIN_DIM * 4 => bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
            _ => {
                let done = std::sync::atomic::AtomicUsize::new(0);
                let total = kino.trajectories.len();
                let per: Vec<Vec<f32>> = kino
                    .trajectories
                    .par_iter()
                    .map(|t| {
                        let world = &kino.worlds[t.world];
                        let mut out = vec![0f32; t.poses.len() * TERRAIN_DIM];
                        for (p, o) in t.poses.iter().zip(out.chunks_exact_mut(TERRAIN_DIM)) {
                            terrain_latent(world, p, scale, encoder, o);
                        }
                        let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                        progress(n, total);
                        out
                    })
                    .collect();
                let flat: Vec<f32> = per.concat();
                let bytes: Vec<u8> = flat.iter().flat_map(|v| v.to_le_bytes()).collect();
                // a cache that cannot be written only costs time next run
                let _ = std::fs::write(&cache, bytes);
                flat
            }
        };
        let mut at = 0;
        let trajectories = kino
            .trajectories
            .iter()
            .map(|t| {
                let n = t.poses.len() * TERRAIN_DIM;
                let terrain = latents[at..at + n].to_vec();
                at += n;
                VaTrajectory {
                    world: t.world,
                    level: t.level,
                    poses: t.poses.clone(),
                    commands: t
                        .commands
                        .iter()
                        .map(|&(v, s)| (v / scale.sqrt(), s))
                        .collect(),
                    terrain,
                }
            })
            .collect();
        Ok(VaData {
            worlds: kino.worlds,
            trajectories,
            units: kino.units,
            dt,
            vehicle: kino.vehicle,
            set: kino.set,
            eval_worlds: kino.eval_worlds,
            hours: kino.hours,
            dir: dir.to_path_buf(),
        })
    }

    /// Trajectory indices per world (in dataset order), only trajectories of at least
    /// `min_len` poses.
    pub fn by_world(&self, min_len: usize) -> BTreeMap<usize, Vec<usize>> {
        let mut out: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (i, t) in self.trajectories.iter().enumerate() {
            if t.len() >= min_len {
                out.entry(t.world).or_default().push(i);
            }
        }
        out
    }

    /// One-step examples of `trajectories` with `model`'s embeddings.
    pub fn examples(&self, model: &VaModel, trajectories: &[usize]) -> Vec<Example> {
        let mut out = Vec::new();
        for &i in trajectories {
            let t = &self.trajectories[i];
            for s in 0..t.len() - 1 {
                out.push(Example {
                    roll: t.poses[s].roll,
                    pitch: t.poses[s].pitch,
                    embedding: model.embed(t.terrain_at(s)),
                    command: t.commands[s],
                    delta: t.delta(s, self.units),
                });
            }
        }
        out
    }
}

fn cache_key(dir: &Path, dt: f64, encoder: &PatchEncoder, rows: usize) -> Result<u64> {
    let manifest = dir.join("manifest.yaml");
    let text = std::fs::read(&manifest).map_err(|e| VaError::io(&manifest, e))?;
    let mut bytes = text;
    for v in encoder.network().params() {
        bytes.extend(v.to_le_bytes());
    }
    bytes.extend(dt.to_le_bytes());
    bytes.extend((rows as u64).to_le_bytes());
    bytes.extend(b"va-terrain-1");
    Ok(verti_nn::card::fnv1a64(&bytes))
}
