//! What a driving policy observes, as the reference's RL systems (Verti-Bench spec §6.4): the
//! terrain under the vehicle, the heading error to the local goal 10 m ahead on the global path,
//! and the forward speed; plus attitude, yaw rate and the current steering, which the
//! reference leaves out and a driver on rough ground needs.
//!
//! The terrain is a heading-aligned elevation patch of 6.4 m x 6.4 m (the reference's crop
//! extent) at 0.4 m, 16 x 16 heights relative to the ground under the vehicle. The reference
//! feeds a 0.1 m crop through a frozen autoencoder and a *random* projection; here the first
//! layer of the policy network is the terrain encoder, trained end to end with the policy.

use verti_bench::features::Feature;
use verti_bench::observation::CropSpec;
use verti_env::{EnvConfig, ObsBuf};

/// The elevation patch a policy sees: 16 x 16 cells of 0.4 m under the vehicle, row 0 ahead.
pub const PATCH: CropSpec = CropSpec {
    size: 16,
    resolution: 0.4,
};

/// Metres of height difference (relative to the ground under the vehicle) that map to ±1.
pub const HEIGHT_SCALE: f32 = 2.0;

/// The environment state features a policy sees, in order.
pub const STATE: [Feature; 5] = [
    Feature::ForwardSpeed,
    Feature::Roll,
    Feature::Pitch,
    Feature::Wz,
    Feature::Steering,
];

/// Names of the non-terrain inputs, in order (after the patch).
pub const SCALAR_NAMES: [&str; 7] = [
    "heading error to the local goal / pi",
    "local-goal distance / lookahead (at most 1.5)",
    "forward speed / max_speed (within ±1.5)",
    "roll / 0.5 rad",
    "pitch / 0.5 rad",
    "yaw rate / 1 rad/s",
    "steering input [-1, 1]",
];

/// Length of a policy's input vector.
pub const INPUT_DIM: usize = PATCH.size * PATCH.size + SCALAR_NAMES.len();

/// Target speed of a normalised action of 1, full-scale m/s (scaled by √scale).
pub const MAX_SPEED: f64 = 4.0;

/// Local-goal lookahead along the global path, full-scale m (scaled by the world).
pub const LOOKAHEAD: f64 = 10.0;

/// The environment settings a policy trains in (and is evaluated with): 10 Hz high-level
/// actions (target speed, steering), the reference's reward with its bug fixed.
pub fn env_config() -> EnvConfig {
    EnvConfig {
        control_rate: 10.0,
        max_speed: MAX_SPEED,
        lookahead: LOOKAHEAD,
        elevation: Some(PATCH),
        state_features: STATE.to_vec(),
        ..EnvConfig::default()
    }
}

/// Writes the policy's input for an observation encoded with [`env_config`] into `out`
/// (cleared first). `scale` is the world's length scale.
pub fn policy_input(buf: &ObsBuf, scale: f64, out: &mut Vec<f32>) {
    debug_assert_eq!(buf.elevation.len(), PATCH.size * PATCH.size);
    debug_assert_eq!(buf.state.len(), STATE.len());
    out.clear();
    out.extend(
        buf.elevation
            .iter()
            .map(|h| (h / HEIGHT_SCALE).clamp(-1.0, 1.0)),
    );
    let [gx, gy] = buf.local_goal;
    let speed_scale = (MAX_SPEED * scale.sqrt()) as f32;
    let lookahead = (LOOKAHEAD * scale) as f32;
    out.extend([
        gy.atan2(gx) / std::f32::consts::PI,
        ((gx * gx + gy * gy).sqrt() / lookahead).min(1.5),
        (buf.state[0] / speed_scale).clamp(-1.5, 1.5),
        buf.state[1] / 0.5,
        buf.state[2] / 0.5,
        buf.state[3],
        buf.state[4],
    ]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_are_scaled_and_ordered() {
        let buf = ObsBuf {
            state: vec![2.0, 0.25, -0.1, 0.3, -0.5],
            goal: [50.0, 0.0],
            local_goal: [0.0, 10.0],
            elevation: (0..256).map(|i| i as f32 * 0.02 - 2.0).collect(),
            ..ObsBuf::default()
        };
        let mut x = Vec::new();
        policy_input(&buf, 1.0, &mut x);
        assert_eq!(x.len(), INPUT_DIM);
        assert_eq!(x[0], -1.0, "heights clamp at -HEIGHT_SCALE");
        assert!((x[100] - (100.0 * 0.02 - 2.0) / 2.0).abs() < 1e-6);
        assert_eq!(x[255], 1.0, "3.1 m clamps to 1");
        let s = &x[256..];
        assert!((s[0] - 0.5).abs() < 1e-6, "goal to the left: +pi/2");
        assert!((s[1] - 1.0).abs() < 1e-6);
        assert!((s[2] - 0.5).abs() < 1e-6);
        assert!((s[3] - 0.5).abs() < 1e-6 && (s[4] + 0.2).abs() < 1e-6);
        assert_eq!(&s[5..], &[0.3, -0.5]);
    }

    #[test]
    fn speed_and_lookahead_scale_with_the_world() {
        let buf = ObsBuf {
            state: vec![2.0, 0.0, 0.0, 0.0, 0.0],
            local_goal: [2.5, 0.0],
            elevation: vec![0.0; 256],
            ..ObsBuf::default()
        };
        let mut x = Vec::new();
        policy_input(&buf, 0.25, &mut x);
        // half the speed scale (√0.25) and a quarter of the lookahead
        assert!((x[256 + 2] - 1.0).abs() < 1e-6);
        assert!((x[256 + 1] - 1.0).abs() < 1e-6);
    }
}
