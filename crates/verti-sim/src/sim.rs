//! The engine: [`Sim`] (immutable model, like MuJoCo's `mjModel`) and [`SimState`] (mutable,
//! cheap to clone, like `mjData`), stepped by [`Sim::step`].
//!
//! # Model
//! The chassis is a rigid body with 6 degrees of freedom (position, unit quaternion). Each wheel
//! has a suspension degree of freedom along the chassis z axis (spring, damper, bump and rebound
//! stops) carrying its unsprung mass, and belongs to a *spin group*: one spin degree of freedom
//! per set of wheels a locked differential (or a track) ties together. Sideways and fore-aft,
//! the wheels move with the chassis, so those forces act on the whole vehicle's mass; along the
//! suspension the unsprung mass moves on its own and only the spring-damper force reaches the
//! chassis. This is the exact mass matrix of that system when every suspension axis is the
//! chassis z axis, which is how vehicles are described here.
//!
//! # Integration
//! Semi-implicit (symplectic) Euler at a fixed internal step, with implicit parts that remove
//! the stiff modes:
//! 1. staggered wheel update: after the chassis step, each wheel's suspension velocity is solved
//!    implicitly against its spring, damper, stops and tyre or soil stiffness, the contact
//!    acting on the wheel's absolute motion (the wheel-hop mode is the stiffest in a vehicle);
//! 2. per spin group, the spin and the tyres' longitudinal forces are solved together
//!    (linearised slip curve), then Coulomb brakes exactly;
//! 3. the transient tyre slip relaxes implicitly (see [`crate::tyre`]).
//!
//! Every shipped vehicle is stable at its `internal_step`: 5 ms at full scale (Verti-Bench's
//! step), 2 ms for the 1/6 and 1/10 vehicles. Stability at those steps is what the validation
//! tests and the soak exercise.

use crate::error::SimError;
use crate::powertrain::{RPM_TO_RAD_S, engine_torque, shift};
use crate::soil::{SoilLayout, SoilState, bekker_pressure, bekker_slope};
use crate::spec::{Differential, SteeringKind, VehicleSpec};
use crate::terrain::{FastObstacle, Ground, HeightBound, ObstacleGrid};
use crate::tyre::{janosi_fraction, janosi_sliding_slip, tmeasy_combined, tmeasy_sliding_slip};
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use verti_core::{Quat, Vec3};
use verti_world::{Surface, World};

/// Standard gravity \[m/s²\] (Chrono: 9.81 along −Z).
pub const GRAVITY: f64 = 9.81;
/// Friction of obstacles (Chrono's default contact material, as Verti-Bench's obstacle boxes).
pub const OBSTACLE_FRICTION: f64 = 0.6;
/// Soil node spacing at full scale \[m\] (Verti-Bench's SCM `terrain_delta`).
pub const SOIL_DELTA_FULL_SCALE: f64 = 0.1;
/// Any position farther than this from the origin, in world-scale units, is a blow-up.
const POSITION_LIMIT: f64 = 1.0e5;
/// Any speed above this (m/s at full scale) is a blow-up.
const SPEED_LIMIT: f64 = 500.0;
/// Body-contact stiffness against obstacles relative to terrain (damping scales with √).
const OBSTACLE_STIFFENING: f64 = 4.0;
/// Safety cap on soil nodes visited per wheel per step.
const MAX_SOIL_NODES_PER_WHEEL: usize = 4096;

/// Driver inputs, held constant over one [`Sim::step`].
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
}

/// Everything that changes during a simulation. `Clone` is cheap: a few hundred bytes plus one
/// `Arc` for the soil, whose chunks are copied only when written (see [`crate::soil`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SimState {
    time: f64,
    /// Centre-of-mass position (world).
    position: Vec3,
    orientation: Quat,
    /// Centre-of-mass velocity (world).
    velocity: Vec3,
    /// Angular velocity (body frame).
    omega: Vec3,
    wheels: Vec<WheelState>,
    /// Spin rate per spin group.
    group_spin: Vec<f64>,
    /// Bicycle-model steer angle \[rad\] (Ackermann) or last steering input (skid).
    steer: f64,
    gear: usize,
    engine_speed: f64,
    engine_torque: f64,
    controls: Controls,
    contacts: ContactInfo,
    soil: SoilState,
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
    /// Sets the chassis velocity (world, m/s) and keeps everything else; for tests and planners
    /// that start from a moving state. Wheels are spun up to roll without slip.
    pub fn set_velocity(&mut self, sim: &Sim, velocity_world: Vec3) {
        self.velocity = velocity_world;
        let forward = self.orientation.rotate(Vec3::X).dot(velocity_world);
        for (g, grp) in sim.groups.iter().enumerate() {
            let r = grp
                .wheels
                .iter()
                .map(|&w| sim.wheels[w].radius)
                .sum::<f64>()
                / grp.wheels.len() as f64;
            self.group_spin[g] = forward / r;
        }
    }
    /// Sets the body-frame angular velocity \[rad/s\].
    pub fn set_angular_velocity_body(&mut self, omega: Vec3) {
        self.omega = omega;
    }

    /// Checks that every state variable is finite and within sane bounds.
    fn check(&self, scale: f64) -> Result<(), SimError> {
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

/// Constants of one wheel, derived from the spec once.
#[derive(Clone, Debug)]
struct WheelModel {
    /// Wheel centre at spring free length, body frame, relative to the centre of mass.
    attach: Vec3,
    /// Lateral position in the reference frame (for Ackermann).
    y: f64,
    /// x relative to the mean of the unsteered axles (for Ackermann).
    ackermann_dx: f64,
    steered: bool,
    radius: f64,
    half_width: f64,
    rim_depth: f64,
    unsprung_mass: f64,
    spring: f64,
    damper: f64,
    bump: f64,
    rebound: f64,
    stop: f64,
    stop_damping: f64,
    brake_torque: f64,
    group: usize,
    /// Low-speed damping of the transient slip \[N s/m\] (bristle damping).
    slip_damping_long: f64,
    slip_damping_lat: f64,
    /// Nominal static load \[N\]: sets the fixed stiffness of the tyre at standstill.
    nominal_load: f64,
    /// Static compression at the start pose.
    static_compression: f64,
}

#[derive(Clone, Debug)]
struct SpinGroup {
    wheels: Vec<usize>,
    inertia: f64,
    /// Share of the engine torque.
    drive_share: f64,
    /// Side for skid steering (+1 left, −1 right, 0 mixed).
    side: f64,
    driven: bool,
}

/// Longitudinal tyre force of one wheel, linearised in the new spin rate.
#[derive(Clone, Copy, Debug, Default)]
struct LongTyre {
    active: bool,
    e_long: Vec3,
    /// Secant slip stiffness \[N per unit slip\].
    stiffness: f64,
    /// κ_new = a + b·ω_new.
    a: f64,
    b: f64,
    /// 1 + h·v_ref/σ: the implicit relaxation factor of this step.
    decay: f64,
    /// Low-speed bristle damping \[N s/m\].
    damping: f64,
    vx: f64,
    radius: f64,
    /// Friction left for the longitudinal force after the lateral one \[N\].
    limit: f64,
}

/// Contact of one wheel with everything (summed).
#[derive(Clone, Copy, Debug, Default)]
struct WheelContact {
    /// Summed normal force (world).
    force: Vec3,
    /// Stiffness and damping along the suspension axis (for the implicit wheel update).
    k_axis: f64,
    c_axis: f64,
    /// Σ k·(n·u)·n and Σ c·(n·u)·n: how the axis force depends on the chassis' motion.
    k_vec: Vec3,
    c_vec: Vec3,
    /// Rigid part: normal load and friction scale (ground μ / tyre μ), load-weighted.
    rigid_load: f64,
    mu_scale: f64,
    /// Deepest rigid penetration \[m\] (loaded-radius correction).
    depth: f64,
    /// Soil part.
    soil_load: f64,
    soil_shear_limit: f64,
    soil_length: f64,
    soil_janosi_k: f64,
    soil_moment: Vec3,
    soil_nodes: u32,
    /// b = 2A/L of this step's soil patch.
    soil_b: f64,
    sinkage: f64,
    obstacle: bool,
}

/// A simulation of one vehicle on one world. Immutable: all mutable data lives in
/// [`SimState`], so one `Sim` can step many states (planners, parallel rollouts).
#[derive(Clone, Debug)]
pub struct Sim {
    world: Arc<World>,
    spec: VehicleSpec,
    start: Pose,
    step: f64,
    wheels: Vec<WheelModel>,
    groups: Vec<SpinGroup>,
    sprung_mass: f64,
    total_mass: f64,
    /// Chassis-only principal inertia and the composite (with unsprung masses) one.
    chassis_inertia: Vec3,
    inertia: Vec3,
    /// Centre of mass in the reference frame.
    com: Vec3,
    body_points: Vec<Vec3>,
    box_center: Vec3,
    box_half: Vec3,
    body_stiffness: f64,
    body_damping: f64,
    friction_speed: f64,
    reach: f64,
    bound: HeightBound,
    ground: Ground,
    obstacles: ObstacleGrid,
    fast_obstacles: Vec<FastObstacle>,
    soil: Option<SoilLayout>,
    driven_wheels: usize,
}

/// Places a vehicle at (x, y) with heading `yaw`, pitched and rolled to the terrain plane fitted
/// under its wheels, springs at their static compression and tyres at their static deflection
/// (on soil the wheels then start slightly sunk and settle by the soil's sinkage).
pub fn start_pose(
    world: &World,
    spec: &VehicleSpec,
    x: f64,
    y: f64,
    yaw: f64,
) -> Result<Pose, SimError> {
    if !(x.is_finite() && y.is_finite() && yaw.is_finite()) {
        return Err(SimError::InvalidStart(format!(
            "({x}, {y}, yaw {yaw}) is not finite"
        )));
    }
    if !world.terrain.contains(x, y) {
        return Err(SimError::InvalidStart(format!(
            "({x:.2}, {y:.2}) is off the map (half extent {:.2} m)",
            world.terrain.half_extent()
        )));
    }
    let hf = &world.terrain;
    let (s, c) = libm::sincos(yaw);
    let comp = static_compressions(spec);
    // Least-squares plane z = a + b·x' + c·y' in heading coordinates through the wheel spots.
    let mut rows = Vec::new();
    for (k, ax) in spec.axles.iter().enumerate() {
        for side in [1.0, -1.0] {
            let (lx, ly) = (ax.x, side * 0.5 * ax.track);
            let h = hf.height_at(x + c * lx - s * ly, y + s * lx + c * ly);
            rows.push((lx, ly, h, k));
        }
    }
    let n = rows.len() as f64;
    let mx = rows.iter().map(|r| r.0).sum::<f64>() / n;
    let my = rows.iter().map(|r| r.1).sum::<f64>() / n;
    let mh = rows.iter().map(|r| r.2).sum::<f64>() / n;
    let sxx: f64 = rows.iter().map(|r| (r.0 - mx).powi(2)).sum();
    let syy: f64 = rows.iter().map(|r| (r.1 - my).powi(2)).sum();
    let sxh: f64 = rows.iter().map(|r| (r.0 - mx) * (r.2 - mh)).sum();
    let syh: f64 = rows.iter().map(|r| (r.1 - my) * (r.2 - mh)).sum();
    let slope_x = if sxx > 1e-12 { sxh / sxx } else { 0.0 };
    let slope_y = if syy > 1e-12 { syh / syy } else { 0.0 };
    let orientation = quat_from_euler(libm::atan(slope_y), -libm::atan(slope_x), yaw);
    // Seat every tyre at its static deflection under an equal share of the weight (so a
    // vehicle set down on flat ground barely moves), and no tyre deeper than that.
    let weight = (spec.chassis.mass
        + spec.track.map_or(0.0, |t| 2.0 * t.track_mass)
        + spec
            .axles
            .iter()
            .map(|a| 2.0 * a.wheel.unsprung_mass)
            .sum::<f64>())
        * GRAVITY;
    let load = weight / spec.wheel_count() as f64;
    let deflection = load / spec.tyre.radial_stiffness;
    let mut z = f64::NEG_INFINITY;
    for (lx, ly, _, k) in &rows {
        let ax = &spec.axles[*k];
        let local = Vec3::new(*lx, *ly, ax.z + comp[*k]);
        let hub = orientation.rotate(local);
        let (hx, hy) = (x + hub.x, y + hub.y);
        let (h, gx, gy) = hf.sample(hx, hy);
        let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
        // On soil, seat the wheel at its static Bekker sinkage instead: dropped onto the
        // undeformed surface it would overshoot, and the plastic memory would keep the ruts of
        // that first bounce (deep enough to high-centre a HMMWV in snow).
        let sunk = match world.patches.at(hx, hy).surface {
            verti_world::Surface::Deformable { soil } if world.terrain.contains(hx, hy) => {
                static_sinkage(load * nz, ax.wheel.width, ax.wheel.radius, &soil)
                    .min(0.8 * ax.wheel.radius)
            }
            _ => deflection,
        };
        z = z.max(h + (ax.wheel.radius - sunk) / nz - hub.z);
    }
    let pose = Pose {
        position: Vec3::new(x, y, z),
        orientation,
    };
    // A start inside a rock or tree would be an explosion, not a drive.
    let bx = &spec.chassis.collision_box;
    let (c, half) = (
        Vec3::new(bx.center[0], bx.center[1], bx.center[2]),
        Vec3::new(bx.size[0], bx.size[1], bx.size[2]) * 0.5,
    );
    let mut probes: Vec<(Vec3, f64)> = Vec::new();
    for ix in [-1.0, 0.0, 1.0] {
        for iy in [-1.0, 0.0, 1.0] {
            for iz in [-1.0, 0.0, 1.0] {
                probes.push((c + Vec3::new(ix * half.x, iy * half.y, iz * half.z), 0.0));
            }
        }
    }
    for (k, ax) in spec.axles.iter().enumerate() {
        for side in [1.0, -1.0] {
            probes.push((
                Vec3::new(ax.x, side * 0.5 * ax.track, ax.z + comp[k]),
                ax.wheel.radius,
            ));
        }
    }
    for (local, clearance) in probes {
        let p = pose.position + orientation.rotate(local);
        for (k, o) in world.obstacles.iter().enumerate() {
            if (p.x - o.position().x).hypot(p.y - o.position().y) > o.radius_xy() + clearance {
                continue;
            }
            if o.signed_distance(p).0 < clearance {
                return Err(SimError::InvalidStart(format!(
                    "at ({x:.2}, {y:.2}) the vehicle would start inside obstacle {k} at ({:.2}, {:.2})",
                    o.position().x,
                    o.position().y
                )));
            }
        }
    }
    Ok(pose)
}

/// Bekker's closed-form sinkage of a rigid wheel (width b, radius r) at rest under `load`,
/// parabolic contact arc over both halves:
/// W = 2·b·k·√(2r)·z^(n+½)·I(n), k = K_c/b + K_φ, I(n) = √π·Γ(n+1) / (2·Γ(n+3/2)).
pub fn static_sinkage(load: f64, b: f64, r: f64, soil: &verti_world::SoilParams) -> f64 {
    let n = soil.bekker_n;
    let k = soil.bekker_kc / b + soil.bekker_kphi;
    let i = std::f64::consts::PI.sqrt() * libm::tgamma(n + 1.0) / (2.0 * libm::tgamma(n + 1.5));
    let z = load.max(0.0) / (2.0 * b * k * (2.0 * r).sqrt() * i);
    let z = libm::pow(z, 1.0 / (n + 0.5));
    if z.is_finite() { z } else { 0.0 }
}

/// Static spring compression per axle: a rigid chassis on the axle springs (heave and pitch),
/// which is exact for two axles and the stiffness-weighted split for more.
fn static_compressions(spec: &VehicleSpec) -> Vec<f64> {
    let w = spec.chassis.mass * GRAVITY;
    let xc = spec.chassis.com[0];
    let (mut k0, mut k1, mut k2) = (0.0, 0.0, 0.0);
    for ax in &spec.axles {
        let k = 2.0 * ax.suspension.stiffness;
        let dx = ax.x - xc;
        k0 += k;
        k1 += k * dx;
        k2 += k * dx * dx;
    }
    // Solve [k0 k1; k1 k2] [z; θ] = [W; 0] with compression_i = z + θ·dx_i.
    let det = k0 * k2 - k1 * k1;
    let (z, th) = if det.abs() > 1e-12 * k0 * k2.max(1e-12) {
        (w * k2 / det, -w * k1 / det)
    } else {
        (w / k0, 0.0)
    };
    spec.axles.iter().map(|ax| z + th * (ax.x - xc)).collect()
}

impl Sim {
    /// Builds the immutable model of `spec` on `world` and remembers `start` for
    /// [`Sim::initial_state`].
    pub fn new(world: &Arc<World>, spec: &VehicleSpec, start: Pose) -> Result<Sim, SimError> {
        spec.validate(&spec.name)
            .map_err(|e| SimError::InvalidSetup(e.to_string()))?;
        if !(start.position.is_finite() && start.orientation.is_finite()) {
            return Err(SimError::InvalidStart(
                "the start pose is not finite".into(),
            ));
        }
        let qn = (start.orientation.w.powi(2)
            + start.orientation.x.powi(2)
            + start.orientation.y.powi(2)
            + start.orientation.z.powi(2))
        .sqrt();
        if (qn - 1.0).abs() > 1e-6 {
            return Err(SimError::InvalidStart(format!(
                "the start orientation is not a unit quaternion (norm {qn})"
            )));
        }
        let scale = world.meta.scale;
        if !(scale.is_finite() && scale > 0.0) {
            return Err(SimError::InvalidSetup(format!(
                "world scale {scale} is not positive"
            )));
        }
        let com = Vec3::new(
            spec.chassis.com[0],
            spec.chassis.com[1],
            spec.chassis.com[2],
        );
        let track_mass = spec.track.map_or(0.0, |t| 2.0 * t.track_mass);
        let sprung_mass = spec.chassis.mass + track_mass;
        let total_mass = sprung_mass
            + spec
                .axles
                .iter()
                .map(|a| 2.0 * a.wheel.unsprung_mass)
                .sum::<f64>();
        let comp = static_compressions(spec);
        let steered_x: Vec<f64> = spec
            .axles
            .iter()
            .filter(|a| !a.steered)
            .map(|a| a.x)
            .collect();
        let x_rear = if steered_x.is_empty() {
            0.0
        } else {
            steered_x.iter().sum::<f64>() / steered_x.len() as f64
        };
        let h = spec.internal_step;

        // Spin groups: tracks tie a side; locked differentials tie axles and sides.
        let mut group_of = vec![usize::MAX; spec.wheel_count()];
        let mut groups: Vec<SpinGroup> = Vec::new();
        let tracked = spec.is_tracked();
        for (k, ax) in spec.axles.iter().enumerate() {
            for (j, side) in [1.0f64, -1.0].into_iter().enumerate() {
                let w = 2 * k + j;
                let key = group_key(spec, tracked, w);
                let existing = key.and_then(|key| {
                    groups
                        .iter()
                        .position(|g| group_key(spec, tracked, g.wheels[0]) == Some(key))
                });
                let g = match existing {
                    Some(g) => g,
                    None => {
                        groups.push(SpinGroup {
                            wheels: Vec::new(),
                            inertia: 0.0,
                            drive_share: 0.0,
                            side,
                            driven: false,
                        });
                        groups.len() - 1
                    }
                };
                let grp = &mut groups[g];
                grp.wheels.push(w);
                grp.inertia += ax.wheel.spin_inertia;
                grp.driven |= ax.driven;
                if grp.side != side {
                    grp.side = 0.0;
                }
                group_of[w] = g;
            }
        }
        if let Some(tr) = &spec.track {
            for g in &mut groups {
                // the track's mass spins with its side at the road-wheel radius
                let r = g
                    .wheels
                    .iter()
                    .map(|&w| spec.axles[w / 2].wheel.radius)
                    .sum::<f64>()
                    / g.wheels.len() as f64;
                g.inertia += tr.track_mass * r * r;
            }
        }
        let driven_wheels = spec.axles.iter().filter(|a| a.driven).count() * 2;
        for g in &mut groups {
            let driven_members = g
                .wheels
                .iter()
                .filter(|&&w| spec.axles[w / 2].driven)
                .count();
            g.drive_share = driven_members as f64 / driven_wheels as f64;
            g.driven = driven_members > 0;
        }

        let mut wheels = Vec::with_capacity(spec.wheel_count());
        let mut inertia = Vec3::new(
            spec.chassis.inertia[0],
            spec.chassis.inertia[1],
            spec.chassis.inertia[2],
        );
        let mut reach: f64 = 0.0;
        let per_wheel_load = total_mass * GRAVITY / spec.wheel_count() as f64;
        for (k, ax) in spec.axles.iter().enumerate() {
            for side in [1.0f64, -1.0] {
                let w = wheels.len();
                let attach = Vec3::new(ax.x, side * 0.5 * ax.track, ax.z) - com;
                let mu = ax.wheel.unsprung_mass;
                inertia += Vec3::new(
                    mu * (attach.y.powi(2) + attach.z.powi(2)),
                    mu * (attach.x.powi(2) + attach.z.powi(2)),
                    mu * (attach.x.powi(2) + attach.y.powi(2)),
                );
                reach = reach.max(attach.norm() + ax.wheel.radius + 0.5 * ax.wheel.width);
                let t = &spec.tyre;
                // Bristle damping at critical-ish ratio 0.3 of the slip-spring against the
                // wheel's spin inertia (longitudinal) and its share of the mass (lateral).
                let k_long = t.dfx0 * per_wheel_load / t.relaxation_length;
                let k_lat = t.dfy0 * per_wheel_load / t.relaxation_length;
                let g = group_of[w];
                let spin_mass =
                    groups[g].inertia / groups[g].wheels.len() as f64 / ax.wheel.radius.powi(2);
                let lat_mass = total_mass / spec.wheel_count() as f64;
                let stop_damping = 2.0 * 0.5 * (ax.suspension.stop_stiffness * mu).sqrt();
                wheels.push(WheelModel {
                    attach,
                    y: side * 0.5 * ax.track,
                    ackermann_dx: ax.x - x_rear,
                    steered: ax.steered,
                    radius: ax.wheel.radius,
                    half_width: 0.5 * ax.wheel.width,
                    rim_depth: ax.wheel.radius - ax.wheel.rim_radius,
                    unsprung_mass: mu,
                    spring: ax.suspension.stiffness,
                    damper: ax.suspension.damping,
                    bump: ax.suspension.bump_travel,
                    rebound: ax.suspension.rebound_travel,
                    stop: ax.suspension.stop_stiffness,
                    stop_damping,
                    brake_torque: ax.brake_torque,
                    group: g,
                    slip_damping_long: 0.6 * (k_long * spin_mass).sqrt(),
                    slip_damping_lat: 0.6 * (k_lat * lat_mass).sqrt(),
                    nominal_load: per_wheel_load,
                    static_compression: comp[k],
                });
            }
        }
        // Chassis collision points: the 18 points of a 3x3x2 lattice on the collision box.
        let bx = &spec.chassis.collision_box;
        let box_center = Vec3::new(bx.center[0], bx.center[1], bx.center[2]) - com;
        let box_half = Vec3::new(bx.size[0], bx.size[1], bx.size[2]) * 0.5;
        let mut body_points = Vec::with_capacity(18);
        for iz in [-1.0, 1.0] {
            for ix in [-1.0, 0.0, 1.0] {
                for iy in [-1.0, 0.0, 1.0] {
                    let p =
                        box_center + Vec3::new(ix * box_half.x, iy * box_half.y, iz * box_half.z);
                    reach = reach.max(p.norm());
                    body_points.push(p);
                }
            }
        }
        // Body contact stiffness: chassis contact mode at ω·h = 0.15 when a quarter of the mass
        // rests on one point; damping ratio 0.5. Against obstacles it is 4x stiffer
        // (ω·h = 0.3): those contacts are few points hit at speed, where a soft contact
        // would let a thin trunk sink half a metre into the body; against terrain many
        // points rest at once (a rolled vehicle on its roof) and the softer value keeps that
        // stable.
        let omega_body = 0.15 / h;
        let body_stiffness = 0.25 * total_mass * omega_body * omega_body;
        let body_damping = 2.0 * 0.5 * (body_stiffness * 0.25 * total_mass).sqrt();
        let reach = reach * 1.1 + 0.2 * scale;
        let soil = if world.patches.has_soil() {
            let delta = SOIL_DELTA_FULL_SCALE * scale;
            let layout = SoilLayout::new(world.terrain.half_extent(), delta);
            if layout.chunks > 4096 {
                return Err(SimError::InvalidSetup(format!(
                    "soil grid of {} chunks per side is too large",
                    layout.chunks
                )));
            }
            Some(layout)
        } else {
            None
        };
        let sim = Sim {
            bound: HeightBound::new(world),
            ground: Ground::new(world),
            fast_obstacles: world.obstacles.iter().map(FastObstacle::new).collect(),
            obstacles: ObstacleGrid::new(world, reach),
            world: Arc::clone(world),
            spec: spec.clone(),
            start,
            step: h,
            wheels,
            groups,
            sprung_mass,
            total_mass,
            chassis_inertia: Vec3::new(
                spec.chassis.inertia[0],
                spec.chassis.inertia[1],
                spec.chassis.inertia[2],
            ),
            inertia,
            com,
            body_points,
            box_center,
            box_half,
            body_stiffness,
            body_damping,
            friction_speed: 0.05 * scale.sqrt(),
            reach,
            soil,
            driven_wheels,
        };
        sim.state_at(start)?;
        Ok(sim)
    }

    pub fn world(&self) -> &Arc<World> {
        &self.world
    }
    pub fn spec(&self) -> &VehicleSpec {
        &self.spec
    }
    pub fn start(&self) -> Pose {
        self.start
    }
    /// The fixed internal step \[s\].
    pub fn internal_step(&self) -> f64 {
        self.step
    }
    /// Total mass including unsprung masses and tracks \[kg\].
    pub fn total_mass(&self) -> f64 {
        self.total_mass
    }
    /// Soil node spacing \[m\], when the world has soil.
    pub fn soil_spacing(&self) -> Option<f64> {
        self.soil.map(|l| l.delta)
    }
    /// Bounding radius of the vehicle around its centre of mass (plus margin) \[m\].
    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// The state at the start pose, at rest.
    pub fn initial_state(&self) -> SimState {
        self.state_at(self.start)
            .expect("start pose validated in Sim::new")
    }

    /// A state at rest at `pose`, springs at their static compression.
    pub fn state_at(&self, pose: Pose) -> Result<SimState, SimError> {
        if !(pose.position.is_finite() && pose.orientation.is_finite()) {
            return Err(SimError::InvalidStart("pose is not finite".into()));
        }
        let orientation = pose.orientation.normalized();
        let position = pose.position + orientation.rotate(self.com);
        // A vehicle at rest on a slope has deflected tyres: preload each tyre's transient slip
        // with its share of the downhill pull (linear part of the slip curve), so a start on a
        // slope begins near static equilibrium instead of sliding until the tyres wind up.
        let t = &self.spec.tyre;
        let n_wheels = self.wheels.len() as f64;
        let wheels = self
            .wheels
            .iter()
            .map(|w| {
                let hub = position + orientation.rotate(w.attach + Vec3::Z * w.static_compression);
                let (_, gx, gy) = self.ground.sample(hub.x, hub.y);
                let n = Vec3::new(-gx, -gy, 1.0).normalized();
                let axle = orientation.rotate(Vec3::Y);
                let e_long = axle.cross(n).normalized();
                let e_lat = n.cross(e_long);
                let weight = Vec3::new(0.0, 0.0, -GRAVITY * self.total_mass / n_wheels);
                let fz = -weight.dot(n);
                let (mut kx, mut ky) = (0.0, 0.0);
                if fz > 0.0 && e_long.is_finite() {
                    // invert the slip curve by bisection along the needed force's direction
                    let (fx, fy) = (-weight.dot(e_long) / fz, -weight.dot(e_lat) / fz);
                    let need = fx.hypot(fy);
                    if need > 1e-9 {
                        let dir = (fx / t.dfx0, fy / t.dfy0);
                        let dn = dir.0.hypot(dir.1);
                        let (mut lo, mut hi) = (0.0, t.sxm.min(t.sym) / dn.max(1e-12) * 0.999);
                        for _ in 0..40 {
                            let mid = 0.5 * (lo + hi);
                            let (cx, cy) = tmeasy_combined(mid * dir.0, mid * dir.1, t, 1.0);
                            if cx.hypot(cy) < need {
                                lo = mid
                            } else {
                                hi = mid
                            }
                        }
                        kx = lo * dir.0;
                        ky = lo * dir.1;
                    }
                }
                WheelState {
                    compression: w.static_compression,
                    slip_long: kx,
                    slip_lat: ky,
                    soil_patch_b: 2.0 * w.half_width,
                    ..Default::default()
                }
            })
            .collect();
        Ok(SimState {
            time: 0.0,
            position,
            orientation,
            velocity: Vec3::ZERO,
            omega: Vec3::ZERO,
            wheels,
            group_spin: vec![0.0; self.groups.len()],
            steer: 0.0,
            gear: 0,
            engine_speed: 0.0,
            engine_torque: 0.0,
            controls: Controls::IDLE,
            contacts: ContactInfo::default(),
            soil: SoilState::new(self.soil.as_ref()),
        })
    }

    /// Pose of the chassis reference frame (the frame the vehicle file is written in).
    pub fn reference_pose(&self, state: &SimState) -> Pose {
        Pose {
            position: state.position - state.orientation.rotate(self.com),
            orientation: state.orientation,
        }
    }

    /// World position of a point given in the chassis reference frame.
    pub fn point_world(&self, state: &SimState, local: Vec3) -> Vec3 {
        state.position + state.orientation.rotate(local - self.com)
    }

    /// World position of each wheel centre.
    pub fn wheel_centers(&self, state: &SimState) -> Vec<Vec3> {
        self.wheels
            .iter()
            .zip(&state.wheels)
            .map(|(m, w)| {
                state.position + state.orientation.rotate(m.attach + Vec3::Z * w.compression)
            })
            .collect()
    }

    /// Ground height under (x, y) as the vehicle sees it: the undeformed terrain minus the
    /// plastic soil sinkage at the nearest soil node.
    pub fn ground_height_at(&self, state: &SimState, x: f64, y: f64) -> f64 {
        let (h, gx, gy) = self.world.terrain.sample(x, y);
        if let Some(layout) = &self.soil {
            let i = (x / layout.delta).round() as i64;
            let j = (y / layout.delta).round() as i64;
            if let Some(at) = layout.locate(i, j) {
                let (plastic, _) = state.soil.node(at);
                let ca = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                return h - plastic / ca;
            }
        }
        h
    }

    /// Total mechanical energy \[J\]: kinetic (chassis, unsprung masses, spinning wheels) plus
    /// gravity, suspension and tyre-spring potential. Soil deformation is dissipative and
    /// not counted.
    pub fn energy(&self, state: &SimState) -> f64 {
        let q = state.orientation;
        let omega_w = q.rotate(state.omega);
        let om = state.omega;
        let i = self.chassis_inertia;
        let mut e = 0.5 * self.sprung_mass * state.velocity.norm_sq()
            + 0.5 * (i.x * om.x * om.x + i.y * om.y * om.y + i.z * om.z * om.z)
            + self.sprung_mass * GRAVITY * state.position.z;
        let up = q.rotate(Vec3::Z);
        for (m, w) in self.wheels.iter().zip(&state.wheels) {
            let r = q.rotate(m.attach + Vec3::Z * w.compression);
            let v = state.velocity + omega_w.cross(r) + up * w.compression_rate;
            let hub = state.position + r;
            e += 0.5 * m.unsprung_mass * v.norm_sq() + m.unsprung_mass * GRAVITY * hub.z;
            e += 0.5 * m.spring * w.compression * w.compression;
            if w.compression > m.bump {
                e += 0.5 * m.stop * (w.compression - m.bump).powi(2);
            }
            if w.compression < -m.rebound {
                e += 0.5 * m.stop * (w.compression + m.rebound).powi(2);
            }
            let d = w.tyre_deflection;
            e += 0.5 * self.spec.tyre.radial_stiffness * d * d;
            if d > m.rim_depth {
                e += 0.5 * 10.0 * self.spec.tyre.radial_stiffness * (d - m.rim_depth).powi(2);
            }
        }
        for (g, grp) in self.groups.iter().enumerate() {
            e += 0.5 * grp.inertia * state.group_spin[g].powi(2);
        }
        e
    }

    /// Advances `state` by `dt` seconds with `controls` held. The internal step is the largest
    /// step not above `spec.internal_step` that divides `dt` evenly.
    pub fn step(&self, state: &mut SimState, controls: Controls, dt: f64) -> Result<(), SimError> {
        controls.validate()?;
        if !(dt.is_finite() && dt > 0.0 && dt <= 10.0) {
            return Err(SimError::InvalidStep(dt));
        }
        state.check(self.world.meta.scale)?;
        let n = ((dt / self.step) - 1e-9).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        state.controls = controls;
        let t0 = state.time;
        for k in 0..n {
            self.substep(state, &controls, h);
            state.time = t0 + (k + 1) as f64 * h;
            // cheap guard so a blow-up cannot run away inside a long step
            if !(state.position.x.abs() < 1e9
                && state.position.y.abs() < 1e9
                && state.position.z.abs() < 1e9)
            {
                break;
            }
        }
        // per-wheel steer angles are outputs only: computed once per call, not per internal step
        let turn_radius = self.turn_radius(state.steer);
        for (m, w) in self.wheels.iter().zip(state.wheels.iter_mut()) {
            w.steer_angle = if m.steered && turn_radius.is_finite() {
                libm::atan(m.ackermann_dx / (turn_radius - m.y))
            } else {
                0.0
            };
        }
        state.check(self.world.meta.scale)
    }

    /// Turn radius of the rear-axle centre for a bicycle steer angle (infinite when straight
    /// or skid-steered).
    fn turn_radius(&self, steer: f64) -> f64 {
        if self.spec.steering.kind == SteeringKind::Ackermann && steer.abs() > 1e-9 {
            self.wheels_base_length() / libm::tan(steer)
        } else {
            f64::INFINITY
        }
    }

    /// One internal step.
    fn substep(&self, st: &mut SimState, ctl: &Controls, h: f64) {
        let spec = &self.spec;
        let q = st.orientation;
        let ex = q.rotate(Vec3::X);
        let ey = q.rotate(Vec3::Y);
        let up = q.rotate(Vec3::Z);
        let omega_w = q.rotate(st.omega);
        let gravity = Vec3::new(0.0, 0.0, -GRAVITY);

        // ---- steering ----
        let skid = spec.steering.kind == SteeringKind::Skid;
        if skid {
            st.steer = ctl.steering;
        } else {
            let target = ctl.steering * spec.steering.max_angle_deg.to_radians();
            let max_delta = spec.steering.rate_deg_per_s.to_radians() * h;
            st.steer += (target - st.steer).clamp(-max_delta, max_delta);
        }
        let turn_radius = self.turn_radius(st.steer);

        // ---- powertrain ----
        let p = &spec.powertrain;
        let mut mean_spin = 0.0;
        for (w, m) in self.wheels.iter().enumerate() {
            if spec.axles[w / 2].driven {
                mean_spin += st.group_spin[m.group];
            }
        }
        mean_spin /= self.driven_wheels as f64;
        let engine_speed_of = |gear: usize| mean_spin.abs() / (p.final_drive * p.gears[gear]);
        st.gear = shift(p, st.gear, engine_speed_of(st.gear));
        let ratio = p.final_drive * p.gears[st.gear];
        let we = engine_speed_of(st.gear);
        // Closed-throttle drag opposes the rotation (smoothly through zero) so coasting never
        // gains energy; the full-throttle part always drives forward.
        let drag_sign = soft_sign(mean_spin / ratio / 5.0);
        let t_full = engine_torque(p, we, 1.0);
        let t_zero = engine_torque(p, we, 0.0);
        let te = t_full * ctl.throttle + t_zero * (1.0 - ctl.throttle) * drag_sign;
        st.engine_speed = we;
        st.engine_torque = te;
        let wheel_torque_total = te / ratio;

        // ---- accumulators (world frame, about the centre of mass) ----
        let mut force = gravity * self.sprung_mass;
        let mut torque = Vec3::ZERO;
        let mut axis_force_sum = 0.0; // Σ external force on wheels along the suspension axis
        let mut susp_sum = 0.0; // Σ suspension force pushing the chassis up
        let mut contacts = ContactInfo::default();

        // ---- obstacles near the vehicle ----
        let near = self.obstacles.near(st.position.x, st.position.y);

        // ---- wheels: contact, tyre forces ----
        let nw = self.wheels.len();
        let mut wheel_axis = [Vec3::ZERO; crate::spec::MAX_WHEELS];
        let mut wheel_arm = [Vec3::ZERO; crate::spec::MAX_WHEELS];
        let mut wheel_axis_force = [0.0; crate::spec::MAX_WHEELS];
        let mut wheel_susp = [0.0; crate::spec::MAX_WHEELS];
        let mut wheel_k = [0.0; crate::spec::MAX_WHEELS];
        let mut wheel_c = [0.0; crate::spec::MAX_WHEELS];
        let mut wheel_kc = [Vec3::ZERO; crate::spec::MAX_WHEELS];
        let mut wheel_cc = [Vec3::ZERO; crate::spec::MAX_WHEELS];
        let mut group_torque = [0.0; crate::spec::MAX_WHEELS];
        let mut group_k = [0.0; crate::spec::MAX_WHEELS];
        let mut long_tyre = [LongTyre::default(); crate::spec::MAX_WHEELS];
        let mut slip_inputs = [(0.0, 0.0, 0.0, 0.0, 0.0); crate::spec::MAX_WHEELS]; // (vx, vy, radius, clamp, fz)
        for (w, m) in self.wheels.iter().enumerate() {
            let ws = st.wheels[w];
            // Ackermann: the wheel points at the turn centre on the rear-axle line, so
            // tan δ = dx / (R − y); sine and cosine follow without trigonometric calls.
            let (sd, cd) = if m.steered && turn_radius.is_finite() {
                let d = turn_radius - m.y;
                let hyp = (m.ackermann_dx * m.ackermann_dx + d * d).sqrt();
                (m.ackermann_dx * d.signum() / hyp, d.abs() / hyp)
            } else {
                (0.0, 1.0)
            };
            let axle = ex * (-sd) + ey * cd;
            let r = q.rotate(m.attach + Vec3::Z * ws.compression);
            let hub = st.position + r;
            let v_hub = st.velocity + omega_w.cross(r) + up * ws.compression_rate;
            let spin = st.group_spin[m.group];
            let contact = self.wheel_contact(st, m, ws.soil_patch_b, hub, axle, v_hub, up, near);

            // suspension force (pushes chassis up, wheel down)
            let mut f_susp = m.spring * ws.compression + m.damper * ws.compression_rate;
            let mut k_extra = m.spring;
            let mut c_extra = m.damper;
            if ws.compression > m.bump {
                f_susp += m.stop * (ws.compression - m.bump) + m.stop_damping * ws.compression_rate;
                k_extra += m.stop;
                c_extra += m.stop_damping;
            } else if ws.compression < -m.rebound {
                f_susp +=
                    m.stop * (ws.compression + m.rebound) + m.stop_damping * ws.compression_rate;
                k_extra += m.stop;
                c_extra += m.stop_damping;
            }

            // tyre / soil tangential force from the transient slip. The lateral force is
            // explicit; the longitudinal force is solved together with the spin (below).
            let fz_total = contact.rigid_load + contact.soil_load;
            let mut f_ext = gravity * m.unsprung_mass + contact.force;
            let mut lat_force = 0.0;
            let mut roll_torque = 0.0;
            let mut contact_moment = Vec3::ZERO;
            let mut radius = m.radius;
            let mut slip_clamp = 0.0;
            let (mut vx, mut vy) = (0.0, 0.0);
            let mut long = LongTyre::default();
            if fz_total > 0.0 {
                let n = contact.force.normalized();
                let e_long = axle.cross(n).normalized();
                let e_lat = n.cross(e_long);
                radius = (m.radius - contact.depth).max(0.5 * m.radius);
                // Slip is measured where the force acts: at the contact, a loaded radius below
                // the hub, moving with the chassis' rotation too. Measuring it at the hub
                // while applying the lateral force's moment at the contact feeds roll motion
                // back into the tyre force and rocks a vehicle parked on a side slope.
                let v_contact = v_hub + omega_w.cross(n * (-radius));
                vx = v_contact.dot(e_long);
                vy = v_contact.dot(e_lat);
                let (kx, ky) = (ws.slip_long, ws.slip_lat);
                let (mut fx, mut fy, initial_slope, limit);
                if contact.soil_load > contact.rigid_load {
                    // Janosi–Hanamoto traction over the soil patch, Mohr–Coulomb limit
                    let kn = (kx * kx + ky * ky).sqrt();
                    let frac = janosi_fraction(kn, contact.soil_length, contact.soil_janosi_k);
                    limit = contact.soil_shear_limit;
                    if kn > 1e-12 {
                        fx = limit * frac * kx / kn;
                        fy = limit * frac * ky / kn;
                    } else {
                        fx = 0.0;
                        fy = 0.0;
                    }
                    initial_slope = limit * 0.5 * contact.soil_length / contact.soil_janosi_k;
                    slip_clamp = janosi_sliding_slip(contact.soil_length, contact.soil_janosi_k);
                } else {
                    let (cx, cy) = tmeasy_combined(kx, ky, &spec.tyre, contact.mu_scale);
                    fx = cx * fz_total;
                    fy = cy * fz_total;
                    initial_slope = spec.tyre.dfx0 * fz_total;
                    limit = spec.tyre.fxm.max(spec.tyre.fym) * contact.mu_scale * fz_total;
                    slip_clamp = -1.0; // rigid: direction-dependent clamp computed later
                }
                // At standstill the tyre is an elastic bristle of fixed stiffness (TMeasy's Dahl
                // model): the force follows the deflection, not the momentary load, up to the
                // friction limit. Making it proportional to the load there closes a fast loop
                // (roll → load → lateral force → roll) that rocks a vehicle parked on a steep
                // side slope. Above 1 m/s (scaled) the slip curve alone acts; in between blend.
                let vref = vx.abs().max((spin * radius).abs());
                let fade = (1.0 - vref / spec.scale.sqrt()).max(0.0);
                if fade > 0.0 {
                    let (cx, cy) = if contact.soil_load > contact.rigid_load {
                        (
                            initial_slope / fz_total.max(1e-9),
                            initial_slope / fz_total.max(1e-9),
                        )
                    } else {
                        (spec.tyre.dfx0, spec.tyre.dfy0)
                    };
                    let (mut dx, mut dy) = (cx * m.nominal_load * kx, cy * m.nominal_load * ky);
                    let dn = dx.hypot(dy);
                    if dn > limit {
                        dx *= limit / dn;
                        dy *= limit / dn;
                    }
                    fx = fade * dx + (1.0 - fade) * fx;
                    fy = fade * dy + (1.0 - fade) * fy;
                }
                fy -= fade * m.slip_damping_lat * vy;
                fy = fy.clamp(-limit, limit);
                lat_force = fy;
                let f_lat = e_lat * fy;
                f_ext += f_lat;
                // The ground force acts at the contact, a loaded radius below the hub. The
                // lateral force's overturning moment reaches the chassis through the bearing;
                // the longitudinal force's moment about the axle drives the spin.
                let m_contact = (n * (-radius)).cross(f_lat);
                contact_moment = m_contact - axle * m_contact.dot(axle);
                let vroll = spin * radius;
                roll_torque = -spec.tyre.rolling_resistance
                    * contact.rigid_load
                    * radius
                    * soft_sign(vroll / 0.1);
                // Longitudinal force linearised in the new spin: F = C·κ_new − c·(vx − ω_new·R)
                // with the secant stiffness C = F(κ)/κ (the initial slope near κ = 0) and
                // κ_new = a + b·ω_new from the implicit relaxation update.
                let secant = if kx.abs() > 1e-6 {
                    (fx / kx).max(0.0)
                } else {
                    initial_slope
                };
                let decay = 1.0 + h * vref / spec.tyre.relaxation_length;
                long = LongTyre {
                    active: true,
                    e_long,
                    stiffness: secant,
                    a: (kx - h * vx / spec.tyre.relaxation_length) / decay,
                    b: h * radius / (spec.tyre.relaxation_length * decay),
                    decay,
                    damping: fade * m.slip_damping_long,
                    vx,
                    radius,
                    limit: (limit * limit - fy * fy).max(0.0).sqrt(),
                };
            }
            slip_inputs[w] = (vx, vy, radius, slip_clamp, fz_total);
            long_tyre[w] = long;

            // spin: rolling resistance and the soil pressure moment about the axle (explicit);
            // the longitudinal tyre force enters the implicit spin solve below
            group_torque[m.group] += roll_torque + contact.soil_moment.dot(axle);
            if long.active {
                group_k[m.group] +=
                    long.radius * (long.stiffness * long.b + long.damping * long.radius);
                group_torque[m.group] -=
                    long.radius * (long.stiffness * long.a - long.damping * long.vx);
            }

            // composite-body force and torque
            let f_axis = f_ext.dot(up);
            force += f_ext;
            // the axle-direction part of the soil moment goes to the spin; the rest to the chassis
            let soil_perp = contact.soil_moment - axle * contact.soil_moment.dot(axle);
            torque += r.cross(f_ext - up * f_axis + up * f_susp) + soil_perp + contact_moment;
            axis_force_sum += f_axis;
            susp_sum += f_susp;
            wheel_axis[w] = axle;
            wheel_arm[w] = r;
            wheel_axis_force[w] = f_axis;
            wheel_susp[w] = f_susp;
            wheel_k[w] = k_extra + contact.k_axis;
            wheel_c[w] = c_extra + contact.c_axis;
            wheel_kc[w] = contact.k_vec;
            wheel_cc[w] = contact.c_vec;

            let out = &mut st.wheels[w];
            out.normal_force = fz_total;
            out.lat_force = lat_force;
            out.in_contact = fz_total > 0.0;
            out.on_soil = contact.soil_nodes > 0;
            out.touches_obstacle = contact.obstacle;
            out.sinkage = contact.sinkage;
            out.tyre_deflection = contact.depth;
            if contact.soil_nodes > 0 {
                out.soil_patch_b = contact.soil_b;
            }
            contacts.wheels_in_contact += u32::from(fz_total > 0.0);
            contacts.wheels_on_soil += u32::from(contact.soil_nodes > 0);
            contacts.wheel_obstacle_contacts += u32::from(contact.obstacle);
            contacts.soil_nodes_in_contact += contact.soil_nodes;
        }

        // ---- spin groups: drive, brakes (exact Coulomb), skid steering ----
        let brake_in = ctl.brake;
        let mut group_reaction = [0.0; crate::spec::MAX_WHEELS];
        for (g, grp) in self.groups.iter().enumerate() {
            let mut share = grp.drive_share;
            let mut brake_max = 0.0;
            for &w in &grp.wheels {
                brake_max += self.wheels[w].brake_torque * brake_in;
            }
            if skid {
                // positive steering turns left: more torque right, brake the left (inner) side
                share *= 1.0 - grp.side * st.steer;
                if grp.side * st.steer > 0.0 {
                    brake_max +=
                        spec.steering.skid_brake_torque * st.steer.abs() * grp.wheels.len() as f64;
                }
            }
            let drive = wheel_torque_total * share;
            // Implicit spin: (I/h + K)·ω_new = I·ω/h + T, with K the tyres' linearised
            // longitudinal stiffness against the spin, then Coulomb brakes solved exactly.
            // Explicitly, a heavily loaded tyre (impacts) overshoots the no-slip speed within
            // one step and pumps energy into the vehicle.
            let w0 = st.group_spin[g];
            let x = grp.inertia * w0 / h + drive + group_torque[g];
            let denom = grp.inertia / h + group_k[g];
            let (w1, brake_applied) = if x.abs() <= brake_max {
                (0.0, -x)
            } else {
                (
                    (x - x.signum() * brake_max) / denom,
                    -x.signum() * brake_max,
                )
            };
            st.group_spin[g] = w1;
            group_reaction[g] = -(drive + brake_applied) / grp.wheels.len() as f64;
        }
        // Longitudinal tyre forces consistent with the new spins, onto the composite body.
        for (w, m) in self.wheels.iter().enumerate() {
            let lt = long_tyre[w];
            if !lt.active {
                st.wheels[w].long_force = 0.0;
                continue;
            }
            let spin = st.group_spin[m.group];
            let fx = (lt.stiffness * (lt.a + lt.b * spin)
                - lt.damping * (lt.vx - spin * lt.radius))
                .clamp(-lt.limit, lt.limit);
            let f = lt.e_long * fx;
            let f_axis = f.dot(up);
            force += f;
            torque += wheel_arm[w].cross(f - up * f_axis);
            axis_force_sum += f_axis;
            wheel_axis_force[w] += f_axis;
            st.wheels[w].long_force = fx;
        }
        for (w, m) in self.wheels.iter().enumerate() {
            torque += wheel_axis[w] * group_reaction[m.group];
            st.wheels[w].spin_rate = st.group_spin[m.group];
        }

        // ---- chassis body contacts ----
        self.body_contacts(st, near, &mut force, &mut torque, &mut contacts);

        // ---- chassis accelerations ----
        let fb = q.inverse_rotate(force);
        let accel_body = Vec3::new(
            fb.x / self.total_mass,
            fb.y / self.total_mass,
            (fb.z - axis_force_sum + susp_sum) / self.sprung_mass,
        );
        let accel = q.rotate(accel_body);
        let tb = q.inverse_rotate(torque);
        let om = st.omega;
        let i = self.inertia;
        let gyro = om.cross(Vec3::new(i.x * om.x, i.y * om.y, i.z * om.z));
        let alpha_body = Vec3::new(
            (tb.x - gyro.x) / i.x,
            (tb.y - gyro.y) / i.y,
            (tb.z - gyro.z) / i.z,
        );
        let alpha = q.rotate(alpha_body);

        // ---- wheels: implicit suspension update ----
        // Staggered: the chassis has just been advanced explicitly; each wheel's absolute
        // velocity along the suspension axis is then solved implicitly against its spring,
        // damper and contact stiffness, with the contact acting on the wheel's *absolute*
        // motion (chassis velocity after this step plus compression rate). Linearising the
        // contact in the compression rate alone gains energy in the heave mode.
        for w in 0..nw {
            let m = &self.wheels[w];
            let r = wheel_arm[w];
            let a_attach_vec = accel + alpha.cross(r) + omega_w.cross(omega_w.cross(r));
            let a_attach = a_attach_vec.dot(up);
            let v_attach_new = st.velocity + omega_w.cross(r) + a_attach_vec * h;
            let f0 = wheel_axis_force[w]
                - wheel_susp[w]
                - m.unsprung_mass * a_attach
                - h * wheel_kc[w].dot(v_attach_new)
                - h * wheel_cc[w].dot(a_attach_vec);
            let ws = &mut st.wheels[w];
            let mc = m.unsprung_mass + h * wheel_c[w];
            let rate = (mc * ws.compression_rate + h * f0) / (mc + h * h * wheel_k[w]);
            ws.compression_rate = rate;
            ws.compression += h * rate;
        }

        // ---- transient slip (implicit relaxation, after the spin update) ----
        // Longitudinally the state takes exactly the value the spin solve used (κ = a + b·ω);
        // laterally it relaxes with the same decay.
        let sigma = spec.tyre.relaxation_length;
        for ((ws, &(_vx, vy, _radius, clamp, fz)), lt) in st
            .wheels
            .iter_mut()
            .zip(&slip_inputs)
            .zip(&long_tyre)
            .take(nw)
        {
            if fz <= 0.0 || !lt.active {
                // a tyre in the air relaxes its deflection
                ws.slip_long = 0.0;
                ws.slip_lat = 0.0;
                continue;
            }
            let spin = ws.spin_rate;
            let mut kx = lt.a + lt.b * spin;
            let mut ky = (ws.slip_lat - h * vy / sigma) / lt.decay;
            let limit = if clamp < 0.0 {
                tmeasy_sliding_slip(kx, ky, &spec.tyre)
            } else {
                clamp
            };
            let kn = (kx * kx + ky * ky).sqrt();
            if kn > limit {
                kx *= limit / kn;
                ky *= limit / kn;
            }
            ws.slip_long = kx;
            ws.slip_lat = ky;
        }

        // ---- chassis integration (semi-implicit Euler) ----
        st.velocity += accel * h;
        st.position += st.velocity * h;
        // Rotation in momentum form: the world angular momentum takes the torque impulse, the
        // attitude advances, and the body rates follow from the momentum in the new attitude.
        // An explicit gyroscopic term (ω × Iω) pumps energy into a fast tumble (a vehicle
        // thrown off a rock spinning at tens of rad/s); this form keeps |L| exact when free.
        let inv_i = |v: Vec3| Vec3::new(v.x / i.x, v.y / i.y, v.z / i.z);
        let momentum = q.rotate(Vec3::new(i.x * om.x, i.y * om.y, i.z * om.z)) + torque * h;
        let omega_mid = q.rotate(inv_i(q.inverse_rotate(momentum)));
        st.orientation = integrate_orientation(st.orientation, omega_mid, h);
        st.omega = inv_i(st.orientation.inverse_rotate(momentum));
        st.contacts = contacts;
    }

    /// Distance from the steered reference (first steered axle) to the unsteered axles.
    fn wheels_base_length(&self) -> f64 {
        self.wheels
            .iter()
            .find(|w| w.steered)
            .map_or(1.0, |w| w.ackermann_dx)
    }

    /// Contact of one wheel with rigid terrain, obstacles and soil.
    #[allow(clippy::too_many_arguments)]
    fn wheel_contact(
        &self,
        st: &mut SimState,
        m: &WheelModel,
        soil_b: f64,
        hub: Vec3,
        axle: Vec3,
        v_hub: Vec3,
        up: Vec3,
        near: &[u32],
    ) -> WheelContact {
        let world = &*self.world;
        let hf = &world.terrain;
        let ground = &self.ground;
        let patches = world.patches.patches();
        let tyre = &self.spec.tyre;
        let mut c = WheelContact::default();
        let r = m.radius;

        // Quick reject: the lowest point of the wheel is above every terrain height around it.
        let down = {
            let d = Vec3::new(0.0, 0.0, -1.0) - axle * (-axle.z);
            let n = d.norm();
            if n > 1e-6 {
                d / n
            } else {
                Vec3::new(0.0, 0.0, -1.0)
            }
        };
        let lowest_z = hub.z + r * down.z - m.half_width * axle.z.abs();
        let ground_max = self
            .bound
            .max_in(hub.x - r, hub.y - r, hub.x + r, hub.y + r);
        let near_ground = lowest_z < ground_max;

        // Soil needs a grid that resolves the wheel: a tread narrower than the node spacing
        // (a 1/10 vehicle on a full-scale world) could fall between nodes, and a wheel far too
        // big for it would visit thousands. Both cases drive on the soil as rigid ground.
        let soil_as_rigid = self.soil.is_none_or(|l| {
            let span = (2.0 * r + 2.0 * m.half_width) / l.delta + 2.0;
            span * span > MAX_SOIL_NODES_PER_WHEEL as f64
                || 2.0 * m.half_width < l.delta
                || r < 1.5 * l.delta
        });
        let mut best_depth = 0.0;
        let mut best_normal = Vec3::Z;
        let mut best_mu = 1.0;
        let mut soil_here = false;
        if near_ground {
            // (1) disc-vs-plane lowest point under the hub, (2) four rim samples fore and aft so
            // steps and rock edges are seen before the hub reaches them.
            let (_, gx, gy) = ground.sample(hub.x, hub.y);
            let n0 = Vec3::new(-gx, -gy, 1.0).normalized();
            let np = n0 - axle * n0.dot(axle);
            let npn = np.norm();
            let extreme = if npn > 1e-6 {
                hub - np * (r / npn) - axle * (m.half_width * n0.dot(axle).signum())
            } else {
                hub - n0 * m.half_width
            };
            let fwd = down.cross(axle);
            let samples = [
                extreme,
                hub + (down * 0.8253 + fwd * 0.5646) * r, // ±34.4°
                hub + (down * 0.8253 - fwd * 0.5646) * r,
                hub + (down * 0.3624 + fwd * 0.9320) * r, // ±68.8°
                hub + (down * 0.3624 - fwd * 0.9320) * r,
            ];
            for (k, p) in samples.iter().enumerate() {
                if k > 0 && (p.z >= ground_max || p.z >= self.bound.max_at(p.x, p.y)) {
                    continue;
                }
                let (h, gx, gy) = ground.sample(p.x, p.y);
                if h <= p.z {
                    continue;
                }
                let mu = match patches[ground.patch_index(p.x, p.y)].surface {
                    Surface::Rigid { friction, .. } => friction,
                    // beyond the map edge there are no soil nodes, and a soil grid that cannot
                    // resolve this wheel (see `soil_as_rigid`): the ground acts rigid there
                    Surface::Deformable { soil } if soil_as_rigid || !hf.contains(p.x, p.y) => {
                        libm::tan(soil.friction_angle_deg.to_radians())
                    }
                    Surface::Deformable { .. } => {
                        soil_here = true;
                        continue;
                    }
                };
                let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                let depth = (h - p.z) * nz;
                if depth > best_depth {
                    best_depth = depth;
                    best_normal = Vec3::new(-gx * nz, -gy * nz, nz);
                    best_mu = mu;
                }
            }
            if !soil_here && self.soil.is_some() {
                // the wheel may be sunk in soil with its rim samples above the undeformed level
                soil_here = patches[ground.patch_index(hub.x, hub.y)]
                    .surface
                    .is_deformable();
            }
        }
        let k_t = tyre.radial_stiffness;
        let c_t = tyre.radial_damping;
        let add_rigid = |c: &mut WheelContact, depth: f64, n: Vec3, mu: f64| {
            let rate = -v_hub.dot(n);
            let mut f = k_t * depth + c_t * rate;
            let mut k = k_t;
            if depth > m.rim_depth {
                // tyre bottomed out on the rim: much stiffer
                f += 10.0 * k_t * (depth - m.rim_depth);
                k += 10.0 * k_t;
            }
            if f <= 0.0 {
                return;
            }
            let nu = n.dot(up);
            c.force += n * f;
            c.k_axis += k * nu * nu;
            c.c_axis += c_t * nu * nu;
            c.k_vec += n * (k * nu);
            c.c_vec += n * (c_t * nu);
            c.mu_scale = (c.mu_scale * c.rigid_load + (mu.min(tyre.friction) / tyre.friction) * f)
                / (c.rigid_load + f);
            c.rigid_load += f;
            c.depth = c.depth.max(depth);
        };
        if best_depth > 0.0 {
            add_rigid(&mut c, best_depth, best_normal, best_mu);
        }

        // Obstacles: the cylinder's support point toward the nearest face.
        let mut obstacle_best: Option<(f64, Vec3)> = None;
        for &k in near {
            let o = &world.obstacles[k as usize];
            let op = o.position();
            let reach = o.radius_xy() + r + m.half_width;
            if (hub.x - op.x).powi(2) + (hub.y - op.y).powi(2) > reach * reach {
                continue;
            }
            let (z0, z1) = o.z_range();
            if hub.z - r > z1 || hub.z + r < z0 {
                continue;
            }
            let fo = &self.fast_obstacles[k as usize];
            let reach3 = fo.radius + r + m.half_width;
            if (hub - fo.center).norm_sq() > reach3 * reach3 {
                continue;
            }
            let (d_hub, n_hub) = fo.signed_distance(hub);
            if d_hub > r + m.half_width {
                continue;
            }
            let np = n_hub - axle * n_hub.dot(axle);
            let npn = np.norm();
            let support = if npn > 1e-6 {
                hub - np * (r / npn) - axle * (m.half_width * n_hub.dot(axle).signum())
            } else {
                hub - n_hub * m.half_width
            };
            let (d, n) = fo.signed_distance(support);
            if d < 0.0 && obstacle_best.is_none_or(|(bd, _)| -d > bd) {
                obstacle_best = Some((-d, n));
            }
        }
        if let Some((depth, n)) = obstacle_best {
            add_rigid(&mut c, depth, n, OBSTACLE_FRICTION);
            c.obstacle = true;
        }

        if soil_here
            && !soil_as_rigid
            && let Some(layout) = self.soil
        {
            self.soil_contact(st, &layout, m, soil_b, hub, axle, v_hub, up, &mut c);
        }
        c
    }

    /// SCM under one wheel: visits the nodes under the lower part of the wheel, updates their
    /// plastic memory and sums the pressure forces and their moment about the hub.
    #[allow(clippy::too_many_arguments)]
    fn soil_contact(
        &self,
        st: &mut SimState,
        layout: &SoilLayout,
        m: &WheelModel,
        b: f64,
        hub: Vec3,
        axle: Vec3,
        v_hub: Vec3,
        up: Vec3,
        c: &mut WheelContact,
    ) {
        let patches = self.world.patches.patches();
        let ground = &self.ground;
        let r = m.radius;
        let delta = layout.delta;
        let area = delta * delta;
        // Footprint bound: the part of the wheel below the highest undeformed level nearby.
        let ground_max = self
            .bound
            .max_in(hub.x - r, hub.y - r, hub.x + r, hub.y + r);
        let drop = hub.z - ground_max;
        if drop >= r {
            return;
        }
        let half_chord = (r * r - drop.max(0.0).powi(2)).sqrt();
        let fwd = Vec3::Z.cross(axle).normalized();
        let ext_x = half_chord * fwd.x.abs() + m.half_width * axle.x.abs() + 0.5 * delta;
        let ext_y = half_chord * fwd.y.abs() + m.half_width * axle.y.abs() + 0.5 * delta;
        let i0 = fast_ceil((hub.x - ext_x) / delta);
        let i1 = fast_floor((hub.x + ext_x) / delta);
        let j0 = fast_ceil((hub.y - ext_y) / delta);
        let j1 = fast_floor((hub.y + ext_y) / delta);
        if i1 < i0 || j1 < j0 || ((i1 - i0 + 1) * (j1 - j0 + 1)) as usize > MAX_SOIL_NODES_PER_WHEEL
        {
            return;
        }
        // Vertical ray vs cylinder: |f + t·e|² = r², e = Z − (Z·a)a, f = w − (w·a)a.
        let e = Vec3::Z - axle * axle.z;
        let ee = e.norm_sq();
        if ee < 1e-6 {
            return; // wheel lying flat: the tread cannot meet a vertical ray
        }
        let mut along_min = f64::INFINITY;
        let mut along_max = f64::NEG_INFINITY;
        let mut across_min = f64::INFINITY;
        let mut across_max = f64::NEG_INFINITY;
        let mut shear_limit = 0.0;
        let mut janosi_weighted = 0.0;
        let mut load = 0.0;
        let mut cached_patch = usize::MAX;
        let mut cached_soil: Option<(verti_world::SoilParams, f64)> = None;
        for j in j0..=j1 {
            let y = j as f64 * delta;
            let row = ground.row(y);
            for i in i0..=i1 {
                let x = i as f64 * delta;
                let w = Vec3::new(x - hub.x, y - hub.y, -hub.z);
                let wa = w.dot(axle);
                let f = w - axle * wa;
                let fe = f.dot(e);
                let disc = fe * fe - ee * (f.norm_sq() - r * r);
                if disc <= 0.0 {
                    continue;
                }
                let t = (-fe - disc.sqrt()) / ee; // lower intersection height
                // the wheel is above every terrain height around here: no sinkage possible
                if t >= ground_max {
                    continue;
                }
                let lateral = wa + t * axle.z;
                if lateral.abs() > m.half_width {
                    continue;
                }
                let pk = ground.patch_index(x, y);
                if pk != cached_patch {
                    cached_patch = pk;
                    cached_soil = match patches[pk].surface {
                        Surface::Deformable { soil } => {
                            Some((soil, libm::tan(soil.friction_angle_deg.to_radians())))
                        }
                        Surface::Rigid { .. } => None,
                    };
                }
                let Some((soil, tan_phi)) = cached_soil else {
                    continue;
                };
                let Some(at) = layout.locate(i, j) else {
                    continue;
                };
                let (z0, gx, gy) = row.sample(x);
                let ca = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                let sinkage = ca * (z0 - t);
                let (plastic, yield_p) = st.soil.node(at);
                if sinkage <= plastic {
                    continue;
                }
                let ke = soil.elastic_k.max(soil.bekker_kphi);
                let mut sigma = ke * (sinkage - plastic);
                let mut slope = ke;
                if sigma > yield_p {
                    sigma = bekker_pressure(&soil, b, sinkage);
                    slope = bekker_slope(&soil, sigma, sinkage).min(ke);
                    let new_plastic = (sinkage - sigma / ke).max(plastic);
                    st.soil.set_node(at, new_plastic, sigma);
                }
                let normal = Vec3::new(-gx * ca, -gy * ca, ca);
                let point = Vec3::new(x, y, t);
                let arm = point - hub;
                // SCM damping on the normal speed of the wheel body. Chrono uses the speed of
                // the contact point including the wheel's spin; a wheel spinning at high slip
                // then sees its rotating tread as a fast plunge at the front of the patch and a
                // lift at the rear (hundreds of kPa at R = 3e4), which is not soil physics.
                // Deliberate fix: the hub's translation only. Like Chrono, it may pull.
                sigma -= v_hub.dot(normal) * soil.damping;
                let fnode = normal * (sigma * area);
                c.force += fnode;
                c.soil_moment += arm.cross(fnode);
                let nu = normal.dot(up);
                c.k_axis += slope * area * nu * nu;
                c.c_axis += soil.damping * area * nu * nu;
                c.k_vec += normal * (slope * area * nu);
                c.c_vec += normal * (soil.damping * area * nu);
                let s_pos = sigma.max(0.0);
                let tau_max = soil.cohesion + s_pos * tan_phi;
                shear_limit += tau_max * area;
                janosi_weighted += soil.janosi_k * sigma.abs() * area;
                load += sigma * area;
                c.sinkage = c.sinkage.max(sinkage);
                c.soil_nodes += 1;
                let along = arm.dot(fwd);
                let across = arm.dot(axle);
                along_min = along_min.min(along);
                along_max = along_max.max(along);
                across_min = across_min.min(across);
                across_max = across_max.max(across);
            }
        }
        if c.soil_nodes > 0 {
            let length = along_max - along_min + delta;
            let width = across_max - across_min + delta;
            c.soil_load += load.max(0.0);
            c.soil_shear_limit += shear_limit;
            c.soil_length = length;
            c.soil_janosi_k = if load.abs() > 0.0 {
                janosi_weighted / load.abs().max(1e-9)
            } else {
                0.01
            };
            // b = 2A/L of the patch (rectangle of the hit extents) for Bekker's K_c/b next time
            let a_patch = f64::from(c.soil_nodes) * area;
            let perimeter = 2.0 * (length + width);
            c.soil_b = (2.0 * a_patch / perimeter).max(0.5 * delta);
        }
    }

    /// Chassis collision box against terrain (rigid, or the undeformed soil surface) and
    /// obstacles: compliant normal force plus regularised Coulomb friction.
    fn body_contacts(
        &self,
        st: &SimState,
        near: &[u32],
        force: &mut Vec3,
        torque: &mut Vec3,
        contacts: &mut ContactInfo,
    ) {
        let world = &*self.world;
        let q = st.orientation;
        let omega_w = q.rotate(st.omega);
        let mu_body = self.spec.chassis.friction;
        let rm = q.to_mat3();
        let mut pts = [Vec3::ZERO; 18];
        let (mut x0, mut y0, mut z0) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for (k, p) in self.body_points.iter().enumerate() {
            let w = st.position + rm.mul_vec(*p);
            pts[k] = w;
            x0 = x0.min(w.x);
            y0 = y0.min(w.y);
            z0 = z0.min(w.z);
            x1 = x1.max(w.x);
            y1 = y1.max(w.y);
        }
        // `stiff` = 1 for terrain, 4 for obstacles: see `Sim::new`
        let mut apply = |point: Vec3, n: Vec3, depth: f64, mu: f64, stiff: f64| {
            let arm = point - st.position;
            let v = st.velocity + omega_w.cross(arm);
            let vn = v.dot(n);
            let fnorm = stiff * self.body_stiffness * depth - stiff.sqrt() * self.body_damping * vn;
            if fnorm <= 0.0 {
                return false;
            }
            let vt = v - n * vn;
            let vtn = vt.norm();
            let ft = if vtn > 0.0 {
                vt * (-mu * fnorm / vtn.max(self.friction_speed))
            } else {
                Vec3::ZERO
            };
            let f = n * fnorm + ft;
            *force += f;
            *torque += arm.cross(f);
            true
        };
        let box_bound = self.bound.max_in(x0, y0, x1, y1);
        if z0 < box_bound {
            let patches = world.patches.patches();
            for p in &pts {
                // cheap compare against the whole box's bound first, then the point's own block
                if p.z >= box_bound || p.z >= self.bound.max_at(p.x, p.y) {
                    continue;
                }
                let (h, gx, gy) = self.ground.sample(p.x, p.y);
                if h <= p.z {
                    continue;
                }
                let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                let n = Vec3::new(-gx * nz, -gy * nz, nz);
                let mu = match patches[self.ground.patch_index(p.x, p.y)].surface {
                    Surface::Rigid { friction, .. } => friction.min(mu_body),
                    Surface::Deformable { soil } => {
                        libm::tan(soil.friction_angle_deg.to_radians()).min(mu_body)
                    }
                };
                if apply(*p, n, (h - p.z) * nz, mu, 1.0) {
                    contacts.chassis_terrain_points += 1;
                }
            }
        }
        let mu_obs = OBSTACLE_FRICTION.min(mu_body);
        for &k in near {
            let o = &world.obstacles[k as usize];
            let op = o.position();
            let reach = o.radius_xy() + self.reach;
            if (st.position.x - op.x).powi(2) + (st.position.y - op.y).powi(2) > reach * reach {
                continue;
            }
            let (oz0, oz1) = o.z_range();
            if st.position.z - self.reach > oz1 || st.position.z + self.reach < oz0 {
                continue;
            }
            // Separating planes: if the whole box lies outside one face plane of the rock (the
            // box's support along the face normal), nothing touches; most nearby obstacles
            // are ruled out this way before any per-point work.
            let fo = &self.fast_obstacles[k as usize];
            let box_world = st.position + rm.mul_vec(self.box_center);
            if fo.separated_from_box(box_world, &rm, self.box_half) {
                continue;
            }
            if let Some((cx, cy, radius, tz0, tz1)) = fo.tree {
                // A trunk is thinner than a body contact's penetration at speed, and a point
                // that passes its axis would be pulled through. Test the trunk's axis (at the
                // box's height) against the box grown by the radius instead: the box face it is
                // nearest to gives a normal that cannot flip.
                let axis_point = Vec3::new(cx, cy, box_world.z.clamp(tz0, tz1));
                let local = q.inverse_rotate(axis_point - box_world);
                let d = Vec3::new(
                    self.box_half.x + radius - local.x.abs(),
                    self.box_half.y + radius - local.y.abs(),
                    self.box_half.z - local.z.abs(),
                );
                if d.x > 0.0 && d.y > 0.0 && d.z > 0.0 {
                    let v_local =
                        -q.inverse_rotate(st.velocity + omega_w.cross(axis_point - st.position));
                    let (depth, n_local) = box_penetration(local, v_local, d);
                    let n = q.rotate(n_local);
                    // contact on the trunk's surface facing the box
                    if apply(
                        axis_point + n * radius,
                        n,
                        depth,
                        mu_obs,
                        OBSTACLE_STIFFENING,
                    ) {
                        contacts.chassis_obstacle_points += 1;
                    }
                }
                continue;
            }
            // chassis points inside the obstacle (outside its bounding sphere: skip)
            let r2 = fo.radius * fo.radius;
            for p in &pts {
                if (*p - fo.center).norm_sq() > r2 {
                    continue;
                }
                let (d, n) = fo.signed_distance(*p);
                if d < 0.0 && apply(*p, n, -d, mu_obs, OBSTACLE_STIFFENING) {
                    contacts.chassis_obstacle_points += 1;
                }
            }
            // obstacle vertices inside the chassis box (a rock edge poking into a flat side)
            let rt = rm.transpose();
            for v in o.vertices() {
                let local = rt.mul_vec(*v - st.position) - self.box_center;
                let d = Vec3::new(
                    self.box_half.x - local.x.abs(),
                    self.box_half.y - local.y.abs(),
                    self.box_half.z - local.z.abs(),
                );
                if d.x <= 0.0 || d.y <= 0.0 || d.z <= 0.0 {
                    continue;
                }
                let v_local = -q.inverse_rotate(st.velocity + omega_w.cross(*v - st.position));
                let (depth, n_local) = box_penetration(local, v_local, d);
                if apply(*v, q.rotate(n_local), depth, mu_obs, OBSTACLE_STIFFENING) {
                    contacts.chassis_obstacle_points += 1;
                }
            }
        }
    }
}

/// Penetration of a point into a box, given its box-frame position `local`, its velocity
/// relative to the box `v_local` and its depths `d` below the three face pairs (all positive).
/// Returns the depth and the box-frame outward normal of the face it entered through: among
/// the faces it crossed within the last 0.2 s (depth / inward speed), the most recent one.
/// The smallest depth alone would switch to a side face once a thin obstacle is pushed deep
/// into a long box (and let the body slide past a tree it hit head-on); without a recent
/// crossing (resting contact, slow creep) it is the right choice and is used.
#[inline]
fn box_penetration(local: Vec3, v_local: Vec3, d: Vec3) -> (f64, Vec3) {
    const RECENT: f64 = 0.2;
    let axes = [
        (
            d.x,
            local.x,
            v_local.x,
            Vec3::new(-local.x.signum(), 0.0, 0.0),
        ),
        (
            d.y,
            local.y,
            v_local.y,
            Vec3::new(0.0, -local.y.signum(), 0.0),
        ),
        (
            d.z,
            local.z,
            v_local.z,
            Vec3::new(0.0, 0.0, -local.z.signum()),
        ),
    ];
    let mut recent: Option<(f64, f64, Vec3)> = None;
    let mut shallowest = axes[0];
    for axis in axes {
        let (depth, pos, vel, n) = axis;
        if depth < shallowest.0 {
            shallowest = axis;
        }
        // inward speed: moving toward the box centre along this axis
        let inward = -vel * pos.signum();
        if inward > 0.0 && depth < RECENT * inward {
            let since = depth / inward;
            if recent.is_none_or(|(best, _, _)| since < best) {
                recent = Some((since, depth, n));
            }
        }
    }
    match recent {
        Some((_, depth, n)) => (depth, n),
        None => (shallowest.0, shallowest.3),
    }
}

/// `Quat::from_euler` with libm's sine and cosine, so a start pose has the same bits on every
/// platform (the engine uses libm wherever a transcendental function enters the dynamics).
fn quat_from_euler(roll: f64, pitch: f64, yaw: f64) -> Quat {
    let axis = |x: f64, y: f64, z: f64, angle: f64| {
        let (s, c) = libm::sincos(0.5 * angle);
        Quat {
            w: c,
            x: x * s,
            y: y * s,
            z: z * s,
        }
    };
    axis(0.0, 0.0, 1.0, yaw)
        .mul(axis(0.0, 1.0, 0.0, pitch))
        .mul(axis(1.0, 0.0, 0.0, roll))
}

/// x / sqrt(1 + x²): a smooth sign without a transcendental call.
#[inline]
fn soft_sign(x: f64) -> f64 {
    x / (1.0 + x * x).sqrt()
}

/// floor for finite values of moderate size, without the library call.
#[inline]
fn fast_floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

#[inline]
fn fast_ceil(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x { t + 1 } else { t }
}

/// First-order quaternion update by a world-frame angular velocity, renormalised. With
/// |ω|·h below 0.1 rad per step its error is far below the model's; it avoids the sin/cos
/// of the exact exponential map on every step.
#[inline]
fn integrate_orientation(q: Quat, omega: Vec3, h: f64) -> Quat {
    let k = 0.5 * h;
    let dq = Quat {
        w: 0.0,
        x: omega.x * k,
        y: omega.y * k,
        z: omega.z * k,
    }
    .mul(q);
    Quat {
        w: q.w + dq.w,
        x: q.x + dq.x,
        y: q.y + dq.y,
        z: q.z + dq.z,
    }
    .normalized()
}

/// Key identifying which spin group a wheel joins (None = its own group).
fn group_key(spec: &VehicleSpec, tracked: bool, w: usize) -> Option<usize> {
    let ax = &spec.axles[w / 2];
    let j = w % 2;
    if tracked {
        return Some(j);
    }
    if !ax.driven {
        return None;
    }
    match (
        spec.powertrain.axle_differential,
        spec.powertrain.central_differential,
    ) {
        (Differential::Locked, Differential::Locked) => Some(100),
        (Differential::Locked, Differential::Open) => Some(200 + w / 2),
        _ => None,
    }
}
