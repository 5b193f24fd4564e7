//! Many samples through one small MLP at a time (the CVaR map's footprints of one heading), as
//! matrix-matrix products: each weight vector loaded once serves several samples, which a
//! one-sample kernel cannot do.
//!
//! Every output is its bias plus its inputs' products in ascending order, multiplied and added
//! separately (Rust never fuses them), exactly as [`verti_nn::Mlp`] and
//! [`verti_nn::Network::forward`] sum: the batched outputs are bit-identical to theirs (tested
//! against `Mlp` with the shipped model).

use verti_nn::{LayerSpec, Network, Shape};

/// Outputs per block: one 256-bit register of f32.
const BLOCK: usize = 8;

/// The element-wise functions this kernel applies after a linear layer; a network with any
/// other (tanh) is not batched and its map takes the one-footprint path.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Act {
    Identity,
    Relu,
    LeakyRelu(f32),
}

/// A linear layer as the card stores it: inputs, outputs, row-major [inputs, outputs] weights,
/// bias, and the activation that follows.
type Dense = (usize, usize, Vec<f32>, Vec<f32>, Act);

#[derive(Clone, Debug)]
struct Layer {
    inputs: usize,
    outputs: usize,
    /// [output block][input][BLOCK], zero-padded.
    weights: Vec<f32>,
    /// Padded to whole blocks.
    bias: Vec<f32>,
    act: Act,
}

impl Layer {
    fn blocks(&self) -> usize {
        self.bias.len() / BLOCK
    }
}

/// An MLP laid out for batches.
#[derive(Clone, Debug)]
pub(crate) struct BatchMlp {
    layers: Vec<Layer>,
    avx: bool,
}

/// Work buffers: two activation matrices, [sample][stride].
#[derive(Clone, Debug, Default)]
pub(crate) struct BatchScratch {
    a: Vec<f32>,
    b: Vec<f32>,
}

impl BatchMlp {
    /// The network's linear layers and activations, with inputs divided by `input_scale` folded
    /// into the first layer as [`verti_nn::Mlp::fold_inputs`] does it (same arithmetic, so the
    /// same f32 weights). `None` if the network is not an MLP this kernel runs.
    pub(crate) fn new(net: &Network, input_scale: Option<f64>) -> Option<BatchMlp> {
        let mut dense: Vec<Dense> = Vec::new();
        for (i, spec) in net.card().layers.iter().enumerate() {
            let act = match *spec {
                LayerSpec::Linear { inputs, outputs } => {
                    let (w, b) = net.layer_params(i).split_at(inputs * outputs);
                    dense.push((inputs, outputs, w.to_vec(), b.to_vec(), Act::Identity));
                    continue;
                }
                LayerSpec::Relu => Act::Relu,
                LayerSpec::LeakyRelu { slope } => Act::LeakyRelu(slope),
                LayerSpec::Flatten if matches!(net.input_shape(), Shape::Flat(_)) => continue,
                _ => return None,
            };
            match dense.last_mut() {
                Some(last) if last.4 == Act::Identity => last.4 = act,
                _ => return None,
            }
        }
        if let (Some(scale), Some(first)) = (input_scale, dense.first_mut()) {
            let (inputs, outputs, w, b) = (first.0, first.1, &mut first.2, &mut first.3);
            for o in 0..outputs {
                let mut bias = b[o] as f64;
                for i in 0..inputs {
                    let v = w[i * outputs + o] as f64 / scale;
                    bias -= 0.0 * v;
                    w[i * outputs + o] = v as f32;
                }
                b[o] = bias as f32;
            }
        }
        if dense.is_empty() {
            return None;
        }
        let layers = dense
            .into_iter()
            .map(|(inputs, outputs, w, b, act)| {
                let blocks = outputs.div_ceil(BLOCK);
                let mut weights = vec![0.0; blocks * inputs * BLOCK];
                for k in 0..blocks {
                    for i in 0..inputs {
                        for j in 0..BLOCK {
                            let o = k * BLOCK + j;
                            if o < outputs {
                                weights[(k * inputs + i) * BLOCK + j] = w[i * outputs + o];
                            }
                        }
                    }
                }
                let mut bias = b;
                bias.resize(blocks * BLOCK, 0.0);
                Layer {
                    inputs,
                    outputs,
                    weights,
                    bias,
                    act,
                }
            })
            .collect();
        Some(BatchMlp {
            layers,
            avx: avx_available(),
        })
    }

    /// The baseline (128-bit) build whatever the CPU, to test that both builds agree.
    #[cfg(test)]
    pub(crate) fn portable(&self) -> BatchMlp {
        BatchMlp {
            avx: false,
            ..self.clone()
        }
    }

    pub(crate) fn inputs(&self) -> usize {
        self.layers[0].inputs
    }

    pub(crate) fn outputs(&self) -> usize {
        self.layers[self.layers.len() - 1].outputs
    }

    /// Runs `n` samples, row `s` of `x` being `x[s * stride..][..inputs()]`, and returns the
    /// outputs as rows of the returned stride (the first `outputs()` values of each row).
    pub(crate) fn forward<'s>(
        &self,
        x: &[f32],
        stride: usize,
        n: usize,
        s: &'s mut BatchScratch,
    ) -> (&'s [f32], usize) {
        assert!(stride >= self.inputs() && x.len() >= n * stride);
        let widest = self.layers.iter().map(|l| l.bias.len()).max().unwrap_or(0);
        for buf in [&mut s.a, &mut s.b] {
            if buf.len() < n * widest {
                buf.resize(n * widest, 0.0);
            }
        }
        let (mut cur, mut next) = (&mut s.a, &mut s.b);
        let mut from_x = true;
        let mut in_stride = stride;
        for layer in &self.layers {
            let out_stride = layer.bias.len();
            let input: &[f32] = if from_x { x } else { cur };
            if !layer_run(layer, input, in_stride, n, next, out_stride, self.avx) {
                activate(layer, next, out_stride, n);
            }
            std::mem::swap(&mut cur, &mut next);
            from_x = false;
            in_stride = out_stride;
        }
        (&cur[..], in_stride)
    }
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

/// The activation, in the scalar form verti-nn applies it (so NaN and signed zeros behave
/// identically).
fn activate(layer: &Layer, y: &mut [f32], stride: usize, n: usize) {
    for row in y[..n * stride].chunks_exact_mut(stride) {
        let row = &mut row[..layer.outputs];
        match layer.act {
            Act::Identity => {}
            Act::Relu => row.iter_mut().for_each(|v| *v = v.max(0.0)),
            // a select, not a branch: the sign is unpredictable
            Act::LeakyRelu(s) => row
                .iter_mut()
                .for_each(|v| *v = if *v < 0.0 { *v * s } else { *v }),
        }
    }
}

/// The linear layer into `y`; true if the activation was applied too.
fn layer_run(
    l: &Layer,
    x: &[f32],
    xs: usize,
    n: usize,
    y: &mut [f32],
    ys: usize,
    avx: bool,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if avx {
        // SAFETY: `avx` is true only where the CPU reported AVX.
        unsafe { layer_avx(l, x, xs, n, y, ys) };
        return matches!(l.act, Act::LeakyRelu(_));
    }
    let _ = avx;
    layer_body(l, x, xs, n, y, ys);
    false
}

/// The kernel in 256-bit intrinsics (the array form below is not kept in registers by the
/// compiler). Separate multiplies and adds, as in the portable form: the same sums.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn layer_avx(l: &Layer, x: &[f32], xs: usize, n: usize, y: &mut [f32], ys: usize) {
    let blocks = l.blocks();
    // every read and write below is inside these bounds
    assert!(
        n == 0 || ((n - 1) * xs + l.inputs <= x.len() && (n - 1) * ys + blocks * BLOCK <= y.len())
    );
    assert!(l.weights.len() == blocks * l.inputs * BLOCK && ys >= blocks * BLOCK);
    let mut s0 = 0;
    while s0 < n {
        let s = (n - s0).min(4);
        let mut g0 = 0;
        while g0 < blocks {
            let g = (blocks - g0).min(2);
            // SAFETY: the asserts above bound every index the tiles use.
            unsafe {
                match (s, g) {
                    (4, 2) => tile_avx::<4, 2>(l, x, xs, y, ys, s0, g0),
                    (4, _) => tile_avx::<4, 1>(l, x, xs, y, ys, s0, g0),
                    (3, 2) => tile_avx::<3, 2>(l, x, xs, y, ys, s0, g0),
                    (3, _) => tile_avx::<3, 1>(l, x, xs, y, ys, s0, g0),
                    (2, 2) => tile_avx::<2, 2>(l, x, xs, y, ys, s0, g0),
                    (2, _) => tile_avx::<2, 1>(l, x, xs, y, ys, s0, g0),
                    (_, 2) => tile_avx::<1, 2>(l, x, xs, y, ys, s0, g0),
                    _ => tile_avx::<1, 1>(l, x, xs, y, ys, s0, g0),
                }
            }
            g0 += g;
        }
        s0 += s;
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
// index loops over the register arrays on purpose (see below)
#[allow(clippy::needless_range_loop)]
unsafe fn tile_avx<const S: usize, const G: usize>(
    l: &Layer,
    x: &[f32],
    xs: usize,
    y: &mut [f32],
    ys: usize,
    s0: usize,
    g0: usize,
) {
    use std::arch::x86_64::*;
    let inputs = l.inputs;
    let leaky = match l.act {
        Act::LeakyRelu(s) => Some(s),
        _ => None,
    };
    let (xp, wp, bp, yp) = (
        x.as_ptr(),
        l.weights.as_ptr(),
        l.bias.as_ptr(),
        y.as_mut_ptr(),
    );
    // SAFETY (all pointer offsets): within the bounds `layer_avx` asserted.
    unsafe {
        let mut acc = [[_mm256_setzero_ps(); G]; S];
        // index loops over the register arrays: iterator adaptors made the compiler keep the
        // sums in memory
        for s in 0..S {
            for g in 0..G {
                acc[s][g] = _mm256_loadu_ps(bp.add((g0 + g) * BLOCK));
            }
        }
        for i in 0..inputs {
            let w: [__m256; G] =
                std::array::from_fn(|g| _mm256_loadu_ps(wp.add(((g0 + g) * inputs + i) * BLOCK)));
            for s in 0..S {
                let xi = _mm256_set1_ps(*xp.add((s0 + s) * xs + i));
                for g in 0..G {
                    acc[s][g] = _mm256_add_ps(acc[s][g], _mm256_mul_ps(xi, w[g]));
                }
            }
        }
        if let Some(slope) = leaky {
            // v < 0 ? v·slope : v, as the scalar form (NaN is not < 0 and stays)
            let (zero, slope) = (_mm256_setzero_ps(), _mm256_set1_ps(slope));
            for s in 0..S {
                for g in 0..G {
                    let v = acc[s][g];
                    let neg = _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero);
                    acc[s][g] = _mm256_blendv_ps(v, _mm256_mul_ps(v, slope), neg);
                }
            }
        }
        for s in 0..S {
            for g in 0..G {
                _mm256_storeu_ps(yp.add((s0 + s) * ys + (g0 + g) * BLOCK), acc[s][g]);
            }
        }
    }
}

/// Tiles of `S` samples x `G` output blocks, whose sums stay in registers over all inputs.
#[inline(always)]
fn layer_body(l: &Layer, x: &[f32], xs: usize, n: usize, y: &mut [f32], ys: usize) {
    let blocks = l.blocks();
    let mut s0 = 0;
    while s0 < n {
        let s = (n - s0).min(4);
        let mut g0 = 0;
        while g0 < blocks {
            let g = (blocks - g0).min(2);
            match (s, g) {
                (4, 2) => tile::<4, 2>(l, x, xs, y, ys, s0, g0),
                (4, _) => tile::<4, 1>(l, x, xs, y, ys, s0, g0),
                (3, 2) => tile::<3, 2>(l, x, xs, y, ys, s0, g0),
                (3, _) => tile::<3, 1>(l, x, xs, y, ys, s0, g0),
                (2, 2) => tile::<2, 2>(l, x, xs, y, ys, s0, g0),
                (2, _) => tile::<2, 1>(l, x, xs, y, ys, s0, g0),
                (_, 2) => tile::<1, 2>(l, x, xs, y, ys, s0, g0),
                _ => tile::<1, 1>(l, x, xs, y, ys, s0, g0),
            }
            g0 += g;
        }
        s0 += s;
    }
}

#[inline(always)]
fn tile<const S: usize, const G: usize>(
    l: &Layer,
    x: &[f32],
    xs: usize,
    y: &mut [f32],
    ys: usize,
    s0: usize,
    g0: usize,
) {
    let inputs = l.inputs;
    let mut acc = [[[0.0f32; BLOCK]; G]; S];
    for a in acc.iter_mut() {
        for (g, b) in a.iter_mut().enumerate() {
            b.copy_from_slice(&l.bias[(g0 + g) * BLOCK..(g0 + g + 1) * BLOCK]);
        }
    }
    let rows: [&[f32]; S] = std::array::from_fn(|s| &x[(s0 + s) * xs..(s0 + s) * xs + inputs]);
    let w: [&[f32]; G] = std::array::from_fn(|g| {
        &l.weights[(g0 + g) * inputs * BLOCK..(g0 + g + 1) * inputs * BLOCK]
    });
    for i in 0..inputs {
        let wi: [&[f32]; G] = std::array::from_fn(|g| &w[g][i * BLOCK..(i + 1) * BLOCK]);
        for s in 0..S {
            let xi = rows[s][i];
            for g in 0..G {
                for j in 0..BLOCK {
                    acc[s][g][j] += xi * wi[g][j];
                }
            }
        }
    }
    for (s, a) in acc.iter().enumerate() {
        for (g, b) in a.iter().enumerate() {
            let at = (s0 + s) * ys + (g0 + g) * BLOCK;
            y[at..at + BLOCK].copy_from_slice(b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_core::Rng;

    #[test]
    fn batches_equal_the_one_sample_mlp_bit_for_bit() {
        let model = crate::shipped::pietra_v1().unwrap();
        let mut rng = Rng::new(4);
        for (i, net) in model.networks.iter().enumerate() {
            let scale = (i == 0).then_some(model.card.input_scale);
            let batch = BatchMlp::new(net, scale).expect("an MLP");
            let mut mlp = verti_nn::Mlp::from_network(net).unwrap();
            if let Some(s) = scale {
                mlp = mlp
                    .fold_inputs(&vec![0.0; mlp.inputs()], &vec![s; mlp.inputs()])
                    .unwrap();
            }
            let (n, stride) = (11, batch.inputs() + 3);
            let x: Vec<f32> = (0..n * stride)
                .map(|_| rng.range(-0.5, 0.5) as f32)
                .collect();
            for b in [batch.clone(), batch.portable()] {
                let mut s = BatchScratch::default();
                let (y, ys) = b.forward(&x, stride, n, &mut s);
                for k in 0..n {
                    let want = mlp.forward(&x[k * stride..k * stride + batch.inputs()]);
                    let got = &y[k * ys..k * ys + batch.outputs()];
                    assert_eq!(
                        got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        "network {i}, sample {k}"
                    );
                }
            }
        }
    }
}
