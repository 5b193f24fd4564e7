//! The plain data that crosses the engine's boundary: driver inputs ([`Controls`]), where a
//! vehicle starts ([`StartPose`]), poses ([`Pose`]) and everything that changes during a
//! simulation ([`SimState`], with its per-wheel [`WheelState`] and [`ContactInfo`]).

use crate::error::SimError;
use crate::math::RPM_TO_RAD_S;
use crate::soil::SoilState;
use serde::{Deserialize, Serialize};
use verti_core::{Quat, Vec3};

/// Any position farther than this from the origin, in world-scale units, is a blow-up.
const POSITION_LIMIT: f64 = 1.0e5;
/// Any speed above this (m/s at full scale) is a blow-up.
const SPEED_LIMIT: f64 = 500.0;

/// Driver inputs, held constant over one [`Sim::step`](crate::Sim::step).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Controls {
    /// \[0, 1\]
    pub throttle: f64,
    /// \[0, 1\]
    pub brake: f64,
    /// \[-1, 1\]; positive turns left (counter-clockwise seen from above).
    pub steering: f64,
}

impl Controls {
    pub const IDLE: Controls = Controls {
        throttle: 0.0,
        brake: 0.0,
        steering: 0.0,
    };

    pub fn new(throttle: f64, brake: f64, steering: f64) -> Controls {
        Controls {
            throttle,
            brake,
            steering,
        }
    }

    /// Rejects NaN and out-of-range values with an error naming the input.
    pub fn validate(&self) -> Result<(), SimError> {
        for (name, value, lo, hi) in [
            ("throttle", self.throttle, 0.0, 1.0),
            ("brake", self.brake, 0.0, 1.0),
            ("steering", self.steering, -1.0, 1.0),
        ] {
            if !(value.is_finite() && value >= lo && value <= hi) {
                return Err(SimError::InvalidControl {
                    name,
                    value,
                    lo,
                    hi,
                });
            }
        }
        Ok(())
    }
}

/// Where a vehicle is set down: a spot on the map \[m\] and a heading \[rad\] (counter-clockwise
/// from +x). [`Sim::state_at`](crate::Sim::state_at) seats the vehicle there on the terrain.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartPose {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
}

impl StartPose {
    pub fn new(x: f64, y: f64, yaw: f64) -> StartPose {
        StartPose { x, y, yaw }
    }
}

/// Pose of the chassis reference frame in the world.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position: Vec3,
    pub orientation: Quat,
}

/// Per-wheel state and the outputs of the last internal step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelState {
    /// Spring compression from free length \[m\] (positive = wheel pushed up).
    pub compression: f64,
    /// Its rate \[m/s\].
    pub compression_rate: f64,
    /// Transient longitudinal and lateral slip (see `tyre`).
    pub slip_long: f64,
    pub slip_lat: f64,
    /// Characteristic size b = 2A/L of the last soil contact patch \[m\] (Bekker's K_c/b term).
    pub soil_patch_b: f64,
    /// Rigid tyre on rigid ground: the stick–slip friction anchor's deflection along the
    /// wheel's longitudinal and lateral contact axes \[m\] (the ground pushes the wheel by
    /// the contact stiffness times it; zero with the handling tyre).
    #[serde(default)]
    pub anchor_long: f64,
    #[serde(default)]
    pub anchor_lat: f64,
    /// Rigid tyre on rigid ground: the contact slid (friction at μ·N) in the last internal
    /// step. The next step's stick/slide decision starts from it.
    #[serde(default)]
    pub sliding: bool,
    // ---- outputs of the last internal step ----
    /// Road-wheel steer angle \[rad\].
    pub steer_angle: f64,
    /// Spin rate \[rad/s\].
    pub spin_rate: f64,
    /// Normal load \[N\].
    pub normal_force: f64,
    /// Longitudinal and lateral ground forces \[N\] in the wheel's contact frame.
    pub long_force: f64,
    pub lat_force: f64,
    pub in_contact: bool,
    pub on_soil: bool,
    pub touches_obstacle: bool,
    /// Deepest soil sinkage under the wheel \[m\].
    pub sinkage: f64,
    /// Radial tyre deflection on rigid ground or obstacles \[m\].
    pub tyre_deflection: f64,
}

/// Contact summary of the last internal step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactInfo {
    /// Chassis collision points touching the terrain (belly, roof, sides).
    pub chassis_terrain_points: u32,
    /// Chassis points or obstacle vertices in contact between chassis and obstacles.
    pub chassis_obstacle_points: u32,
    /// Wheels pressing on an obstacle.
    pub wheel_obstacle_contacts: u32,
    /// Wheels with any ground contact.
    pub wheels_in_contact: u32,
    /// Wheels on deformable soil.
    pub wheels_on_soil: u32,
    /// Soil nodes in contact with wheels.
    pub soil_nodes_in_contact: u32,
    /// Points of a track's raised ends (both lines) touching terrain or obstacles.
    pub track_run_points: u32,
}

/// Everything that changes during a simulation. `Clone` is cheap: a few hundred bytes plus one
/// `Arc` for the soil, whose chunks are copied only when written (see [`SoilState`]).
///
/// The fields are the engine's to write (stage by stage, see `step.rs`); users read them
/// through the accessors.
#[derive(Clone, Debug, PartialEq)]
pub struct SimState {
    pub(crate) time: f64,
    /// Centre-of-mass position (world).
    pub(crate) position: Vec3,
    pub(crate) orientation: Quat,
    /// Centre-of-mass velocity (world).
    pub(crate) velocity: Vec3,
    /// Angular velocity (body frame).
    pub(crate) omega: Vec3,
    pub(crate) wheels: Vec<WheelState>,
    /// Spin rate per spin group.
    pub(crate) group_spin: Vec<f64>,
    /// Bicycle-model steer angle \[rad\] (Ackermann) or last steering input (skid).
    pub(crate) steer: f64,
    pub(crate) gear: usize,
    pub(crate) engine_speed: f64,
    pub(crate) engine_torque: f64,
    pub(crate) controls: Controls,
    pub(crate) contacts: ContactInfo,
    pub(crate) soil: SoilState,
}

impl SimState {
    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Centre-of-mass position (world) \[m\].
    pub fn com_position(&self) -> Vec3 {
        self.position
    }
    /// Chassis attitude (body to world).
    pub fn orientation(&self) -> Quat {
        self.orientation
    }
    /// (roll, pitch, yaw) \[rad\], Z-Y-X convention (`Quat::to_euler`).
    pub fn euler(&self) -> (f64, f64, f64) {
        self.orientation.to_euler()
    }
    /// Centre-of-mass velocity in the world frame \[m/s\].
    pub fn velocity_world(&self) -> Vec3 {
        self.velocity
    }
    /// Centre-of-mass velocity in the body frame (x forward, y left, z up) \[m/s\].
    pub fn velocity_body(&self) -> Vec3 {
        self.orientation.inverse_rotate(self.velocity)
    }
    /// Angular velocity in the body frame \[rad/s\].
    pub fn angular_velocity_body(&self) -> Vec3 {
        self.omega
    }
    /// Angular velocity in the world frame \[rad/s\].
    pub fn angular_velocity_world(&self) -> Vec3 {
        self.orientation.rotate(self.omega)
    }
    /// Speed along the chassis x axis \[m/s\] (Verti-Bench's `GetSpeed` sign convention).
    pub fn forward_speed(&self) -> f64 {
        self.velocity_body().x
    }
    pub fn wheels(&self) -> &[WheelState] {
        &self.wheels
    }
    /// Bicycle-model steer angle \[rad\] (Ackermann vehicles).
    pub fn steer_angle(&self) -> f64 {
        self.steer
    }
    /// Current gear (0-based).
    pub fn gear(&self) -> usize {
        self.gear
    }
    /// Engine speed \[rpm\] and torque \[N m\] of the last internal step.
    pub fn engine(&self) -> (f64, f64) {
        (self.engine_speed / RPM_TO_RAD_S, self.engine_torque)
    }
    /// The controls applied in the last step.
    pub fn controls(&self) -> Controls {
        self.controls
    }
    pub fn contacts(&self) -> ContactInfo {
        self.contacts
    }
    pub fn soil(&self) -> &SoilState {
        &self.soil
    }
    /// True when the chassis is upside down or on its side (|roll| or |pitch| beyond 90°).
    pub fn is_rolled_over(&self) -> bool {
        // body z axis pointing below the horizon
        self.orientation.rotate(Vec3::Z).z < 0.0
    }
    // `set_velocity` is in `sim.rs`: it reads the wheel radii from the `Sim`, which sits above
    // this plain data.
    /// Sets the body-frame angular velocity \[rad/s\].
    pub fn set_angular_velocity_body(&mut self, omega: Vec3) {
        self.omega = omega;
    }

    /// Checks that every state variable is finite and within sane bounds.
    pub(crate) fn check(&self, scale: f64) -> Result<(), SimError> {
        let nf = |what: &str| SimError::NonFinite {
            what: what.to_string(),
            time: self.time,
        };
        if !self.position.is_finite() {
            return Err(nf("chassis position"));
        }
        if !self.orientation.is_finite() {
            return Err(nf("chassis orientation"));
        }
        if !self.velocity.is_finite() {
            return Err(nf("chassis velocity"));
        }
        if !self.omega.is_finite() {
            return Err(nf("chassis angular velocity"));
        }
        for (i, w) in self.wheels.iter().enumerate() {
            if !(w.compression.is_finite() && w.compression_rate.is_finite()) {
                return Err(nf(&format!("suspension of wheel {i}")));
            }
            if !(w.slip_long.is_finite() && w.slip_lat.is_finite()) {
                return Err(nf(&format!("tyre slip of wheel {i}")));
            }
            if !(w.anchor_long.is_finite() && w.anchor_lat.is_finite()) {
                return Err(nf(&format!("friction anchor of wheel {i}")));
            }
        }
        for (g, s) in self.group_spin.iter().enumerate() {
            if !s.is_finite() {
                return Err(nf(&format!("spin rate of wheel group {g}")));
            }
        }
        let limit = POSITION_LIMIT * scale.max(1e-3);
        if self.position.x.abs() > limit
            || self.position.y.abs() > limit
            || self.position.z.abs() > limit
        {
            return Err(SimError::BlowUp {
                what: format!("chassis position {:?} is absurdly far", self.position),
                time: self.time,
            });
        }
        let vmax = SPEED_LIMIT * scale.max(1e-3).sqrt();
        if self.velocity.norm() > vmax {
            return Err(SimError::BlowUp {
                what: format!(
                    "chassis speed {:.1} m/s exceeds {vmax:.0} m/s",
                    self.velocity.norm()
                ),
                time: self.time,
            });
        }
        if self.omega.norm() > 1000.0 {
            return Err(SimError::BlowUp {
                what: format!(
                    "chassis spin {:.1} rad/s exceeds 1000 rad/s",
                    self.omega.norm()
                ),
                time: self.time,
            });
        }
        Ok(())
    }
}
