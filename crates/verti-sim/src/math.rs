//! Small numeric helpers the inner loops use instead of library calls, and unit conversions.
//! Depends on nothing, so any file may use it.

/// rpm to rad/s. Here rather than in `drivetrain` (its main user) because `state` reports
/// the engine speed in rpm and sits below the drivetrain.
pub(crate) const RPM_TO_RAD_S: f64 = std::f64::consts::PI / 30.0;

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
