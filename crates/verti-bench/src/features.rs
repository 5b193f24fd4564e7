//! The one schema of named vehicle-state features.
//!
//! Step logs (`verti-log` columns), the environment's state vector (`verti-env`) and the Python
//! state vectors all read the vehicle through this module: a feature is declared once here, with
//! its name, unit and meaning, and computed in one place ([`FeatureSource::value`]). A policy
//! trained on some selection of features can therefore be evaluated on exactly the same inputs
//! under `verti eval`, and a new feature appears everywhere at once.

use crate::pose::Pose6;
use verti_core::Vec3;
use verti_sim::{Controls, SimState};

/// A named scalar of the vehicle state, the controls or the trial clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Feature {
    /// Trial (or simulator) time, s.
    Time,
    /// Chassis reference point, world frame, m.
    X,
    Y,
    Z,
    /// Z-Y-X Euler angles of the chassis, rad.
    Roll,
    Pitch,
    Yaw,
    /// The heading as sine and cosine, which have no jump at ±π.
    SinYaw,
    CosYaw,
    /// Linear velocity in the body frame (x forward, y left, z up), m/s.
    Vx,
    Vy,
    Vz,
    /// Angular velocity in the body frame, rad/s.
    Wx,
    Wy,
    Wz,
    /// Forward speed of the chassis, m/s.
    ForwardSpeed,
    /// Road-wheel steer angle of the vehicle, rad.
    SteerAngle,
    /// 1 when the vehicle lies on its side or roof, else 0.
    RolledOver,
    /// The driver inputs applied in the latest inner step: throttle and brake in [0, 1],
    /// steering in [-1, 1] (positive left).
    Throttle,
    Brake,
    Steering,
    /// throttle - brake, in [-1, 1].
    Drive,
    /// 1 - t / max_time: the share of the time limit left.
    TimeLeft,
}

impl Feature {
    /// Every feature, in declaration order.
    pub const ALL: [Feature; 23] = [
        Feature::Time,
        Feature::X,
        Feature::Y,
        Feature::Z,
        Feature::Roll,
        Feature::Pitch,
        Feature::Yaw,
        Feature::SinYaw,
        Feature::CosYaw,
        Feature::Vx,
        Feature::Vy,
        Feature::Vz,
        Feature::Wx,
        Feature::Wy,
        Feature::Wz,
        Feature::ForwardSpeed,
        Feature::SteerAngle,
        Feature::RolledOver,
        Feature::Throttle,
        Feature::Brake,
        Feature::Steering,
        Feature::Drive,
        Feature::TimeLeft,
    ];

    /// The name used in files, Python and settings.
    pub fn name(self) -> &'static str {
        self.describe().0
    }

    /// The unit ("" for dimensionless).
    pub fn unit(self) -> &'static str {
        self.describe().1
    }

    /// One line on what it is.
    pub fn doc(self) -> &'static str {
        self.describe().2
    }

    fn describe(self) -> (&'static str, &'static str, &'static str) {
        match self {
            Feature::Time => ("t", "s", "time since the start of the trial"),
            Feature::X => ("x", "m", "chassis reference point, world frame"),
            Feature::Y => ("y", "m", "chassis reference point, world frame"),
            Feature::Z => ("z", "m", "chassis reference point, world frame"),
            Feature::Roll => ("roll", "rad", "Z-Y-X Euler roll"),
            Feature::Pitch => ("pitch", "rad", "Z-Y-X Euler pitch"),
            Feature::Yaw => ("yaw", "rad", "Z-Y-X Euler yaw (heading)"),
            Feature::SinYaw => ("sin_yaw", "", "sine of the heading"),
            Feature::CosYaw => ("cos_yaw", "", "cosine of the heading"),
            Feature::Vx => ("vx", "m/s", "body-frame velocity, forward"),
            Feature::Vy => ("vy", "m/s", "body-frame velocity, left"),
            Feature::Vz => ("vz", "m/s", "body-frame velocity, up"),
            Feature::Wx => ("wx", "rad/s", "body-frame angular velocity about x"),
            Feature::Wy => ("wy", "rad/s", "body-frame angular velocity about y"),
            Feature::Wz => ("wz", "rad/s", "body-frame angular velocity about z"),
            Feature::ForwardSpeed => ("forward_speed", "m/s", "forward speed of the chassis"),
            Feature::SteerAngle => ("steer_angle", "rad", "road-wheel steer angle"),
            Feature::RolledOver => ("rolled_over", "", "1 when on its side or roof"),
            Feature::Throttle => ("throttle", "", "latest throttle input, [0, 1]"),
            Feature::Brake => ("brake", "", "latest brake input, [0, 1]"),
            Feature::Steering => ("steering", "", "latest steering input, [-1, 1], + left"),
            Feature::Drive => ("drive", "", "latest throttle - brake, [-1, 1]"),
            Feature::TimeLeft => ("time_left", "", "1 - t / max_time"),
        }
    }

    /// The feature called `name`, if any.
    pub fn from_name(name: &str) -> Option<Feature> {
        Feature::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Features from their names, with an error naming the unknown one.
    pub fn parse_list<S: AsRef<str>>(names: &[S]) -> Result<Vec<Feature>, String> {
        names
            .iter()
            .map(|n| {
                Feature::from_name(n.as_ref()).ok_or_else(|| {
                    format!(
                        "unknown state feature `{}`; known: {}",
                        n.as_ref(),
                        names_of(&Feature::ALL).join(", ")
                    )
                })
            })
            .collect()
    }
}

/// The names of a selection of features.
pub fn names_of(features: &[Feature]) -> Vec<&'static str> {
    features.iter().map(|f| f.name()).collect()
}

/// The columns of a per-step trial log (`verti-log`).
pub const STEP_LOG: [Feature; 16] = [
    Feature::Time,
    Feature::X,
    Feature::Y,
    Feature::Z,
    Feature::Roll,
    Feature::Pitch,
    Feature::Yaw,
    Feature::Vx,
    Feature::Vy,
    Feature::Vz,
    Feature::Wx,
    Feature::Wy,
    Feature::Wz,
    Feature::Throttle,
    Feature::Brake,
    Feature::Steering,
];

/// The environment's default state vector: everything a policy needs about its own motion,
/// nothing that ties it to a place on the map.
pub const ENV_STATE: [Feature; 13] = [
    Feature::Vx,
    Feature::Vy,
    Feature::Vz,
    Feature::Wx,
    Feature::Wy,
    Feature::Wz,
    Feature::Roll,
    Feature::Pitch,
    Feature::SinYaw,
    Feature::CosYaw,
    Feature::Steering,
    Feature::Drive,
    Feature::TimeLeft,
];

/// The simulator state vector of Python's `SimState.vector` and `Sim.rollout` rows.
pub const SIM_STATE: [Feature; 16] = [
    Feature::Time,
    Feature::X,
    Feature::Y,
    Feature::Z,
    Feature::Roll,
    Feature::Pitch,
    Feature::Yaw,
    Feature::Vx,
    Feature::Vy,
    Feature::Vz,
    Feature::Wx,
    Feature::Wy,
    Feature::Wz,
    Feature::ForwardSpeed,
    Feature::SteerAngle,
    Feature::RolledOver,
];

/// What features are computed from: the vehicle's state and pose, the latest controls and the
/// clock. Build it with [`FeatureSource::new`] from a simulator state.
#[derive(Clone, Copy, Debug)]
pub struct FeatureSource {
    pub time: f64,
    /// The time limit, for [`Feature::TimeLeft`] (infinite when there is none).
    pub max_time: f64,
    pub pose: Pose6,
    pub velocity_body: Vec3,
    pub angular_velocity_body: Vec3,
    pub forward_speed: f64,
    pub steer_angle: f64,
    pub rolled_over: bool,
    pub controls: Controls,
}

impl FeatureSource {
    /// The features of `state` at `time`, with `controls` the latest applied inputs.
    pub fn new(
        state: &SimState,
        pose: Pose6,
        time: f64,
        max_time: f64,
        controls: Controls,
    ) -> FeatureSource {
        FeatureSource {
            time,
            max_time,
            pose,
            velocity_body: state.velocity_body(),
            angular_velocity_body: state.angular_velocity_body(),
            forward_speed: state.forward_speed(),
            steer_angle: state.steer_angle(),
            rolled_over: state.is_rolled_over(),
            controls,
        }
    }

    /// One feature's value.
    /// A vehicle standing still at `pose` with idle controls, at time 0 with no time limit
    /// (observations built outside a trial: tests, dataset patches).
    pub fn at_rest(pose: Pose6) -> FeatureSource {
        FeatureSource {
            time: 0.0,
            max_time: f64::INFINITY,
            pose,
            velocity_body: Vec3::ZERO,
            angular_velocity_body: Vec3::ZERO,
            forward_speed: 0.0,
            steer_angle: 0.0,
            rolled_over: false,
            controls: Controls::IDLE,
        }
    }

    pub fn value(&self, f: Feature) -> f64 {
        let (p, v, w, c) = (
            &self.pose,
            &self.velocity_body,
            &self.angular_velocity_body,
            &self.controls,
        );
        match f {
            Feature::Time => self.time,
            Feature::X => p.x,
            Feature::Y => p.y,
            Feature::Z => p.z,
            Feature::Roll => p.roll,
            Feature::Pitch => p.pitch,
            Feature::Yaw => p.yaw,
            Feature::SinYaw => p.yaw.sin(),
            Feature::CosYaw => p.yaw.cos(),
            Feature::Vx => v.x,
            Feature::Vy => v.y,
            Feature::Vz => v.z,
            Feature::Wx => w.x,
            Feature::Wy => w.y,
            Feature::Wz => w.z,
            Feature::ForwardSpeed => self.forward_speed,
            Feature::SteerAngle => self.steer_angle,
            Feature::RolledOver => f64::from(u8::from(self.rolled_over)),
            Feature::Throttle => c.throttle,
            Feature::Brake => c.brake,
            Feature::Steering => c.steering,
            Feature::Drive => c.throttle - c.brake,
            Feature::TimeLeft => 1.0 - self.time / self.max_time,
        }
    }

    /// The values of `features`, in order, into `out` (which must be as long).
    pub fn extract_into(&self, features: &[Feature], out: &mut [f64]) {
        assert_eq!(features.len(), out.len(), "one slot per feature");
        for (o, f) in out.iter_mut().zip(features) {
            *o = self.value(*f);
        }
    }

    /// The values of a fixed-size selection.
    pub fn extract<const N: usize>(&self, features: &[Feature; N]) -> [f64; N] {
        features.map(|f| self.value(f))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        let mut names = names_of(&Feature::ALL);
        for f in Feature::ALL {
            assert_eq!(Feature::from_name(f.name()), Some(f));
            assert!(!f.doc().is_empty());
        }
        names.sort();
        names.dedup();
        assert_eq!(names.len(), Feature::ALL.len());
        let err = Feature::parse_list(&["vx", "speed"]).unwrap_err();
        assert!(
            err.contains("`speed`") && err.contains("forward_speed"),
            "{err}"
        );
    }

    #[test]
    fn values_follow_the_source() {
        let src = FeatureSource {
            time: 15.0,
            max_time: 60.0,
            pose: Pose6 {
                x: 1.0,
                y: 2.0,
                z: 3.0,
                roll: 0.1,
                pitch: -0.2,
                yaw: std::f64::consts::FRAC_PI_2,
            },
            velocity_body: Vec3::new(4.0, 5.0, 6.0),
            angular_velocity_body: Vec3::new(7.0, 8.0, 9.0),
            forward_speed: 4.0,
            steer_angle: 0.3,
            rolled_over: true,
            controls: Controls::new(0.25, 0.5, -0.75),
        };
        assert_eq!(src.value(Feature::TimeLeft), 0.75);
        assert_eq!(src.value(Feature::Drive), -0.25);
        assert_eq!(src.value(Feature::RolledOver), 1.0);
        assert!((src.value(Feature::SinYaw) - 1.0).abs() < 1e-15);
        let log = src.extract(&STEP_LOG);
        assert_eq!(log[0], 15.0);
        assert_eq!(&log[13..], &[0.25, 0.5, -0.75]);
        let mut out = vec![0.0; 2];
        src.extract_into(&[Feature::Wz, Feature::Y], &mut out);
        assert_eq!(out, vec![9.0, 2.0]);
    }
}
