//! VertiAdaptor inside MPPI: every sampled control sequence is rolled out with the adapted
//! model, Σ α_i G_i per step of 0.1 s (full scale), from the vehicle's pose.
//!
//! The terrain embedding under a rollout pose comes from a grid memo: cells 2 m apart (full
//! scale) and eight headings, each embedded once per trial when a plan first needs it; a
//! pose reads its nearest cell. Before each plan the cells every rollout can reach (within the
//! horizon at the highest sampled speed) are filled, so the loop over samples does no terrain
//! work. Embedding every pose of every sample exactly would cost one patch encoding each —
//! thousands per plan.

use crate::adapter::Adapter;
use crate::model::{EMBED, POSE_DIM};
use crate::terrain::{TERRAIN_DIM, terrain_latent};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};
use verti_bench::observation::Pose6;
use verti_bench::{Observation, TaskInfo};
use verti_kino::features::{Units, apply_delta};
use verti_nn::patch::PatchEncoder;
use verti_systems::rollout::{ControlSamples, PlanContext, RolloutModel, Rollouts};

/// Spacing of the embedding grid, full-scale metres.
pub const GRID_CELL: f64 = 2.0;
/// Heading bins of the embedding grid.
pub const GRID_HEADINGS: usize = 8;

type Key = (i64, i64, usize);

/// Embeddings of the trial's world on the grid, filled on demand.
#[derive(Default)]
pub struct EmbeddingGrid {
    cells: HashMap<Key, [f32; 2 * EMBED]>,
    cell: f64,
}

impl EmbeddingGrid {
    fn key(&self, x: f64, y: f64, yaw: f64) -> Key {
        let bin = 2.0 * PI / GRID_HEADINGS as f64;
        let h = (yaw / bin).round().rem_euclid(GRID_HEADINGS as f64) as usize;
        (
            (x / self.cell).round() as i64,
            (y / self.cell).round() as i64,
            h,
        )
    }

    fn reset(&mut self, scale: f64) {
        self.cells.clear();
        self.cell = GRID_CELL * scale;
    }

    /// Embeds every grid point within `radius` of `pose`, at `pose`'s heading bin and its two
    /// neighbours, that is not embedded yet.
    fn fill(&mut self, obs: &Observation, adapter: &Adapter, encoder: &PatchEncoder, radius: f64) {
        let c = self.cell;
        let n = (radius / c).ceil() as i64;
        let (cx, cy, h0) = self.key(obs.pose.x, obs.pose.y, obs.pose.yaw);
        let mut latent = [0f32; TERRAIN_DIM];
        for dx in -n..=n {
            for dy in -n..=n {
                if ((dx * dx + dy * dy) as f64).sqrt() * c > radius + c {
                    continue;
                }
                for dh in [GRID_HEADINGS - 1, 0, 1] {
                    let key = (cx + dx, cy + dy, (h0 + dh) % GRID_HEADINGS);
                    if self.cells.contains_key(&key) {
                        continue;
                    }
                    let pose = Pose6 {
                        x: key.0 as f64 * c,
                        y: key.1 as f64 * c,
                        yaw: key.2 as f64 * 2.0 * PI / GRID_HEADINGS as f64,
                        ..Pose6::default()
                    };
                    terrain_latent(obs.world(), &pose, obs.world_scale, encoder, &mut latent);
                    self.cells.insert(key, adapter.model().embed(&latent));
                }
            }
        }
    }

    /// The embedding nearest `pose`, or `fallback` off the filled grid.
    fn get<'a>(&'a self, pose: &Pose6, fallback: &'a [f32; 2 * EMBED]) -> &'a [f32; 2 * EMBED] {
        self.cells
            .get(&self.key(pose.x, pose.y, pose.yaw))
            .unwrap_or(fallback)
    }

    pub fn len(&self) -> usize {
        self.cells.len()
    }
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }
}

/// MPPI's rollout model: the adapted VertiAdaptor (or a baseline card).
pub struct VaRollout {
    adapter: Arc<Mutex<Adapter>>,
    encoder: PatchEncoder,
    grid: EmbeddingGrid,
    units: Units,
    alpha: Vec<f64>,
    here: [f32; 2 * EMBED],
    start: Pose6,
}

impl VaRollout {
    pub fn new(adapter: Arc<Mutex<Adapter>>, encoder: PatchEncoder) -> VaRollout {
        VaRollout {
            adapter,
            encoder,
            grid: EmbeddingGrid::default(),
            units: Units::new(1.0),
            alpha: Vec::new(),
            here: [0.0; 2 * EMBED],
            start: Pose6::default(),
        }
    }
}

impl RolloutModel for VaRollout {
    fn reset(&mut self, task: &TaskInfo) {
        self.units = Units::new(task.world_scale);
        self.grid.reset(task.world_scale);
    }

    fn prepare(&mut self, obs: &Observation, ctx: &PlanContext) {
        let adapter = self
            .adapter
            .lock()
            .expect("the adapter lock is never poisoned");
        self.alpha = adapter.alpha().to_vec();
        let dt_world = adapter.dt_world();
        let reach = ctx.speed_range.1.max(ctx.nominal_speed) * dt_world * ctx.horizon as f64;
        self.grid.fill(obs, &adapter, &self.encoder, reach);
        self.here = *self.grid.get(&obs.pose, &[0.0; 2 * EMBED]);
        self.start = obs.pose;
    }

    fn rollout(&mut self, _ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts) {
        let adapter = self
            .adapter
            .lock()
            .expect("the adapter lock is never poisoned");
        let model = adapter.model();
        let h = controls.horizon;
        let speed_factor = 1.0 / self.units.scale.sqrt();
        let mut g = vec![0.0; model.card.bases * POSE_DIM];
        for s in 0..controls.samples {
            let mut pose = self.start;
            for t in 0..h {
                let (v, steer) = controls.controls[s * h + t];
                let e = self.grid.get(&pose, &self.here);
                model.basis_changes(pose.roll, pose.pitch, e, (v * speed_factor, steer), &mut g);
                let d: [f64; POSE_DIM] = std::array::from_fn(|j| {
                    (0..self.alpha.len())
                        .map(|i| self.alpha[i] * g[i * POSE_DIM + j])
                        .sum()
                });
                pose = apply_delta(&pose, &self.units.delta_to_world(&d));
                out.poses[s * h + t] = pose;
            }
        }
    }
}
