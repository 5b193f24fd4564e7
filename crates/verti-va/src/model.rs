//! A VertiAdaptor model file and its evaluation without a learning framework.
//!
//! One card format serves VertiAdaptor and its three baselines, which share inputs and
//! network shapes (paper §IV-B, §IV-C):
//!
//! * `va`: k neural-ODE basis fields g_i, each integrated with RK4 over the model step into
//!   G_i; the change is Σ_i α_i G_i with coefficients from least squares;
//! * `node`: one field, integrated with RK4 (k = 1, α = 1);
//! * `mlp` and `maml`: one network predicting the change directly.
//!
//! A field sees [roll, pitch, e_elev(8), e_sem(8), speed, steer] — the paper's
//! [0, 0, 0, roll, pitch, 0, e, u] without the four coordinates it zeroes — and returns the
//! rates of the heading-frame pose change [forward, left, up, yaw, roll, pitch] (full-scale
//! m/s and rad/s). Inside RK4 only roll and pitch move the field's input: the change of
//! position and heading cannot, because the model is invariant to them (the paper's reason
//! for zeroing them). All six outputs are changes, roll and pitch included: the paper's
//! Algorithm 1 adds the prediction to the state, while its text calls the roll/pitch targets
//! absolute; verti follows the algorithm.
//!
//! Weights live in one little-endian f32 file: each embedding network's layers (weights
//! \[inputs\]\[outputs\], then biases), then the fields' layers stacked over the k fields
//! (weights \[k\]\[inputs\]\[outputs\], then biases \[k\]\[outputs\]).

// the network's dimensions live in `dims` (the field kernel needs them too); `model::` stays
// their public path
pub use crate::dims::{EMBED, EMBED_HIDDEN, FIELD_INPUT, POSE_DIM};
use crate::fields::{FieldKernel, StackedRef};
use crate::lsq::{EXAMPLE_BATCH, NormalEquations};
use crate::rk4::rk4_delta;
use crate::terrain::{ELEVATION_LATENT, SEMANTIC_LATENT, TERRAIN_DIM};
use crate::{Result, VaError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use verti_nn::WeightsCard;

pub const VA_FORMAT: u32 = 1;

/// Which model family a card holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    Va,
    Node,
    Mlp,
    Maml,
}

impl Method {
    pub const ALL: [Method; 4] = [Method::Va, Method::Node, Method::Mlp, Method::Maml];
    pub fn name(self) -> &'static str {
        match self {
            Method::Va => "va",
            Method::Node => "node",
            Method::Mlp => "mlp",
            Method::Maml => "maml",
        }
    }
    pub fn parse(s: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == s)
    }
    /// True when the network is a vector field integrated with RK4.
    pub fn integrates(self) -> bool {
        matches!(self, Method::Va | Method::Node)
    }
}

/// The weights file a card points to: the same record as a network card's, checked the same
/// way ([`verti_nn::WeightsInfo::check`]).
pub use verti_nn::WeightsInfo as WeightsRef;

/// What training did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VaTraining {
    pub data: String,
    /// The worlds the model saw (never an evaluation set).
    pub worlds: String,
    pub command: String,
    pub seed: u64,
    pub steps: usize,
    pub wall_time_s: f64,
    pub verti_version: String,
    pub settings: String,
}

/// The model card.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VaCard {
    pub name: String,
    pub format: u32,
    pub summary: String,
    pub method: Method,
    pub vehicle: String,
    /// Model step, full-scale seconds.
    pub dt: f64,
    /// Basis fields k (1 for the baselines).
    pub bases: usize,
    /// Hidden widths of each field (ReLU).
    pub hidden: Vec<usize>,
    /// False in the ablations that drop an embedding (its eight inputs are then zero).
    pub elevation: bool,
    pub semantics: bool,
    /// Gram regularisation λ.
    pub lambda: f64,
    /// Coefficients before any adaptation: the least-squares fit on all training data.
    pub alpha_prior: Vec<f64>,
    pub weights: WeightsRef,
    pub training: VaTraining,
    pub metrics: BTreeMap<String, f64>,
}

impl VaCard {
    /// Layer sizes of one field: FIELD_INPUT → hidden → POSE_DIM.
    pub fn field_sizes(&self) -> Vec<usize> {
        let mut s = vec![FIELD_INPUT];
        s.extend(&self.hidden);
        s.push(POSE_DIM);
        s
    }
    /// Floats the weights file must hold.
    pub fn float_count(&self) -> usize {
        let dense = |sizes: &[usize], copies: usize| -> usize {
            sizes
                .windows(2)
                .map(|w| copies * (w[0] * w[1] + w[1]))
                .sum()
        };
        dense(&embed_sizes(ELEVATION_LATENT), 1)
            + dense(&embed_sizes(SEMANTIC_LATENT), 1)
            + dense(&self.field_sizes(), self.bases)
    }
}

/// Layer sizes of an embedding compression from `latent` values.
pub fn embed_sizes(latent: usize) -> Vec<usize> {
    let mut s = vec![latent];
    s.extend(EMBED_HIDDEN);
    s.push(EMBED);
    s
}

/// One dense layer stacked over `copies` networks: w [copies][inputs][outputs], b [copies][outputs].
#[derive(Clone, Debug)]
struct Stacked {
    inputs: usize,
    outputs: usize,
    w: Vec<f32>,
    b: Vec<f32>,
}

fn take_layers(params: &[f32], at: &mut usize, sizes: &[usize], copies: usize) -> Vec<Stacked> {
    sizes
        .windows(2)
        .map(|w| {
            let (i, o) = (w[0], w[1]);
            let wn = copies * i * o;
            let layer = Stacked {
                inputs: i,
                outputs: o,
                w: params[*at..*at + wn].to_vec(),
                b: params[*at + wn..*at + wn + copies * o].to_vec(),
            };
            *at += wn + copies * o;
            layer
        })
        .collect()
}

/// `x` through layers of copy `copy`, ReLU between layers; the last layer is linear.
fn dense_forward(layers: &[Stacked], copy: usize, x: &[f32], buf: &mut [Vec<f32>; 2]) -> Vec<f32> {
    let mut cur = x.to_vec();
    for (l, layer) in layers.iter().enumerate() {
        let (i_n, o_n) = (layer.inputs, layer.outputs);
        let w = &layer.w[copy * i_n * o_n..(copy + 1) * i_n * o_n];
        let out = &mut buf[l % 2];
        out.clear();
        out.extend_from_slice(&layer.b[copy * o_n..(copy + 1) * o_n]);
        for (i, &xi) in cur.iter().enumerate() {
            if xi != 0.0 {
                for (o, wv) in out.iter_mut().zip(&w[i * o_n..(i + 1) * o_n]) {
                    *o += xi * wv;
                }
            }
        }
        if l + 1 < layers.len() {
            for v in out.iter_mut() {
                *v = v.max(0.0);
            }
        }
        cur.clone_from(out);
    }
    cur
}

/// A loaded model.
#[derive(Clone, Debug)]
pub struct VaModel {
    pub card: VaCard,
    elevation: Vec<Stacked>,
    semantics: Vec<Stacked>,
    fields: Vec<Stacked>,
    /// The fields in the fast layout (bit-identical to the plain loops below).
    kernel: Option<FieldKernel>,
}

/// One example for adaptation or evaluation: the model's inputs and the true change.
#[derive(Clone, Debug, PartialEq)]
pub struct Example {
    pub roll: f64,
    pub pitch: f64,
    /// Compressed embeddings ([`VaModel::embed`]).
    pub embedding: [f32; 2 * EMBED],
    /// Full-scale target speed (m/s) and steering.
    pub command: (f64, f64),
    /// Full-scale heading-frame change.
    pub delta: [f64; POSE_DIM],
}

impl VaModel {
    /// Checks a card against its weights.
    pub fn new(card: VaCard, params: &[f32], origin: &Path) -> Result<VaModel> {
        let bad = |field: &str, why: String| VaError::card(origin, field, why);
        if card.format != VA_FORMAT {
            return Err(bad(
                "format",
                format!(
                    "{} is not supported (this verti reads {VA_FORMAT})",
                    card.format
                ),
            ));
        }
        if !(card.dt.is_finite() && card.dt > 0.0) {
            return Err(bad("dt", format!("{} must be a positive time", card.dt)));
        }
        if card.bases == 0 || (card.method != Method::Va && card.bases != 1) {
            return Err(bad(
                "bases",
                format!(
                    "{} for method {}: va needs k ≥ 1, the baselines exactly 1",
                    card.bases,
                    card.method.name()
                ),
            ));
        }
        if card.hidden.is_empty() || card.hidden.contains(&0) {
            return Err(bad(
                "hidden",
                format!("{:?} must be non-empty and positive", card.hidden),
            ));
        }
        if card.alpha_prior.len() != card.bases || card.alpha_prior.iter().any(|a| !a.is_finite()) {
            return Err(bad(
                "alpha_prior",
                format!(
                    "{} values, expected {} finite ones",
                    card.alpha_prior.len(),
                    card.bases
                ),
            ));
        }
        if !(card.lambda >= 0.0 && card.lambda.is_finite()) {
            return Err(bad("lambda", format!("{} must be ≥ 0", card.lambda)));
        }
        let want = card.float_count();
        if params.len() != want || card.weights.floats != want {
            return Err(bad(
                "weights",
                format!(
                    "{} floats (card says {}), the architecture needs {want}",
                    params.len(),
                    card.weights.floats
                ),
            ));
        }
        if params.iter().any(|v| !v.is_finite()) {
            return Err(bad("weights", "non-finite values".into()));
        }
        let mut at = 0;
        let elevation = take_layers(params, &mut at, &embed_sizes(ELEVATION_LATENT), 1);
        let semantics = take_layers(params, &mut at, &embed_sizes(SEMANTIC_LATENT), 1);
        let fields = take_layers(params, &mut at, &card.field_sizes(), card.bases);
        let stacked: Vec<StackedRef> = fields
            .iter()
            .map(|l| StackedRef {
                inputs: l.inputs,
                outputs: l.outputs,
                w: &l.w,
                b: &l.b,
            })
            .collect();
        let kernel = FieldKernel::new(card.bases, &stacked);
        Ok(VaModel {
            card,
            elevation,
            semantics,
            fields,
            kernel,
        })
    }

    /// Reads a card and the weights file beside it.
    pub fn load(path: &Path) -> Result<VaModel> {
        let io = VaError::io;
        let text = std::fs::read_to_string(path).map_err(|e| io(path, e))?;
        let card = parse_card(&text, path)?;
        let wpath = path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&card.weights.file);
        let bytes = std::fs::read(&wpath).map_err(|e| io(&wpath, e))?;
        VaModel::from_bytes(card, &bytes, path)
    }

    /// A card and its weight bytes (as compiled-in models come), checked against the count
    /// and digest the card records.
    pub fn from_bytes(card: VaCard, bytes: &[u8], origin: &Path) -> Result<VaModel> {
        card.weights.check(bytes, origin)?;
        let params: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        VaModel::new(card, &params, origin)
    }

    /// The parameters in file order.
    pub fn params(&self) -> Vec<f32> {
        let mut out = Vec::new();
        for l in self
            .elevation
            .iter()
            .chain(&self.semantics)
            .chain(&self.fields)
        {
            out.extend(&l.w);
            out.extend(&l.b);
        }
        out
    }

    /// Writes the card to `path` and the weights beside it (the card's digest is updated).
    pub fn save(&mut self, path: &Path) -> Result<()> {
        let io = VaError::io;
        let dir = path.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let bytes: Vec<u8> = self.params().iter().flat_map(|v| v.to_le_bytes()).collect();
        self.card.weights.floats = bytes.len() / 4;
        self.card.weights.fnv1a64 = format!("{:016x}", verti_nn::card::fnv1a64(&bytes));
        let wpath = dir.join(&self.card.weights.file);
        std::fs::write(&wpath, &bytes).map_err(|e| io(&wpath, e))?;
        let text =
            serde_norway::to_string(&self.card).map_err(|e| VaError::card(path, "card", e))?;
        std::fs::write(path, text).map_err(|e| io(path, e))
    }

    /// Multiply-adds of one predicted step (all fields, all RK4 stages).
    pub fn multiply_adds(&self) -> usize {
        let per_eval: usize = self.fields.iter().map(|l| l.inputs * l.outputs).sum();
        let stages = if self.card.method.integrates() { 4 } else { 1 };
        per_eval * stages * self.card.bases
    }

    /// The compressed embeddings of a terrain latent ([`TERRAIN_DIM`] values); an ablated
    /// embedding is zero.
    pub fn embed(&self, terrain: &[f32]) -> [f32; 2 * EMBED] {
        debug_assert_eq!(terrain.len(), TERRAIN_DIM);
        let mut out = [0f32; 2 * EMBED];
        let mut buf = [Vec::new(), Vec::new()];
        if self.card.elevation {
            let e = dense_forward(&self.elevation, 0, &terrain[..ELEVATION_LATENT], &mut buf);
            for (o, v) in out[..EMBED].iter_mut().zip(e) {
                *o = v.tanh();
            }
        }
        if self.card.semantics {
            let e = dense_forward(&self.semantics, 0, &terrain[ELEVATION_LATENT..], &mut buf);
            for (o, v) in out[EMBED..].iter_mut().zip(e) {
                *o = v.tanh();
            }
        }
        out
    }

    /// Field `i`'s first-layer sums without roll and pitch: b₁ + W₁[2..]ᵀ·rest. The rest of
    /// the input (embeddings, command) is held through the RK4 stages, so this part is
    /// computed once per step instead of once per stage.
    fn field_base(&self, i: usize, rest: &[f32; FIELD_INPUT - 2], base: &mut Vec<f32>) {
        let l = &self.fields[0];
        let o_n = l.outputs;
        let w = &l.w[i * l.inputs * o_n..(i + 1) * l.inputs * o_n];
        base.clear();
        base.extend_from_slice(&l.b[i * o_n..(i + 1) * o_n]);
        for (j, &x) in rest.iter().enumerate() {
            if x != 0.0 {
                for (o, wv) in base.iter_mut().zip(&w[(j + 2) * o_n..(j + 3) * o_n]) {
                    *o += x * wv;
                }
            }
        }
    }

    /// Field `i` at attitude (roll, pitch) from its [`VaModel::field_base`]: the pose rates.
    fn field_from_base(
        &self,
        i: usize,
        base: &[f32],
        roll: f64,
        pitch: f64,
        scratch: &mut [Vec<f32>; 2],
    ) -> [f64; POSE_DIM] {
        let l0 = &self.fields[0];
        let o_n = l0.outputs;
        let w = &l0.w[i * l0.inputs * o_n..];
        let (r, p) = (roll as f32, pitch as f32);
        let [a, b] = scratch;
        a.clear();
        a.extend(
            base.iter()
                .zip(&w[..o_n])
                .zip(&w[o_n..2 * o_n])
                .map(|((c, wr), wp)| c + r * wr + p * wp),
        );
        let layers = self.fields.len();
        for (l, layer) in self.fields.iter().enumerate().skip(1) {
            // the previous layer was hidden: ReLU
            for v in a.iter_mut() {
                *v = v.max(0.0);
            }
            let (i_n, o_n) = (layer.inputs, layer.outputs);
            let w = &layer.w[i * i_n * o_n..(i + 1) * i_n * o_n];
            b.clear();
            b.extend_from_slice(&layer.b[i * o_n..(i + 1) * o_n]);
            for (j, &x) in a.iter().enumerate() {
                if x != 0.0 {
                    for (o, wv) in b.iter_mut().zip(&w[j * o_n..(j + 1) * o_n]) {
                        *o += x * wv;
                    }
                }
            }
            std::mem::swap(a, b);
            debug_assert!(l < layers);
        }
        std::array::from_fn(|d| f64::from(a[d]))
    }

    /// Every basis function's change G_i over one step, k × 6 row-major into `out`: RK4 of
    /// the field for `va` and `node`, the network's output for `mlp` and `maml`. Computed by
    /// the fast field kernel, bit-identical to [`VaModel::basis_changes_reference`].
    pub fn basis_changes(
        &self,
        roll: f64,
        pitch: f64,
        embedding: &[f32; 2 * EMBED],
        command: (f64, f64),
        out: &mut [f64],
    ) {
        let Some(kernel) = &self.kernel else {
            return self.basis_changes_reference(roll, pitch, embedding, command, out);
        };
        let rest = held_inputs(embedding, command);
        let integrates = self.card.method.integrates();
        kernel.basis_changes(integrates, self.card.dt, roll, pitch, &rest, out);
    }

    /// The fast kernel, if this card's fields fit it.
    #[cfg(test)]
    pub(crate) fn kernel(&self) -> Option<&FieldKernel> {
        self.kernel.as_ref()
    }

    /// [`VaModel::basis_changes`] by plain loops over the stacked weights: the definition the
    /// fast kernel is tested against (and the path for fields wider than it takes).
    pub fn basis_changes_reference(
        &self,
        roll: f64,
        pitch: f64,
        embedding: &[f32; 2 * EMBED],
        command: (f64, f64),
        out: &mut [f64],
    ) {
        let rest = held_inputs(embedding, command);
        let width = self
            .card
            .hidden
            .iter()
            .copied()
            .max()
            .unwrap_or(POSE_DIM)
            .max(POSE_DIM);
        let mut base = Vec::with_capacity(width);
        let mut scratch = [Vec::with_capacity(width), Vec::with_capacity(width)];
        let dt = self.card.dt;
        for i in 0..self.card.bases {
            self.field_base(i, &rest, &mut base);
            let g = if self.card.method.integrates() {
                let start = [0.0, 0.0, 0.0, 0.0, roll, pitch];
                rk4_delta(&start, dt, |s| {
                    self.field_from_base(i, &base, s[4], s[5], &mut scratch)
                })
            } else {
                self.field_from_base(i, &base, roll, pitch, &mut scratch)
            };
            out[i * POSE_DIM..(i + 1) * POSE_DIM].copy_from_slice(&g);
        }
    }

    /// The predicted change Σ α_i G_i.
    pub fn predict(
        &self,
        alpha: &[f64],
        roll: f64,
        pitch: f64,
        embedding: &[f32; 2 * EMBED],
        command: (f64, f64),
    ) -> [f64; POSE_DIM] {
        let mut g = vec![0.0; self.card.bases * POSE_DIM];
        self.basis_changes(roll, pitch, embedding, command, &mut g);
        std::array::from_fn(|d| {
            (0..self.card.bases)
                .map(|i| alpha[i] * g[i * POSE_DIM + d])
                .sum()
        })
    }

    /// The least-squares sums of `examples`, computed in batches of 256 (paper Table I) on
    /// all cores; the result does not depend on the thread count (batches add in order).
    pub fn normal_equations(&self, examples: &[Example]) -> NormalEquations {
        use rayon::prelude::*;
        let k = self.card.bases;
        let batches: Vec<NormalEquations> = examples
            .par_chunks(EXAMPLE_BATCH)
            .map(|chunk| {
                let mut ne = NormalEquations::new(k, POSE_DIM);
                let mut g = vec![0.0; k * POSE_DIM];
                for ex in chunk {
                    self.basis_changes(ex.roll, ex.pitch, &ex.embedding, ex.command, &mut g);
                    ne.add(&g, &ex.delta);
                }
                ne
            })
            .collect();
        let mut total = NormalEquations::new(k, POSE_DIM);
        for b in &batches {
            total.merge(b);
        }
        total
    }

    /// Coefficients fitted to `examples` (VertiAdaptor's adaptation: one least-squares
    /// solve). The baselines have nothing to fit: their coefficient stays 1.
    pub fn adapt(&self, examples: &[Example]) -> Result<Vec<f64>> {
        if self.card.method != Method::Va {
            return Ok(vec![1.0]);
        }
        self.normal_equations(examples)
            .solve(self.card.lambda)
            .map_err(|e| VaError::Data(format!("{}: {e}", self.card.name)))
    }
}

/// A field's inputs other than roll and pitch: the embeddings and the command, held through
/// the RK4 stages.
pub(crate) fn held_inputs(
    embedding: &[f32; 2 * EMBED],
    command: (f64, f64),
) -> [f32; FIELD_INPUT - 2] {
    let mut rest = [0f32; FIELD_INPUT - 2];
    rest[..2 * EMBED].copy_from_slice(embedding);
    rest[2 * EMBED] = command.0 as f32;
    rest[2 * EMBED + 1] = command.1 as f32;
    rest
}

impl WeightsCard for VaCard {
    fn weights_info(&self) -> &WeightsRef {
        &self.weights
    }
}

/// Parses a card, naming the file and the problem.
pub fn parse_card(text: &str, path: &Path) -> Result<VaCard> {
    verti_nn::card::parse(text, path)
}
