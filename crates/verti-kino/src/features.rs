//! What a learned kinodynamic step sees and predicts, computed by one piece of code for
//! training (from dataset rows and the world) and for planning (inside MPPI's rollouts), so
//! the two cannot drift apart.
//!
//! Frames and units. Deltas are in the *heading frame* of the pose they start from: yaw only,
//! gravity-aligned (forward, left, up), as VertiAdaptor and TAL use. Models work in full-scale
//! units: on a world of scale s a length is divided by s and a duration by √s (Froude scaling,
//! the rule verti's scaled worlds follow), so one model serves every scale of its vehicle.
//!
//! Input (22 values): roll and pitch; the pose rates over the previous step (forward, left,
//! up, yaw, roll, pitch per second); the command (target speed, steering); and the terrain
//! height, relative to the vehicle's reference point, at a 4 x 3 grid of points in the heading
//! frame (behind the rear axle to one wheelbase ahead of the front, across the track).
//! Output (6 values): the heading-frame pose change over one model step.

use std::f64::consts::PI;
use verti_bench::observation::Pose6;
use verti_core::math::wrap_angle;
use verti_world::Heightfield;

/// Pose rates and attitude.
pub const STATE_DIM: usize = 8;
/// Target speed (m/s) and steering ([-1, 1], + left).
pub const COMMAND_DIM: usize = 2;
/// Terrain probe points ahead (m, full scale; the HMMWV's wheelbase is 3.4 m).
pub const PROBE_AHEAD: [f64; 4] = [-1.7, 0.0, 1.7, 3.4];
/// Terrain probe points to the left (m, full scale; the HMMWV's track is ~1.8 m).
pub const PROBE_LEFT: [f64; 3] = [-0.9, 0.0, 0.9];
pub const TERRAIN_DIM: usize = PROBE_AHEAD.len() * PROBE_LEFT.len();
pub const INPUT_DIM: usize = STATE_DIM + COMMAND_DIM + TERRAIN_DIM;
/// Forward, left, up, yaw, roll, pitch.
pub const OUTPUT_DIM: usize = 6;
pub const OUTPUT_NAMES: [&str; OUTPUT_DIM] = ["fwd", "left", "z", "yaw", "roll", "pitch"];

/// The input features' names, in order (for cards and error messages).
pub fn input_names() -> Vec<String> {
    let mut names: Vec<String> = [
        "roll",
        "pitch",
        "v_fwd",
        "v_left",
        "v_z",
        "w_yaw",
        "w_roll",
        "w_pitch",
        "cmd_speed",
        "cmd_steer",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for a in PROBE_AHEAD {
        for l in PROBE_LEFT {
            names.push(format!("h({a:+},{l:+})"));
        }
    }
    names
}

/// Pose change from `from` to `to` in the heading frame of `from` (world units).
pub fn heading_delta(from: &Pose6, to: &Pose6) -> [f64; OUTPUT_DIM] {
    let (s, c) = from.yaw.sin_cos();
    let (dx, dy) = (to.x - from.x, to.y - from.y);
    [
        c * dx + s * dy,
        -s * dx + c * dy,
        to.z - from.z,
        wrap_angle(to.yaw - from.yaw),
        to.roll - from.roll,
        to.pitch - from.pitch,
    ]
}

/// `pose` moved by a heading-frame change (world units): the inverse of [`heading_delta`].
pub fn apply_delta(pose: &Pose6, d: &[f64; OUTPUT_DIM]) -> Pose6 {
    let (s, c) = pose.yaw.sin_cos();
    apply_delta_sc(pose, d, (s, c))
}

/// [`apply_delta`] with the sine and cosine of `pose.yaw` already known (rollouts compute them
/// once per step).
#[inline]
pub fn apply_delta_sc(pose: &Pose6, d: &[f64; OUTPUT_DIM], (s, c): (f64, f64)) -> Pose6 {
    // one step turns by far less than a full turn: a conditional wrap instead of a remainder
    let mut yaw = pose.yaw + d[3];
    if !(-PI..PI).contains(&yaw) {
        yaw = wrap_angle(yaw);
    }
    Pose6 {
        x: pose.x + c * d[0] - s * d[1],
        y: pose.y + s * d[0] + c * d[1],
        z: pose.z + d[2],
        yaw,
        roll: pose.roll + d[4],
        pitch: pose.pitch + d[5],
    }
}

/// Terrain heights as [`Heightfield::height_at`] gives them (the same triangles, clamped at
/// the edges), with the per-call constants hoisted: the probes run 12 times per rollout step.
pub struct Ground<'a> {
    heights: &'a [f64],
    n: usize,
    inv_cell: f64,
    half: f64,
    last: f64,
}

impl<'a> Ground<'a> {
    pub fn new(hf: &'a Heightfield) -> Ground<'a> {
        let n = hf.size();
        Ground {
            heights: hf.heights(),
            n,
            inv_cell: 1.0 / hf.cell(),
            half: 0.5 * (n - 1) as f64,
            last: (n - 1) as f64,
        }
    }

    #[inline]
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let gc = (x * self.inv_cell + self.half).clamp(0.0, self.last);
        let gr = (self.half - y * self.inv_cell).clamp(0.0, self.last);
        // non-negative after the clamp: truncation is the floor, without a library call
        let c0 = (gc as usize).min(self.n - 2);
        let r0 = (gr as usize).min(self.n - 2);
        let u = gc - c0 as f64;
        let v = 1.0 - (gr - r0 as f64);
        let i = r0 * self.n + c0;
        let (nw, ne) = (self.heights[i], self.heights[i + 1]);
        let (sw, se) = (self.heights[i + self.n], self.heights[i + self.n + 1]);
        // both triangles, then a select: the branch would be mispredicted half the time
        let lower = sw + u * (se - sw) + v * (ne - se);
        let upper = sw + v * (nw - sw) + u * (ne - nw);
        if u >= v { lower } else { upper }
    }
}

impl Ground<'_> {
    /// The heights at the probe grid around `pose` (heading `(sin, cos)`) on a world of
    /// scale `scale`, in [`input_names`] order. Each stage runs over all probes at once so
    /// the compiler can vectorise it; the arithmetic per probe is [`Ground::height`]'s.
    pub fn probe(&self, pose: &Pose6, sc: (f64, f64), scale: f64, out: &mut [f64; TERRAIN_DIM]) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has just reported AVX.
            unsafe { self.probe_avx(pose, sc, scale, out) };
            return;
        }
        self.probe_body(pose, sc, scale, out);
    }

    /// The same code for 256-bit registers: the same operations, so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn probe_avx(
        &self,
        pose: &Pose6,
        sc: (f64, f64),
        scale: f64,
        out: &mut [f64; TERRAIN_DIM],
    ) {
        self.probe_body(pose, sc, scale, out);
    }

    #[inline(always)]
    fn probe_body(
        &self,
        pose: &Pose6,
        (s, c): (f64, f64),
        scale: f64,
        out: &mut [f64; TERRAIN_DIM],
    ) {
        const N: usize = TERRAIN_DIM;
        let (mut gc, mut gr) = ([0.0; N], [0.0; N]);
        for k in 0..N {
            let a = PROBE_AHEAD[k / PROBE_LEFT.len()] * scale;
            let l = PROBE_LEFT[k % PROBE_LEFT.len()] * scale;
            let (x, y) = (pose.x + c * a - s * l, pose.y + s * a + c * l);
            // max/min rather than clamp: the same values for finite input, and vectorisable
            gc[k] = (x * self.inv_cell + self.half).max(0.0).min(self.last);
            gr[k] = (self.half - y * self.inv_cell).max(0.0).min(self.last);
        }
        let (mut u, mut v) = ([0.0; N], [0.0; N]);
        let (mut c0, mut r0) = ([0i32; N], [0i32; N]);
        let top = self.n as i32 - 2;
        for k in 0..N {
            // in [0, n − 1] after the clamp: truncation to i32 is the floor
            c0[k] = (gc[k] as i32).min(top);
            r0[k] = (gr[k] as i32).min(top);
            u[k] = gc[k] - c0[k] as f64;
            v[k] = 1.0 - (gr[k] - r0[k] as f64);
        }
        let (mut nw, mut ne, mut sw, mut se) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        for k in 0..N {
            let i = r0[k] as usize * self.n + c0[k] as usize;
            (nw[k], ne[k]) = (self.heights[i], self.heights[i + 1]);
            (sw[k], se[k]) = (self.heights[i + self.n], self.heights[i + self.n + 1]);
        }
        for k in 0..N {
            let lower = sw[k] + u[k] * (se[k] - sw[k]) + v[k] * (ne[k] - se[k]);
            let upper = sw[k] + v[k] * (nw[k] - sw[k]) + u[k] * (ne[k] - nw[k]);
            out[k] = if u[k] >= v[k] { lower } else { upper };
        }
    }
}

/// Converts between world units and the model's full-scale units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    /// World length scale s.
    pub scale: f64,
}

impl Units {
    pub fn new(scale: f64) -> Units {
        Units { scale }
    }
    /// Full-scale seconds per world second: 1/√s.
    pub fn time_factor(&self) -> f64 {
        1.0 / self.scale.sqrt()
    }
    /// A world-unit heading delta over `dt_world` as full-scale units.
    pub fn delta_to_model(&self, d: &[f64; OUTPUT_DIM]) -> [f64; OUTPUT_DIM] {
        let s = self.scale;
        [d[0] / s, d[1] / s, d[2] / s, d[3], d[4], d[5]]
    }
    /// A full-scale delta as world units.
    pub fn delta_to_world(&self, d: &[f64; OUTPUT_DIM]) -> [f64; OUTPUT_DIM] {
        let s = self.scale;
        [d[0] * s, d[1] * s, d[2] * s, d[3], d[4], d[5]]
    }
}

/// The vehicle's state as the model sees it: its pose and the heading-frame change over the
/// previous model step (world units), from which the rates are formed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinoState {
    pub pose: Pose6,
    pub last_delta: [f64; OUTPUT_DIM],
}

/// The attitude, pose rates and command part of the inputs (the first
/// `STATE_DIM + COMMAND_DIM` values), raw; shared by every model kind.
pub fn write_head(state: &KinoState, command: (f64, f64), units: Units, dt: f64, out: &mut [f32]) {
    let p = &state.pose;
    let d = units.delta_to_model(&state.last_delta);
    let inv_dt = 1.0 / dt;
    let head = [
        p.roll,
        p.pitch,
        d[0] * inv_dt,
        d[1] * inv_dt,
        d[2] * inv_dt,
        d[3] * inv_dt,
        d[4] * inv_dt,
        d[5] * inv_dt,
        command.0 / units.scale.sqrt(),
        command.1,
    ];
    for (o, v) in out.iter_mut().zip(head) {
        *o = v as f32;
    }
}

/// Writes the 22 raw (unnormalised) inputs for one step into `out`; returns the sine and
/// cosine of the heading, which the caller may reuse.
///
/// `dt` is the model step in full-scale seconds; `command` is (target speed m/s in world units,
/// steering); heights are read from `terrain` (the world's undeformed ground truth, as every
/// Verti-Bench system gets it).
pub fn write_inputs(
    state: &KinoState,
    command: (f64, f64),
    terrain: &Heightfield,
    units: Units,
    dt: f64,
    out: &mut [f32],
) -> (f64, f64) {
    write_head(state, command, units, dt, out);
    let p = &state.pose;
    let (s, c) = p.yaw.sin_cos();
    let mut heights = [0.0; TERRAIN_DIM];
    Ground::new(terrain).probe(p, (s, c), units.scale, &mut heights);
    let inv_scale = 1.0 / units.scale;
    for (o, h) in out[STATE_DIM + COMMAND_DIM..].iter_mut().zip(heights) {
        *o = ((h - p.z) * inv_scale) as f32;
    }
    (s, c)
}

/// Per-dimension standardisation: (x - mean) / std.
#[derive(Clone, Debug, PartialEq)]
pub struct Standardiser {
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
}

impl Standardiser {
    /// Mean and standard deviation of each column of `rows` (row-major, `dim` columns);
    /// a constant column gets std 1 so it maps to 0 instead of dividing by zero.
    pub fn fit(rows: &[f32], dim: usize) -> Standardiser {
        let n = (rows.len() / dim).max(1) as f64;
        let mut mean = vec![0.0; dim];
        for row in rows.chunks_exact(dim) {
            for (m, &v) in mean.iter_mut().zip(row) {
                *m += v as f64;
            }
        }
        mean.iter_mut().for_each(|m| *m /= n);
        let mut var = vec![0.0; dim];
        for row in rows.chunks_exact(dim) {
            for ((s, &v), m) in var.iter_mut().zip(row).zip(&mean) {
                *s += (v as f64 - m).powi(2);
            }
        }
        let std = var
            .iter()
            .map(|v| {
                let s = (v / n).sqrt();
                if s > 1e-9 { s } else { 1.0 }
            })
            .collect();
        Standardiser { mean, std }
    }
    pub fn dim(&self) -> usize {
        self.mean.len()
    }
    pub fn apply(&self, x: &mut [f32]) {
        for ((v, m), s) in x.iter_mut().zip(&self.mean).zip(&self.std) {
            *v = ((*v as f64 - m) / s) as f32;
        }
    }
    pub fn invert(&self, x: &[f32], out: &mut [f64]) {
        for (((o, &v), m), s) in out.iter_mut().zip(x).zip(&self.mean).zip(&self.std) {
            *o = v as f64 * s + m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_and_apply_are_inverse() {
        let a = Pose6 {
            x: 3.0,
            y: -2.0,
            z: 1.0,
            roll: 0.1,
            pitch: -0.05,
            yaw: 3.0,
        };
        let b = Pose6 {
            x: 3.4,
            y: -1.7,
            z: 1.2,
            roll: 0.12,
            pitch: -0.02,
            yaw: -3.1,
        };
        let d = heading_delta(&a, &b);
        // crossing ±π: the yaw change is the short way round
        assert!((d[3] - (2.0 * std::f64::consts::PI - 6.1)).abs() < 1e-12);
        let back = apply_delta(&a, &d);
        for (u, v) in [
            (back.x, b.x),
            (back.y, b.y),
            (back.z, b.z),
            (back.roll, b.roll),
            (back.pitch, b.pitch),
            (back.yaw, b.yaw),
        ] {
            assert!((u - v).abs() < 1e-12, "{u} vs {v}");
        }
    }

    #[test]
    fn heading_frame_forward_is_along_the_yaw() {
        let a = Pose6 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            roll: 0.0,
            pitch: 0.0,
            yaw: std::f64::consts::FRAC_PI_2,
        };
        let b = Pose6 { y: 2.0, ..a };
        let d = heading_delta(&a, &b);
        assert!((d[0] - 2.0).abs() < 1e-12 && d[1].abs() < 1e-12);
    }

    #[test]
    fn ground_matches_the_heightfield() {
        let n = 9;
        let heights: Vec<f64> = (0..n * n).map(|i| ((i * 37 % 11) as f64) * 0.3).collect();
        let hf = Heightfield::new(n, 1.5, heights);
        let g = Ground::new(&hf);
        let mut x = -7.0;
        while x < 7.0 {
            let mut y = -6.9;
            while y < 7.0 {
                let (a, b) = (g.height(x, y), hf.height_at(x, y));
                assert!((a - b).abs() < 1e-12, "({x}, {y}): {a} vs {b}");
                y += 0.37;
            }
            x += 0.41;
        }
    }

    #[test]
    fn probes_are_the_heights_at_the_probe_grid() {
        let n = 9;
        let heights: Vec<f64> = (0..n * n).map(|i| ((i * 53 % 13) as f64) * 0.2).collect();
        let hf = Heightfield::new(n, 1.5, heights);
        let g = Ground::new(&hf);
        // inside, and partly off the edge (clamped)
        for (x, y, yaw, scale) in [
            (0.3, -0.4, 0.7, 1.0),
            (5.5, 4.0, -2.9, 0.5),
            (1.0, 1.0, 0.0, 2.0),
        ] {
            let pose = Pose6 {
                x,
                y,
                yaw,
                ..Default::default()
            };
            let sc = yaw.sin_cos();
            let mut got = [0.0; TERRAIN_DIM];
            g.probe(&pose, sc, scale, &mut got);
            let mut k = 0;
            for a in PROBE_AHEAD {
                for l in PROBE_LEFT {
                    let (a, l) = (a * scale, l * scale);
                    let want = g.height(x + sc.1 * a - sc.0 * l, y + sc.0 * a + sc.1 * l);
                    assert_eq!(got[k].to_bits(), want.to_bits(), "probe {k} at {x}, {y}");
                    k += 1;
                }
            }
        }
    }

    #[test]
    fn standardiser_round_trips_and_survives_constant_columns() {
        let rows = [1.0f32, 5.0, 3.0, 5.0, 5.0, 5.0];
        let st = Standardiser::fit(&rows, 2);
        assert_eq!(st.mean, vec![3.0, 5.0]);
        assert_eq!(st.std[1], 1.0);
        let mut x = [5.0f32, 5.0];
        st.apply(&mut x);
        assert!((x[0] - 2.0 / (8.0f32 / 3.0).sqrt()).abs() < 1e-6 && x[1] == 0.0);
        let mut back = [0.0; 2];
        st.invert(&x, &mut back);
        assert!((back[0] - 5.0).abs() < 1e-6 && back[1] == 5.0);
    }
}
