//! A trained traversability model, evaluated without a learning framework: the card (method,
//! normalisation, flow parameters, prior, training record) and its six networks — encoder,
//! four decoders, evidence scaler — as verti-nn MLPs. `verti learn pietra` writes it; CVaR maps
//! and the planner read it.
//!
//! The computation is the one `train` (feature `train`) trains (tested against it there): z = enc(o / s),
//! p_φ,k = softmax(dec_k(z)), log p(z) through the radial flow, n_k = exp(clamp(log p(z) +
//! log N)) · sigmoid(scale_k(z)), β_k = n_prior p_prior,k + n_k p_φ,k, and the expected PMF
//! β_k / Σβ_k (eq. 11). Methods without evidence predict p_φ,k.

use crate::batch_mlp::BatchMlp;
use crate::bins::{B, Bins, PARAMS, Pmf, uniform};
use crate::dataset::FEATURES;
use crate::prior::PriorConfig;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_nn::{Mlp, MlpScratch, Network, TrainingInfo};

/// Card format this crate reads and writes.
pub const TRAV_FORMAT: u32 = 1;

/// The model card of a traversability model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TravCard {
    pub name: String,
    pub format: u32,
    pub summary: String,
    /// Learning-benchmark method: pietra, evora, vanilla, pi, upi-only, pp-only.
    pub method: String,
    /// Dirichlet posterior with a flow (false: the decoders' PMFs are the prediction).
    pub evidential: bool,
    /// The physics prior (true) or the uniform one in the posterior.
    pub physics_in_posterior: bool,
    pub scales_evidence: bool,
    /// Inputs (footprint heights, m) are divided by this.
    pub input_scale: f64,
    /// log N, the certainty budget; log-evidence is clamped to ±`log_evidence_clamp`.
    pub log_budget: f64,
    pub log_evidence_clamp: f64,
    /// n_prior of eq. 9.
    pub prior_evidence: f64,
    pub prior: PriorConfig,
    pub bins: Vec<Bins>,
    /// Radial flow, raw parameters (α = softplus(alpha), β = softplus(beta) − α), layer-major.
    pub latent: usize,
    pub flow_z0: Vec<f64>,
    pub flow_alpha: Vec<f64>,
    pub flow_beta: Vec<f64>,
    /// The lowest latent log-density of a training sample: below it a footprint is OOD.
    pub ood_log_density: f64,
    /// Network cards beside this one: encoder, decoder 1..4, scaler.
    pub networks: Vec<String>,
    pub training: TrainingInfo,
    #[serde(default)]
    pub metrics: BTreeMap<String, f64>,
}

/// A loaded model.
#[derive(Clone, Debug)]
pub struct TravModel {
    pub card: TravCard,
    pub networks: Vec<Arc<Network>>,
    encoder: Mlp,
    decoders: Vec<Mlp>,
    scaler: Mlp,
    /// Flow parameters after the softplus.
    alpha: Vec<f64>,
    beta: Vec<f64>,
    batch: Option<Arc<BatchNets>>,
}

/// Work buffers of one thread.
#[derive(Clone, Debug, Default)]
pub struct TravScratch {
    mlp: MlpScratch,
    input: Vec<f32>,
    z: Vec<f32>,
    flow: Vec<f64>,
}

/// The six networks in the batch kernel's layout.
#[derive(Clone, Debug)]
pub(crate) struct BatchNets {
    pub encoder: BatchMlp,
    pub decoders: Vec<BatchMlp>,
    pub scaler: BatchMlp,
}

/// What a model says about one footprint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TravPrediction {
    /// The expected PMF of each parameter (eq. 11).
    pub pmf: [Pmf; PARAMS],
    /// log p(z) of the latent (NaN for methods without a flow).
    pub log_density: f64,
}

#[inline]
pub(crate) fn softplus(x: f64) -> f64 {
    if x > 20.0 { x } else { x.exp().ln_1p() }
}

impl TravModel {
    /// Checks a card against its networks.
    pub fn new(
        card: TravCard,
        networks: Vec<Arc<Network>>,
        origin: &Path,
    ) -> Result<TravModel, String> {
        let bad =
            |field: &str, why: String| format!("{}: field `{field}`: {why}", origin.display());
        if card.format != TRAV_FORMAT {
            return Err(bad(
                "format",
                format!(
                    "{} is not supported (this verti reads {TRAV_FORMAT})",
                    card.format
                ),
            ));
        }
        if networks.len() != 2 + PARAMS || card.networks.len() != networks.len() {
            return Err(bad(
                "networks",
                format!(
                    "{} listed, {} loaded; expected {}",
                    card.networks.len(),
                    networks.len(),
                    2 + PARAMS
                ),
            ));
        }
        if card.bins.len() != PARAMS {
            return Err(bad(
                "bins",
                format!("{} entries, expected {PARAMS}", card.bins.len()),
            ));
        }
        if !(card.input_scale.is_finite() && card.input_scale > 0.0) {
            return Err(bad(
                "input_scale",
                format!("{} must be positive", card.input_scale),
            ));
        }
        let h = card.latent;
        let layers = card.flow_alpha.len();
        if card.flow_beta.len() != layers || card.flow_z0.len() != layers * h {
            return Err(bad(
                "flow_z0",
                format!("{} values for {layers} layers of {h}", card.flow_z0.len()),
            ));
        }
        let mlp = |i: usize, inputs: usize, outputs: usize| -> Result<Mlp, String> {
            let m = Mlp::from_network(&networks[i]).map_err(|e| bad("networks", e))?;
            if m.inputs() != inputs || m.outputs() != outputs {
                return Err(bad(
                    "networks",
                    format!(
                        "{} maps {} → {}, expected {inputs} → {outputs}",
                        card.networks[i],
                        m.inputs(),
                        m.outputs()
                    ),
                ));
            }
            Ok(m)
        };
        // the input scale folds into the encoder's first layer
        let encoder = mlp(0, FEATURES, h)?
            .fold_inputs(&vec![0.0; FEATURES], &vec![card.input_scale; FEATURES])
            .map_err(|e| bad("networks", e))?;
        let decoders = (0..PARAMS)
            .map(|k| mlp(1 + k, h, B))
            .collect::<Result<Vec<_>, _>>()?;
        let scaler = mlp(1 + PARAMS, h, PARAMS)?;
        let alpha: Vec<f64> = card.flow_alpha.iter().map(|a| softplus(*a)).collect();
        let beta = card
            .flow_beta
            .iter()
            .zip(&alpha)
            .map(|(b, a)| softplus(*b) - a)
            .collect();
        let batch = (|| {
            Some(Arc::new(BatchNets {
                encoder: BatchMlp::new(&networks[0], Some(card.input_scale))?,
                decoders: (1..=PARAMS)
                    .map(|k| BatchMlp::new(&networks[k], None))
                    .collect::<Option<_>>()?,
                scaler: BatchMlp::new(&networks[1 + PARAMS], None)?,
            }))
        })();
        Ok(TravModel {
            batch,
            card,
            networks,
            encoder,
            decoders,
            scaler,
            alpha,
            beta,
        })
    }

    /// Reads a card and the networks beside it.
    pub fn load(path: &Path) -> Result<TravModel, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::parse(&text, path, &|file| {
            Network::load(&path.parent().unwrap_or(Path::new(".")).join(file))
                .map_err(|e| e.to_string())
        })
    }

    /// Parses a card, loading each listed network with `network`.
    pub fn parse(
        text: &str,
        origin: &Path,
        network: &dyn Fn(&str) -> Result<Network, String>,
    ) -> Result<TravModel, String> {
        let card: TravCard =
            serde_norway::from_str(text).map_err(|e| format!("{}: {e}", origin.display()))?;
        let networks = card
            .networks
            .iter()
            .map(|f| {
                network(f)
                    .map(Arc::new)
                    .map_err(|e| format!("{}: network {f}: {e}", origin.display()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        TravModel::new(card, networks, origin)
    }

    /// Writes the card to `path` and its networks beside it.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let dir = path.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (file, net) in self.card.networks.iter().zip(&self.networks) {
            let p: PathBuf = dir.join(file);
            net.save(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        }
        let text = serde_norway::to_string(&self.card).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
    }

    pub fn scratch(&self) -> TravScratch {
        TravScratch {
            mlp: self.encoder.scratch(),
            input: vec![0.0; FEATURES],
            z: vec![0.0; self.card.latent],
            flow: Vec::with_capacity(self.card.latent),
        }
    }

    /// The radial flow's α and β per layer, after the softplus.
    pub(crate) fn flow(&self) -> (&[f64], &[f64]) {
        (&self.alpha, &self.beta)
    }

    /// log p(z) under the radial flow with a standard normal base.
    pub fn log_density(&self, z: &[f32]) -> f64 {
        self.log_density_in(z, &mut Vec::new())
    }

    /// [`TravModel::log_density`] with the flow's state in `v` (no allocation once it has grown).
    #[inline]
    fn log_density_in(&self, z: &[f32], v: &mut Vec<f64>) -> f64 {
        let h = self.card.latent;
        v.clear();
        v.extend(z.iter().map(|x| f64::from(*x)));
        let mut log_det = 0.0;
        for l in 0..self.alpha.len() {
            let z0 = &self.card.flow_z0[l * h..(l + 1) * h];
            let (a, b) = (self.alpha[l], self.beta[l]);
            let r = (v
                .iter()
                .zip(z0)
                .map(|(x, c)| (x - c) * (x - c))
                .sum::<f64>()
                + 1e-12)
                .sqrt();
            let hh = 1.0 / (a + r);
            let bh = b * hh;
            for (x, c) in v.iter_mut().zip(z0) {
                *x += bh * (*x - c);
            }
            log_det += (h as f64 - 1.0) * (1.0 + bh).ln() + (1.0 + a * b * hh * hh).ln();
        }
        log_det
            - 0.5
                * (v.iter().map(|x| x * x).sum::<f64>()
                    + h as f64 * (2.0 * std::f64::consts::PI).ln())
    }

    /// The expected PMFs for one footprint patch (`FEATURES` heights, m) with its physics prior.
    pub fn predict(
        &self,
        features: &[f32],
        physics: &[Pmf; PARAMS],
        s: &mut TravScratch,
    ) -> TravPrediction {
        s.input.copy_from_slice(features);
        self.encoder.forward_into(&s.input, &mut s.mlp, &mut s.z);
        let mut logits = [[0.0f32; B]; PARAMS];
        for (dec, l) in self.decoders.iter().zip(&mut logits) {
            dec.forward_into(&s.z, &mut s.mlp, l);
        }
        let mut scale = [0.0f32; PARAMS];
        if self.card.evidential && self.card.scales_evidence {
            self.scaler.forward_into(&s.z, &mut s.mlp, &mut scale);
        }
        self.finish(&s.z, &logits, &scale, physics, &mut s.flow)
    }

    /// The networks laid out for many footprints at once, if every one is an MLP the batch
    /// kernel runs.
    pub(crate) fn batch(&self) -> Option<&BatchNets> {
        self.batch.as_deref()
    }

    /// What follows the networks: the decoders' softmax, the flow's density, the evidence and
    /// the posterior's expected PMF (eq. 11), from the latent `z`, the decoders' `logits` and
    /// the scaler's outputs (read only when the card scales evidence). `flow` is work space.
    #[inline]
    pub(crate) fn finish(
        &self,
        z: &[f32],
        logits: &[[f32; B]; PARAMS],
        scale: &[f32; PARAMS],
        physics: &[Pmf; PARAMS],
        flow: &mut Vec<f64>,
    ) -> TravPrediction {
        let c = &self.card;
        let mut learned = [[0.0; B]; PARAMS];
        for (k, logits) in logits.iter().enumerate() {
            let max = logits.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            let mut sum = 0.0;
            for (p, l) in learned[k].iter_mut().zip(logits) {
                *p = f64::from(l - max).exp();
                sum += *p;
            }
            learned[k].iter_mut().for_each(|p| *p /= sum);
        }
        if !c.evidential {
            return TravPrediction {
                pmf: learned,
                log_density: f64::NAN,
            };
        }
        let log_density = self.log_density_in(z, flow);
        let log_n = (log_density + c.log_budget).clamp(-c.log_evidence_clamp, c.log_evidence_clamp);
        let u = uniform();
        let mut pmf = [[0.0; B]; PARAMS];
        for k in 0..PARAMS {
            let mut ln = log_n;
            if c.scales_evidence {
                // log sigmoid, stable for any sign
                let x = f64::from(scale[k]);
                ln += -softplus(-x);
            }
            let n = ln.exp();
            let prior = if c.physics_in_posterior {
                &physics[k]
            } else {
                &u
            };
            let mut total = 0.0;
            for b in 0..B {
                pmf[k][b] = c.prior_evidence * prior[b] + n * learned[k][b];
                total += pmf[k][b];
            }
            pmf[k].iter_mut().for_each(|p| *p /= total);
        }
        TravPrediction { pmf, log_density }
    }
}
