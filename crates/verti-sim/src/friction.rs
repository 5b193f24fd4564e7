//! Friction: every friction coefficient and every tangential force of the engine is computed
//! here, so the one question "how hard can this surface push sideways" has one answer.
//!
//! * [`surface_mu`]: the Coulomb coefficient of terrain acting as rigid ground (a rigid patch's
//!   μ, or soil's tan φ where the soil grid does not act), and [`OBSTACLE_FRICTION`].
//! * Tyres: [`tyre_mu_scale`] combines ground and tyre μ; [`tyre_forces`] turns a wheel's
//!   transient slip into its lateral force and a longitudinal force linearised in the new spin
//!   ([`LongTyre`], solved with the spin in `drivetrain`); [`relax_slip`] advances the slip
//!   state; [`static_slip`] inverts the curve for a vehicle parked on a slope. The curve
//!   shapes themselves are in [`crate::tyre`].
//! * Rigid tyres on rigid ground: [`coulomb_tyre`] sets up Coulomb friction with a stick–slip
//!   anchor ([`CoulombTyre`]); its sticking or sliding is decided with the spin in
//!   `drivetrain::solve_spins_coulomb`. On soil a rigid tyre uses the soil shear above.
//! * Soil: [`soil_tan_phi`] and [`soil_shear_strength`] (Mohr–Coulomb) per node.
//! * Chassis: [`body_friction`], regularised Coulomb at each body contact point.

use crate::contact::{RigidContact, WheelContact, WheelKinematics};
use crate::math::soft_sign;
use crate::model::WheelModel;
use crate::spec::TyreSpec;
use crate::state::WheelState;
use crate::tyre::{janosi_fraction, janosi_sliding_slip, tmeasy_combined, tmeasy_sliding_slip};
use verti_core::Vec3;
use verti_world::{SoilParams, Surface};

/// Friction of obstacles (Chrono's default contact material, as Verti-Bench's obstacle boxes).
pub(crate) const OBSTACLE_FRICTION: f64 = 0.6;

/// Coulomb coefficient of a terrain surface where it acts as rigid ground: a rigid patch's
/// friction, or tan φ of soil the deformable model does not cover (ground off the map, a soil
/// grid that cannot resolve the wheel, and the chassis, which meets the undeformed surface).
/// `Surface::effective_friction` with libm's tangent, like every transcendental function in
/// the dynamics, so trajectories have the same bits on every platform.
#[inline]
pub(crate) fn surface_mu(surface: &Surface) -> f64 {
    match *surface {
        Surface::Rigid { friction, .. } => friction,
        Surface::Deformable { soil } => soil_tan_phi(&soil),
    }
}

/// tan φ of a soil's internal friction angle.
#[inline]
pub(crate) fn soil_tan_phi(soil: &SoilParams) -> f64 {
    libm::tan(soil.friction_angle_deg.to_radians())
}

/// Mohr–Coulomb shear strength τ = c + σ·tan φ of a soil node under pressure `sigma` ≥ 0 \[Pa\].
#[inline]
pub(crate) fn soil_shear_strength(soil: &SoilParams, sigma: f64, tan_phi: f64) -> f64 {
    soil.cohesion + sigma * tan_phi
}

/// The factor that scales the tyre's friction curve on ground of friction `ground_mu`:
/// `min(tyre μ, ground μ) / tyre μ`, as Chrono combines materials.
#[inline]
pub(crate) fn tyre_mu_scale(ground_mu: f64, tyre: &TyreSpec) -> f64 {
    ground_mu.min(tyre.friction) / tyre.friction
}

/// Regularised Coulomb friction at a chassis contact point: opposes the sliding velocity `vt`
/// with μ·N, fading linearly to zero below `friction_speed` (so a resting body does not
/// chatter).
#[inline]
pub(crate) fn body_friction(vt: Vec3, mu: f64, normal_force: f64, friction_speed: f64) -> Vec3 {
    let vtn = vt.norm();
    if vtn > 0.0 {
        vt * (-mu * normal_force / vtn.max(friction_speed))
    } else {
        Vec3::ZERO
    }
}

/// Longitudinal tyre force of one wheel, linearised in the new spin rate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LongTyre {
    pub active: bool,
    pub e_long: Vec3,
    /// Secant slip stiffness \[N per unit slip\].
    pub stiffness: f64,
    /// κ_new = a + b·ω_new.
    pub a: f64,
    pub b: f64,
    /// 1 + h·v_ref/σ: the implicit relaxation factor of this step.
    pub decay: f64,
    /// Low-speed bristle damping \[N s/m\].
    pub damping: f64,
    pub vx: f64,
    pub radius: f64,
    /// Friction left for the longitudinal force after the lateral one \[N\].
    pub limit: f64,
}

impl LongTyre {
    /// d(torque on the spin)/d(ω_new) \[N m s\]: the tyre's stiffness against the spin.
    #[inline]
    pub fn spin_stiffness(&self) -> f64 {
        self.radius * (self.stiffness * self.b + self.damping * self.radius)
    }
    /// The part of the torque on the spin that does not depend on ω_new, with its sign
    /// flipped (the spin solve subtracts it).
    #[inline]
    pub fn spin_torque_offset(&self) -> f64 {
        self.radius * (self.stiffness * self.a - self.damping * self.vx)
    }
    /// The longitudinal force \[N\] at the solved spin rate.
    #[inline]
    pub fn force_at(&self, spin: f64) -> f64 {
        (self.stiffness * (self.a + self.b * spin) - self.damping * (self.vx - spin * self.radius))
            .clamp(-self.limit, self.limit)
    }
}

/// A wheel's tangential ground forces, from its transient slip.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TyreForces {
    /// Lateral force \[N\] along the contact's lateral axis, and the same as a world vector.
    pub lat: f64,
    pub lat_force: Vec3,
    /// The lateral force's overturning moment, which reaches the chassis through the bearing.
    pub contact_moment: Vec3,
    /// Rolling resistance about the axle \[N m\].
    pub roll_torque: f64,
    /// The longitudinal force, solved together with the spin.
    pub long: LongTyre,
    /// Inputs of the slip relaxation: lateral slip speed \[m/s\], the slip clamp (negative:
    /// rigid ground, clamp by direction) and the normal load \[N\].
    pub vy: f64,
    pub slip_clamp: f64,
    pub normal_load: f64,
}

/// Tyre (rigid ground) or traction (soil) forces of one wheel from its transient slip. The
/// lateral force is final; the longitudinal one is returned linearised in the new spin.
/// (Always inlined: called from the handling and the rigid tyres' stages, it would otherwise
/// become a call with its large result copied, a few per cent of a step.)
#[inline(always)]
pub(crate) fn tyre_forces(
    tyre: &TyreSpec,
    vehicle_scale: f64,
    m: &WheelModel,
    ws: &WheelState,
    contact: &WheelContact,
    kin: &WheelKinematics,
    h: f64,
) -> TyreForces {
    let fz_total = contact.rigid_load + contact.soil_load;
    let mut out = TyreForces {
        normal_load: fz_total,
        ..Default::default()
    };
    if fz_total <= 0.0 {
        return out;
    }
    let axle = kin.axle;
    let n = contact.force.normalized();
    let e_long = axle.cross(n).normalized();
    let e_lat = n.cross(e_long);
    let radius = (m.radius - contact.depth).max(0.5 * m.radius);
    // Slip is measured where the force acts: at the contact, a loaded radius below the hub,
    // moving with the chassis' rotation too. Measuring it at the hub while applying the
    // lateral force's moment at the contact feeds roll motion back into the tyre force and
    // rocks a vehicle parked on a side slope.
    let v_contact = kin.hub_velocity + kin.chassis_omega.cross(n * (-radius));
    let vx = v_contact.dot(e_long);
    let vy = v_contact.dot(e_lat);
    let (kx, ky) = (ws.slip_long, ws.slip_lat);
    let (mut fx, mut fy, initial_slope, limit);
    let on_soil = contact.soil_load > contact.rigid_load;
    if on_soil {
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
        out.slip_clamp = janosi_sliding_slip(contact.soil_length, contact.soil_janosi_k);
    } else {
        let (cx, cy) = tmeasy_combined(kx, ky, tyre, contact.mu_scale);
        fx = cx * fz_total;
        fy = cy * fz_total;
        initial_slope = tyre.dfx0 * fz_total;
        limit = tyre.fxm.max(tyre.fym) * contact.mu_scale * fz_total;
        out.slip_clamp = -1.0; // rigid: direction-dependent clamp computed in `relax_slip`
    }
    // At standstill the tyre is an elastic bristle of fixed stiffness (TMeasy's Dahl model):
    // the force follows the deflection, not the momentary load, up to the friction limit.
    // Making it proportional to the load there closes a fast loop (roll → load → lateral
    // force → roll) that rocks a vehicle parked on a steep side slope. Above 1 m/s (scaled)
    // the slip curve alone acts; in between blend.
    let vref = vx.abs().max((kin.spin * radius).abs());
    let fade = (1.0 - vref / vehicle_scale.sqrt()).max(0.0);
    if fade > 0.0 {
        let (cx, cy) = if on_soil {
            (
                initial_slope / fz_total.max(1e-9),
                initial_slope / fz_total.max(1e-9),
            )
        } else {
            (tyre.dfx0, tyre.dfy0)
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
    out.lat = fy;
    out.lat_force = e_lat * fy;
    // The ground force acts at the contact, a loaded radius below the hub. The lateral
    // force's overturning moment reaches the chassis through the bearing; the longitudinal
    // force's moment about the axle drives the spin.
    let m_contact = (n * (-radius)).cross(out.lat_force);
    out.contact_moment = m_contact - axle * m_contact.dot(axle);
    let vroll = kin.spin * radius;
    out.roll_torque =
        -tyre.rolling_resistance * contact.rigid_load * radius * soft_sign(vroll / 0.1);
    // Longitudinal force linearised in the new spin: F = C·κ_new − c·(vx − ω_new·R) with the
    // secant stiffness C = F(κ)/κ (the initial slope near κ = 0) and κ_new = a + b·ω_new from
    // the implicit relaxation update.
    let secant = if kx.abs() > 1e-6 {
        (fx / kx).max(0.0)
    } else {
        initial_slope
    };
    let decay = 1.0 + h * vref / tyre.relaxation_length;
    out.long = LongTyre {
        active: true,
        e_long,
        stiffness: secant,
        a: (kx - h * vx / tyre.relaxation_length) / decay,
        b: h * radius / (tyre.relaxation_length * decay),
        decay,
        damping: fade * m.slip_damping_long,
        vx,
        radius,
        limit: (limit * limit - fy * fy).max(0.0).sqrt(),
    };
    out.vy = vy;
    out
}

/// Transient slip after the spin update (implicit relaxation). Longitudinally the slip takes
/// exactly the value the spin solve used (κ = a + b·ω); laterally it relaxes with the same
/// decay. Either is clamped where the curve reaches its sliding plateau, so the state never
/// winds up; a tyre in the air relaxes its deflection at once.
#[inline(always)]
pub(crate) fn relax_slip(ws: &mut WheelState, tyre_forces: &TyreForces, tyre: &TyreSpec, h: f64) {
    let lt = &tyre_forces.long;
    if tyre_forces.normal_load <= 0.0 || !lt.active {
        ws.slip_long = 0.0;
        ws.slip_lat = 0.0;
        return;
    }
    let sigma = tyre.relaxation_length;
    let spin = ws.spin_rate;
    let mut kx = lt.a + lt.b * spin;
    let mut ky = (ws.slip_lat - h * tyre_forces.vy / sigma) / lt.decay;
    let limit = if tyre_forces.slip_clamp < 0.0 {
        tmeasy_sliding_slip(kx, ky, tyre)
    } else {
        tyre_forces.slip_clamp
    };
    let kn = (kx * kx + ky * ky).sqrt();
    if kn > limit {
        kx *= limit / kn;
        ky *= limit / kn;
    }
    ws.slip_long = kx;
    ws.slip_lat = ky;
}

/// The transient slip (kx, ky) at which a tyre on rigid ground develops the force coefficients
/// (fx, fy) = F / Fz: the tyre deflection of a vehicle at rest on a slope. Bisection along the
/// needed force's direction, within the rising part of the curve.
pub(crate) fn static_slip(fx: f64, fy: f64, tyre: &TyreSpec) -> (f64, f64) {
    let need = fx.hypot(fy);
    if need > 1e-9 {
        let dir = (fx / tyre.dfx0, fy / tyre.dfy0);
        let dn = dir.0.hypot(dir.1);
        let (mut lo, mut hi) = (0.0, tyre.sxm.min(tyre.sym) / dn.max(1e-12) * 0.999);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            let (cx, cy) = tmeasy_combined(mid * dir.0, mid * dir.1, tyre, 1.0);
            if cx.hypot(cy) < need {
                lo = mid
            } else {
                hi = mid
            }
        }
        (lo * dir.0, lo * dir.1)
    } else {
        (0.0, 0.0) // no pull (or a NaN one): no deflection
    }
}

/// Coulomb friction of a rigid tyre on rigid ground (Chrono's rigid tyre under NSC contact:
/// the contact sticks while the force it needs is within μ·N and slides at μ·N otherwise).
///
/// Penalty form: a spring-damper of the contact's own stiffness k and damping c ties the tread
/// to an anchor on the ground. Per internal step the anchor deflection u grows by the tread's
/// velocity relative to the ground (u' = u + h·(ω·r − v_x) along the wheel, u' = u − h·v_y
/// across), the ground pushes with k·u' + c·u̇, and where that exceeds μ·N the anchor slips so
/// the force is μ·N in the same direction. So a braked vehicle on a slope holds with a fixed
/// deflection (k·u = its share of m·g·sin θ, about a millimetre) and never creeps, and a
/// sliding one feels exactly μ·N. The spring stands in for NSC's exact stick; its period is
/// the normal contact's (`vehicles/hmmwv.yaml` derives it from the step).
///
/// The deflection is updated with the velocity before the force is applied (symplectic Euler,
/// position first), and along the wheel it is implicit in the new spin rate ω, which the spin
/// solve finds together with the stick/slide decision: while sticking the force along the
/// wheel is `fx0 + dfx·ω`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CoulombTyre {
    /// Contact axes: along the wheel (forward for a wheel rolling forward) and across it.
    pub e_long: Vec3,
    pub e_lat: Vec3,
    /// Contact point relative to the hub \[m\].
    pub arm: Vec3,
    /// Lever of the longitudinal force about the axle \[m\].
    pub radius: f64,
    /// Sticking forces: along the wheel `fx0 + dfx·ω` \[N\], across it `fy` \[N\].
    pub fx0: f64,
    pub dfx: f64,
    pub fy: f64,
    /// Sticking anchor deflections: along `ux0 + dux·ω`, across `uy` \[m\].
    pub ux0: f64,
    pub dux: f64,
    pub uy: f64,
    pub stiffness: f64,
    /// μ·N \[N\].
    pub limit: f64,
}

impl CoulombTyre {
    /// The sticking forces (along, across) at spin rate `spin`.
    #[inline]
    pub fn trial(&self, spin: f64) -> (f64, f64) {
        (self.fx0 + self.dfx * spin, self.fy)
    }

    /// Final forces (along, across) and anchor deflections at spin rate `spin`; `sliding`:
    /// the longitudinal force the spin solve used for a sliding contact.
    #[inline]
    pub fn resolve(&self, spin: f64, sliding: Option<f64>) -> (f64, f64, f64, f64) {
        let (fx, fy) = self.trial(spin);
        let f = (fx * fx + fy * fy).sqrt();
        match sliding {
            None if f <= self.limit => (fx, fy, self.ux0 + self.dux * spin, self.uy),
            _ => {
                // sliding: the solve's longitudinal force, the rest of μ·N across, and the
                // anchor slipped to where its spring alone carries that force
                let fx = sliding.unwrap_or(self.limit * fx / f);
                let rest = (self.limit * self.limit - fx * fx).max(0.0).sqrt();
                let fy = if f > 0.0 {
                    (self.limit * fy / f).clamp(-rest, rest)
                } else {
                    0.0
                };
                (fx, fy, fx / self.stiffness, fy / self.stiffness)
            }
        }
    }
}

/// Sets up the Coulomb friction of a rigid tyre whose rigid contact carries more load than the
/// soil under it. Returns the rolling-resistance torque on the spin and the contact's
/// friction state (the tangential forces come after the spin solve, see [`CoulombTyre`]).
#[inline]
pub(crate) fn coulomb_tyre(
    tyre: &TyreSpec,
    ws: &WheelState,
    contact: &WheelContact,
    rigid: &RigidContact,
    kin: &WheelKinematics,
    h: f64,
) -> (f64, CoulombTyre) {
    let axle = kin.axle;
    let n = contact.force.normalized();
    let t = axle.cross(n);
    // a push along the axle alone (the wheel's side against a rock): the wheel's forward axis
    let e_long = if t.norm_sq() > 1e-12 {
        t.normalized()
    } else {
        axle.cross(kin.up).normalized()
    };
    let e_lat = n.cross(e_long);
    let arm = rigid.arm;
    // the tread at `arm` moves at spin·(axle × arm); its part along e_long is −spin·radius
    let radius = -axle.cross(arm).dot(e_long);
    let v = kin.hub_velocity + kin.chassis_omega.cross(arm);
    let (vx, vy) = (v.dot(e_long), v.dot(e_lat));
    let (k, c) = (tyre.radial_stiffness, tyre.radial_damping);
    // anchors after the step: u' = u + h·(ω·r − v_x) along, u − h·v_y across
    let (ux0, dux, uy) = (ws.anchor_long - h * vx, h * radius, ws.anchor_lat - h * vy);
    let ct = CoulombTyre {
        e_long,
        e_lat,
        arm,
        radius,
        fx0: k * ux0 - c * vx,
        dfx: radius * (k * h + c),
        fy: k * uy - c * vy,
        ux0,
        dux,
        uy,
        stiffness: k,
        limit: rigid.friction_limit,
    };
    let roll = if tyre.rolling_resistance > 0.0 {
        -tyre.rolling_resistance * contact.rigid_load * radius * soft_sign(kin.spin * radius / 0.1)
    } else {
        0.0
    };
    (roll, ct)
}
