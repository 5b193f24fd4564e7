//! Left- and right-tail CVaR of a PMF on ordered bin values (PIETRA eqs. 3–8, spec §A.7).
//!
//! The planner simulates rollouts with the left-tail CVaR of traction (the mean of the worst,
//! lowest, α fraction) and constrains the right-tail CVaR of |roll| and |pitch| (the mean of the
//! highest α fraction). α ∈ (0, 1] is the risk tolerance: small α is risk-averse, α = 1 is the
//! mean.
//!
//! Conventions shared by every function here, so that a bad PMF never stops a planner:
//! * `values` must be ascending (as [`crate::bins::Bins::values`] returns); they are not sorted.
//! * Masses that are negative or NaN count as 0, and the rest are normalised by their sum, so a
//!   PMF that sums to 0.999 or to 5 is handled as the distribution it is proportional to.
//! * A PMF with no usable mass (all zero, or an infinite sum) returns the plain mean of `values`,
//!   i.e. it is treated as uniform.
//! * α > 1 is treated as 1; α ≤ 0 or NaN as the smallest positive α, which returns the worst
//!   atom with positive mass.

use crate::bins::{B, Pmf};
use crate::lanes::{LANES, Lanes, sum_start};

/// Mass of one bin after the "negative or NaN counts as 0" rule.
#[inline]
fn mass(p: f64) -> f64 {
    if p > 0.0 { p } else { 0.0 }
}

/// What a PMF with no usable mass gets: the plain mean of `values`.
#[inline]
fn uniform_mean(values: &[f64; B]) -> f64 {
    values.iter().sum::<f64>() / B as f64
}

/// α as the tails use it: above 1 is 1, and 0, negative or NaN the smallest positive α.
#[inline]
fn tail_fraction(alpha: f64) -> f64 {
    if alpha > 0.0 {
        alpha.min(1.0)
    } else {
        f64::MIN_POSITIVE
    }
}

/// Mean of the worst α fraction of the mass, visiting bins in `order` (worst first).
/// `exact` splits the crossing atom; otherwise the whole crossing atom is taken (mppi_numba).
#[inline]
fn tail(p: &Pmf, values: &[f64; B], alpha: f64, order: [usize; B], exact: bool) -> f64 {
    let total: f64 = p.iter().map(|&x| mass(x)).sum();
    if !(total > 0.0 && total.is_finite()) {
        return uniform_mean(values);
    }
    let alpha = tail_fraction(alpha);
    let (mut cum, mut acc) = (0.0, 0.0);
    let mut last = order[0];
    for b in order {
        let q = mass(p[b]) / total;
        if q == 0.0 {
            continue;
        }
        last = b;
        if cum + q >= alpha {
            return if exact {
                // (1/α)[acc + (α − cum)·v], written so that a tiny α loses no precision.
                acc / alpha + (1.0 - cum / alpha) * values[b]
            } else {
                (acc + q * values[b]) / (cum + q)
            };
        }
        cum += q;
        acc += q * values[b];
    }
    // Only reachable when rounding leaves Σq just below α ≈ 1: the remainder is the last atom's.
    if exact {
        acc / alpha + (1.0 - cum / alpha) * values[last]
    } else {
        acc / cum
    }
}

/// [`cvar_left`] (`left`) or [`cvar_right`] of [`LANES`] PMFs side by side (`p[b][l]`: bin `b`
/// of lane `l`), each lane with exactly the operations of `tail` in its order, so the values
/// are bit-identical to one PMF at a time (tested through the CVaR map). Every lane visits all
/// bins; a lane whose tail is complete only stops accumulating, so the divisions of four lanes
/// share one vector instruction.
#[inline(always)]
pub(crate) fn cvar_lanes(p: &[Lanes; B], values: &[f64; B], alpha: f64, left: bool) -> Lanes {
    let order = if left { ascending() } else { descending() };
    let mut total: Lanes = [sum_start(); LANES];
    for q in p {
        for l in 0..LANES {
            total[l] += mass(q[l]);
        }
    }
    let alpha = tail_fraction(alpha);
    let (mut cum, mut acc) = ([0.0; LANES], [0.0; LANES]);
    let mut last = [order[0]; LANES];
    let mut done = [false; LANES];
    for b in order {
        let q: Lanes = std::array::from_fn(|l| mass(p[b][l]) / total[l]);
        for l in 0..LANES {
            if done[l] || q[l] == 0.0 {
                continue;
            }
            last[l] = b;
            if cum[l] + q[l] >= alpha {
                done[l] = true;
            } else {
                cum[l] += q[l];
                acc[l] += q[l] * values[b];
            }
        }
    }
    // `tail`'s return at the crossing atom and after the loop are the same expression
    std::array::from_fn(|l| {
        if !(total[l] > 0.0 && total[l].is_finite()) {
            uniform_mean(values)
        } else {
            acc[l] / alpha + (1.0 - cum[l] / alpha) * values[last[l]]
        }
    })
}

#[inline]
fn ascending() -> [usize; B] {
    std::array::from_fn(|k| k)
}

#[inline]
fn descending() -> [usize; B] {
    std::array::from_fn(|k| B - 1 - k)
}

/// Left-tail CVaR←_α: the mean of the lowest α fraction of the mass, exact with a fractional last
/// atom. With b* = min{b : Σ_{j≤b} p_j ≥ α} it is (1/α)[Σ_{b<b*} p_b v_b + (α − Σ_{b<b*} p_b) v_{b*}].
/// Used for traction (ψ1, ψ2) in the CVaR dynamics of eq. 4, because low traction is the risk.
/// See the module docs for the handling of unnormalised PMFs and out-of-range α.
#[inline]
pub fn cvar_left(p: &Pmf, values: &[f64; B], alpha: f64) -> f64 {
    tail(p, values, alpha, ascending(), true)
}

/// Right-tail CVaR→_α: the mean of the highest α fraction of the mass, exact with a fractional
/// last atom; equals −CVaR←_α of the negated values. Used for |roll| and |pitch| (ψ3, ψ4) in the
/// constraints of eq. 5, because large attitude is the risk.
#[inline]
pub fn cvar_right(p: &Pmf, values: &[f64; B], alpha: f64) -> f64 {
    tail(p, values, alpha, descending(), true)
}

/// The reference code's variant, kept for comparisons (mppi_numba `set_TDM_from_semantic_grid`):
/// with b* = min{b : Σ_{j≤b} p_j ≥ α} it takes the whole crossing bin,
/// Σ_{b≤b*} p_b v_b / Σ_{b≤b*} p_b, so it is less pessimistic than [`cvar_left`] and is a step
/// function of α. (mppi_numba also quantises to int8 percent; that is not reproduced.)
pub fn cvar_left_binwise(p: &Pmf, values: &[f64; B], alpha: f64) -> f64 {
    tail(p, values, alpha, ascending(), false)
}

/// The reference code's variant, kept for comparisons: the right-tail counterpart of
/// [`cvar_left_binwise`] (whole crossing bin, counted from the highest value down).
pub fn cvar_right_binwise(p: &Pmf, values: &[f64; B], alpha: f64) -> f64 {
    tail(p, values, alpha, descending(), false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bins::{Bins, uniform};
    use verti_core::Rng;

    fn idx_values() -> [f64; B] {
        std::array::from_fn(|k| k as f64)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    fn random_pmf(rng: &mut Rng) -> Pmf {
        let mut p: Pmf = std::array::from_fn(|_| rng.uniform().powi(3));
        let s: f64 = p.iter().sum();
        p.iter_mut().for_each(|x| *x /= s);
        p
    }

    #[test]
    fn one_hot_gives_its_value_for_any_alpha() {
        let bins = Bins::traction();
        let v = bins.values();
        for k in [0, 5, 11] {
            let p = bins.one_hot(v[k]);
            for a in [1e-9, 0.1, 0.5, 0.99, 1.0, 0.0, -1.0, f64::NAN, 3.0] {
                for f in [cvar_left, cvar_right, cvar_left_binwise, cvar_right_binwise] {
                    assert!(close(f(&p, &v, a), v[k]), "bin {k}, alpha {a}");
                }
            }
        }
    }

    #[test]
    fn uniform_half_is_mean_of_half() {
        let v = Bins::traction().values();
        let u = uniform();
        let low: f64 = v[..6].iter().sum::<f64>() / 6.0;
        let high: f64 = v[6..].iter().sum::<f64>() / 6.0;
        assert!(close(cvar_left(&u, &v, 0.5), low));
        assert!(close(cvar_right(&u, &v, 0.5), high));
        // α = 0.5 lands exactly on a bin edge, so the binwise variant agrees up to rounding.
        assert!((cvar_left_binwise(&u, &v, 0.5) - low).abs() < 0.1);
        // α = 0.25 → lowest three values (0, 1, 2) → 1.
        assert!(close(cvar_left(&u, &idx_values(), 0.25), 1.0));
    }

    #[test]
    fn alpha_one_is_the_mean() {
        let mut rng = Rng::new(3);
        let v = Bins::attitude().values();
        for _ in 0..50 {
            let p = random_pmf(&mut rng);
            let mean: f64 = p.iter().zip(&v).map(|(a, b)| a * b).sum();
            for f in [cvar_left, cvar_right, cvar_left_binwise, cvar_right_binwise] {
                assert!(close(f(&p, &v, 1.0), mean));
                assert!(close(f(&p, &v, 7.0), mean));
            }
        }
    }

    #[test]
    fn two_atoms_fractional_split_by_hand() {
        let v = idx_values();
        let mut p = [0.0; B];
        p[2] = 0.3;
        p[7] = 0.7;
        // Lowest 0.5: 0.3 at 2 and 0.2 at 7 → (0.6 + 1.4) / 0.5 = 4.
        assert!(close(cvar_left(&p, &v, 0.5), 4.0));
        // Binwise takes all of bin 7: (0.6 + 4.9) / 1.0 = 5.5.
        assert!(close(cvar_left_binwise(&p, &v, 0.5), 5.5));
        // Lowest 0.3 is exactly the atom at 2; lowest 0.2 too.
        assert!(close(cvar_left(&p, &v, 0.3), 2.0));
        assert!(close(cvar_left(&p, &v, 0.2), 2.0));
        // Highest 0.5 is all at 7; highest 0.8: 0.7·7 + 0.1·2 = 5.1 → 6.375.
        assert!(close(cvar_right(&p, &v, 0.5), 7.0));
        assert!(close(cvar_right(&p, &v, 0.8), 6.375));
        assert!(close(cvar_right_binwise(&p, &v, 0.8), 5.5));
        // Degenerate α: worst atom with positive mass, not the empty bin 0 / 11.
        assert!(close(cvar_left(&p, &v, 0.0), 2.0));
        assert!(close(cvar_left(&p, &v, f64::NAN), 2.0));
        assert!(close(cvar_right(&p, &v, -0.5), 7.0));
    }

    #[test]
    fn right_is_minus_left_of_negated_reversed() {
        let mut rng = Rng::new(5);
        let v = Bins::attitude().values();
        let neg: [f64; B] = std::array::from_fn(|k| -v[B - 1 - k]);
        for _ in 0..50 {
            let p = random_pmf(&mut rng);
            let rev: Pmf = std::array::from_fn(|k| p[B - 1 - k]);
            let a = rng.range(0.01, 1.0);
            assert!(close(cvar_right(&p, &v, a), -cvar_left(&rev, &neg, a)));
            let (r, l) = (
                cvar_right_binwise(&p, &v, a),
                cvar_left_binwise(&rev, &neg, a),
            );
            assert!(close(r, -l));
        }
    }

    #[test]
    fn matches_sorted_sample_tail_mean() {
        // Monte Carlo: draw from the PMF, sort, average the lowest ⌈αN⌉ draws.
        let mut rng = Rng::new(9);
        let v = Bins::traction().values();
        let p = random_pmf(&mut rng);
        let n = 200_000;
        let mut draws: Vec<f64> = (0..n)
            .map(|_| {
                let (u, mut c) = (rng.uniform(), 0.0);
                for k in 0..B {
                    c += p[k];
                    if u < c {
                        return v[k];
                    }
                }
                v[B - 1]
            })
            .collect();
        draws.sort_by(f64::total_cmp);
        for a in [0.05, 0.2, 0.45, 0.8] {
            let m = (a * n as f64).ceil() as usize;
            let low = draws[..m].iter().sum::<f64>() / m as f64;
            let high = draws[n - m..].iter().sum::<f64>() / m as f64;
            assert!((cvar_left(&p, &v, a) - low).abs() < 5e-3, "alpha {a}");
            assert!((cvar_right(&p, &v, a) - high).abs() < 5e-3, "alpha {a}");
        }
    }

    #[test]
    fn monotone_in_alpha_and_binwise_less_pessimistic() {
        let mut rng = Rng::new(13);
        let v = Bins::traction().values();
        for _ in 0..20 {
            let p = random_pmf(&mut rng);
            let mut prev = f64::NEG_INFINITY;
            for i in 1..=100 {
                let a = i as f64 / 100.0;
                let c = cvar_left(&p, &v, a);
                assert!(c >= prev - 1e-12, "left CVaR must not decrease with alpha");
                assert!(cvar_left_binwise(&p, &v, a) >= c - 1e-12);
                assert!(cvar_right_binwise(&p, &v, a) <= cvar_right(&p, &v, a) + 1e-12);
                prev = c;
            }
        }
    }

    #[test]
    fn unnormalised_and_bad_pmfs() {
        let v = idx_values();
        let mut p = [0.0; B];
        p[2] = 0.3;
        p[7] = 0.7;
        let scaled: Pmf = std::array::from_fn(|k| p[k] * 4.0);
        assert!(close(cvar_left(&scaled, &v, 0.5), 4.0));
        let short: Pmf = std::array::from_fn(|k| p[k] * 0.999);
        assert!(close(cvar_left(&short, &v, 0.5), 4.0));
        // Negative and NaN masses count as zero.
        let mut noisy = p;
        noisy[0] = -0.2;
        noisy[11] = f64::NAN;
        assert!(close(cvar_left(&noisy, &v, 0.5), 4.0));
        assert!(close(cvar_right(&noisy, &v, 0.5), 7.0));
        // No usable mass → plain mean of the values (5.5).
        for bad in [[0.0; B], [f64::NAN; B], [-1.0; B], [f64::INFINITY; B]] {
            for f in [cvar_left, cvar_right, cvar_left_binwise, cvar_right_binwise] {
                assert!(close(f(&bad, &v, 0.3), 5.5));
            }
        }
    }
}
