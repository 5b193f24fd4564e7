//! Contact stages: normal forces between the vehicle and the world.
//!
//! * [`wheel`]: one wheel against rigid ground and obstacles (a compliant tyre), handing the
//!   soil under it to [`soil`];
//! * [`rigid`]: the same for a rigid tyre (a rigid cylinder, `tyre.model: rigid`);
//! * [`soil`]: SCM under one wheel (pressure–sinkage per node, plastic memory);
//! * [`body`]: the chassis collision box against terrain and obstacles;
//! * [`belly`]: the box's bottom face against the terrain between its lattice points;
//! * [`track_run`]: a tracked vehicle's raised track ends against terrain and obstacles.
//!
//! Wheel contacts return a [`WheelContact`] summary; their tangential forces come later from
//! the slip state (`friction::tyre_forces`). Body contacts apply their forces, friction
//! included, directly.

pub(crate) mod belly;
pub(crate) mod body;
#[cfg(test)]
mod body_tests;
pub(crate) mod bulldozing;
pub(crate) mod rigid;
pub(crate) mod soil;
pub(crate) mod track_run;
#[cfg(test)]
mod track_run_tests;
pub(crate) mod wheel;

use verti_core::Vec3;

/// A wheel's placement and motion at the start of an internal step (world frame): the input
/// of its contact and friction stages.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WheelKinematics {
    /// Hub position relative to the centre of mass (the lever arm of the wheel's forces).
    pub arm: Vec3,
    pub hub: Vec3,
    /// Spin axis, pointing to the wheel's left.
    pub axle: Vec3,
    pub hub_velocity: Vec3,
    /// The chassis z axis, along which the suspension moves.
    pub up: Vec3,
    /// Chassis angular velocity.
    pub chassis_omega: Vec3,
    /// Spin rate of the wheel's group \[rad/s\].
    pub spin: f64,
}

#[cfg(test)]
impl WheelKinematics {
    /// An upright wheel at rest at `hub`, axle along +y, its hub the centre of mass (tests).
    pub fn at_rest(hub: Vec3) -> WheelKinematics {
        WheelKinematics {
            arm: Vec3::ZERO,
            hub,
            axle: Vec3::Y,
            hub_velocity: Vec3::ZERO,
            up: Vec3::Z,
            chassis_omega: Vec3::ZERO,
            spin: 0.0,
        }
    }
}

/// Contact of one wheel with everything (summed).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WheelContact {
    /// Summed normal force (world).
    pub force: Vec3,
    /// Stiffness and damping along the suspension axis (for the implicit wheel update).
    pub k_axis: f64,
    pub c_axis: f64,
    /// Σ k·(n·u)·n and Σ c·(n·u)·n: how the axis force depends on the chassis' motion.
    pub k_vec: Vec3,
    pub c_vec: Vec3,
    /// Rigid part: normal load and friction scale (ground μ / tyre μ), load-weighted.
    pub rigid_load: f64,
    pub mu_scale: f64,
    /// Deepest rigid penetration \[m\] (loaded-radius correction).
    pub depth: f64,
    /// Soil part.
    pub soil_load: f64,
    pub soil_shear_limit: f64,
    pub soil_length: f64,
    pub soil_janosi_k: f64,
    pub soil_moment: Vec3,
    /// The part of `soil_moment` about the axle that a track's belt plate carries
    /// (`soil::BeltPlate`): the hull takes it through the road wheels, not their spin, as the
    /// belt is not part of the wheel.
    pub belt_axle_moment: f64,
    pub soil_nodes: u32,
    /// b = 2A/L of this step's soil patch.
    pub soil_b: f64,
    pub sinkage: f64,
    pub obstacle: bool,
}

impl WheelContact {
    /// Total normal load \[N\].
    #[inline]
    pub fn normal_load(&self) -> f64 {
        self.rigid_load + self.soil_load
    }
}

/// What the rigid tyre's friction needs beyond the summed normal force (the second result of
/// `rigid::rigid_wheel_contact`). Here beside [`WheelContact`], not in `rigid`, because
/// `friction` reads both and sits below the contact stages.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RigidContact {
    /// Load-weighted contact point relative to the hub (world) \[m\]. Each contact's point
    /// is on the cylinder (the wheel's point deepest in what it touches), so on one contact
    /// the lever about the axle is the radius itself: the penetration is the penalty method's
    /// stand-in for a rigid contact, not a loaded radius, and a load-dependent lever would
    /// make the locked axles of a 4x4 fight each other.
    pub arm: Vec3,
    /// Coulomb limit Σ μ·N over the rigid contacts \[N\], μ = min(tyre μ, surface μ).
    pub friction_limit: f64,
    /// Moment of the normal forces about the hub without its part along the axle \[N m\].
    pub moment: Vec3,
}

/// The height at which the ground at height `h` holds a part of the vehicle that is not a
/// wheel (the hull, a track's raised ends): rigid ground at its surface, soil only at a floor
/// one (largest) wheel diameter below it. In Chrono's SCM only the wheels (the bodies with an
/// active domain) meet the soil, and the chassis passes through it; holding it at the
/// undeformed surface instead left verti's HMMWV high-centred on snow wherever its wheels sank
/// 0.2-0.4 m, stuck where Chrono's drives on (issue 34). No upright vehicle reaches the floor
/// while its wheels carry it: it keeps a capsized vehicle from falling through the map, as
/// Chrono's can (a reference artifact, not physics).
#[inline]
pub(crate) fn body_ground(
    h: f64,
    surface: &verti_world::Surface,
    model: &crate::model::Model,
) -> f64 {
    match surface {
        verti_world::Surface::Deformable { .. } => h - model.soil_floor,
        verti_world::Surface::Rigid { .. } => h,
    }
}

/// The broad phase of a wheel (radius `r`, half width `half_width`, hub at `hub`) against
/// obstacle `k`: `None` when the obstacle is out of reach by its planar circle, its height
/// range or its bounding sphere (cheapest test first), else its fast geometry. Shared by both
/// tyre models so they skip exactly the same obstacles.
#[inline]
pub(crate) fn obstacle_in_reach(
    terrain: &crate::terrain::Terrain,
    k: u32,
    hub: Vec3,
    r: f64,
    half_width: f64,
) -> Option<&crate::terrain::FastObstacle> {
    let o = &terrain.world.obstacles[k as usize];
    let op = o.position();
    let reach = o.radius_xy() + r + half_width;
    if (hub.x - op.x).powi(2) + (hub.y - op.y).powi(2) > reach * reach {
        return None;
    }
    let (z0, z1) = o.z_range();
    if hub.z - r > z1 || hub.z + r < z0 {
        return None;
    }
    let fo = &terrain.fast_obstacles[k as usize];
    let reach3 = fo.radius + r + half_width;
    if (hub - fo.center).norm_sq() > reach3 * reach3 {
        return None;
    }
    Some(fo)
}
