//! The lane width and lane type of the code that computes [`LANES`] footprints side by side
//! (`model_lanes`, `cvar::cvar_lanes`, `map_simd`), and the start value of their hand-written
//! sums. Its own module, below all of them, so that `cvar` and `model_lanes` (which calls
//! `cvar_lanes`) do not import each other.

/// Footprints per call: one 256-bit vector of f64.
pub(crate) const LANES: usize = 4;

/// One value per lane.
pub(crate) type Lanes = [f64; LANES];

/// Where `Iterator::sum` of f64 starts (−0.0 in current Rust), so that sums written out by
/// hand, lane by lane, equal it.
#[inline(always)]
pub(crate) fn sum_start() -> f64 {
    std::iter::empty::<f64>().sum()
}
