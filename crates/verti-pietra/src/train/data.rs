//! The learning benchmark's data (paper §V-A): samples of the 30 PIETRA maps turned into flat
//! arrays — features, one-hot targets, the physics prior — and split the paper's way: the
//! ID/OOD boundary is the median unevenness of the training samples; training and validation
//! keep ID samples only; the test maps (scaled up vertically) are kept whole.

use crate::bins::{B, Bins, PARAMS, param_bins};
use crate::dataset::{DataConfig, FEATURES, Sample, SplitData, collect};
use crate::maps::Split;
use crate::prior::{PriorConfig, physics_prior};
use burn::tensor::{Device, Tensor, TensorData};
use std::collections::BTreeMap;

/// Samples as arrays, row i of each belonging to sample i.
#[derive(Clone, Debug, Default)]
pub struct Prepared {
    pub n: usize,
    /// [n, FEATURES], metres.
    pub features: Vec<f32>,
    /// [n · 4, B] one-hot targets.
    pub targets: Vec<f32>,
    /// [n · 4, B] physics prior (eq. 18).
    pub physics: Vec<f32>,
    /// Raw targets ψ [n, 4].
    pub psi: Vec<[f64; PARAMS]>,
    pub unevenness: Vec<f64>,
}

impl Prepared {
    pub fn new(samples: &[&Sample], bins: &[Bins; PARAMS], prior: &PriorConfig) -> Prepared {
        let mut p = Prepared {
            n: samples.len(),
            ..Default::default()
        };
        for s in samples {
            p.features.extend_from_slice(&s.features);
            let phys = physics_prior(&s.footprint, prior, bins);
            for k in 0..PARAMS {
                p.targets
                    .extend(bins[k].one_hot(s.targets[k]).iter().map(|v| *v as f32));
                p.physics.extend(phys[k].iter().map(|v| *v as f32));
            }
            p.psi.push(s.targets);
            p.unevenness.push(s.unevenness);
        }
        p
    }

    /// Rows `idx` as tensors: features [b, F], targets and physics prior [b·4, B].
    pub fn batch(&self, idx: &[usize], device: &Device) -> (Tensor<2>, Tensor<2>, Tensor<2>) {
        let rows = PARAMS * B;
        let (mut x, mut y, mut ph) = (
            Vec::with_capacity(idx.len() * FEATURES),
            Vec::with_capacity(idx.len() * rows),
            Vec::with_capacity(idx.len() * rows),
        );
        for &i in idx {
            x.extend_from_slice(&self.features[i * FEATURES..(i + 1) * FEATURES]);
            y.extend_from_slice(&self.targets[i * rows..(i + 1) * rows]);
            ph.extend_from_slice(&self.physics[i * rows..(i + 1) * rows]);
        }
        let b = idx.len();
        (
            Tensor::from_data(TensorData::new(x, [b, FEATURES]), device),
            Tensor::from_data(TensorData::new(y, [b * PARAMS, B]), device),
            Tensor::from_data(TensorData::new(ph, [b * PARAMS, B]), device),
        )
    }

    /// Whether sample i is in distribution.
    pub fn is_id(&self, i: usize, threshold: f64) -> bool {
        self.unevenness[i] <= threshold
    }
}

/// How a split's driving went, for the model card and the README.
#[derive(Clone, Debug, Default)]
pub struct SplitSummary {
    pub trials: usize,
    pub seconds: f64,
    pub samples: usize,
    pub kept: usize,
    pub endings: BTreeMap<String, usize>,
}

/// The three splits, ready to train on.
#[derive(Clone, Debug)]
pub struct PietraData {
    pub train: Prepared,
    pub val: Prepared,
    pub test: Prepared,
    /// ID/OOD boundary: the median unevenness of the training samples, metres.
    pub threshold: f64,
    /// Spread of the training features (inputs are divided by it).
    pub input_scale: f32,
    pub bins: [Bins; PARAMS],
    pub prior: PriorConfig,
    pub summary: BTreeMap<&'static str, SplitSummary>,
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return 0.0;
    }
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

impl PietraData {
    /// Drives the three splits (in parallel inside each) and prepares them. `progress` is told
    /// each split as it finishes.
    pub fn build(
        cfg: &DataConfig,
        prior: PriorConfig,
        progress: &mut dyn FnMut(Split, &SplitData),
    ) -> Result<PietraData, String> {
        let mut raw = BTreeMap::new();
        for split in Split::ALL {
            let data = collect(split, cfg)?;
            if data.samples.is_empty() {
                return Err(format!("the {} maps gave no samples", split.name()));
            }
            progress(split, &data);
            raw.insert(split, data);
        }
        Ok(Self::from_splits(&raw, prior))
    }

    /// Splits and prepares samples already driven.
    pub fn from_splits(raw: &BTreeMap<Split, SplitData>, prior: PriorConfig) -> PietraData {
        let bins = param_bins();
        let train_all = &raw[&Split::Train].samples;
        let threshold = median(&train_all.iter().map(|s| s.unevenness).collect::<Vec<_>>());
        let id = |s: &&Sample| s.unevenness <= threshold;
        let pick = |split: Split, only_id: bool| -> Vec<&Sample> {
            raw[&split]
                .samples
                .iter()
                .filter(|s| !only_id || id(s))
                .collect()
        };
        let (train, val, test) = (
            pick(Split::Train, true),
            pick(Split::Validation, true),
            pick(Split::Test, false),
        );
        let mut summary = BTreeMap::new();
        for (split, kept) in [
            (Split::Train, train.len()),
            (Split::Validation, val.len()),
            (Split::Test, test.len()),
        ] {
            let d = &raw[&split];
            summary.insert(
                split.name(),
                SplitSummary {
                    trials: d.trials,
                    seconds: d.seconds,
                    samples: d.samples.len(),
                    kept,
                    endings: d.endings.clone(),
                },
            );
        }
        let train = Prepared::new(&train, &bins, &prior);
        let n = train.features.len().max(1) as f64;
        let var = train
            .features
            .iter()
            .map(|v| f64::from(*v).powi(2))
            .sum::<f64>()
            / n;
        PietraData {
            input_scale: var.sqrt().max(1e-3) as f32,
            val: Prepared::new(&val, &bins, &prior),
            test: Prepared::new(&test, &bins, &prior),
            train,
            threshold,
            bins,
            prior,
            summary,
        }
    }
}
