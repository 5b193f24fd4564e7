//! The scalar tail of a CVaR map footprint — [`TravModel::finish`] and the four CVaRs of
//! [`crate::cvar_map`] — for [`LANES`] footprints at a time.
//!
//! Lane `l` of every array is footprint `l`, and each lane runs exactly the operations of the
//! one-footprint code in the same order (the same sums from the same start, divisions kept as
//! divisions, the same `exp`/`ln` calls), so the results are bit-identical to it (tested through
//! the map in `cvar_map`). What changes is only that four footprints' divisions, square roots
//! and sums sit side by side, where the compiler puts them in one vector instruction: the
//! one-footprint tail is ~150 dependent scalar divisions per footprint.
//!
//! [`TravModel::finish`]: crate::model::TravModel

use crate::bins::{B, Bins, PARAMS, Pmf, uniform};
use crate::cvar::cvar_lanes;
use crate::lanes::{LANES, Lanes, sum_start};
use crate::model::TravModel;

/// The inputs of [`finish_cvars`] for one lane: the latent, the decoders' logits, the
/// evidence scaler's outputs and the physics prior of one footprint.
pub(crate) struct LaneInput<'a> {
    pub z: &'a [f32],
    pub logits: &'a [[f32; B]; PARAMS],
    pub scale: &'a [f32; PARAMS],
    pub physics: &'a [Pmf; PARAMS],
}

/// What [`TravModel::finish`] followed by `pmf_cvars` gives for each of four footprints: the
/// four CVaRs at `alpha` on `bins` and the latent log-density (NaN without a flow).
#[inline(always)]
pub(crate) fn finish_cvars(
    m: &TravModel,
    input: [LaneInput<'_>; LANES],
    bins: &[Bins; PARAMS],
    alpha: f64,
    flow: &mut Vec<Lanes>,
) -> ([[f64; PARAMS]; LANES], Lanes) {
    let c = &m.card;
    // softmax of each decoder's logits, in f64 from the f32 differences to the maximum
    let mut learned = [[[0.0; LANES]; B]; PARAMS];
    for (k, learned) in learned.iter_mut().enumerate() {
        let max: [f32; LANES] = std::array::from_fn(|l| {
            input[l].logits[k]
                .iter()
                .copied()
                .fold(f32::NEG_INFINITY, f32::max)
        });
        let mut sum = [0.0; LANES];
        for (b, p) in learned.iter_mut().enumerate() {
            for l in 0..LANES {
                p[l] = f64::from(input[l].logits[k][b] - max[l]).exp();
                sum[l] += p[l];
            }
        }
        for p in learned.iter_mut() {
            for l in 0..LANES {
                p[l] /= sum[l];
            }
        }
    }
    if !c.evidential {
        return (cvars(&learned, bins, alpha), [f64::NAN; LANES]);
    }
    let log_density = log_density_lanes(m, &input, flow);
    let mut pmf = [[[0.0; LANES]; B]; PARAMS];
    let log_n: Lanes = std::array::from_fn(|l| {
        (log_density[l] + c.log_budget).clamp(-c.log_evidence_clamp, c.log_evidence_clamp)
    });
    let u = uniform();
    for k in 0..PARAMS {
        let n: Lanes = std::array::from_fn(|l| {
            let mut ln = log_n[l];
            if c.scales_evidence {
                ln += -crate::model::softplus(-f64::from(input[l].scale[k]));
            }
            ln.exp()
        });
        let mut total = [0.0; LANES];
        for b in 0..B {
            for l in 0..LANES {
                let prior = if c.physics_in_posterior {
                    input[l].physics[k][b]
                } else {
                    u[b]
                };
                pmf[k][b][l] = c.prior_evidence * prior + n[l] * learned[k][b][l];
                total[l] += pmf[k][b][l];
            }
        }
        for p in pmf[k].iter_mut() {
            for l in 0..LANES {
                p[l] /= total[l];
            }
        }
    }
    (cvars(&pmf, bins, alpha), log_density)
}

/// `pmf_cvars` of four footprints: left tails of the tractions, right tails of the attitudes.
#[inline(always)]
fn cvars(pmf: &[[Lanes; B]; PARAMS], bins: &[Bins; PARAMS], alpha: f64) -> [[f64; PARAMS]; LANES] {
    let mut out = [[0.0; PARAMS]; LANES];
    for k in 0..PARAMS {
        let v = cvar_lanes(&pmf[k], &bins[k].values(), alpha, k < 2);
        for l in 0..LANES {
            out[l][k] = v[l];
        }
    }
    out
}

/// `TravModel::log_density_in` of four latents.
#[inline(always)]
fn log_density_lanes(m: &TravModel, input: &[LaneInput<'_>; LANES], v: &mut Vec<Lanes>) -> Lanes {
    let h = m.card.latent;
    let (alpha, beta) = m.flow();
    v.clear();
    v.extend((0..h).map(|i| std::array::from_fn(|l| f64::from(input[l].z[i]))));
    let mut log_det = [0.0; LANES];
    for (layer, (&a, &b)) in alpha.iter().zip(beta).enumerate() {
        let z0 = &m.card.flow_z0[layer * h..(layer + 1) * h];
        let mut sq = [sum_start(); LANES];
        for (x, c) in v.iter().zip(z0) {
            for l in 0..LANES {
                sq[l] += (x[l] - c) * (x[l] - c);
            }
        }
        let mut bh = [0.0; LANES];
        let mut hh = [0.0; LANES];
        for l in 0..LANES {
            let r = (sq[l] + 1e-12).sqrt();
            hh[l] = 1.0 / (a + r);
            bh[l] = b * hh[l];
        }
        for (x, c) in v.iter_mut().zip(z0) {
            for l in 0..LANES {
                x[l] += bh[l] * (x[l] - c);
            }
        }
        for l in 0..LANES {
            log_det[l] +=
                (h as f64 - 1.0) * (1.0 + bh[l]).ln() + (1.0 + a * b * hh[l] * hh[l]).ln();
        }
    }
    let mut sq = [sum_start(); LANES];
    for x in v.iter() {
        for l in 0..LANES {
            sq[l] += x[l] * x[l];
        }
    }
    let ln_2pi = (2.0 * std::f64::consts::PI).ln();
    std::array::from_fn(|l| log_det[l] - 0.5 * (sq[l] + h as f64 * ln_2pi))
}
