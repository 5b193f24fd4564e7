//! Allocation-free evaluation of small fully connected networks, for models that run inside
//! planners (a learned kinodynamic step is called K × H ≈ 16,000 times per plan).
//!
//! [`Mlp`] is a [`Network`] made only of linear layers and element-wise activations, laid out
//! for one-sample calls that write into caller-owned buffers. It sums in exactly the order of
//! [`Network::forward`] (bias first, then inputs ascending), so both give bit-identical
//! outputs: the loop over outputs is the one the compiler vectorises, and vectorising over
//! outputs does not change any output's summation order.

use crate::layer::{LayerSpec, Shape};
use crate::network::Network;

/// Element-wise activation after a linear layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Activation {
    Identity,
    Relu,
    LeakyRelu(f32),
    Tanh,
}

/// Outputs are computed in blocks of this many, each block's sums held in registers across
/// the whole loop over inputs.
const BLOCK: usize = 8;

#[derive(Clone, Debug)]
struct Dense {
    inputs: usize,
    outputs: usize,
    /// Row-major [inputs, outputs], as the model card stores them.
    weights: Vec<f32>,
    bias: Vec<f32>,
    activation: Activation,
}

impl Dense {
    fn padded(&self) -> usize {
        self.outputs.div_ceil(BLOCK) * BLOCK
    }
    /// Weights as [output block][input][BLOCK], zero-padded, and the padded bias.
    fn blocked(&self) -> (Vec<f32>, Vec<f32>) {
        let blocks = self.padded() / BLOCK;
        let mut w = vec![0.0; blocks * self.inputs * BLOCK];
        for b in 0..blocks {
            for i in 0..self.inputs {
                for j in 0..BLOCK {
                    let o = b * BLOCK + j;
                    if o < self.outputs {
                        w[(b * self.inputs + i) * BLOCK + j] = self.weights[i * self.outputs + o];
                    }
                }
            }
        }
        let mut bias = self.bias.clone();
        bias.resize(self.padded(), 0.0);
        (w, bias)
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

/// Output blocks summed together in one pass over the inputs.
const GROUP: usize = 4;

/// `G` output blocks of one layer: `w` is G × [inputs][BLOCK], `b` and `y` G × BLOCK.
/// Every output is its bias plus its inputs' products in ascending order, as in
/// [`Network::forward`].
#[inline(always)]
fn dense_group<const G: usize>(
    x: &[f32],
    w: &[f32],
    b: &[f32],
    activation: Activation,
    y: &mut [f32],
) {
    let inputs = x.len();
    let mut acc = [[0.0f32; BLOCK]; G];
    for (g, a) in acc.iter_mut().enumerate() {
        a.copy_from_slice(&b[g * BLOCK..(g + 1) * BLOCK]);
    }
    for (i, &xi) in x.iter().enumerate() {
        for (g, a) in acc.iter_mut().enumerate() {
            let wi = &w[(g * inputs + i) * BLOCK..(g * inputs + i + 1) * BLOCK];
            for j in 0..BLOCK {
                a[j] += xi * wi[j];
            }
        }
    }
    for (a, y) in acc.iter_mut().zip(y.chunks_exact_mut(BLOCK)) {
        activate(a, activation);
        y.copy_from_slice(a);
    }
}

/// [`dense_group`] for two inputs through the same blocks at once: twice the independent sums
/// (one block alone, an output layer, is a single chain of dependent adds), each output's sum
/// unchanged. Separate arrays of sums for the two, so that they stay in registers.
#[inline(always)]
fn dense_group_pair<const G: usize>(
    x1: &[f32],
    x2: &[f32],
    w: &[f32],
    b: &[f32],
    activation: Activation,
    y1: &mut [f32],
    y2: &mut [f32],
) {
    let inputs = x1.len();
    let x2 = &x2[..inputs];
    let mut acc1 = [[0.0f32; BLOCK]; G];
    let mut acc2 = [[0.0f32; BLOCK]; G];
    for g in 0..G {
        acc1[g].copy_from_slice(&b[g * BLOCK..(g + 1) * BLOCK]);
        acc2[g].copy_from_slice(&b[g * BLOCK..(g + 1) * BLOCK]);
    }
    for i in 0..inputs {
        let (u, v) = (x1[i], x2[i]);
        for g in 0..G {
            let wi = &w[(g * inputs + i) * BLOCK..(g * inputs + i + 1) * BLOCK];
            for j in 0..BLOCK {
                acc1[g][j] += u * wi[j];
                acc2[g][j] += v * wi[j];
            }
        }
    }
    for (a, y) in acc1.iter_mut().zip(y1.chunks_exact_mut(BLOCK)) {
        activate(a, activation);
        y.copy_from_slice(a);
    }
    for (a, y) in acc2.iter_mut().zip(y2.chunks_exact_mut(BLOCK)) {
        activate(a, activation);
        y.copy_from_slice(a);
    }
}

#[inline(always)]
fn activate(a: &mut [f32; BLOCK], activation: Activation) {
    match activation {
        Activation::Identity => {}
        Activation::Relu => a.iter_mut().for_each(|v| *v = v.max(0.0)),
        Activation::LeakyRelu(s) => a.iter_mut().for_each(|v| {
            if *v < 0.0 {
                *v *= s
            }
        }),
        Activation::Tanh => a.iter_mut().for_each(|v| *v = libm::tanhf(*v)),
    }
}

/// A layer in the evaluation layout.
#[derive(Clone, Debug)]
struct Blocked {
    inputs: usize,
    weights: Vec<f32>,
    bias: Vec<f32>,
    activation: Activation,
}

/// A multi-layer perceptron read from a [`Network`].
#[derive(Clone, Debug)]
pub struct Mlp {
    /// The layers as the card has them (kept for folding affine maps in).
    layers: Vec<Dense>,
    /// The same, laid out for evaluation.
    blocked: Vec<Blocked>,
    widest: usize,
    /// Whether this CPU runs the 256-bit build of the kernel.
    avx: bool,
}

/// Two work buffers as wide as the widest layer; one per thread.
#[derive(Clone, Debug, Default)]
pub struct MlpScratch {
    a: Vec<f32>,
    b: Vec<f32>,
}

impl Mlp {
    /// The network as an MLP; an error names the first layer that is not linear or an
    /// element-wise activation (flatten of a flat input is accepted).
    pub fn from_network(net: &Network) -> Result<Mlp, String> {
        let name = &net.card().name;
        let mut layers: Vec<Dense> = Vec::new();
        for (i, spec) in net.card().layers.iter().enumerate() {
            let activation = match *spec {
                LayerSpec::Linear { inputs, outputs } => {
                    let params = net.layer_params(i);
                    let (w, b) = params.split_at(inputs * outputs);
                    layers.push(Dense {
                        inputs,
                        outputs,
                        weights: w.to_vec(),
                        bias: b.to_vec(),
                        activation: Activation::Identity,
                    });
                    continue;
                }
                LayerSpec::Relu => Activation::Relu,
                LayerSpec::LeakyRelu { slope } => Activation::LeakyRelu(slope),
                LayerSpec::Tanh => Activation::Tanh,
                LayerSpec::Flatten if matches!(net.input_shape(), Shape::Flat(_)) => continue,
                ref other => {
                    return Err(format!(
                        "{name}: layer {i} ({}) is not part of an MLP (linear layers and \
                         activations only)",
                        other.kind()
                    ));
                }
            };
            match layers.last_mut() {
                Some(last) if last.activation == Activation::Identity => {
                    last.activation = activation
                }
                _ => {
                    return Err(format!(
                        "{name}: layer {i} is an activation that does not follow a linear layer"
                    ));
                }
            }
        }
        if layers.is_empty() {
            return Err(format!("{name}: no linear layer"));
        }
        Ok(Mlp::from_layers(layers))
    }

    fn from_layers(layers: Vec<Dense>) -> Mlp {
        let widest = layers
            .iter()
            .map(|l| l.inputs.max(l.padded()))
            .max()
            .unwrap_or(0);
        let blocked = layers
            .iter()
            .map(|l| {
                let (weights, bias) = l.blocked();
                Blocked {
                    inputs: l.inputs,
                    weights,
                    bias,
                    activation: l.activation,
                }
            })
            .collect();
        Mlp {
            layers,
            blocked,
            widest,
            avx: avx_available(),
        }
    }

    /// The same function on raw inputs and raw outputs, for a network trained on standardised
    /// ones: x → (x − in_mean)/in_std goes into the first layer's weights and bias,
    /// y → y·out_std + out_mean into the last layer's (which must have no activation).
    /// Saves the two passes per call; results equal the unfolded ones to rounding.
    pub fn fold_standardisation(
        &self,
        in_mean: &[f64],
        in_std: &[f64],
        out_mean: &[f64],
        out_std: &[f64],
    ) -> Result<Mlp, String> {
        self.fold_inputs(in_mean, in_std)?
            .fold_outputs(out_mean, out_std)
    }

    /// The input half of [`Mlp::fold_standardisation`] (for networks whose outputs feed
    /// another network, or whose last layer has an activation).
    pub fn fold_inputs(&self, in_mean: &[f64], in_std: &[f64]) -> Result<Mlp, String> {
        let mut layers = self.layers.clone();
        let first = &mut layers[0];
        if in_mean.len() != first.inputs || in_std.len() != first.inputs {
            return Err(format!("input standardisation for {} inputs", first.inputs));
        }
        for o in 0..first.outputs {
            let mut b = first.bias[o] as f64;
            for i in 0..first.inputs {
                let w = first.weights[i * first.outputs + o] as f64 / in_std[i];
                b -= in_mean[i] * w;
                first.weights[i * first.outputs + o] = w as f32;
            }
            first.bias[o] = b as f32;
        }
        Ok(Mlp::from_layers(layers))
    }

    /// The output half of [`Mlp::fold_standardisation`].
    pub fn fold_outputs(&self, out_mean: &[f64], out_std: &[f64]) -> Result<Mlp, String> {
        let mut layers = self.layers.clone();
        let last = layers.last_mut().expect("an MLP has a layer");
        if out_mean.len() != last.outputs || out_std.len() != last.outputs {
            return Err(format!(
                "output standardisation for {} outputs",
                last.outputs
            ));
        }
        if last.activation != Activation::Identity {
            return Err("the last layer has an activation: outputs cannot be rescaled".into());
        }
        for o in 0..last.outputs {
            for i in 0..last.inputs {
                let w = &mut last.weights[i * last.outputs + o];
                *w = (*w as f64 * out_std[o]) as f32;
            }
            last.bias[o] = (last.bias[o] as f64 * out_std[o] + out_mean[o]) as f32;
        }
        Ok(Mlp::from_layers(layers))
    }

    /// The same network evaluated by the baseline (128-bit) build of the kernel, whatever the
    /// CPU: for checking that both builds agree bit for bit.
    pub fn portable(&self) -> Mlp {
        Mlp {
            avx: false,
            ..self.clone()
        }
    }

    pub fn inputs(&self) -> usize {
        self.layers[0].inputs
    }
    pub fn outputs(&self) -> usize {
        self.layers[self.layers.len() - 1].outputs
    }
    /// Multiply-adds per call.
    pub fn multiply_adds(&self) -> usize {
        self.layers.iter().map(|l| l.inputs * l.outputs).sum()
    }

    pub fn scratch(&self) -> MlpScratch {
        MlpScratch {
            a: vec![0.0; self.widest],
            b: vec![0.0; self.widest],
        }
    }

    /// Evaluates one input into `out` (`outputs()` values). Panics if the lengths are wrong
    /// (a programming error, not bad data).
    pub fn forward_into(&self, input: &[f32], scratch: &mut MlpScratch, out: &mut [f32]) {
        assert_eq!(input.len(), self.inputs(), "MLP input length");
        assert_eq!(out.len(), self.outputs(), "MLP output length");
        if scratch.a.len() < self.widest {
            *scratch = self.scratch();
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the CPU reported AVX at construction.
            unsafe { self.forward_avx(input, scratch, out) };
            return;
        }
        self.forward_body(input, scratch, out);
    }

    /// The same code compiled for 256-bit registers. Separate multiplies and adds (Rust never
    /// contracts them into FMA), so the results are bit-identical to the baseline build.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn forward_avx(&self, input: &[f32], scratch: &mut MlpScratch, out: &mut [f32]) {
        self.forward_body(input, scratch, out);
    }

    #[inline(always)]
    fn forward_body(&self, input: &[f32], scratch: &mut MlpScratch, out: &mut [f32]) {
        let (mut cur, mut next) = (&mut scratch.a, &mut scratch.b);
        cur[..input.len()].copy_from_slice(input);
        for layer in &self.blocked {
            let x = &cur[..layer.inputs];
            let col = layer.inputs * BLOCK;
            let blocks = layer.bias.len() / BLOCK;
            let mut first = 0;
            while first < blocks {
                // up to GROUP blocks at once: independent sums hide the adds' latency
                let g = (blocks - first).min(GROUP);
                let w = &layer.weights[first * col..(first + g) * col];
                let b = &layer.bias[first * BLOCK..(first + g) * BLOCK];
                let y = &mut next[first * BLOCK..(first + g) * BLOCK];
                match g {
                    4 => dense_group::<4>(x, w, b, layer.activation, y),
                    3 => dense_group::<3>(x, w, b, layer.activation, y),
                    2 => dense_group::<2>(x, w, b, layer.activation, y),
                    _ => dense_group::<1>(x, w, b, layer.activation, y),
                }
                first += g;
            }
            std::mem::swap(&mut cur, &mut next);
        }
        out.copy_from_slice(&cur[..out.len()]);
    }

    /// Evaluates two inputs at once into `out` (bit for bit what two [`Mlp::forward_into`]
    /// calls give): the sums of both run side by side, which hides the adds' latency where a
    /// layer has few output blocks. `scratch` holds one pair of buffers per input.
    pub fn forward_pair_into(
        &self,
        input: [&[f32]; 2],
        scratch: [&mut MlpScratch; 2],
        out: [&mut [f32]; 2],
    ) {
        for (x, o) in input.iter().zip(&out) {
            assert_eq!(x.len(), self.inputs(), "MLP input length");
            assert_eq!(o.len(), self.outputs(), "MLP output length");
        }
        let [s1, s2] = scratch;
        for s in [&mut *s1, &mut *s2] {
            if s.a.len() < self.widest {
                *s = self.scratch();
            }
        }
        let scratch = [s1, s2];
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the CPU reported AVX at construction.
            unsafe { self.forward_pair_avx(input, scratch, out) };
            return;
        }
        self.forward_pair_body(input, scratch, out);
    }

    /// [`Mlp::forward_pair_into`] compiled for 256-bit registers (bit-identical, as
    /// [`Mlp::forward_avx`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn forward_pair_avx(
        &self,
        input: [&[f32]; 2],
        scratch: [&mut MlpScratch; 2],
        out: [&mut [f32]; 2],
    ) {
        self.forward_pair_body(input, scratch, out);
    }

    #[inline(always)]
    fn forward_pair_body(
        &self,
        input: [&[f32]; 2],
        scratch: [&mut MlpScratch; 2],
        out: [&mut [f32]; 2],
    ) {
        let [s1, s2] = scratch;
        let (mut cur1, mut next1) = (&mut s1.a, &mut s1.b);
        let (mut cur2, mut next2) = (&mut s2.a, &mut s2.b);
        cur1[..input[0].len()].copy_from_slice(input[0]);
        cur2[..input[1].len()].copy_from_slice(input[1]);
        for layer in &self.blocked {
            let n = layer.inputs;
            let col = n * BLOCK;
            let blocks = layer.bias.len() / BLOCK;
            let mut first = 0;
            while first < blocks {
                let g = (blocks - first).min(GROUP);
                let w = &layer.weights[first * col..(first + g) * col];
                let b = &layer.bias[first * BLOCK..(first + g) * BLOCK];
                let (x1, x2) = (&cur1[..n], &cur2[..n]);
                let range = first * BLOCK..(first + g) * BLOCK;
                let (y1, y2) = (&mut next1[range.clone()], &mut next2[range]);
                let act = layer.activation;
                match g {
                    4 => dense_group_pair::<4>(x1, x2, w, b, act, y1, y2),
                    3 => dense_group_pair::<3>(x1, x2, w, b, act, y1, y2),
                    2 => dense_group_pair::<2>(x1, x2, w, b, act, y1, y2),
                    _ => dense_group_pair::<1>(x1, x2, w, b, act, y1, y2),
                }
                first += g;
            }
            std::mem::swap(&mut cur1, &mut next1);
            std::mem::swap(&mut cur2, &mut next2);
        }
        let [o1, o2] = out;
        let n = o1.len();
        o1.copy_from_slice(&cur1[..n]);
        o2.copy_from_slice(&cur2[..n]);
    }

    /// Convenience: one call that allocates its output.
    pub fn forward(&self, input: &[f32]) -> Vec<f32> {
        let mut out = vec![0.0; self.outputs()];
        self.forward_into(input, &mut self.scratch(), &mut out);
        out
    }
}
