//! Integration of the chassis: from the summed loads to accelerations, then semi-implicit
//! (symplectic) Euler with the rotation in momentum form.
//!
//! The step's implicit parts, which remove the stiff modes, live with their stages: the
//! staggered wheel update in [`crate::suspension`], the spin/longitudinal-tyre solve with
//! exact Coulomb brakes in [`crate::drivetrain`], the slip relaxation in [`crate::friction`].

use crate::model::Model;
use crate::state::SimState;
use verti_core::{Quat, Vec3};

/// Force and torque on the composite body (world frame, about the centre of mass), summed
/// stage by stage, and the sums along the suspension axis that split the vertical part
/// between the sprung and unsprung masses.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Loads {
    pub force: Vec3,
    pub torque: Vec3,
    /// Σ external force on the wheels along the suspension axis \[N\].
    pub wheel_axis_force: f64,
    /// Σ suspension force pushing the chassis up \[N\].
    pub suspension_force: f64,
}

impl Loads {
    /// Gravity on the sprung mass, nothing else yet.
    #[inline]
    pub fn gravity(gravity: Vec3, sprung_mass: f64) -> Loads {
        Loads {
            force: gravity * sprung_mass,
            torque: Vec3::ZERO,
            wheel_axis_force: 0.0,
            suspension_force: 0.0,
        }
    }
}

impl Loads {
    /// Adds a wheel's external force `f_ext` (gravity on its unsprung mass, the ground's normal
    /// force, the lateral tyre force) and its suspension force `spring`. Across the suspension
    /// axis `f_ext` acts on the whole vehicle; along it, only through the spring. `moments`:
    /// the moments that reach the chassis directly (the soil's pressure moment off the axle,
    /// the lateral tyre force's overturning moment). Returns `f_ext` along the axis.
    #[inline]
    pub fn add_wheel(
        &mut self,
        arm: Vec3,
        up: Vec3,
        f_ext: Vec3,
        spring: f64,
        moments: (Vec3, Vec3),
    ) -> f64 {
        let f_axis = f_ext.dot(up);
        self.force += f_ext;
        self.torque += arm.cross(f_ext - up * f_axis + up * spring) + moments.0 + moments.1;
        self.wheel_axis_force += f_axis;
        self.suspension_force += spring;
        f_axis
    }

    /// Adds a force `f` on a wheel that has no suspension part of its own (the longitudinal tyre
    /// force, after the spin solve). Returns `f` along the axis.
    #[inline]
    pub fn add_wheel_force(&mut self, arm: Vec3, up: Vec3, f: Vec3) -> f64 {
        let f_axis = f.dot(up);
        self.force += f;
        self.torque += arm.cross(f - up * f_axis);
        self.wheel_axis_force += f_axis;
        f_axis
    }
}

/// Chassis accelerations (world frame).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Accelerations {
    pub linear: Vec3,
    pub angular: Vec3,
}

/// Accelerations of the chassis under `loads`. Along the suspension axis only the sprung mass
/// moves with the chassis (the wheels' own axis forces go to the wheels, the springs' to the
/// chassis); sideways and fore-aft the whole vehicle does.
#[inline]
pub(crate) fn accelerations(model: &Model, st: &SimState, loads: &Loads) -> Accelerations {
    let q = st.orientation;
    let fb = q.inverse_rotate(loads.force);
    let accel_body = Vec3::new(
        fb.x / model.total_mass,
        fb.y / model.total_mass,
        (fb.z - loads.wheel_axis_force + loads.suspension_force) / model.sprung_mass,
    );
    let linear = q.rotate(accel_body);
    let tb = q.inverse_rotate(loads.torque);
    let om = st.omega;
    let i = model.inertia;
    let gyro = om.cross(Vec3::new(i.x * om.x, i.y * om.y, i.z * om.z));
    let alpha_body = Vec3::new(
        (tb.x - gyro.x) / i.x,
        (tb.y - gyro.y) / i.y,
        (tb.z - gyro.z) / i.z,
    );
    Accelerations {
        linear,
        angular: q.rotate(alpha_body),
    }
}

/// Advances the chassis by `h`: semi-implicit Euler for the translation; the rotation in
/// momentum form. The world angular momentum takes the torque impulse, the attitude advances,
/// and the body rates follow from the momentum in the new attitude. An explicit gyroscopic
/// term (ω × Iω) pumps energy into a fast tumble (a vehicle thrown off a rock spinning at tens
/// of rad/s); this form keeps |L| exact when free.
#[inline]
pub(crate) fn advance_chassis(
    model: &Model,
    st: &mut SimState,
    loads: &Loads,
    acc: &Accelerations,
    h: f64,
) {
    let q = st.orientation;
    let om = st.omega;
    let i = model.inertia;
    st.velocity += acc.linear * h;
    st.position += st.velocity * h;
    let inv_i = |v: Vec3| Vec3::new(v.x / i.x, v.y / i.y, v.z / i.z);
    let momentum = q.rotate(Vec3::new(i.x * om.x, i.y * om.y, i.z * om.z)) + loads.torque * h;
    let omega_mid = q.rotate(inv_i(q.inverse_rotate(momentum)));
    st.orientation = integrate_orientation(st.orientation, omega_mid, h);
    st.omega = inv_i(st.orientation.inverse_rotate(momentum));
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
