//! One step of a learned kinodynamic model, in world units: used alike by MPPI's rollouts, by
//! the accuracy evaluation and (through [`crate::features`]) by training.

use crate::attentive::{MapContext, squash, write_map, write_offset};
use crate::card::{KinoFile, KinoKind};
use crate::features::{
    Ground, INPUT_DIM, KinoState, OUTPUT_DIM, Units, apply_delta_sc, heading_delta, write_head,
    write_inputs,
};
use std::sync::Arc;
use verti_bench::observation::Pose6;
use verti_core::math::wrap_angle;
use verti_nn::MlpScratch;
use verti_world::Heightfield;

/// Geometry the decomposed model's bicycle needs (from the task).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    pub wheelbase: f64,
    pub max_steer: f64,
}

impl Default for Geometry {
    fn default() -> Self {
        // the HMMWV's
        Geometry {
            wheelbase: 3.378,
            max_steer: 0.5,
        }
    }
}

/// Work buffers of one caller (one per thread).
#[derive(Clone, Debug)]
pub struct StepScratch {
    input: [f32; INPUT_DIM],
    out: Vec<f32>,
    sum: Vec<f32>,
    mlp: MlpScratch,
    /// An attentive model's map, set by [`KinoModel::begin`].
    map: MapContext,
}

/// A loaded model, cheap to clone (the file is shared).
#[derive(Clone, Debug)]
pub struct KinoModel {
    file: Arc<KinoFile>,
}

impl KinoModel {
    pub fn new(file: Arc<KinoFile>) -> KinoModel {
        KinoModel { file }
    }
    pub fn file(&self) -> &KinoFile {
        &self.file
    }
    pub fn name(&self) -> &str {
        &self.file.card.name
    }
    /// The model step in full-scale seconds.
    pub fn dt(&self) -> f64 {
        self.file.card.dt
    }
    /// Multiply-adds of the networks per step.
    pub fn multiply_adds(&self) -> usize {
        self.file.mlps.iter().map(|m| m.multiply_adds()).sum()
    }

    pub fn scratch(&self) -> StepScratch {
        let n = self.file.card.kind.network_outputs();
        let widest = self
            .file
            .mlps
            .iter()
            .max_by_key(|m| m.inputs().max(m.outputs()));
        StepScratch {
            input: [0.0; INPUT_DIM],
            out: vec![0.0; n],
            sum: vec![0.0; n],
            mlp: widest.map(|m| m.scratch()).unwrap_or_default(),
            map: MapContext::new(match self.file.card.kind {
                KinoKind::Attentive => self.file.mlps[0].outputs(),
                _ => 0,
            }),
        }
    }

    /// Starts a plan (or an open-loop prediction) from `reference`: an attentive model encodes
    /// the terrain map around it, once, for every step that follows; other kinds need nothing.
    pub fn begin(
        &self,
        reference: &Pose6,
        terrain: &Heightfield,
        units: Units,
        scratch: &mut StepScratch,
    ) {
        if self.file.card.kind != KinoKind::Attentive {
            return;
        }
        let m = &mut scratch.map;
        write_map(reference, terrain, units, &mut m.map);
        self.file.mlps[0].forward_into(&m.map, &mut scratch.mlp, &mut m.features);
        m.reference = Some(*reference);
    }

    /// An attentive model's change over one step (full-scale units), from the map features
    /// gated by the offset and the head.
    fn attentive_delta(
        &self,
        state: &KinoState,
        command: (f64, f64),
        units: Units,
        scratch: &mut StepScratch,
    ) -> [f64; OUTPUT_DIM] {
        let f = &*self.file;
        let m = &mut scratch.map;
        let reference = m
            .reference
            .expect("KinoModel::begin runs before an attentive model steps");
        write_offset(&reference, &state.pose, units, &mut m.offset);
        f.mlps[1].forward_into(&m.offset, &mut scratch.mlp, &mut m.gate);
        let n = m.features.len();
        for ((x, e), g) in m.dynamics_in[..n].iter_mut().zip(&m.features).zip(&m.gate) {
            *x = e * squash(*g);
        }
        write_head(state, command, units, f.card.dt, &mut m.dynamics_in[n..]);
        f.mlps[2].forward_into(&m.dynamics_in, &mut scratch.mlp, &mut m.out);
        m.out.map(f64::from)
    }

    /// The networks' mean prediction for the raw inputs in `scratch.input`, into `out` (the
    /// standardisation is folded into the networks).
    fn predict(&self, scratch: &mut StepScratch, out: &mut [f64]) {
        let f = &*self.file;
        scratch.sum.iter_mut().for_each(|v| *v = 0.0);
        for mlp in &f.mlps {
            mlp.forward_into(&scratch.input, &mut scratch.mlp, &mut scratch.out);
            for (s, o) in scratch.sum.iter_mut().zip(&scratch.out) {
                *s += o;
            }
        }
        let inv = 1.0 / f.mlps.len() as f64;
        for (o, s) in out.iter_mut().zip(&scratch.sum) {
            *o = *s as f64 * inv;
        }
    }

    /// The state one model step later under `command` (target speed m/s, steering), world
    /// units. `terrain` is the world's (undeformed) ground. An attentive model steps from the
    /// map of the last [`KinoModel::begin`].
    pub fn step(
        &self,
        state: &KinoState,
        command: (f64, f64),
        terrain: &Heightfield,
        units: Units,
        geometry: Geometry,
        scratch: &mut StepScratch,
    ) -> KinoState {
        let dt = self.dt();
        let pose = &state.pose;
        let (delta, sc) = match self.file.card.kind {
            KinoKind::Ensemble => {
                let sc = write_inputs(state, command, terrain, units, dt, &mut scratch.input);
                let mut d = [0.0; OUTPUT_DIM];
                self.predict(scratch, &mut d);
                (units.delta_to_world(&d), sc)
            }
            KinoKind::Decomposed => {
                let sc = write_inputs(state, command, terrain, units, dt, &mut scratch.input);
                let mut rp = [0.0; 2];
                self.predict(scratch, &mut rp);
                let dt_world = dt / units.time_factor();
                let mut d = bicycle_on_ground(pose, command, terrain, geometry, dt_world, sc);
                // the network predicts the next attitude itself
                d[4] = rp[0] - pose.roll;
                d[5] = rp[1] - pose.pitch;
                (d, sc)
            }
            KinoKind::Attentive => {
                let d = self.attentive_delta(state, command, units, scratch);
                (units.delta_to_world(&d), pose.yaw.sin_cos())
            }
        };
        KinoState {
            pose: apply_delta_sc(pose, &delta, sc),
            last_delta: delta,
        }
    }
}

/// Heading-frame change of a kinematic bicycle driving `command` for `dt` seconds: it turns
/// by dψ = v/L·tan(δ)·dt along a circular arc (chord at half the turn).
pub fn bicycle_delta(command: (f64, f64), g: Geometry, dt: f64) -> [f64; OUTPUT_DIM] {
    let (v, steer) = command;
    let dpsi = v / g.wheelbase * (steer.clamp(-1.0, 1.0) * g.max_steer).tan() * dt;
    let chord = if dpsi.abs() < 1e-9 {
        v * dt
    } else {
        v * dt * (0.5 * dpsi).sin() / (0.5 * dpsi)
    };
    let (s, c) = (0.5 * dpsi).sin_cos();
    [chord * c, chord * s, 0.0, wrap_angle(dpsi), 0.0, 0.0]
}

/// [`bicycle_delta`] with z following the ground: the ride height over the terrain is held.
/// `sc` is the sine and cosine of `pose.yaw`. Roll and pitch changes are zero.
fn bicycle_on_ground(
    pose: &Pose6,
    command: (f64, f64),
    terrain: &Heightfield,
    geometry: Geometry,
    dt_world: f64,
    sc: (f64, f64),
) -> [f64; OUTPUT_DIM] {
    let mut d = bicycle_delta(command, geometry, dt_world);
    let ground = Ground::new(terrain);
    let ride = pose.z - ground.height(pose.x, pose.y);
    let next = apply_delta_sc(pose, &d, sc);
    d[2] = ground.height(next.x, next.y) + ride - pose.z;
    d
}

/// The bicycle as a model of the same shape as the learned ones: forward/left/yaw from the
/// command, z held on the ground (ride height kept), roll and pitch held. The baseline every
/// learned model is compared with.
pub fn bicycle_step(
    state: &KinoState,
    command: (f64, f64),
    terrain: &Heightfield,
    geometry: Geometry,
    dt_world: f64,
) -> KinoState {
    let pose = &state.pose;
    let sc = pose.yaw.sin_cos();
    let d = bicycle_on_ground(pose, command, terrain, geometry, dt_world, sc);
    KinoState {
        pose: apply_delta_sc(pose, &d, sc),
        last_delta: d,
    }
}

/// The state at `pose` given the pose one model step earlier.
pub fn state_from(previous: &Pose6, pose: &Pose6) -> KinoState {
    KinoState {
        pose: *pose,
        last_delta: heading_delta(previous, pose),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bicycle_arc_matches_the_circle() {
        let g = Geometry {
            wheelbase: 2.0,
            max_steer: 0.5,
        };
        let (v, dt) = (3.0, 0.5);
        let d = bicycle_delta((v, 1.0), g, dt);
        let radius = g.wheelbase / 0.5f64.tan();
        let dpsi = v * dt / radius;
        // exact point on the circle after arc length v·dt
        let (x, y) = (radius * dpsi.sin(), radius * (1.0 - dpsi.cos()));
        assert!((d[0] - x).abs() < 1e-12 && (d[1] - y).abs() < 1e-12);
        assert!((d[3] - dpsi).abs() < 1e-12);
        let straight = bicycle_delta((v, 0.0), g, dt);
        assert_eq!(straight, [1.5, 0.0, 0.0, 0.0, 0.0, 0.0]);
    }
}
