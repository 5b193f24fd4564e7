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

#[derive(Clone, Debug)]
struct Dense {
    inputs: usize,
    outputs: usize,
    /// Row-major [inputs, outputs], as the model card stores them.
    weights: Vec<f32>,
    bias: Vec<f32>,
    activation: Activation,
}

/// A multi-layer perceptron read from a [`Network`].
#[derive(Clone, Debug)]
pub struct Mlp {
    layers: Vec<Dense>,
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
        let widest = layers
            .iter()
            .map(|l| l.inputs.max(l.outputs))
            .max()
            .unwrap_or(0);
        Ok(Mlp { layers, widest })
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
        let last = self.layers.len() - 1;
        let (mut cur, mut next) = (&mut scratch.a, &mut scratch.b);
        cur[..input.len()].copy_from_slice(input);
        for (i, layer) in self.layers.iter().enumerate() {
            let y: &mut [f32] = if i == last {
                &mut *out
            } else {
                &mut next[..layer.outputs]
            };
            y.copy_from_slice(&layer.bias);
            for (xi, row) in cur[..layer.inputs]
                .iter()
                .zip(layer.weights.chunks_exact(layer.outputs))
            {
                for (yo, w) in y.iter_mut().zip(row) {
                    *yo += xi * w;
                }
            }
            match layer.activation {
                Activation::Identity => {}
                Activation::Relu => y.iter_mut().for_each(|v| *v = v.max(0.0)),
                Activation::LeakyRelu(s) => y.iter_mut().for_each(|v| {
                    if *v < 0.0 {
                        *v *= s
                    }
                }),
                Activation::Tanh => y.iter_mut().for_each(|v| *v = libm::tanhf(*v)),
            }
            std::mem::swap(&mut cur, &mut next);
        }
    }

    /// Convenience: one call that allocates its output.
    pub fn forward(&self, input: &[f32]) -> Vec<f32> {
        let mut out = vec![0.0; self.outputs()];
        self.forward_into(input, &mut self.scratch(), &mut out);
        out
    }
}
