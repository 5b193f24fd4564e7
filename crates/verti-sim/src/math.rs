//! Small numeric helpers the inner loops use instead of library calls.

/// x / sqrt(1 + x²): a smooth sign without a transcendental call.
#[inline]
pub(crate) fn soft_sign(x: f64) -> f64 {
    x / (1.0 + x * x).sqrt()
}

/// floor for finite values of moderate size, without the library call.
#[inline]
pub(crate) fn fast_floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// ceil for finite values of moderate size, without the library call.
#[inline]
pub(crate) fn fast_ceil(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x { t + 1 } else { t }
}
