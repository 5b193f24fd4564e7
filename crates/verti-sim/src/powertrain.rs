//! Engine (torque map) and automatic transmission, as in Chrono's `ChEngineSimpleMap` and
//! `ChAutomaticTransmissionSimpleMap`: no torque converter, so the engine speed is tied to the
//! driven wheels' mean speed through the gear and final-drive ratios.

use crate::spec::PowertrainSpec;

/// Piecewise-linear interpolation in a map of (x, y) points with increasing x; clamps at the
/// ends.
#[inline]
pub fn interpolate(map: &[[f64; 2]], x: f64) -> f64 {
    let first = map[0];
    if x <= first[0] {
        return first[1];
    }
    for w in map.windows(2) {
        let (a, b) = (w[0], w[1]);
        if x <= b[0] {
            let t = (x - a[0]) / (b[0] - a[0]);
            return a[1] + t * (b[1] - a[1]);
        }
    }
    map[map.len() - 1][1]
}

pub const RPM_TO_RAD_S: f64 = std::f64::consts::PI / 30.0;

/// Engine torque \[N m\] at engine speed `omega` \[rad/s\] and throttle in \[0, 1\]:
/// `T = T0(ω)·(1 − throttle) + TF(ω)·throttle`, speed clamped to \[0, max\].
#[inline]
pub fn engine_torque(p: &PowertrainSpec, omega: f64, throttle: f64) -> f64 {
    let w = omega.clamp(0.0, p.max_speed_rpm * RPM_TO_RAD_S);
    interpolate(&p.zero_throttle, w) * (1.0 - throttle)
        + interpolate(&p.full_throttle, w) * throttle
}

/// The gear after applying the shift rules once at engine speed `omega` \[rad/s\].
#[inline]
pub fn shift(p: &PowertrainSpec, gear: usize, omega: f64) -> usize {
    let rpm = omega / RPM_TO_RAD_S;
    if rpm > p.upshift_rpm && gear + 1 < p.gears.len() {
        gear + 1
    } else if rpm < p.downshift_rpm && gear > 0 {
        gear - 1
    } else {
        gear
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_clamps_and_is_linear() {
        let m = [[0.0, 1.0], [2.0, 3.0], [4.0, -1.0]];
        assert_eq!(interpolate(&m, -1.0), 1.0);
        assert_eq!(interpolate(&m, 1.0), 2.0);
        assert_eq!(interpolate(&m, 3.0), 1.0);
        assert_eq!(interpolate(&m, 9.0), -1.0);
    }
}
