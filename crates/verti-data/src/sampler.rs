//! Mini-batches of windows of N consecutive steps, with heading-aligned elevation and
//! semantic patches recomputed from the worlds (the data store poses, not maps).
//!
//! The patches are the benchmark's own crops (`Observation::elevation_crop` and
//! `semantic_crop`): row 0 farthest ahead of the vehicle, column 0 farthest to its left, the
//! vehicle at the centre. Elevation is relative to the vehicle's height (the `z` feature, the
//! chassis reference point), so a patch does not depend on where the world's zero is.

use crate::reader::Dataset;
use crate::{DataError, Result};
use std::sync::Arc;
use verti_bench::features::{Feature, FeatureSource};
use verti_bench::observation::{CropSpec, Observation, Pose6};
use verti_core::rng::Rng;
use verti_world::World;

/// One mini-batch, row-major: `windows` × `steps` × (features | size × size).
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    pub windows: usize,
    pub steps: usize,
    /// The sampled features, in the order given to the sampler.
    pub features: Vec<Feature>,
    /// windows × steps × features.
    pub state: Vec<f64>,
    /// windows × steps × 2: commanded steering and target speed.
    pub commands: Vec<f64>,
    /// windows × steps × size × size, metres relative to the vehicle's `z`.
    pub elevation: Vec<f32>,
    /// windows × steps × size × size, semantic class ids.
    pub semantic: Vec<u8>,
    /// Each window's first row in the dataset's table.
    pub first_rows: Vec<usize>,
}

/// Draws windows of `steps` consecutive rows of one trial.
pub struct WindowSampler<'a> {
    data: &'a Dataset,
    /// World of each row's trial, by the dataset's world index.
    worlds: Vec<Arc<World>>,
    steps: usize,
    crop: CropSpec,
    features: Vec<Feature>,
    /// Every valid window start (row index).
    starts: Vec<usize>,
}

impl<'a> WindowSampler<'a> {
    /// A sampler over every window of `steps` rows that lies inside one trial. `worlds` must
    /// hold every world index the data use (e.g. `data.load_worlds()`).
    pub fn new(
        data: &'a Dataset,
        worlds: Vec<Arc<World>>,
        steps: usize,
        crop: CropSpec,
        features: Vec<Feature>,
    ) -> Result<WindowSampler<'a>> {
        if steps == 0 {
            return Err(DataError::Argument(
                "a window needs at least one step".into(),
            ));
        }
        if crop.size == 0 || !(crop.resolution.is_finite() && crop.resolution > 0.0) {
            return Err(DataError::Argument(format!(
                "bad patch size {} or resolution {}",
                crop.size, crop.resolution
            )));
        }
        let mut starts = Vec::new();
        for t in data.trials() {
            if !worlds.iter().any(|w| w.meta.index == t.world) {
                return Err(DataError::Argument(format!(
                    "trial {} was recorded on world {}, which is not among the worlds given",
                    t.trial, t.world
                )));
            }
            if t.len() >= steps {
                starts.extend(t.rows.0..=t.rows.1 - steps);
            }
        }
        Ok(WindowSampler {
            data,
            worlds,
            steps,
            crop,
            features,
            starts,
        })
    }

    /// How many distinct windows there are.
    pub fn windows(&self) -> usize {
        self.starts.len()
    }

    /// `count` windows drawn uniformly (with replacement) with `rng`: deterministic for a seed.
    pub fn sample(&self, rng: &mut Rng, count: usize) -> Result<Batch> {
        if self.starts.is_empty() {
            return Err(DataError::Argument(format!(
                "no trial has {} steps for a window",
                self.steps
            )));
        }
        let firsts: Vec<usize> = (0..count)
            .map(|_| self.starts[rng.below(self.starts.len() as u64) as usize])
            .collect();
        self.batch(&firsts)
    }

    /// The windows starting at the given table rows (each must be a valid window start).
    pub fn batch(&self, first_rows: &[usize]) -> Result<Batch> {
        let t = &self.data.table;
        let col = |name: &str| {
            t.f64(name)
                .ok_or_else(|| DataError::Run(format!("the table has no column {name}")))
        };
        let feats: Vec<&[f64]> = self
            .features
            .iter()
            .map(|f| col(f.name()))
            .collect::<Result<_>>()?;
        let pose_cols: Vec<&[f64]> = ["x", "y", "z", "roll", "pitch", "yaw"]
            .iter()
            .map(|n| col(n))
            .collect::<Result<_>>()?;
        let (steer, speed) = (col("cmd_steering")?, col("cmd_speed")?);
        let world_col = t.i32("world").expect("checked at load");
        let cells = self.crop.size * self.crop.size;
        let mut b = Batch {
            windows: first_rows.len(),
            steps: self.steps,
            features: self.features.clone(),
            state: Vec::with_capacity(first_rows.len() * self.steps * self.features.len()),
            commands: Vec::with_capacity(first_rows.len() * self.steps * 2),
            elevation: Vec::with_capacity(first_rows.len() * self.steps * cells),
            semantic: Vec::with_capacity(first_rows.len() * self.steps * cells),
            first_rows: first_rows.to_vec(),
        };
        for &first in first_rows {
            if self.starts.binary_search(&first).is_err() {
                return Err(DataError::Argument(format!(
                    "row {first} does not start a window of {} steps inside one trial",
                    self.steps
                )));
            }
            for r in first..first + self.steps {
                b.state.extend(feats.iter().map(|c| c[r]));
                b.commands.extend([steer[r], speed[r]]);
                let world = self
                    .worlds
                    .iter()
                    .find(|w| w.meta.index as i32 == world_col[r])
                    .expect("checked in new");
                let pose = Pose6 {
                    x: pose_cols[0][r],
                    y: pose_cols[1][r],
                    z: pose_cols[2][r],
                    roll: pose_cols[3][r],
                    pitch: pose_cols[4][r],
                    yaw: pose_cols[5][r],
                };
                let obs =
                    Observation::new(world, FeatureSource::at_rest(pose), [pose.x, pose.y], &[]);
                b.elevation.extend(
                    obs.elevation_crop(self.crop)
                        .data
                        .iter()
                        .map(|h| (h - pose.z) as f32),
                );
                b.semantic.extend(obs.semantic_crop(self.crop).data);
            }
        }
        Ok(b)
    }
}
