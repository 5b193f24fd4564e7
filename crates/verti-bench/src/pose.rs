//! The chassis pose, as plain data.
//!
//! It sits at the bottom of the crate (it names nothing else here) because features,
//! perception, observations, the rules and the trial all speak of poses; defined in any of
//! them (it was in `observation`) it tied the others to that one. Its public path is still
//! `verti_bench::observation::Pose6`, which re-exports it.

/// Chassis pose: position of the reference point and Z-Y-X Euler angles (radians). The
/// default is the origin, level, facing +x.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose6 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub roll: f64,
    pub pitch: f64,
    pub yaw: f64,
}
