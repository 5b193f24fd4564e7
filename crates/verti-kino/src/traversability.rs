//! TNT's learned traversability (Pan et al. 2024, in spirit): a small fully convolutional
//! network reads terrain slopes and predicts, for the ground under a vehicle centred on a
//! cell, how hard the next second will be: the largest roll or pitch it reaches and how far it
//! falls short of its commanded speed. Trained self-supervised from exploration datasets
//! (`verti learn kino --model tnt`); applied once per plan to a map around the vehicle; its
//! value at every rollout pose is a cost
//! ([`AttitudeCost::with_traversability`](crate::rollout::AttitudeCost::with_traversability)).
//!
//! Input: two channels of slopes, along the heading and to the left (dimensionless rise over
//! run, full-scale), on a square lattice of `SPACING`; slopes ignore the absolute height, so
//! the network applies to any cell of a larger map, and valid convolutions give every map
//! cell exactly the value a training patch centred there gets.

use crate::features::{Ground, Units, heading_delta};
use std::path::Path;
use std::sync::Arc;
use verti_bench::observation::Pose6;
use verti_nn::{Network, Shape};
use verti_world::Heightfield;

/// Lattice spacing, full-scale metres.
pub const SPACING: f64 = 0.75;
/// Slope cells one output cell sees per side (its receptive field): 6.75 m, about the
/// HMMWV's length plus a margin.
pub const FIELD: usize = 9;
pub const CHANNELS: usize = 2;
/// Attitude risk (largest |roll| or |pitch| over the next second, in units of `RISK_ANGLE`)
/// and slowdown (1 − distance made good / distance commanded, in [0, 1]).
pub const OUTPUTS: usize = 2;
pub const RISK_ANGLE: f64 = 0.5;
/// How far ahead the labels look, full-scale seconds.
pub const LABEL_HORIZON: f64 = 1.0;
/// The plan map: cells ahead from `MAP_BEHIND` and to each side, one per `SPACING`.
pub const MAP_CELLS: usize = 24;
pub const MAP_BEHIND: f64 = -3.0;

/// Slope channels ([`CHANNELS`] × side × side, side = `cells + FIELD − 1`) for a `cells` ×
/// `cells` block of output cells in the heading frame of `frame`: output cell (a, b) is
/// centred at `origin + (a, b)·SPACING` (ahead, left), full scale.
pub fn write_slopes(
    frame: &Pose6,
    origin: (f64, f64),
    cells: usize,
    terrain: &Heightfield,
    units: Units,
    out: &mut [f32],
) {
    let side = cells + FIELD - 1;
    let lattice = side + 1;
    let (s, c) = frame.yaw.sin_cos();
    let ground = Ground::new(terrain);
    let sp = SPACING * units.scale;
    let half = 0.5 * FIELD as f64;
    let mut h = vec![0.0; lattice * lattice];
    for i in 0..lattice {
        let a = (origin.0 + (i as f64 - half) * SPACING) * units.scale;
        for j in 0..lattice {
            let l = (origin.1 + (j as f64 - half) * SPACING) * units.scale;
            h[i * lattice + j] = ground.height(frame.x + c * a - s * l, frame.y + s * a + c * l);
        }
    }
    let plane = side * side;
    for i in 0..side {
        for j in 0..side {
            let here = h[i * lattice + j];
            out[i * side + j] = ((h[(i + 1) * lattice + j] - here) / sp) as f32;
            out[plane + i * side + j] = ((h[i * lattice + j + 1] - here) / sp) as f32;
        }
    }
}

/// Labels of the pose at index `t` of a trajectory sampled every `dt_world` seconds, or
/// `None` where the trajectory ends within the label horizon or the command was too slow to
/// judge progress by.
pub fn labels(
    poses: &[Pose6],
    commands: &[(f64, f64)],
    t: usize,
    steps: usize,
    dt_world: f64,
    units: Units,
) -> Option<[f32; OUTPUTS]> {
    if t + steps >= poses.len() {
        return None;
    }
    let commanded: f64 = commands[t..t + steps]
        .iter()
        .map(|c| c.0.max(0.0))
        .sum::<f64>()
        * dt_world;
    if commanded < 0.5 * units.scale * steps as f64 * dt_world {
        return None;
    }
    let attitude = poses[t + 1..=t + steps]
        .iter()
        .map(|p| p.roll.abs().max(p.pitch.abs()))
        .fold(0.0, f64::max);
    let d = heading_delta(&poses[t], &poses[t + steps]);
    let made = d[0].hypot(d[1]);
    Some([
        (attitude / RISK_ANGLE) as f32,
        (1.0 - made / commanded).clamp(0.0, 1.0) as f32,
    ])
}

/// A trained traversability network, with the same weights laid out for the plan map.
#[derive(Clone, Debug)]
pub struct Traversability {
    pub patch: Arc<Network>,
    map: Arc<Network>,
}

impl Traversability {
    /// Checks the network reads one [`FIELD`]-wide patch of slopes and gives [`OUTPUTS`]
    /// values, and builds its plan-map twin (same weights, larger input).
    pub fn new(net: Arc<Network>) -> Result<Traversability, String> {
        let name = net.card().name.clone();
        let want = Shape::Image([CHANNELS, FIELD, FIELD]);
        if net.input_shape() != want || net.output_shape().len() != OUTPUTS {
            return Err(format!(
                "{name}: a traversability network maps {want} to {OUTPUTS} values, this one {} to {}",
                net.input_shape(),
                net.output_shape()
            ));
        }
        let mut card = net.card().clone();
        let side = MAP_CELLS + FIELD - 1;
        card.input = Shape::Image([CHANNELS, side, side]);
        let map = Network::from_params(card, net.params())
            .map_err(|e| format!("{name}: not fully convolutional: {e}"))?;
        if map.output_shape().len() != OUTPUTS * MAP_CELLS * MAP_CELLS {
            return Err(format!(
                "{name}: not fully convolutional (output {})",
                map.output_shape()
            ));
        }
        Ok(Traversability {
            patch: net,
            map: Arc::new(map),
        })
    }

    pub fn load(path: &Path) -> Result<Traversability, String> {
        let net = Network::load(path).map_err(|e| e.to_string())?;
        Traversability::new(Arc::new(net))
    }

    /// The plan map around `frame`: one difficulty per cell (risk + slowdown).
    pub fn plan_map(&self, frame: &Pose6, terrain: &Heightfield, units: Units) -> TravMap {
        let side = MAP_CELLS + FIELD - 1;
        let mut input = vec![0.0; CHANNELS * side * side];
        let origin = (MAP_BEHIND, -0.5 * (MAP_CELLS - 1) as f64 * SPACING);
        write_slopes(frame, origin, MAP_CELLS, terrain, units, &mut input);
        let out = self.map.forward(&input);
        let plane = MAP_CELLS * MAP_CELLS;
        let cost: Vec<f64> = (0..plane)
            .map(|k| f64::from(out[k].max(0.0) + out[plane + k].max(0.0)))
            .collect();
        let outside = cost.iter().copied().fold(0.0, f64::max);
        TravMap {
            frame: *frame,
            origin,
            scale: units.scale,
            cost,
            outside,
        }
    }
}

/// Difficulty per cell around a plan's start pose.
#[derive(Clone, Debug)]
pub struct TravMap {
    frame: Pose6,
    origin: (f64, f64),
    scale: f64,
    pub cost: Vec<f64>,
    /// The value off the map: its largest (unknown ground is taken as the worst seen).
    pub outside: f64,
}

impl TravMap {
    /// Difficulty of the cell under `pose` (nearest cell).
    pub fn at(&self, pose: &Pose6) -> f64 {
        let d = heading_delta(&self.frame, pose);
        let a = ((d[0] / self.scale - self.origin.0) / SPACING).round();
        let b = ((d[1] / self.scale - self.origin.1) / SPACING).round();
        let n = MAP_CELLS as f64;
        if a < 0.0 || b < 0.0 || a >= n || b >= n {
            return self.outside;
        }
        self.cost[a as usize * MAP_CELLS + b as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_core::Rng;
    use verti_nn::{LayerSpec, ModelCard};

    fn random_net() -> Arc<Network> {
        let conv = |i, o, k| LayerSpec::Conv2d {
            in_channels: i,
            out_channels: o,
            kernel: k,
            stride: 1,
            padding: 0,
        };
        let layers = vec![
            conv(CHANNELS, 4, 3),
            LayerSpec::Relu,
            conv(4, 4, 3),
            LayerSpec::Relu,
            conv(4, OUTPUTS, FIELD - 4),
            LayerSpec::Flatten,
        ];
        let n: usize = layers.iter().map(|l| l.parameter_count()).sum();
        let mut rng = Rng::new(5);
        let params: Vec<f32> = (0..n).map(|_| rng.normal() as f32 * 0.3).collect();
        let card = ModelCard::new("trav", Shape::Image([CHANNELS, FIELD, FIELD]), layers);
        Arc::new(Network::from_params(card, &params).unwrap())
    }

    #[test]
    fn every_map_cell_is_what_a_patch_centred_there_gets() {
        let n = 65;
        let heights: Vec<f64> = (0..n * n)
            .map(|i| ((i % n) as f64 * 0.37).sin() * 1.5 + ((i / n) as f64 * 0.21).cos())
            .collect();
        let hf = Heightfield::new(n, 0.5, heights);
        let t = Traversability::new(random_net()).unwrap();
        let units = Units::new(1.0);
        let frame = Pose6 {
            x: 1.0,
            y: -2.0,
            yaw: 0.6,
            ..Default::default()
        };
        let map = t.plan_map(&frame, &hf, units);
        let (s, c) = frame.yaw.sin_cos();
        let mut patch = vec![0.0; CHANNELS * FIELD * FIELD];
        for (a, b) in [(0, 0), (5, 17), (23, 23), (11, 2)] {
            let ahead = MAP_BEHIND + a as f64 * SPACING;
            let left = -0.5 * (MAP_CELLS - 1) as f64 * SPACING + b as f64 * SPACING;
            let centre = Pose6 {
                x: frame.x + c * ahead - s * left,
                y: frame.y + s * ahead + c * left,
                ..frame
            };
            write_slopes(&centre, (0.0, 0.0), 1, &hf, units, &mut patch);
            let y = t.patch.forward(&patch);
            let want = f64::from(y[0].max(0.0) + y[1].max(0.0));
            assert!(
                (map.cost[a * MAP_CELLS + b] - want).abs() < 1e-5,
                "cell {a},{b}"
            );
            assert!((map.at(&centre) - want).abs() < 1e-5, "lookup {a},{b}");
        }
        // far off the map: the worst value seen
        let far = Pose6 { x: 100.0, ..frame };
        assert_eq!(map.at(&far), map.outside);
    }

    #[test]
    fn labels_read_tilt_and_lost_progress() {
        let units = Units::new(1.0);
        let dt = 0.2;
        let moving: Vec<Pose6> = (0..8)
            .map(|k| Pose6 {
                x: k as f64 * 0.6,
                roll: if k == 3 { -0.25 } else { 0.0 },
                ..Default::default()
            })
            .collect();
        let cmd = vec![(3.0, 0.0); 8];
        let y = labels(&moving, &cmd, 0, 5, dt, units).unwrap();
        assert!((y[0] - (0.25 / RISK_ANGLE) as f32).abs() < 1e-6);
        assert!(y[1].abs() < 1e-6, "made good all it was told: {}", y[1]);
        let stuck = vec![Pose6::default(); 8];
        assert_eq!(labels(&stuck, &cmd, 0, 5, dt, units).unwrap(), [0.0, 1.0]);
        // too close to the end, or too slow a command to judge
        assert!(labels(&moving, &cmd, 3, 5, dt, units).is_none());
        assert!(labels(&moving, &[(0.1, 0.0); 8], 0, 5, dt, units).is_none());
    }
}
