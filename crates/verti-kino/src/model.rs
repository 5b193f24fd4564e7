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
    /// What the networks predicted this step (the first `network_outputs` values).
    result: [f64; OUTPUT_DIM],
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
            result: [0.0; OUTPUT_DIM],
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

    /// Step phase 1: the networks' inputs for `state` under `command`, into `scratch`; returns
    /// the sine and cosine of the heading. (An attentive model's gate needs its network's
    /// output first: phase 2 finishes that input.)
    fn write_step_inputs(
        &self,
        state: &KinoState,
        command: (f64, f64),
        terrain: &Heightfield,
        units: Units,
        scratch: &mut StepScratch,
    ) -> (f64, f64) {
        let dt = self.dt();
        match self.file.card.kind {
            KinoKind::Ensemble | KinoKind::Decomposed => {
                write_inputs(state, command, terrain, units, dt, &mut scratch.input)
            }
            KinoKind::Attentive => {
                let m = &mut scratch.map;
                let reference = m
                    .reference
                    .expect("KinoModel::begin runs before an attentive model steps");
                write_offset(&reference, &state.pose, units, &mut m.offset);
                let n = m.features.len();
                write_head(state, command, units, dt, &mut m.dynamics_in[n..]);
                state.pose.yaw.sin_cos()
            }
        }
    }

    /// Step phase 2: the networks on the inputs of phase 1, into `scratch.result` — an
    /// ensemble's mean, or an attentive model's gated dynamics.
    fn run_networks(&self, scratch: &mut StepScratch) {
        let f = &*self.file;
        match f.card.kind {
            KinoKind::Ensemble | KinoKind::Decomposed => {
                scratch.sum.iter_mut().for_each(|v| *v = 0.0);
                for mlp in &f.mlps {
                    mlp.forward_into(&scratch.input, &mut scratch.mlp, &mut scratch.out);
                    accumulate(&mut scratch.sum, &scratch.out);
                }
                mean_into(&scratch.sum, f.mlps.len(), &mut scratch.result);
            }
            KinoKind::Attentive => {
                let m = &mut scratch.map;
                f.mlps[1].forward_into(&m.offset, &mut scratch.mlp, &mut m.gate);
                gate_features(m);
                f.mlps[2].forward_into(&m.dynamics_in, &mut scratch.mlp, &mut m.out);
                scratch.result = m.out.map(f64::from);
            }
        }
    }

    /// [`KinoModel::run_networks`] for two samples at once (bit for bit the same): each
    /// network evaluates both inputs side by side, hiding its adds' latency.
    fn run_networks_pair(&self, s: [&mut StepScratch; 2]) {
        let f = &*self.file;
        let [a, b] = s;
        match f.card.kind {
            KinoKind::Ensemble | KinoKind::Decomposed => {
                a.sum.iter_mut().for_each(|v| *v = 0.0);
                b.sum.iter_mut().for_each(|v| *v = 0.0);
                for mlp in &f.mlps {
                    mlp.forward_pair_into(
                        [&a.input, &b.input],
                        [&mut a.mlp, &mut b.mlp],
                        [&mut a.out, &mut b.out],
                    );
                    accumulate(&mut a.sum, &a.out);
                    accumulate(&mut b.sum, &b.out);
                }
                mean_into(&a.sum, f.mlps.len(), &mut a.result);
                mean_into(&b.sum, f.mlps.len(), &mut b.result);
            }
            KinoKind::Attentive => {
                let (ma, mb) = (&mut a.map, &mut b.map);
                f.mlps[1].forward_pair_into(
                    [&ma.offset, &mb.offset],
                    [&mut a.mlp, &mut b.mlp],
                    [&mut ma.gate, &mut mb.gate],
                );
                gate_features(ma);
                gate_features(mb);
                f.mlps[2].forward_pair_into(
                    [&ma.dynamics_in, &mb.dynamics_in],
                    [&mut a.mlp, &mut b.mlp],
                    [&mut ma.out, &mut mb.out],
                );
                a.result = ma.out.map(f64::from);
                b.result = mb.out.map(f64::from);
            }
        }
    }

    /// Step phase 3: the next state from the networks' `result` (world units).
    #[allow(clippy::too_many_arguments)]
    fn finish_step(
        &self,
        state: &KinoState,
        command: (f64, f64),
        terrain: &Heightfield,
        units: Units,
        geometry: Geometry,
        sc: (f64, f64),
        result: &[f64; OUTPUT_DIM],
    ) -> KinoState {
        let pose = &state.pose;
        let delta = match self.file.card.kind {
            KinoKind::Ensemble | KinoKind::Attentive => units.delta_to_world(result),
            KinoKind::Decomposed => {
                let dt_world = self.dt() / units.time_factor();
                let mut d = bicycle_on_ground(pose, command, terrain, geometry, dt_world, sc);
                // the network predicts the next attitude itself
                d[4] = result[0] - pose.roll;
                d[5] = result[1] - pose.pitch;
                d
            }
        };
        KinoState {
            pose: apply_delta_sc(pose, &delta, sc),
            last_delta: delta,
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
        let sc = self.write_step_inputs(state, command, terrain, units, scratch);
        self.run_networks(scratch);
        let result = scratch.result;
        self.finish_step(state, command, terrain, units, geometry, sc, &result)
    }

    /// Two states one step later, bit for bit what two [`KinoModel::step`] calls give, with
    /// the networks evaluated as a pair (each scratch must have seen the same `begin`).
    pub fn step_pair(
        &self,
        states: [&KinoState; 2],
        commands: [(f64, f64); 2],
        terrain: &Heightfield,
        units: Units,
        geometry: Geometry,
        scratch: &mut [StepScratch; 2],
    ) -> [KinoState; 2] {
        let [a, b] = scratch;
        let sc = [
            self.write_step_inputs(states[0], commands[0], terrain, units, a),
            self.write_step_inputs(states[1], commands[1], terrain, units, b),
        ];
        self.run_networks_pair([&mut *a, &mut *b]);
        [
            self.finish_step(
                states[0],
                commands[0],
                terrain,
                units,
                geometry,
                sc[0],
                &a.result,
            ),
            self.finish_step(
                states[1],
                commands[1],
                terrain,
                units,
                geometry,
                sc[1],
                &b.result,
            ),
        ]
    }
}

/// sum += out, in f32 as the ensemble has always summed.
fn accumulate(sum: &mut [f32], out: &[f32]) {
    for (s, o) in sum.iter_mut().zip(out) {
        *s += o;
    }
}

/// The ensemble mean: each f32 sum in f64 times 1/members.
fn mean_into(sum: &[f32], members: usize, out: &mut [f64; OUTPUT_DIM]) {
    let inv = 1.0 / members as f64;
    for (o, s) in out.iter_mut().zip(sum) {
        *o = *s as f64 * inv;
    }
}

/// An attentive model's dynamics input: the map features gated by the gate network's output.
fn gate_features(m: &mut MapContext) {
    let n = m.features.len();
    for ((x, e), g) in m.dynamics_in[..n].iter_mut().zip(&m.features).zip(&m.gate) {
        *x = e * squash(*g);
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
