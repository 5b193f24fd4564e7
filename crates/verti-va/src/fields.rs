//! The k basis fields laid out for fast evaluation inside the planner's rollouts, where they
//! cost almost everything (k fields x 4 RK4 stages per rollout step).
//!
//! [`FieldKernel`] computes exactly what the plain loops of [`crate::model`] compute, bit for
//! bit: every output is its bias plus its inputs' products in the same order, and multiplies
//! and adds stay separate (Rust never fuses them). What changes is the layout and the
//! control flow: each field's weights are stored in blocks of eight outputs; two fields go
//! through their layers together, up to four blocks of each at once, with the sums held in
//! registers across the whole loop over inputs (instead of loading and storing every output
//! once per input; two fields, because one field's one-block output layer alone is a single
//! chain of dependent adds); and zero inputs are not branched around (see
//! [`dense_group_pair`] for why that keeps the bits). Where the CPU has AVX the same code is
//! compiled for 256-bit registers.

use crate::dims::{FIELD_INPUT, POSE_DIM};

/// Outputs per block (one 256-bit register of f32).
const BLOCK: usize = 8;
/// Blocks summed together in one pass over the inputs.
const GROUP: usize = 4;
/// Widest hidden layer the kernel takes (stack buffers); wider cards use the plain loops.
pub(crate) const MAX_WIDTH: usize = 256;
/// Inputs held through the RK4 stages: embeddings and command (all but roll and pitch).
const REST: usize = FIELD_INPUT - 2;

/// One layer of one field: weights as [block][inputs][BLOCK], zero-padded, and the padded bias.
#[derive(Clone, Debug)]
struct Blocked {
    inputs: usize,
    weights: Vec<f32>,
    bias: Vec<f32>,
}

impl Blocked {
    /// Rows `rows` of a row-major [inputs][outputs] matrix `w` with bias `b`.
    fn new(w: &[f32], b: &[f32], outputs: usize, rows: std::ops::Range<usize>) -> Blocked {
        let padded = outputs.div_ceil(BLOCK) * BLOCK;
        let inputs = rows.len();
        let mut weights = vec![0.0; padded * inputs];
        for blk in 0..padded / BLOCK {
            for (i, row) in rows.clone().enumerate() {
                for j in 0..BLOCK {
                    let o = blk * BLOCK + j;
                    if o < outputs {
                        weights[(blk * inputs + i) * BLOCK + j] = w[row * outputs + o];
                    }
                }
            }
        }
        let mut bias = b.to_vec();
        bias.resize(padded, 0.0);
        Blocked {
            inputs,
            weights,
            bias,
        }
    }

    fn padded(&self) -> usize {
        self.bias.len()
    }
}

/// One field: its first layer split into the part held through RK4 and the roll/pitch rows.
#[derive(Clone, Debug)]
struct Field {
    /// First-layer rows of the held inputs, with the first layer's bias.
    rest: Blocked,
    /// First-layer rows of roll and pitch, padded like the bias.
    roll: Vec<f32>,
    pitch: Vec<f32>,
    /// The layers after the first (ReLU before each).
    layers: Vec<Blocked>,
}

/// The fields of a model in the evaluation layout.
#[derive(Clone, Debug)]
pub(crate) struct FieldKernel {
    fields: Vec<Field>,
    avx: bool,
}

/// A dense layer stacked over the k fields: `w` [k][inputs][outputs], `b` [k][outputs].
pub(crate) struct StackedRef<'a> {
    pub inputs: usize,
    pub outputs: usize,
    pub w: &'a [f32],
    pub b: &'a [f32],
}

fn avx_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Up to `G` blocks of one layer for two fields of the same shape at once (twice the
/// independent sums, which hides the adds' latency): inputs `x1`, `x2`; `w` is G × [inputs]
/// [BLOCK], `b` and `y` G × BLOCK.
///
/// The plain loops skip zero inputs; this kernel adds their products, because a branch per
/// input mispredicts on ReLU's random zeros and costs more than the arithmetic. The bits are
/// the same: with finite weights a zero input's product is ±0, and adding ±0 leaves every
/// sum unchanged except −0 (−0 + +0 = +0). A sum is −0 only if its bias is −0 — starting
/// anywhere else, adds give a nonzero value or +0 (exact cancellation rounds to +0) — and
/// [`FieldKernel::new`] refuses such biases.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn dense_group_pair<const G: usize>(
    x1: &[f32],
    x2: &[f32],
    w1: &[f32],
    w2: &[f32],
    b1: &[f32],
    b2: &[f32],
    y1: &mut [f32],
    y2: &mut [f32],
) {
    let inputs = x1.len();
    let mut acc1 = [[0.0f32; BLOCK]; G];
    let mut acc2 = [[0.0f32; BLOCK]; G];
    for g in 0..G {
        acc1[g].copy_from_slice(&b1[g * BLOCK..(g + 1) * BLOCK]);
        acc2[g].copy_from_slice(&b2[g * BLOCK..(g + 1) * BLOCK]);
    }
    for i in 0..inputs {
        let (u, v) = (x1[i], x2[i]);
        for g in 0..G {
            let wa = &w1[(g * inputs + i) * BLOCK..(g * inputs + i + 1) * BLOCK];
            let wb = &w2[(g * inputs + i) * BLOCK..(g * inputs + i + 1) * BLOCK];
            for j in 0..BLOCK {
                acc1[g][j] += u * wa[j];
                acc2[g][j] += v * wb[j];
            }
        }
    }
    for g in 0..G {
        y1[g * BLOCK..(g + 1) * BLOCK].copy_from_slice(&acc1[g]);
        y2[g * BLOCK..(g + 1) * BLOCK].copy_from_slice(&acc2[g]);
    }
}

/// All outputs of one layer of two fields (`l1.padded()` values each).
#[inline(always)]
fn dense_layer_pair(
    l1: &Blocked,
    l2: &Blocked,
    x1: &[f32],
    x2: &[f32],
    y1: &mut [f32],
    y2: &mut [f32],
) {
    let col = l1.inputs * BLOCK;
    let blocks = l1.padded() / BLOCK;
    let mut first = 0;
    while first < blocks {
        let g = (blocks - first).min(GROUP);
        let (w1, w2) = (
            &l1.weights[first * col..(first + g) * col],
            &l2.weights[first * col..(first + g) * col],
        );
        let (b1, b2) = (
            &l1.bias[first * BLOCK..(first + g) * BLOCK],
            &l2.bias[first * BLOCK..(first + g) * BLOCK],
        );
        let (y1, y2) = (
            &mut y1[first * BLOCK..(first + g) * BLOCK],
            &mut y2[first * BLOCK..(first + g) * BLOCK],
        );
        match g {
            4 => dense_group_pair::<4>(x1, x2, w1, w2, b1, b2, y1, y2),
            3 => dense_group_pair::<3>(x1, x2, w1, w2, b1, b2, y1, y2),
            2 => dense_group_pair::<2>(x1, x2, w1, w2, b1, b2, y1, y2),
            _ => dense_group_pair::<1>(x1, x2, w1, w2, b1, b2, y1, y2),
        }
        first += g;
    }
}

/// The first layer's sums at attitude (r, p) from their held part `base`: base + r·w_roll +
/// p·w_pitch, in that order.
#[inline(always)]
fn first_layer(field: &Field, base: &[f32], r: f32, p: f32, a: &mut [f32; MAX_WIDTH]) {
    for (((a, c), wr), wp) in a.iter_mut().zip(base).zip(&field.roll).zip(&field.pitch) {
        *a = c + r * wr + p * wp;
    }
}

/// Two fields of the same shape, each at its attitude (roll, pitch), from their first layers' held
/// parts `base`: the pose rates of each.
#[inline(always)]
fn stage_pair(
    fields: [&Field; 2],
    base: [&[f32]; 2],
    at: [(f64, f64); 2],
    a: &mut [[f32; MAX_WIDTH]; 2],
    b: &mut [[f32; MAX_WIDTH]; 2],
) -> [[f64; POSE_DIM]; 2] {
    for f in 0..2 {
        let (r, p) = (at[f].0 as f32, at[f].1 as f32);
        first_layer(fields[f], base[f], r, p, &mut a[f]);
    }
    let (mut cur, mut next) = (a, b);
    for (l1, l2) in fields[0].layers.iter().zip(&fields[1].layers) {
        for x in cur.iter_mut() {
            for v in x[..l1.inputs].iter_mut() {
                *v = v.max(0.0);
            }
        }
        let [x1, x2] = &*cur;
        let [y1, y2] = &mut *next;
        dense_layer_pair(
            l1,
            l2,
            &x1[..l1.inputs],
            &x2[..l1.inputs],
            &mut y1[..l1.padded()],
            &mut y2[..l1.padded()],
        );
        std::mem::swap(&mut cur, &mut next);
    }
    [0, 1].map(|f| std::array::from_fn(|d| f64::from(cur[f][d])))
}

impl FieldKernel {
    /// The kernel for `k` fields stacked as `layers` (the first takes [`FIELD_INPUT`] inputs,
    /// the last gives [`POSE_DIM`] outputs); `None` when a layer is wider than [`MAX_WIDTH`]
    /// or a bias is −0 (see [`dense_group_pair`]; weights are finite, as model cards are checked).
    pub(crate) fn new<'a>(k: usize, layers: &[StackedRef<'a>]) -> Option<FieldKernel> {
        let (first, rest) = layers.split_first()?;
        if first.inputs != FIELD_INPUT
            || layers
                .iter()
                .any(|l| l.outputs.div_ceil(BLOCK) * BLOCK > MAX_WIDTH)
            || layers.last()?.outputs != POSE_DIM
            || layers
                .iter()
                .any(|l| l.b.iter().any(|v| v.to_bits() == (-0.0f32).to_bits()))
        {
            return None;
        }
        let fields = (0..k)
            .map(|i| {
                let slice = |l: &StackedRef<'a>| -> (&'a [f32], &'a [f32]) {
                    let (ni, no) = (l.inputs, l.outputs);
                    (
                        &l.w[i * ni * no..(i + 1) * ni * no],
                        &l.b[i * no..(i + 1) * no],
                    )
                };
                let (w0, b0) = slice(first);
                let padded_row = |row: usize| {
                    let mut r = w0[row * first.outputs..(row + 1) * first.outputs].to_vec();
                    r.resize(first.outputs.div_ceil(BLOCK) * BLOCK, 0.0);
                    r
                };
                Field {
                    rest: Blocked::new(w0, b0, first.outputs, 2..FIELD_INPUT),
                    roll: padded_row(0),
                    pitch: padded_row(1),
                    layers: rest
                        .iter()
                        .map(|l| {
                            let (w, b) = slice(l);
                            Blocked::new(w, b, l.outputs, 0..l.inputs)
                        })
                        .collect(),
                }
            })
            .collect();
        Some(FieldKernel {
            fields,
            avx: avx_available(),
        })
    }

    /// The same kernel compiled for the baseline (128-bit) target whatever the CPU, to check
    /// that both builds agree bit for bit.
    #[cfg(test)]
    pub(crate) fn portable(&self) -> FieldKernel {
        FieldKernel {
            avx: false,
            ..self.clone()
        }
    }

    /// Every field's change over one step of `dt` into `out` (k × 6), RK4-integrated when
    /// `integrates`, as `VaModel::basis_changes` defines it.
    pub(crate) fn basis_changes(
        &self,
        integrates: bool,
        dt: f64,
        roll: f64,
        pitch: f64,
        rest: &[f32; REST],
        out: &mut [f64],
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the CPU reported AVX at construction.
            unsafe { self.basis_changes_avx(integrates, dt, roll, pitch, rest, out) };
            return;
        }
        self.basis_changes_body(integrates, dt, roll, pitch, rest, out);
    }

    /// The same code compiled for 256-bit registers; separate multiplies and adds, so the bits
    /// equal the baseline build's.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn basis_changes_avx(
        &self,
        integrates: bool,
        dt: f64,
        roll: f64,
        pitch: f64,
        rest: &[f32; REST],
        out: &mut [f64],
    ) {
        self.basis_changes_body(integrates, dt, roll, pitch, rest, out);
    }

    #[inline(always)]
    fn basis_changes_body(
        &self,
        integrates: bool,
        dt: f64,
        roll: f64,
        pitch: f64,
        rest: &[f32; REST],
        out: &mut [f64],
    ) {
        let mut base = [[0.0f32; MAX_WIDTH]; 2];
        let mut a = [[0.0f32; MAX_WIDTH]; 2];
        let mut b = [[0.0f32; MAX_WIDTH]; 2];
        // two fields at a time; an odd last field is paired with itself (the baselines'
        // single field pays twice, VertiAdaptor's 24 never)
        for first in (0..self.fields.len()).step_by(2) {
            let second = (first + 1).min(self.fields.len() - 1);
            let fields = [&self.fields[first], &self.fields[second]];
            let width = fields[0].rest.padded();
            // the held inputs' part of the first layer, once per step instead of per stage
            let [b0, b1] = &mut base;
            dense_layer_pair(
                &fields[0].rest,
                &fields[1].rest,
                rest,
                rest,
                &mut b0[..width],
                &mut b1[..width],
            );
            let bases = [&b0[..width], &b1[..width]];
            let g = if integrates {
                // crate::rk4::rk4_delta written out for the pair (a closure would be compiled
                // without this function's AVX target); only roll and pitch move the input
                let shifted = |k: &[[f64; POSE_DIM]; 2], h: f64| {
                    [0, 1].map(|f| (roll + h * k[f][4], pitch + h * k[f][5]))
                };
                let k1 = stage_pair(fields, bases, [(roll, pitch); 2], &mut a, &mut b);
                let k2 = stage_pair(fields, bases, shifted(&k1, 0.5 * dt), &mut a, &mut b);
                let k3 = stage_pair(fields, bases, shifted(&k2, 0.5 * dt), &mut a, &mut b);
                let k4 = stage_pair(fields, bases, shifted(&k3, dt), &mut a, &mut b);
                [0, 1].map(|f| {
                    std::array::from_fn(|d| {
                        dt / 6.0 * (k1[f][d] + 2.0 * k2[f][d] + 2.0 * k3[f][d] + k4[f][d])
                    })
                })
            } else {
                stage_pair(fields, bases, [(roll, pitch); 2], &mut a, &mut b)
            };
            for (i, g) in [first, second].into_iter().zip(&g) {
                out[i * POSE_DIM..(i + 1) * POSE_DIM].copy_from_slice(g);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::model::{
        EMBED, Method, POSE_DIM, VA_FORMAT, VaCard, VaModel, VaTraining, WeightsRef,
    };
    use std::path::Path;
    use verti_core::Rng;

    /// A model with random weights and the given fields.
    fn random(method: Method, bases: usize, hidden: &[usize], seed: u64) -> VaModel {
        let mut card = VaCard {
            name: "random".into(),
            format: VA_FORMAT,
            summary: "test".into(),
            method,
            vehicle: "hmmwv".into(),
            dt: 0.1,
            bases,
            hidden: hidden.to_vec(),
            elevation: true,
            semantics: true,
            lambda: 1e-3,
            alpha_prior: vec![1.0; bases],
            weights: WeightsRef {
                file: "random.bin".into(),
                floats: 0,
                fnv1a64: String::new(),
            },
            training: VaTraining {
                data: "none".into(),
                worlds: "none".into(),
                command: "test".into(),
                seed,
                steps: 0,
                wall_time_s: 0.0,
                verti_version: "test".into(),
                settings: String::new(),
            },
            metrics: Default::default(),
        };
        let n = card.float_count();
        card.weights.floats = n;
        let mut rng = Rng::new(seed);
        // weights of both signs, some exactly zero
        let params: Vec<f32> = (0..n)
            .map(|_| {
                if rng.uniform() < 0.05 {
                    0.0
                } else {
                    rng.range(-0.6, 0.6) as f32
                }
            })
            .collect();
        VaModel::new(card, &params, Path::new("random")).unwrap()
    }

    /// Inputs as the planner meets them: attitudes up to ±0.6 rad, some embeddings and
    /// commands exactly zero (the plain loops skip those).
    fn inputs(rng: &mut Rng) -> (f64, f64, [f32; 2 * EMBED], (f64, f64)) {
        let mut e = [0f32; 2 * EMBED];
        for v in &mut e {
            if rng.uniform() < 0.7 {
                *v = rng.range(-1.0, 1.0) as f32;
            }
        }
        let speed = if rng.uniform() < 0.2 {
            0.0
        } else {
            rng.range(-1.0, 3.0)
        };
        let steer = if rng.uniform() < 0.2 {
            0.0
        } else {
            rng.range(-1.0, 1.0)
        };
        (
            rng.range(-0.6, 0.6),
            rng.range(-0.6, 0.6),
            e,
            (speed, steer),
        )
    }

    /// The kernel (both builds) gives the plain loops' bits.
    fn check(model: &VaModel, cases: usize, seed: u64) {
        let kernel = model.kernel().expect("these fields fit the kernel");
        let portable = kernel.portable();
        let k = model.card.bases;
        let mut rng = Rng::new(seed);
        let (mut want, mut fast, mut base) = (
            vec![0.0; k * POSE_DIM],
            vec![0.0; k * POSE_DIM],
            vec![0.0; k * POSE_DIM],
        );
        for _ in 0..cases {
            let (roll, pitch, e, cmd) = inputs(&mut rng);
            model.basis_changes_reference(roll, pitch, &e, cmd, &mut want);
            model.basis_changes(roll, pitch, &e, cmd, &mut fast);
            let rest = crate::model::held_inputs(&e, cmd);
            let integrates = model.card.method.integrates();
            portable.basis_changes(integrates, model.card.dt, roll, pitch, &rest, &mut base);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&fast),
                bits(&want),
                "{}: {:?}",
                model.card.name,
                model.card.hidden
            );
            assert_eq!(
                bits(&base),
                bits(&want),
                "portable build, {:?}",
                model.card.hidden
            );
        }
    }

    #[test]
    fn the_kernel_equals_the_plain_loops_bit_for_bit() {
        // widths that fill whole groups, leave partial blocks, and need several groups
        for (i, hidden) in [
            vec![8, 8],
            vec![32, 32],
            vec![13, 40],
            vec![64, 64, 64, 64],
            vec![100],
        ]
        .iter()
        .enumerate()
        {
            for (j, method) in [Method::Va, Method::Node, Method::Mlp]
                .into_iter()
                .enumerate()
            {
                let bases = if method == Method::Va { 5 } else { 1 };
                check(
                    &random(method, bases, hidden, (10 * i + j) as u64),
                    50,
                    i as u64,
                );
            }
        }
    }

    #[test]
    fn the_shipped_models_take_the_kernel_bit_for_bit() {
        let small = crate::shipped::va_small_v1().unwrap();
        check(&small, 200, 7);
        let big = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/va-v1.yaml");
        check(&VaModel::load(&big).unwrap(), 20, 8);
    }

    #[test]
    fn a_negative_zero_bias_keeps_the_plain_loops() {
        let m = random(Method::Va, 2, &[16], 4);
        let mut params = m.params();
        let n = params.len();
        params[n - 1] = -0.0; // the last field's last output bias
        let m = VaModel::new(m.card.clone(), &params, Path::new("random")).unwrap();
        assert!(m.kernel().is_none());
    }

    #[test]
    fn fields_wider_than_the_kernel_use_the_plain_loops() {
        let m = random(Method::Va, 2, &[super::MAX_WIDTH + 1], 3);
        assert!(m.kernel().is_none());
        let mut g = vec![0.0; 2 * POSE_DIM];
        m.basis_changes(0.1, 0.0, &[0.5; 2 * EMBED], (1.0, 0.2), &mut g);
        assert!(g.iter().all(|v| v.is_finite()));
    }
}
