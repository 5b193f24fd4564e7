//! The B = 12 ordered bins on which every traversability parameter is predicted.
//!
//! PIETRA (§IV-D) predicts each parameter as a categorical distribution over B = 12 bins but does
//! not publish the bin edges. Following the learning spec (§A.6) we use uniform bins: [0, 1] for
//! the two tractions and [0, 45°] for |roll| and |pitch|. Every PMF, loss and CVaR in this crate
//! is on these bins, so they live in one place.

use serde::{Deserialize, Serialize};

/// Number of bins per traversability parameter. PIETRA uses 12; it is a constant (not a config
/// value) so that PMFs can be fixed-size arrays that are cheap to copy and never mis-sized.
pub const B: usize = 12;

/// A probability mass function over the [`B`] bins of one parameter, lowest value first.
/// A fixed-size array, so that lengths can never disagree between a prediction and its target.
pub type Pmf = [f64; B];

/// Number of traversability parameters ψ1..ψ4; the network has one decoder head per parameter.
pub const PARAMS: usize = 4;

/// Human-readable names of ψ1..ψ4 in order, for logs, plots and reports.
pub const PARAM_NAMES: [&str; PARAMS] = ["linear traction", "angular traction", "roll", "pitch"];

/// Uniform bins on `[lo, hi]`: bin k covers `[lo + k·w, lo + (k+1)·w)` with w = (hi − lo)/B and
/// is represented by its centre. Values outside the range fall into the first or last bin, so
/// that out-of-range targets (e.g. a 60° roll) still become a valid one-hot PMF.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bins {
    /// Lower edge of the first bin.
    pub lo: f64,
    /// Upper edge of the last bin.
    pub hi: f64,
}

impl Bins {
    /// Uniform bins on `[lo, hi]`. `hi > lo` is expected; degenerate or non-finite ranges do not
    /// panic (every value then lands in bin 0 or bin B − 1), because bins may come from files.
    pub fn new(lo: f64, hi: f64) -> Self {
        Bins { lo, hi }
    }

    /// Bins of the linear and angular traction ψ1, ψ2, which are ratios of achieved to commanded
    /// velocity and therefore lie in [0, 1] (eq. 2).
    pub fn traction() -> Self {
        Bins::new(0.0, 1.0)
    }

    /// Bins of |roll| ψ3 and |pitch| ψ4, in radians on [0, 45°]: this covers the hardware pitch
    /// limit (45°) and roll limit (30°) of the paper; steeper attitudes go to the last bin.
    pub fn attitude() -> Self {
        Bins::new(0.0, 45f64.to_radians())
    }

    /// Width of one bin; used to turn a value into a bin index and a bin into its centre.
    #[inline]
    pub fn width(&self) -> f64 {
        (self.hi - self.lo) / B as f64
    }

    /// Index of the bin that contains `v`, clamped to `0..B`. NaN maps to bin 0 so that a bad
    /// measurement still yields a valid PMF instead of a panic; callers that need a different
    /// NaN policy (e.g. pessimistic attitude) must handle NaN before calling.
    #[inline(always)]
    pub fn index(&self, v: f64) -> usize {
        let t = (v - self.lo) / (self.hi - self.lo) * B as f64;
        if t.is_nan() || t <= 0.0 {
            0
        } else if t >= (B - 1) as f64 {
            B - 1
        } else {
            // 0 < t < B − 1, so the cast cannot saturate, and truncation is the floor (one
            // instruction, where `floor` may be a library call).
            t as usize
        }
    }

    /// Representative value (centre) of bin `k`; the CVaR and the expected value of a PMF are
    /// computed on these values. `k ≥ B` is a programmer error and panics.
    #[inline]
    pub fn value(&self, k: usize) -> f64 {
        assert!(k < B, "bin index {k} out of range 0..{B}");
        self.lo + (k as f64 + 0.5) * self.width()
    }

    /// All [`B`] bin centres in ascending order, the `values` argument of the CVaR functions.
    #[inline]
    pub fn values(&self) -> [f64; B] {
        std::array::from_fn(|k| self.value(k))
    }

    /// One-hot PMF on the bin that contains `v` (the 𝟙 operator of eqs. 15–17 and the form of a
    /// data target); NaN goes to bin 0 as in [`Bins::index`].
    pub fn one_hot(&self, v: f64) -> Pmf {
        let mut p = [0.0; B];
        p[self.index(v)] = 1.0;
        p
    }
}

/// The uniform PMF: EVORA's uninformative prior and the `w_unif` component of eq. 18 that keeps
/// the physics prior from being over-confident.
pub fn uniform() -> Pmf {
    [1.0 / B as f64; B]
}

/// Bins of ψ1..ψ4 in order (traction, traction, attitude, attitude), so that code can loop over
/// the four parameters instead of special-casing each.
pub fn param_bins() -> [Bins; PARAMS] {
    [
        Bins::traction(),
        Bins::traction(),
        Bins::attitude(),
        Bins::attitude(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traction_edges_and_centres() {
        let b = Bins::traction();
        // Edges at k/12: 0.0 and 0.0833 are in bin 0, 1/12 + ε in bin 1, 0.5 in bin 6.
        assert_eq!(b.index(0.0), 0);
        assert_eq!(b.index(0.08), 0);
        assert_eq!(b.index(0.09), 1);
        assert_eq!(b.index(0.5), 6);
        assert_eq!(b.index(0.99), 11);
        assert_eq!(b.index(1.0), 11);
        assert!((b.value(0) - 1.0 / 24.0).abs() < 1e-15);
        assert!((b.value(11) - 23.0 / 24.0).abs() < 1e-15);
        let v = b.values();
        for k in 0..B {
            assert_eq!(b.index(v[k]), k, "centre of bin {k} maps back to it");
            if k > 0 {
                assert!((v[k] - v[k - 1] - 1.0 / 12.0).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn out_of_range_and_nan_are_clamped() {
        let b = Bins::traction();
        assert_eq!(b.index(-3.0), 0);
        assert_eq!(b.index(7.0), B - 1);
        assert_eq!(b.index(f64::NEG_INFINITY), 0);
        assert_eq!(b.index(f64::INFINITY), B - 1);
        assert_eq!(b.index(f64::NAN), 0);
        // Degenerate ranges must not panic.
        let d = Bins::new(1.0, 1.0);
        assert_eq!(d.index(1.0), 0);
        assert_eq!(d.index(2.0), B - 1);
        let n = Bins::new(f64::NAN, 1.0);
        assert_eq!(n.index(0.5), 0);
    }

    #[test]
    fn attitude_is_in_radians() {
        let b = Bins::attitude();
        assert!((b.hi - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        // 20° / 45° · 12 = 5.33 → bin 5; 44° → bin 11; 90° clamps to bin 11.
        assert_eq!(b.index(20f64.to_radians()), 5);
        assert_eq!(b.index(44f64.to_radians()), 11);
        assert_eq!(b.index(90f64.to_radians()), 11);
        assert!((b.value(0).to_degrees() - 45.0 / 24.0).abs() < 1e-12);
    }

    #[test]
    fn one_hot_and_uniform_are_pmfs() {
        let b = Bins::attitude();
        let p = b.one_hot(0.3);
        assert_eq!(p.iter().sum::<f64>(), 1.0);
        assert_eq!(p[b.index(0.3)], 1.0);
        assert_eq!(p.iter().filter(|&&x| x == 0.0).count(), B - 1);
        let u = uniform();
        assert!((u.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(u.iter().all(|&x| x == u[0]));
    }

    #[test]
    fn param_bins_order_and_names() {
        let pb = param_bins();
        assert_eq!(pb[0], Bins::traction());
        assert_eq!(pb[1], Bins::traction());
        assert_eq!(pb[2], Bins::attitude());
        assert_eq!(pb[3], Bins::attitude());
        assert_eq!(PARAM_NAMES[2], "roll");
        assert_eq!(PARAM_NAMES.len(), PARAMS);
    }

    #[test]
    #[should_panic]
    fn value_out_of_range_panics() {
        let _ = Bins::traction().value(B);
    }

    #[test]
    fn serde_round_trip() {
        let b = Bins::attitude();
        let s = serde_json::to_string(&b).unwrap();
        let back: Bins = serde_json::from_str(&s).unwrap();
        assert_eq!(b, back);
    }
}
