//! The CVaR map's terrain lookups four footprints at a time (AVX2): lane k is the k-th of four
//! neighbouring cells of one heading, so every lane runs the scalar code's operations in the
//! scalar code's order, on the same values: the results are bit-identical to
//! [`crate::dataset::footprint_patch`] (tested through the map).

#![cfg(target_arch = "x86_64")]

use crate::dataset::FEATURES;
use std::arch::x86_64::*;
use verti_world::Heightfield;

/// [`crate::dataset::height_on_grid`] in four lanes.
///
/// # Safety
/// AVX2 must be available, and `t` must have fewer than 2^30 vertices per side.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn height_on_grid4(t: &Heightfield, gc: __m256d, gr: __m256d) -> __m256d {
    let n = t.size();
    let m = _mm256_set1_pd((n - 1) as f64);
    let zero = _mm256_setzero_pd();
    // max(0, x) and min(m, x) return x when x is NaN, as `clamp` does (and keep −0)
    let gc = _mm256_min_pd(m, _mm256_max_pd(zero, gc));
    let gr = _mm256_min_pd(m, _mm256_max_pd(zero, gr));
    // truncation; NaN lanes convert to i32::MIN and are taken to 0, as `as i64` takes NaN
    let top = _mm_set1_epi32((n - 2) as i32);
    let z32 = _mm_setzero_si128();
    let c0 = _mm_min_epi32(_mm_max_epi32(_mm256_cvttpd_epi32(gc), z32), top);
    let r0 = _mm_min_epi32(_mm_max_epi32(_mm256_cvttpd_epi32(gr), z32), top);
    let u = _mm256_sub_pd(gc, _mm256_cvtepi32_pd(c0));
    let v = _mm256_sub_pd(
        _mm256_set1_pd(1.0),
        _mm256_sub_pd(gr, _mm256_cvtepi32_pd(r0)),
    );
    let idx = _mm_add_epi32(_mm_mullo_epi32(r0, _mm_set1_epi32(n as i32)), c0);
    let h = t.heights().as_ptr();
    // SAFETY: r0, c0 ≤ n − 2, so idx + n + 1 < n².
    let (nw, ne, sw, se) = unsafe {
        (
            _mm256_i32gather_pd::<8>(h, idx),
            _mm256_i32gather_pd::<8>(h.add(1), idx),
            _mm256_i32gather_pd::<8>(h.add(n), idx),
            _mm256_i32gather_pd::<8>(h.add(n + 1), idx),
        )
    };
    let lower = _mm256_add_pd(
        _mm256_add_pd(sw, _mm256_mul_pd(u, _mm256_sub_pd(se, sw))),
        _mm256_mul_pd(v, _mm256_sub_pd(ne, se)),
    );
    let upper = _mm256_add_pd(
        _mm256_add_pd(sw, _mm256_mul_pd(v, _mm256_sub_pd(nw, sw))),
        _mm256_mul_pd(u, _mm256_sub_pd(ne, nw)),
    );
    _mm256_blendv_pd(upper, lower, _mm256_cmp_pd::<_CMP_GE_OQ>(u, v))
}

/// The features of four patches: lane k centred on grid coordinates (`gc0[k]`, `gr0`), point
/// p at ((gc0 + `cf[p]`) + `cl[p]`, gr0 − `rf[p]`), written to `out[k]` relative to the patch
/// mean.
///
/// # Safety
/// AVX2 must be available, and `t` must have fewer than 2^30 vertices per side.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn patches4(
    t: &Heightfield,
    gc0: [f64; 4],
    gr0: f64,
    cf: &[f64; FEATURES],
    cl: &[f64; FEATURES],
    rf: &[f64; FEATURES],
    out: [&mut [f32]; 4],
) {
    assert!(t.size() < 1 << 30);
    let mut z = [_mm256_setzero_pd(); FEATURES];
    let gc0 = _mm256_set_pd(gc0[3], gc0[2], gc0[1], gc0[0]);
    let gr0 = _mm256_set1_pd(gr0);
    // the sum starts where `Iterator::sum` of f64 starts
    let mut sum = _mm256_set1_pd(crate::lanes::sum_start());
    for p in 0..FEATURES {
        let gc = _mm256_add_pd(
            _mm256_add_pd(gc0, _mm256_set1_pd(cf[p])),
            _mm256_set1_pd(cl[p]),
        );
        let gr = _mm256_sub_pd(gr0, _mm256_set1_pd(rf[p]));
        // SAFETY: AVX2 (this function's contract) and the size asserted above.
        z[p] = unsafe { height_on_grid4(t, gc, gr) };
        sum = _mm256_add_pd(sum, z[p]);
    }
    let mean = _mm256_div_pd(sum, _mm256_set1_pd(FEATURES as f64));
    let mut lanes = [[0.0f32; 4]; FEATURES];
    for p in 0..FEATURES {
        // SAFETY: 4 f32 into a 4-element array.
        unsafe {
            _mm_storeu_ps(
                lanes[p].as_mut_ptr(),
                _mm256_cvtpd_ps(_mm256_sub_pd(z[p], mean)),
            )
        };
    }
    for (k, o) in out.into_iter().enumerate() {
        for (p, v) in o.iter_mut().enumerate().take(FEATURES) {
            *v = lanes[p][k];
        }
    }
}
