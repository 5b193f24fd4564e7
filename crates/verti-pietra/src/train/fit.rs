//! One training run of a learning-benchmark method, and the scores every method (trained or
//! not) gets on a set of samples.
//!
//! The run, in order: draw the network from the seed; for each step draw a mini-batch from the
//! training samples, form the method's posterior and loss, take one Adam step at a constant
//! learning rate; then score the final network on validation and test samples by the EMD² of
//! its expected PMF against the one-hot targets, summed over the four parameters.

use super::data::{PietraData, Prepared};
use super::model::{LossWeights, Method, TravNet, expected_pmf, loss};
use super::special::cumsum_matrix;
use crate::bins::{B, PARAMS, Pmf, uniform};
use crate::emd::emd2;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};
use std::time::Instant;
use verti_core::Rng;
use verti_nn::train::seq::values;

/// One point of the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunConfig {
    pub method: Method,
    pub lr: f64,
    pub weights: LossWeights,
    pub seed: u64,
    pub steps: usize,
    pub batch: usize,
}

/// The EMD² of every sample (summed over the four parameters), and each parameter's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleErrors {
    pub total: Vec<f64>,
    pub per_param: Vec<[f64; PARAMS]>,
    /// log p(z) of every sample (evidential methods; NaN otherwise).
    pub log_density: Vec<f64>,
}

/// Mean EMD² overall, on ID and on OOD samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    #[serde(with = "nan_as_null")]
    pub overall: f64,
    #[serde(with = "nan_as_null")]
    pub id: f64,
    #[serde(with = "nan_as_null")]
    pub ood: f64,
}

/// JSON has no NaN: a score of an empty set (no OOD samples, say) is written as null.
pub mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            s.serialize_f64(*v)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }

    /// The same for every element of a vector.
    pub mod vec {
        use serde::{Deserialize, Deserializer, Serializer};

        pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
            s.collect_seq(v.iter().map(|x| x.is_finite().then_some(*x)))
        }

        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
            Ok(Vec::<Option<f64>>::deserialize(d)?
                .into_iter()
                .map(|x| x.unwrap_or(f64::NAN))
                .collect())
        }
    }
}

impl SampleErrors {
    /// Errors of fixed PMFs (the physics or the uniform prior).
    pub fn of_pmfs(set: &Prepared, pmf: impl Fn(usize, usize) -> Pmf) -> SampleErrors {
        let mut out = SampleErrors::default();
        for i in 0..set.n {
            let mut per = [0.0; PARAMS];
            for (k, e) in per.iter_mut().enumerate() {
                let row = (i * PARAMS + k) * B;
                let y: Pmf = std::array::from_fn(|b| f64::from(set.targets[row + b]));
                *e = emd2(&pmf(i, k), &y);
            }
            out.total.push(per.iter().sum());
            out.per_param.push(per);
            out.log_density.push(f64::NAN);
        }
        out
    }

    pub fn scores(&self, set: &Prepared, threshold: f64) -> Scores {
        let mean = |keep: &dyn Fn(usize) -> bool| {
            let (mut s, mut n) = (0.0, 0usize);
            for (i, e) in self.total.iter().enumerate() {
                if keep(i) {
                    s += e;
                    n += 1;
                }
            }
            if n == 0 { f64::NAN } else { s / n as f64 }
        };
        Scores {
            overall: mean(&|_| true),
            id: mean(&|i| set.is_id(i, threshold)),
            ood: mean(&|i| !set.is_id(i, threshold)),
        }
    }
}

/// The physics prior's own PMFs of a set's samples.
pub fn physics_pmf(set: &Prepared) -> impl Fn(usize, usize) -> Pmf + '_ {
    move |i, k| {
        let row = (i * PARAMS + k) * B;
        std::array::from_fn(|b| f64::from(set.physics[row + b]))
    }
}

/// The prior each row of a batch of `b` samples uses in `method`'s posterior.
fn posterior_prior(method: Method, physics: &Tensor<2>) -> Tensor<2> {
    if method.physics_in_posterior() {
        physics.clone()
    } else {
        physics.ones_like() / B as f64
    }
}

/// Scores a trained network on every sample of `set` (in chunks, no gradients kept).
pub fn evaluate(net: &TravNet, set: &Prepared, device: &Device) -> SampleErrors {
    let mut out = SampleErrors::default();
    let all: Vec<usize> = (0..set.n).collect();
    for chunk in all.chunks(2048) {
        let (x, _, ph) = set.batch(chunk, device);
        let prior = posterior_prior(net.method, &ph);
        let (p, logd) = expected_pmf(net, x, prior);
        let p = values(p);
        let logd = values(logd);
        for (j, &i) in chunk.iter().enumerate() {
            let mut per = [0.0; PARAMS];
            for (k, e) in per.iter_mut().enumerate() {
                let row = (j * PARAMS + k) * B;
                let q: Pmf = std::array::from_fn(|b| f64::from(p[row + b]));
                let trow = (i * PARAMS + k) * B;
                let y: Pmf = std::array::from_fn(|b| f64::from(set.targets[trow + b]));
                *e = emd2(&q, &y);
            }
            out.total.push(per.iter().sum());
            out.per_param.push(per);
            out.log_density.push(f64::from(logd[j]));
        }
    }
    out
}

/// What a run produced.
pub struct Trained {
    pub net: TravNet,
    pub val: SampleErrors,
    pub test: SampleErrors,
    /// Mean training loss over the last tenth of the steps.
    pub final_loss: f64,
    pub wall_s: f64,
}

/// Trains one network and scores it.
pub fn train(data: &PietraData, cfg: &RunConfig, device: &Device) -> Result<Trained, String> {
    let started = Instant::now();
    if data.train.n == 0 {
        return Err("no training samples".into());
    }
    // 1. the network and the optimiser
    let mut net = TravNet::new(cfg.method, data.input_scale, cfg.seed, device)?;
    let mut optim = AdamConfig::new().init();
    let cs = cumsum_matrix(device);
    let mut rng = Rng::derive(cfg.seed, "pietra-batches", 0);
    let tail = (cfg.steps / 10).max(1);
    let (mut tail_sum, mut tail_n) = (0.0, 0usize);
    for step in 1..=cfg.steps {
        // 2. a mini-batch with its priors
        let idx: Vec<usize> = (0..cfg.batch)
            .map(|_| rng.below(data.train.n as u64) as usize)
            .collect();
        let (x, y, physics) = data.train.batch(&idx, device);
        let prior = posterior_prior(cfg.method, &physics);
        // 3. the method's loss and one Adam step
        let l = loss(&net, x, y, prior, physics, cfg.weights, &cs);
        let value = f64::from(values(l.clone())[0]);
        if !value.is_finite() {
            return Err(format!(
                "{} (lr {}, κ {}, entropy {}, seed {}) diverged at step {step}",
                cfg.method.name(),
                cfg.lr,
                cfg.weights.physics,
                cfg.weights.entropy,
                cfg.seed
            ));
        }
        if step > cfg.steps - tail {
            tail_sum += value;
            tail_n += 1;
        }
        let grads = GradientsParams::from_grads(l.backward(), &net);
        net = optim.step(cfg.lr, net, grads);
    }
    // 4. scores
    let val = evaluate(&net, &data.val, device);
    let test = evaluate(&net, &data.test, device);
    Ok(Trained {
        net,
        val,
        test,
        final_loss: tail_sum / tail_n.max(1) as f64,
        wall_s: started.elapsed().as_secs_f64(),
    })
}

/// "Use the physics model if OOD" (Table II): an EVORA network's expected PMF where the latent
/// density is at least the lowest seen on the training samples, the physics prior below it.
pub fn physics_if_ood(
    evora: &SampleErrors,
    set: &Prepared,
    train_log_density_min: f64,
) -> SampleErrors {
    let phys = SampleErrors::of_pmfs(set, physics_pmf(set));
    let mut out = evora.clone();
    for i in 0..set.n {
        if evora.log_density[i] < train_log_density_min {
            out.total[i] = phys.total[i];
            out.per_param[i] = phys.per_param[i];
        }
    }
    out
}

/// The lowest latent log-density a network gives a training sample.
pub fn train_log_density_min(net: &TravNet, data: &PietraData, device: &Device) -> f64 {
    evaluate(net, &data.train, device)
        .log_density
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// Errors of the uniform prior.
pub fn uniform_errors(set: &Prepared) -> SampleErrors {
    let u = uniform();
    SampleErrors::of_pmfs(set, |_, _| u)
}

/// A tensor of PMF rows (tests).
pub fn pmf_rows(rows: &[Pmf], device: &Device) -> Tensor<2> {
    let v: Vec<f32> = rows.iter().flatten().map(|x| *x as f32).collect();
    Tensor::from_data(TensorData::new(v, [rows.len(), B]), device)
}
