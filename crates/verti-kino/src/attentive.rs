//! TAL's model (terrain-attentive learning, Datar et al. 2024, in spirit): the terrain is seen
//! once per plan, as a heading-aligned elevation map around the vehicle encoded to a feature
//! vector; every rollout step then *gates* those features by where the vehicle now stands
//! relative to the map (the "attention" to the patch under it) and predicts the pose change
//! from the gated features, attitude, pose rates and command.
//!
//! Three networks: encoder (map → features, ReLU), gate (offset → one logit per feature,
//! squashed to (0, 1) here by [`squash`]), dynamics ([gated features, head] → heading-frame change).
//! The encoder runs once per plan; a rollout step costs the gate and the dynamics only, and
//! reads no terrain at all.

use crate::features::{
    COMMAND_DIM, KinoState, OUTPUT_DIM, STATE_DIM, Units, heading_delta, input_names, write_head,
};
use verti_bench::observation::Pose6;
use verti_world::Heightfield;

/// Map rows ahead of the reference pose (m, full scale): from behind the vehicle to about
/// where a 4-s rollout at 3 m/s ends.
pub const MAP_AHEAD: [f64; 10] = [-3.0, -1.5, 0.0, 1.5, 3.0, 4.5, 6.0, 7.5, 9.0, 10.5];
/// Map columns to the left (m, full scale).
pub const MAP_LEFT: [f64; 8] = [-5.25, -3.75, -2.25, -0.75, 0.75, 2.25, 3.75, 5.25];
pub const MAP_DIM: usize = MAP_AHEAD.len() * MAP_LEFT.len();
/// Offset of the vehicle from the reference pose: forward, left, up (m, full scale) in the
/// reference's heading frame, and the sine and cosine of the heading change.
pub const OFFSET_DIM: usize = 5;
/// Attitude, pose rates and command (as every kind has them).
pub const HEAD_DIM: usize = STATE_DIM + COMMAND_DIM;
/// The card's input columns: map, offset, head.
pub const ATTENTIVE_INPUT_DIM: usize = MAP_DIM + OFFSET_DIM + HEAD_DIM;

/// Names of the card's input columns, in order.
pub fn attentive_input_names() -> Vec<String> {
    let mut names = Vec::with_capacity(ATTENTIVE_INPUT_DIM);
    for a in MAP_AHEAD {
        for l in MAP_LEFT {
            names.push(format!("map({a:+},{l:+})"));
        }
    }
    for n in [
        "off_fwd",
        "off_left",
        "off_up",
        "off_sin_yaw",
        "off_cos_yaw",
    ] {
        names.push(n.to_string());
    }
    names.extend(input_names().into_iter().take(HEAD_DIM));
    names
}

/// The map around `reference`: terrain heights relative to the reference point, full-scale
/// metres, rows ahead then columns left.
pub fn write_map(reference: &Pose6, terrain: &Heightfield, units: Units, out: &mut [f32]) {
    let (s, c) = reference.yaw.sin_cos();
    let ground = crate::features::Ground::new(terrain);
    let inv_scale = 1.0 / units.scale;
    let mut k = 0;
    for a in MAP_AHEAD {
        let a = a * units.scale;
        for l in MAP_LEFT {
            let l = l * units.scale;
            let h = ground.height(reference.x + c * a - s * l, reference.y + s * a + c * l);
            out[k] = ((h - reference.z) * inv_scale) as f32;
            k += 1;
        }
    }
}

/// Where `pose` is relative to the map's `reference` (see [`OFFSET_DIM`]).
pub fn write_offset(reference: &Pose6, pose: &Pose6, units: Units, out: &mut [f32]) {
    let d = units.delta_to_model(&heading_delta(reference, pose));
    let (s, c) = d[3].sin_cos();
    for (o, v) in out.iter_mut().zip([d[0], d[1], d[2], s, c]) {
        *o = v as f32;
    }
}

/// The gate's squashing: a sigmoid shape on (0, 1) from the softsign, ½ + ½·x/(1 + |x|).
/// The logistic function would cost an exponential per feature and rollout step (half a
/// million per plan); this costs a division.
#[inline]
pub fn squash(x: f32) -> f32 {
    0.5 + 0.5 * x / (1.0 + x.abs())
}

/// One training row: map at `reference`, offset of `state` from it, and the head.
pub fn write_row(
    reference: &Pose6,
    state: &KinoState,
    command: (f64, f64),
    terrain: &Heightfield,
    units: Units,
    dt: f64,
    out: &mut [f32],
) {
    let (map, rest) = out.split_at_mut(MAP_DIM);
    let (offset, head) = rest.split_at_mut(OFFSET_DIM);
    write_map(reference, terrain, units, map);
    write_offset(reference, &state.pose, units, offset);
    write_head(state, command, units, dt, head);
}

/// The per-plan part of an attentive model's work buffers: the map's reference pose and its
/// encoded features.
#[derive(Clone, Debug, Default)]
pub struct MapContext {
    pub reference: Option<Pose6>,
    pub map: Vec<f32>,
    pub features: Vec<f32>,
    pub offset: [f32; OFFSET_DIM],
    pub gate: Vec<f32>,
    /// Gated features followed by the head: the dynamics network's input.
    pub dynamics_in: Vec<f32>,
    pub out: [f32; OUTPUT_DIM],
}

impl MapContext {
    pub fn new(features: usize) -> MapContext {
        MapContext {
            reference: None,
            map: vec![0.0; MAP_DIM],
            features: vec![0.0; features],
            offset: [0.0; OFFSET_DIM],
            gate: vec![0.0; features],
            dynamics_in: vec![0.0; features + HEAD_DIM],
            out: [0.0; OUTPUT_DIM],
        }
    }
}
