//! The speed controller that turns a target speed into throttle and brake, like the
//! reference's (spec §4.5): a proportional controller with gain 1 whose positive output is
//! throttle and negative output brake, both clipped to [0, 1].

use verti_sim::Controls;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedController {
    /// Gain per m/s of speed error.
    pub kp: f64,
}

impl Default for SpeedController {
    fn default() -> Self {
        SpeedController { kp: 1.0 }
    }
}

impl SpeedController {
    /// Driver inputs for a target and a measured forward speed (m/s), with the given steering.
    pub fn controls(&self, target: f64, measured: f64, steering: f64) -> Controls {
        let u = (self.kp * (target - measured)).clamp(-1.0, 1.0);
        let steering = steering.clamp(-1.0, 1.0);
        if u > 0.0 {
            Controls::new(u, 0.0, steering)
        } else {
            Controls::new(0.0, -u, steering)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_into_throttle_and_brake() {
        let c = SpeedController::default();
        assert_eq!(c.controls(3.0, 2.5, 0.2), Controls::new(0.5, 0.0, 0.2));
        assert!((c.controls(3.0, 3.4, 0.0).brake - 0.4).abs() < 1e-12);
        assert_eq!(c.controls(10.0, 0.0, 5.0), Controls::new(1.0, 0.0, 1.0));
        assert_eq!(c.controls(0.0, 5.0, -5.0), Controls::new(0.0, 1.0, -1.0));
    }
}
