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
        let (mut cur, mut next) = (&mut scratch.a, &mut scratch.b);
        cur[..input.len()].copy_from_slice(input);
        for layer in &self.blocked {
            let x = &cur[..layer.inputs];
            let col = layer.inputs * BLOCK;
            for ((w, b), y) in layer
                .weights
                .chunks_exact(col)
                .zip(layer.bias.chunks_exact(BLOCK))
                .zip(next.chunks_exact_mut(BLOCK))
            {
                // bias first, then inputs ascending: Network::forward's order for every output
                let mut acc = [0.0f32; BLOCK];
                acc.copy_from_slice(b);
                for (xi, wi) in x.iter().zip(w.chunks_exact(BLOCK)) {
                    for j in 0..BLOCK {
                        acc[j] += xi * wi[j];
                    }
                }
                match layer.activation {
                    Activation::Identity => {}
                    Activation::Relu => acc.iter_mut().for_each(|v| *v = v.max(0.0)),
                    Activation::LeakyRelu(s) => acc.iter_mut().for_each(|v| {
                        if *v < 0.0 {
                            *v *= s
                        }
                    }),
                    Activation::Tanh => acc.iter_mut().for_each(|v| *v = libm::tanhf(*v)),
                }
                y.copy_from_slice(&acc);
            }
            std::mem::swap(&mut cur, &mut next);
        }
        out.copy_from_slice(&cur[..out.len()]);
    }

    /// Convenience: one call that allocates its output.
    pub fn forward(&self, input: &[f32]) -> Vec<f32> {
        let mut out = vec![0.0; self.outputs()];
        self.forward_into(input, &mut self.scratch(), &mut out);
        out
    }
}
