//! The networks of PIETRA and its baselines (paper §IV, spec §A.2–A.3): a shared MLP encoder
//! of the footprint patch, four softmax decoders (one per traversability parameter), a radial
//! normalizing flow on the latent whose density is the evidence, and PIETRA's evidence-scaling
//! MLP. One module serves every method; [`Method`] says which parts a method uses and how its
//! posterior and loss are formed.

use super::special::{dirichlet_entropy, emd2, uemd2};
use crate::bins::{B, PARAMS};
use crate::dataset::FEATURES;
use burn::module::{Module, Param};
use burn::tensor::activation::{log_sigmoid, softmax, softplus};
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};
use verti_core::Rng;
use verti_nn::train::seq::{Act, SeqNet, mlp_layers};
use verti_nn::{LayerSpec, Shape};

/// Latent dimension H (NatPN's default).
pub const LATENT: usize = 16;
/// Encoder hidden widths. NatPN's tabular default is 64 wide; 32 keeps a CVaR map of the
/// paper's size (81 x 96 cells, 13 yaws: 101 k footprints) near 100 ms on one core, and the
/// ~9 k training samples need no more.
pub const ENCODER_HIDDEN: [usize; 3] = [32, 32, 32];
/// Decoder hidden width (one hidden layer per decoder), for the same reason.
pub const DECODER_HIDDEN: usize = 32;
/// Radial flow layers (NatPN's default).
pub const FLOW_LAYERS: usize = 8;
/// Evidence of the prior, n_phys = B (paper §IV-A).
pub const PRIOR_EVIDENCE: f64 = B as f64;
/// log N_H, the certainty budget scaled exponentially with H (NatPN's "normal":
/// N = (4π)^{H/2}).
pub fn log_budget() -> f64 {
    0.5 * (4.0 * std::f64::consts::PI).ln() * LATENT as f64
}
/// log-evidence is clamped to ±this (NatPN), so no density under- or overflows.
pub const LOG_EVIDENCE_CLAMP: f64 = 30.0;

/// A method of the learning benchmark that trains a network.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Physics prior in the posterior + UPI loss (the proposal).
    Pietra,
    /// Uniform prior, UEMD² loss.
    Evora,
    /// Encoder–decoder, EMD² loss.
    Vanilla,
    /// Encoder–decoder, EMD² + κ·EMD² to the physics prior.
    Pi,
    /// Ablation: EVORA with the UPI loss (uniform prior in the posterior).
    UpiOnly,
    /// Ablation: EVORA with the physics prior in the posterior (UEMD² loss only).
    PpOnly,
}

impl Method {
    pub const ALL: [Method; 6] = [
        Method::Pietra,
        Method::Pi,
        Method::Vanilla,
        Method::Evora,
        Method::UpiOnly,
        Method::PpOnly,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Method::Pietra => "pietra",
            Method::Evora => "evora",
            Method::Vanilla => "vanilla",
            Method::Pi => "pi",
            Method::UpiOnly => "upi-only",
            Method::PpOnly => "pp-only",
        }
    }

    pub fn from_name(s: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == s)
    }

    /// Dirichlet posterior with a flow (true) or a plain softmax prediction (false).
    pub fn evidential(self) -> bool {
        !matches!(self, Method::Vanilla | Method::Pi)
    }
    /// The physics prior (true) or the uniform one (false) in the posterior of eq. 9.
    pub fn physics_in_posterior(self) -> bool {
        matches!(self, Method::Pietra | Method::PpOnly)
    }
    /// Whether the loss has the physics term κ·(U)EMD²(·, p_phys).
    pub fn physics_in_loss(self) -> bool {
        matches!(self, Method::Pietra | Method::Pi | Method::UpiOnly)
    }
    /// PIETRA's evidence-scaling MLP (with the physics prior: its accuracy differs per
    /// parameter, so the network learns how much to trust itself over it per parameter).
    pub fn scales_evidence(self) -> bool {
        self.physics_in_posterior()
    }
}

/// A radial flow (Rezende & Mohamed 2015) of [`FLOW_LAYERS`] layers on R^H; its density of a
/// latent is the evidence. Layer l: α = softplus(α'), β = −α + softplus(β') (invertible),
/// r = |z − z0|, h = 1/(α + r), z ← z + β h (z − z0),
/// log|det J| = (H − 1) ln(1 + β h) + ln(1 + β α h²).
#[derive(Module, Debug)]
pub struct RadialFlow {
    pub z0: Param<Tensor<2>>,
    pub alpha: Param<Tensor<1>>,
    pub beta: Param<Tensor<1>>,
}

impl RadialFlow {
    pub fn new(rng: &mut Rng, device: &Device) -> RadialFlow {
        let bound = 1.0 / (LATENT as f64).sqrt();
        let mut draw =
            |n: usize| -> Vec<f32> { (0..n).map(|_| rng.range(-bound, bound) as f32).collect() };
        RadialFlow {
            z0: Param::from_tensor(Tensor::from_data(
                TensorData::new(draw(FLOW_LAYERS * LATENT), [FLOW_LAYERS, LATENT]),
                device,
            )),
            alpha: Param::from_tensor(Tensor::from_data(
                TensorData::new(draw(FLOW_LAYERS), [FLOW_LAYERS]),
                device,
            )),
            beta: Param::from_tensor(Tensor::from_data(
                TensorData::new(draw(FLOW_LAYERS), [FLOW_LAYERS]),
                device,
            )),
        }
    }

    /// The flow's map of latents z [N, H] and the log-determinant of its Jacobian [N, 1].
    pub fn forward(&self, z: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        let [n, h] = z.dims();
        let alpha = softplus(self.alpha.val(), 1.0);
        let beta = softplus(self.beta.val(), 1.0) - alpha.clone();
        let mut z = z;
        let mut log_det: Tensor<2> = Tensor::zeros([n, 1], &z.device());
        for l in 0..FLOW_LAYERS {
            let z0 = self.z0.val().narrow(0, l, 1); // [1, H]
            let a = alpha.clone().narrow(0, l, 1).reshape([1, 1]);
            let b = beta.clone().narrow(0, l, 1).reshape([1, 1]);
            let diff = z.clone() - z0;
            // the small floor keeps the gradient of r finite at z = z0
            let r = (diff.clone().powi_scalar(2).sum_dim(1) + 1e-12).sqrt(); // [N, 1]
            let hh = (r + a.clone()).recip();
            let bh = hh.clone() * b.clone();
            z = z + diff * bh.clone();
            log_det = log_det
                + (bh + 1.0).log() * (h as f64 - 1.0)
                + (hh.powi_scalar(2) * (a * b) + 1.0).log();
        }
        (z, log_det)
    }

    /// log p(z) of latents z [N, H] under the flow with a standard normal base → \[N\].
    pub fn log_prob(&self, z: Tensor<2>) -> Tensor<1> {
        let [n, h] = z.dims();
        let (z, log_det) = self.forward(z);
        let base =
            (z.powi_scalar(2).sum_dim(1) + h as f64 * (2.0 * std::f64::consts::PI).ln()) * -0.5;
        (base + log_det).reshape([n])
    }
}

/// Weights and biases for `layers` drawn from `rng` (U(±1/√fan_in), burn's default bound), in
/// verti-nn's layout. Drawn here rather than by burn, whose generator is shared process-wide:
/// runs of a sweep train in parallel and must not draw from one another's stream.
pub fn init_params(layers: &[LayerSpec], rng: &mut Rng) -> Vec<f32> {
    let mut out = Vec::new();
    for l in layers {
        if let LayerSpec::Linear { inputs, outputs } = *l {
            let bound = 1.0 / (inputs as f64).sqrt();
            out.extend((0..inputs * outputs + outputs).map(|_| rng.range(-bound, bound) as f32));
        }
    }
    out
}

/// What the network says about a batch.
pub struct Prediction {
    /// log p(z) under the flow \[N\] (evidential methods).
    pub log_density: Tensor<1>,
    /// p_φ: one PMF per (sample, parameter), rows [N·4, B].
    pub pmf: Tensor<2>,
    /// Evidence n(o) per row [N·4, 1] (evidential methods).
    pub evidence: Tensor<2>,
}

/// The encoder, decoders, flow and evidence scaler.
#[derive(Module, Debug)]
pub struct TravNet {
    pub encoder: SeqNet,
    pub decoders: Vec<SeqNet>,
    pub flow: RadialFlow,
    pub scaler: SeqNet,
    #[module(skip)]
    pub method: Method,
    /// Inputs are divided by this (the spread of the training features, metres).
    #[module(skip)]
    pub input_scale: f32,
}

pub fn encoder_layers() -> Vec<LayerSpec> {
    mlp_layers(
        FEATURES,
        &ENCODER_HIDDEN,
        LATENT,
        LayerSpec::LeakyRelu { slope: 0.01 },
    )
}
pub fn decoder_layers() -> Vec<LayerSpec> {
    mlp_layers(
        LATENT,
        &[DECODER_HIDDEN],
        B,
        LayerSpec::LeakyRelu { slope: 0.01 },
    )
}
pub fn scaler_layers() -> Vec<LayerSpec> {
    mlp_layers(LATENT, &[32], PARAMS, LayerSpec::LeakyRelu { slope: 0.01 })
}

impl TravNet {
    /// A fresh network for `method`, every weight drawn from `seed`.
    pub fn new(
        method: Method,
        input_scale: f32,
        seed: u64,
        device: &Device,
    ) -> Result<TravNet, String> {
        let mut rng = Rng::derive(seed, "pietra-init", 0);
        let net = |layers: Vec<LayerSpec>, inputs: usize, rng: &mut Rng| {
            let params = init_params(&layers, rng);
            SeqNet::new(Shape::Flat(inputs), &layers, device)?.import_params(&params, device)
        };
        let encoder = net(encoder_layers(), FEATURES, &mut rng)?;
        let decoders = (0..PARAMS)
            .map(|_| net(decoder_layers(), LATENT, &mut rng))
            .collect::<Result<Vec<_>, _>>()?;
        let scaler = net(scaler_layers(), LATENT, &mut rng)?;
        let flow = RadialFlow::new(&mut rng, device);
        Ok(TravNet {
            encoder,
            decoders,
            flow,
            scaler,
            method,
            input_scale,
        })
    }

    /// Runs features [N, FEATURES] (metres) through the network.
    pub fn predict(&self, features: Tensor<2>) -> Prediction {
        let [n, _] = features.dims();
        let z = self
            .encoder
            .forward(Act::Flat(features / f64::from(self.input_scale)))
            .flat();
        let pmfs: Vec<Tensor<2>> = self
            .decoders
            .iter()
            .map(|d| softmax(d.forward(Act::Flat(z.clone())).flat(), 1))
            .collect();
        let pmf = Tensor::stack::<3>(pmfs, 1).reshape([n * PARAMS, B]);
        let log_density = self.flow.log_prob(z.clone());
        let mut log_n = (log_density.clone() + log_budget())
            .clamp(-LOG_EVIDENCE_CLAMP, LOG_EVIDENCE_CLAMP)
            .reshape([n, 1])
            .expand([n, PARAMS]);
        if self.method.scales_evidence() {
            log_n = log_n + log_sigmoid(self.scaler.forward(Act::Flat(z)).flat());
        }
        Prediction {
            log_density,
            pmf,
            evidence: log_n.exp().reshape([n * PARAMS, 1]),
        }
    }
}

/// The posterior concentration β = n_prior p_prior + n p_φ (eq. 9) per row [N·4, B].
pub fn posterior(pred: &Prediction, prior: Tensor<2>) -> Tensor<2> {
    prior * PRIOR_EVIDENCE + pred.pmf.clone() * pred.evidence.clone()
}

/// The loss terms' weights.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LossWeights {
    /// κ, the physics term's weight (eq. 14).
    pub physics: f64,
    /// Weight of the Dirichlet entropy bonus (NatPN's sign: high entropy is rewarded).
    pub entropy: f64,
}

/// The training loss of a batch, summed over the four parameters and averaged over samples.
/// `prior` holds, per row, the prior of the method's posterior (physics or uniform);
/// `physics` the physics prior; `target` the one-hot targets.
pub fn loss(
    net: &TravNet,
    features: Tensor<2>,
    target: Tensor<2>,
    prior: Tensor<2>,
    physics: Tensor<2>,
    weights: LossWeights,
    cs: &Tensor<2>,
) -> Tensor<1> {
    let pred = net.predict(features);
    let m = net.method;
    let per_row = if m.evidential() {
        let beta = posterior(&pred, prior);
        let mut l = uemd2(beta.clone(), target, cs);
        if m.physics_in_loss() {
            l = l + uemd2(beta.clone(), physics, cs) * weights.physics;
        }
        l - dirichlet_entropy(beta) * weights.entropy
    } else {
        let mut l = emd2(pred.pmf.clone(), target, cs);
        if m.physics_in_loss() {
            l = l + emd2(pred.pmf, physics, cs) * weights.physics;
        }
        l
    };
    per_row.mean() * PARAMS as f64
}

/// The expected PMF each row predicts: β/β0 for evidential methods, p_φ otherwise.
pub fn expected_pmf(
    net: &TravNet,
    features: Tensor<2>,
    prior: Tensor<2>,
) -> (Tensor<2>, Tensor<1>) {
    let pred = net.predict(features);
    if net.method.evidential() {
        let beta = posterior(&pred, prior);
        let b0 = beta.clone().sum_dim(1);
        (beta / b0, pred.log_density)
    } else {
        (pred.pmf, pred.log_density)
    }
}
