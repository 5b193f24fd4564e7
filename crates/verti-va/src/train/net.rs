//! VertiAdaptor's networks on burn: the two embedding compressions and the k basis fields,
//! stacked so one batched matrix product evaluates all fields; RK4 of every field; the
//! least-squares coefficients inside the graph; and export to `verti_va`'s plain-Rust model.

use crate::Method;
use crate::lsq::cholesky_solve;
use crate::model::{EMBED, FIELD_INPUT, POSE_DIM, embed_sizes};
use crate::terrain::{ELEVATION_LATENT, SEMANTIC_LATENT, TERRAIN_DIM};
use burn::module::{Module, Param};
use burn::tensor::activation::{relu, tanh};
use burn::tensor::{Device, Tensor, TensorData};
use verti_core::Rng;
use verti_nn::train::seq::values;

/// One dense layer for `copies` networks at once: w [copies, inputs, outputs], b [copies, 1, outputs].
#[derive(Module, Debug)]
pub struct Stacked {
    pub w: Param<Tensor<3>>,
    pub b: Param<Tensor<3>>,
}

impl Stacked {
    /// Weights and biases U(±1/√inputs) (burn's default bound), drawn from verti's generator
    /// so training is reproducible bit for bit.
    pub fn new(
        copies: usize,
        inputs: usize,
        outputs: usize,
        rng: &mut Rng,
        device: &Device,
    ) -> Stacked {
        let bound = 1.0 / (inputs as f64).sqrt();
        let mut draw =
            |n: usize| -> Vec<f32> { (0..n).map(|_| rng.range(-bound, bound) as f32).collect() };
        let w = draw(copies * inputs * outputs);
        let b = draw(copies * outputs);
        Stacked {
            w: Param::from_tensor(Tensor::from_data(
                TensorData::new(w, [copies, inputs, outputs]),
                device,
            )),
            b: Param::from_tensor(Tensor::from_data(
                TensorData::new(b, [copies, 1, outputs]),
                device,
            )),
        }
    }

    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        x.matmul(self.w.val()) + self.b.val()
    }
}

fn layers(sizes: &[usize], copies: usize, rng: &mut Rng, device: &Device) -> Vec<Stacked> {
    sizes
        .windows(2)
        .map(|w| Stacked::new(copies, w[0], w[1], rng, device))
        .collect()
}

/// Layers in order, ReLU between them, none after the last.
fn dense(layers: &[Stacked], x: Tensor<3>) -> Tensor<3> {
    let mut h = x;
    for (i, l) in layers.iter().enumerate() {
        h = l.forward(h);
        if i + 1 < layers.len() {
            h = relu(h);
        }
    }
    h
}

/// What the network is.
#[derive(Clone, Debug, PartialEq)]
pub struct NetSpec {
    pub method: Method,
    pub bases: usize,
    pub hidden: Vec<usize>,
    pub elevation: bool,
    pub semantics: bool,
    /// Model step, full-scale seconds.
    pub dt: f64,
}

impl NetSpec {
    pub fn field_sizes(&self) -> Vec<usize> {
        let mut s = vec![FIELD_INPUT];
        s.extend(&self.hidden);
        s.push(POSE_DIM);
        s
    }
}

#[derive(Module, Debug)]
pub struct VaNet {
    pub elevation: Vec<Stacked>,
    pub semantics: Vec<Stacked>,
    pub fields: Vec<Stacked>,
    #[module(skip)]
    pub spec: NetSpec,
}

impl VaNet {
    pub fn new(spec: NetSpec, seed: u64, device: &Device) -> VaNet {
        let mut rng = Rng::derive(seed, "va-init", 0);
        VaNet {
            elevation: layers(&embed_sizes(ELEVATION_LATENT), 1, &mut rng, device),
            semantics: layers(&embed_sizes(SEMANTIC_LATENT), 1, &mut rng, device),
            fields: layers(&spec.field_sizes(), spec.bases, &mut rng, device),
            spec,
        }
    }

    /// A network with the given parameters (in `verti_va`'s file order, as
    /// [`VaNet::export_params`] writes them).
    pub fn from_params(spec: NetSpec, params: &[f32], device: &Device) -> Result<VaNet, String> {
        let mut at = 0;
        let mut take = |sizes: &[usize], copies: usize| -> Result<Vec<Stacked>, String> {
            let mut out = Vec::new();
            for w in sizes.windows(2) {
                let (i, o) = (w[0], w[1]);
                let (wn, bn) = (copies * i * o, copies * o);
                if at + wn + bn > params.len() {
                    return Err(format!(
                        "{} parameters are too few for {sizes:?}",
                        params.len()
                    ));
                }
                let tensor = |v: &[f32], dims: [usize; 3]| {
                    Param::from_tensor(Tensor::from_data(TensorData::new(v.to_vec(), dims), device))
                };
                out.push(Stacked {
                    w: tensor(&params[at..at + wn], [copies, i, o]),
                    b: tensor(&params[at + wn..at + wn + bn], [copies, 1, o]),
                });
                at += wn + bn;
            }
            Ok(out)
        };
        let elevation = take(&embed_sizes(ELEVATION_LATENT), 1)?;
        let semantics = take(&embed_sizes(SEMANTIC_LATENT), 1)?;
        let fields = take(&spec.field_sizes(), spec.bases)?;
        if at != params.len() {
            return Err(format!("{} parameters, the network has {at}", params.len()));
        }
        Ok(VaNet {
            elevation,
            semantics,
            fields,
            spec,
        })
    }

    /// Terrain latents [N, TERRAIN_DIM] → compressed embeddings [N, 16] (an ablated half is 0).
    pub fn embed(&self, terrain: Tensor<2>) -> Tensor<2> {
        let [n, _] = terrain.dims();
        let device = terrain.device();
        let part = |layers: &[Stacked], x: Tensor<2>, on: bool| -> Tensor<2> {
            if on {
                tanh(dense(layers, x.unsqueeze::<3>())).reshape([n, EMBED])
            } else {
                Tensor::zeros([n, EMBED], &device)
            }
        };
        let e = part(
            &self.elevation,
            terrain.clone().narrow(1, 0, ELEVATION_LATENT),
            self.spec.elevation,
        );
        let s = part(
            &self.semantics,
            terrain.narrow(1, ELEVATION_LATENT, SEMANTIC_LATENT),
            self.spec.semantics,
        );
        debug_assert_eq!(ELEVATION_LATENT + SEMANTIC_LATENT, TERRAIN_DIM);
        Tensor::cat(vec![e, s], 1)
    }

    /// All fields at attitudes rp [k, N, 2] with the rest of the input [k, N, 18] → [k, N, 6].
    fn field(&self, rp: Tensor<3>, rest: Tensor<3>) -> Tensor<3> {
        dense(&self.fields, Tensor::cat(vec![rp, rest], 2))
    }

    /// Every basis function's change over one step, [k, N, 6]: RK4 of each field for `va`
    /// and `node` (only roll and pitch move the input between stages), the network's output
    /// for `mlp` and `maml`. roll_pitch [N, 2], embedding [N, 16], command [N, 2].
    pub fn basis_changes(
        &self,
        roll_pitch: Tensor<2>,
        embedding: Tensor<2>,
        command: Tensor<2>,
    ) -> Tensor<3> {
        let k = self.spec.bases;
        let rest = Tensor::cat(vec![embedding, command], 1)
            .unsqueeze::<3>()
            .repeat_dim(0, k);
        let rp = roll_pitch.unsqueeze::<3>().repeat_dim(0, k);
        if !self.spec.method.integrates() {
            return self.field(rp, rest);
        }
        let dt = self.spec.dt;
        let attitude = |k: &Tensor<3>| k.clone().narrow(2, 4, 2);
        let k1 = self.field(rp.clone(), rest.clone());
        let k2 = self.field(rp.clone() + attitude(&k1) * (0.5 * dt), rest.clone());
        let k3 = self.field(rp.clone() + attitude(&k2) * (0.5 * dt), rest.clone());
        let k4 = self.field(rp + attitude(&k3) * dt, rest);
        (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0)
    }

    /// The last hidden layer's activations [N, h] of the (single) field: what the MLP
    /// baseline's last-layer adaptation regresses on.
    pub fn last_hidden(
        &self,
        roll_pitch: Tensor<2>,
        embedding: Tensor<2>,
        command: Tensor<2>,
    ) -> Tensor<2> {
        let x = Tensor::cat(vec![roll_pitch, embedding, command], 1).unsqueeze::<3>();
        let n = self.fields.len();
        let mut h = x;
        for l in &self.fields[..n - 1] {
            h = relu(l.forward(h));
        }
        let [_, rows, width] = h.dims();
        h.reshape([rows, width])
    }

    /// The parameters in `verti_va`'s file order.
    pub fn export_params(&self) -> Vec<f32> {
        let mut out = Vec::new();
        for l in self
            .elevation
            .iter()
            .chain(&self.semantics)
            .chain(&self.fields)
        {
            out.extend(values(l.w.val()));
            out.extend(values(l.b.val()));
        }
        out
    }
}

/// Σ_i α_i G_i per row: g [k, N, 6], alpha [N, k] → [N, 6].
pub fn combine(g: Tensor<3>, alpha: Tensor<2>) -> Tensor<2> {
    let [k, n, d] = g.dims();
    alpha
        .reshape([n, 1, k])
        .matmul(g.swap_dims(0, 1))
        .reshape([n, d])
}

/// The least-squares coefficients α = (G + λI)⁻¹F of basis changes g [k, M, 6] against
/// targets y [M, 6], as a [k, 1] tensor whose gradient is that of the exact solve.
///
/// The solve runs on the host (Cholesky, f64); the graph gets α₀ + A₀⁻¹(F − (G + λI)α₀),
/// which equals α₀ and whose derivatives in G and F are those of A⁻¹F at A₀ = G + λI:
/// ∂α/∂F = A⁻¹ and ∂α/∂A = −A⁻¹(·)α₀ᵀ — the gradient of the solve without a solve in burn.
pub fn coefficients(g: Tensor<3>, y: Tensor<2>, lambda: f64) -> Result<Tensor<2>, String> {
    let [k, m, d] = g.dims();
    let device = g.device();
    let a = g.reshape([k, m * d]);
    let gram = a.clone().matmul(a.clone().transpose()) / m as f64;
    let f = a.matmul(y.reshape([m * d, 1])) / m as f64;
    let mut reg: Vec<f64> = values(gram.clone()).into_iter().map(f64::from).collect();
    for i in 0..k {
        reg[i * k + i] += lambda;
    }
    let f0: Vec<f64> = values(f.clone()).into_iter().map(f64::from).collect();
    let solve = |b: &[f64]| {
        cholesky_solve(&reg, k, b)
            .ok_or_else(|| format!("the Gram matrix of {m} points is not positive definite"))
    };
    let alpha0 = solve(&f0)?;
    let mut inverse = vec![0f32; k * k];
    for j in 0..k {
        let mut e = vec![0.0; k];
        e[j] = 1.0;
        for (i, v) in solve(&e)?.into_iter().enumerate() {
            inverse[i * k + j] = v as f32;
        }
    }
    let a0: Tensor<2> = Tensor::from_data(
        TensorData::new(alpha0.iter().map(|&v| v as f32).collect::<Vec<_>>(), [k, 1]),
        &device,
    );
    let inv: Tensor<2> = Tensor::from_data(TensorData::new(inverse, [k, k]), &device);
    let residual = f - gram.matmul(a0.clone()) - a0.clone() * lambda;
    Ok(a0 + inv.matmul(residual))
}
