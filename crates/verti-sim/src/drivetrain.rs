//! Drivetrain stages: steering, engine and gearbox, and the spin of each spin group under
//! drive, tyre and brake torques.
//!
//! The engine (torque map) and automatic transmission are Chrono's `ChEngineSimpleMap` and
//! `ChAutomaticTransmissionSimpleMap`: no torque converter, so the engine speed is tied to the
//! driven wheels' mean speed through the gear and final-drive ratios.

use crate::friction::{CoulombTyre, LongTyre};
use crate::math::{RPM_TO_RAD_S, soft_sign};
use crate::model::{Coupling, LINKAGE_SAMPLES, Model, WheelModel};
use crate::spec::{MAX_LINKAGES, MAX_WHEELS, PowertrainSpec, SteeringKind, VehicleSpec};
use crate::state::{Controls, SimState};

// ---- steering ----

/// How the steered wheels point in an internal step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WheelSteer {
    /// Ackermann: the turn radius of the rear-axle centre (infinite when straight, for skid
    /// steering and for a linkage).
    pub turn_radius: f64,
    /// Linkage: (sin δ, cos δ) of the left and right steered wheels' angles, per steered
    /// axle (the first `linkages`).
    pub linkage: Option<[[(f64, f64); 2]; MAX_LINKAGES]>,
}

/// Moves the steering toward the driver's input at the steering's slew rate: the bicycle-model
/// angle, for Ackermann steering the road wheels' centre angle, for skid steering the
/// equivalent bicycle's (see [`skid_speed_ratio`]), and for a linkage its input times the
/// linkage's bicycle angle at full input. Returns how the steered wheels point.
#[inline]
pub(crate) fn steer(
    spec: &VehicleSpec,
    model: &Model,
    st: &mut SimState,
    ctl: &Controls,
    h: f64,
) -> WheelSteer {
    let target = ctl.steering * spec.steering.max_angle_deg.to_radians();
    let max_delta = spec.steering.rate_deg_per_s.to_radians() * h;
    st.steer += (target - st.steer).clamp(-max_delta, max_delta);
    wheel_steer(spec, model, st.steer)
}

/// How the steered wheels point for the bicycle angle `steer`.
#[inline]
pub(crate) fn wheel_steer(spec: &VehicleSpec, model: &Model, steer: f64) -> WheelSteer {
    let linkage = (!model.linkage_tables.is_empty()).then(|| {
        // the linkages' input; each table is interpolated linearly and the (sin, cos) pairs
        // normalised again
        let input = (steer / spec.steering.max_angle_deg.to_radians()).clamp(-1.0, 1.0);
        let at = (input + 1.0) * 0.5 * LINKAGE_SAMPLES as f64;
        let k = (at as usize).min(LINKAGE_SAMPLES - 1);
        let t = at - k as f64;
        let mut out = [[(0.0, 1.0); 2]; MAX_LINKAGES];
        for (sides, table) in out.iter_mut().zip(&model.linkage_tables) {
            let (a, b) = (&table[k], &table[k + 1]);
            let side = |j: usize| {
                let sin = a[j].0 + t * (b[j].0 - a[j].0);
                let cos = a[j].1 + t * (b[j].1 - a[j].1);
                let norm = (sin * sin + cos * cos).sqrt();
                (sin / norm, cos / norm)
            };
            *sides = [side(0), side(1)];
        }
        out
    });
    WheelSteer {
        turn_radius: turn_radius(spec, model, steer),
        linkage,
    }
}

/// Skid steering's speed ratio ρ = inner / outer track speed for the equivalent bicycle angle
/// `steer`. Every system plans with a bicycle (wheelbase L = [`VehicleSpec::wheelbase`], steer
/// angle up to `max_angle_deg`); the steer unit realises that bicycle's path curvature
/// κ = tan(steer) / L kinematically: the vehicle centre moves at v = (v_o + v_i) / 2 and turns
/// at (v_o − v_i) / B for track speeds v_o, v_i and track gauge B, so κ = 2 (1 − ρ) / (B (1 + ρ))
/// and ρ = (1 − κ B/2) / (1 + κ B/2) (ρ < 0 counter-rotates the inner track when κ B/2 > 1).
#[inline]
pub fn skid_speed_ratio(spec: &VehicleSpec, steer: f64) -> f64 {
    speed_ratio_for(spec, libm::tan(steer.abs()) / spec.wheelbase())
}

/// Gain of the steer unit's yaw-rate feedback on the path curvature's error (see
/// [`steered_curvature`]).
const YAW_FEEDBACK_GAIN: f64 = 3.0;
/// Forward speed \[m/s at full scale\] from which the feedback acts fully; it fades in
/// linearly from a third of it (at a standstill the measured curvature r/v means nothing).
const YAW_FEEDBACK_SPEED: f64 = 1.0;

/// The path curvature the steer unit of a skid-steered vehicle realises this step: the
/// equivalent bicycle's κ = tan(steer) / L, corrected in proportion to how far the measured
/// curvature (yaw rate over forward speed) falls short of it. A skid-steered vehicle slides
/// sideways at both ends of its tracks as it turns and turns 30–40 % wider than its tracks'
/// speed ratio says (`tests/tracked.rs`); steered by wire with a yaw-rate sensor, as a
/// hydrostatic steer unit can be, it follows the path the input names, which is what every
/// system, planning with a bicycle, asks of it.
#[inline]
fn steered_curvature(spec: &VehicleSpec, st: &SimState) -> f64 {
    let kappa = libm::tan(st.steer) / spec.wheelbase();
    let v = st.velocity_body().x;
    let v_full = YAW_FEEDBACK_SPEED * spec.scale.sqrt();
    let weight = ((v.abs() - v_full / 3.0) / (v_full * 2.0 / 3.0)).clamp(0.0, 1.0);
    if weight == 0.0 {
        return kappa;
    }
    let measured = st.omega.z / v;
    kappa + weight * YAW_FEEDBACK_GAIN * (kappa - measured)
}

/// [`skid_speed_ratio`] for a path curvature's magnitude `kappa`.
#[inline]
fn speed_ratio_for(spec: &VehicleSpec, kappa: f64) -> f64 {
    let kb = kappa * 0.5 * spec.axles.first().map_or(0.0, |a| a.track);
    (1.0 - kb) / (1.0 + kb)
}

/// Turn radius of the rear-axle centre for a bicycle steer angle (infinite when straight or
/// skid-steered).
#[inline]
pub(crate) fn turn_radius(spec: &VehicleSpec, model: &Model, steer: f64) -> f64 {
    if spec.steering.kind == SteeringKind::Ackermann && steer.abs() > 1e-9 {
        model.wheelbase / libm::tan(steer)
    } else {
        f64::INFINITY
    }
}

/// (sin δ, cos δ) of a wheel's steer angle δ. Ackermann: the wheel points at the turn centre
/// on the rear-axle line, so tan δ = dx / (R − y); sine and cosine follow without
/// trigonometric calls. Linkage: the linkage's angle for the wheel's side.
#[inline]
pub(crate) fn steer_sin_cos(m: &WheelModel, steer: &WheelSteer) -> (f64, f64) {
    if let Some(axles) = &steer.linkage {
        return if m.steered {
            axles[m.linkage][usize::from(m.y < 0.0)]
        } else {
            (0.0, 1.0)
        };
    }
    let turn_radius = steer.turn_radius;
    if m.steered && turn_radius.is_finite() {
        let d = turn_radius - m.y;
        let hyp = (m.ackermann_dx * m.ackermann_dx + d * d).sqrt();
        (m.ackermann_dx * d.signum() / hyp, d.abs() / hyp)
    } else {
        (0.0, 1.0)
    }
}

/// A wheel's steer angle \[rad\] (an output only).
#[inline]
pub(crate) fn steer_angle(m: &WheelModel, steer: &WheelSteer) -> f64 {
    if steer.linkage.is_some() {
        let (sin, cos) = steer_sin_cos(m, steer);
        return libm::atan2(sin, cos);
    }
    let turn_radius = steer.turn_radius;
    if m.steered && turn_radius.is_finite() {
        libm::atan(m.ackermann_dx / (turn_radius - m.y))
    } else {
        0.0
    }
}

// ---- engine and gearbox ----

/// Shifts gear, then returns the total drive torque at the wheels \[N m\] (records the engine
/// speed and torque in `st`).
#[inline]
pub(crate) fn engine(spec: &VehicleSpec, model: &Model, st: &mut SimState, throttle: f64) -> f64 {
    let p = &spec.powertrain;
    let mut mean_spin = 0.0;
    for m in &model.wheels {
        if m.driven {
            mean_spin += st.group_spin[m.group];
        }
    }
    mean_spin /= model.driven_wheels as f64;
    let engine_speed_of = |gear: usize| mean_spin.abs() / (p.final_drive * p.gears[gear]);
    st.gear = shift(p, st.gear, engine_speed_of(st.gear));
    let ratio = p.final_drive * p.gears[st.gear];
    let we = engine_speed_of(st.gear);
    // Closed-throttle drag opposes the rotation (smoothly through zero) so coasting never
    // gains energy; the full-throttle part always drives forward.
    let drag_sign = soft_sign(mean_spin / ratio / 5.0);
    let t_full = engine_torque(p, we, 1.0);
    let t_zero = engine_torque(p, we, 0.0);
    let te = t_full * throttle + t_zero * (1.0 - throttle) * drag_sign;
    st.engine_speed = we;
    st.engine_torque = te;
    te / ratio
}

/// Piecewise-linear interpolation in a map of (x, y) points with increasing x; clamps at the
/// ends.
#[inline]
pub(crate) fn interpolate(map: &[[f64; 2]], x: f64) -> f64 {
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

/// Engine torque \[N m\] at engine speed `omega` \[rad/s\] and throttle in \[0, 1\]:
/// `T = T0(ω)·(1 − throttle) + TF(ω)·throttle`, speed clamped to \[0, max\].
#[inline]
pub(crate) fn engine_torque(p: &PowertrainSpec, omega: f64, throttle: f64) -> f64 {
    let w = omega.clamp(0.0, p.max_speed_rpm * RPM_TO_RAD_S);
    interpolate(&p.zero_throttle, w) * (1.0 - throttle)
        + interpolate(&p.full_throttle, w) * throttle
}

/// The gear after applying the shift rules once at engine speed `omega` \[rad/s\].
#[inline]
pub(crate) fn shift(p: &PowertrainSpec, gear: usize, omega: f64) -> usize {
    let rpm = omega / RPM_TO_RAD_S;
    if rpm > p.upshift_rpm && gear + 1 < p.gears.len() {
        gear + 1
    } else if rpm < p.downshift_rpm && gear > 0 {
        gear - 1
    } else {
        gear
    }
}

// ---- spin groups ----

/// Torques on each spin group from its tyres, gathered wheel by wheel: explicit torques and
/// the linearised longitudinal tyre forces' dependence on the new spin.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpinLoads {
    /// Torque not depending on the new spin \[N m\].
    pub torque: [f64; MAX_WHEELS],
    /// d(torque)/d(new spin) with its sign flipped \[N m s\].
    pub stiffness: [f64; MAX_WHEELS],
}

impl SpinLoads {
    pub const ZERO: SpinLoads = SpinLoads {
        torque: [0.0; MAX_WHEELS],
        stiffness: [0.0; MAX_WHEELS],
    };

    /// One wheel's share: `explicit` (rolling resistance, the soil pressure moment about the
    /// axle) and its longitudinal tyre force.
    #[inline]
    pub fn add_wheel(&mut self, group: usize, explicit: f64, long: &LongTyre) {
        self.torque[group] += explicit;
        if long.active {
            self.stiffness[group] += long.spin_stiffness();
            self.torque[group] -= long.spin_torque_offset();
        }
    }
}

/// Solves each spin group's new spin rate under drive, tyre and brake torques (writes
/// `st.group_spin`) and returns the reaction torque each group's wheels put on the chassis
/// \[N m per wheel\].
///
/// Implicit spin: (I/h + K)·ω_new = I·ω/h + T, with K the tyres' linearised longitudinal
/// stiffness against the spin, then Coulomb brakes solved exactly. Explicitly, a heavily
/// loaded tyre (impacts) overshoots the no-slip speed within one step and pumps energy into
/// the vehicle. Skid-steered vehicles then hold their two sides at the steer unit's speed
/// ratio ([`hold_speed_ratio`]).
#[inline]
pub(crate) fn solve_spins(
    spec: &VehicleSpec,
    model: &Model,
    st: &mut SimState,
    ctl: &Controls,
    wheel_torque: f64,
    loads: &SpinLoads,
    h: f64,
) -> [f64; MAX_WHEELS] {
    let brake_in = ctl.brake;
    let mut group_reaction = [0.0; MAX_WHEELS];
    // what the steer unit needs of each side: the implicit equation's right-hand side (after
    // the brakes) and its factor, and whether the brakes hold the side still
    let mut rhs = [0.0; MAX_WHEELS];
    let mut factor = [0.0; MAX_WHEELS];
    let mut held = [false; MAX_WHEELS];
    for (g, grp) in model.groups.iter().enumerate() {
        let mut brake_max = 0.0;
        for &w in &grp.wheels {
            brake_max += model.wheels[w].brake_torque * brake_in;
        }
        let drive = wheel_torque * grp.drive_share;
        let w0 = st.group_spin[g];
        let x = grp.inertia * w0 / h + drive + loads.torque[g];
        let denom = grp.inertia / h + loads.stiffness[g];
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
        rhs[g] = x + brake_applied;
        factor[g] = denom;
        held[g] = x.abs() <= brake_max;
    }
    if !model.couplings.is_empty() {
        let added = hold_couplings(&model.couplings, &mut rhs, &factor, &held);
        for (g, grp) in model.groups.iter().enumerate() {
            if !held[g] {
                st.group_spin[g] = rhs[g] / factor[g];
            }
            group_reaction[g] -= added[g] / grp.wheels.len() as f64;
        }
    }
    if spec.steering.kind == SteeringKind::Skid {
        hold_speed_ratio(spec, model, st, &rhs, &factor, &held, &mut group_reaction);
    }
    group_reaction
}

/// Gauss–Seidel sweeps over the differential clutches: with the three clutches of a four-wheel
/// driveline, strong enough to hold, the unit test's spins are within 1e-6 of the locked
/// driveline's after these.
const CLUTCH_SWEEPS: usize = 12;

/// The differential clutches ([`Coupling`]) on the groups' implicit equations `factor·ω = rhs`
/// (after the brakes): each clutch's torque Λ, going in equal parts into the wheels of its side
/// `a` and out of those of side `b`, is the one that makes the two sides' mean spins equal,
/// limited to ±capacity (beyond it the clutch slips at its capacity, as Chrono's
/// `ChShaftsClutch` does). Several clutches share groups (a central one and the axles'), so
/// they are solved together by projected Gauss–Seidel, each sweep taking the others' torques
/// as they stand. Writes the torques into `rhs` and returns the torque added to each group. A
/// group the brakes hold still takes no part.
fn hold_couplings(
    couplings: &[Coupling],
    rhs: &mut [f64; MAX_WHEELS],
    factor: &[f64; MAX_WHEELS],
    held: &[bool; MAX_WHEELS],
) -> [f64; MAX_WHEELS] {
    let mut added = [0.0; MAX_WHEELS];
    // one torque per clutch: at most one per axle and a central one, fewer than MAX_WHEELS
    let mut lambda = [0.0; MAX_WHEELS];
    for _ in 0..CLUTCH_SWEEPS {
        for (k, c) in couplings.iter().enumerate() {
            if c.a.iter().chain(&c.b).any(|&g| held[g]) {
                continue;
            }
            // mean spin of a side as it stands, and its change per unit of Λ (one wheel per
            // group, Λ/n to each of a side's n wheels)
            let mean = |side: &[usize]| {
                side.iter().map(|&g| rhs[g] / factor[g]).sum::<f64>() / side.len() as f64
            };
            let gain = |side: &[usize]| {
                let n = side.len() as f64;
                side.iter().map(|&g| 1.0 / factor[g]).sum::<f64>() / (n * n)
            };
            let step = (mean(&c.b) - mean(&c.a)) / (gain(&c.a) + gain(&c.b));
            let total = (lambda[k] + step).clamp(-c.capacity, c.capacity);
            let delta = total - lambda[k];
            lambda[k] = total;
            for (side, sign) in [(&c.a, 1.0), (&c.b, -1.0)] {
                let share = sign * delta / side.len() as f64;
                for &g in side {
                    rhs[g] += share;
                    added[g] += share;
                }
            }
        }
    }
    added
}

/// The steer unit of a skid-steered vehicle: it holds the inner side's spin at ρ times the
/// outer side's ([`skid_speed_ratio`]; ρ = 1 going straight, so the tracks cannot drift
/// apart), like a hydrostatic or geared steer unit rather than a brake that only slows one
/// side. The constraint ω_in − ρ ω_out = 0 acts with torque λ on the inner side and −ρ λ on
/// the outer (no work while it holds: power passes from the inner side to the outer). With
/// each side's implicit equation f·ω = r, λ = (ρ r_out / f_out − r_in / f_in) / (1 / f_in +
/// ρ² / f_out), limited to the steering brake's capacity `skid_brake_torque` per wheel of the
/// inner side, beyond which the unit slips and the vehicle turns wider. While the brakes hold
/// a side still the unit does nothing.
#[inline]
fn hold_speed_ratio(
    spec: &VehicleSpec,
    model: &Model,
    st: &mut SimState,
    rhs: &[f64; MAX_WHEELS],
    factor: &[f64; MAX_WHEELS],
    held: &[bool; MAX_WHEELS],
    group_reaction: &mut [f64; MAX_WHEELS],
) {
    let (Some(left), Some(right)) = (
        model.groups.iter().position(|g| g.side > 0.0),
        model.groups.iter().position(|g| g.side < 0.0),
    ) else {
        return;
    };
    if held[left] || held[right] {
        return;
    }
    let kappa = steered_curvature(spec, st);
    // positive curvature turns left: the left side is the inner one
    let (inner, outer) = if kappa >= 0.0 {
        (left, right)
    } else {
        (right, left)
    };
    let rho = speed_ratio_for(spec, kappa.abs());
    let (f_in, f_out) = (factor[inner], factor[outer]);
    let n_in = model.groups[inner].wheels.len() as f64;
    let capacity = spec.steering.skid_brake_torque * n_in;
    let lambda = ((rho * rhs[outer] / f_out - rhs[inner] / f_in)
        / (1.0 / f_in + rho * rho / f_out))
        .clamp(-capacity, capacity);
    st.group_spin[inner] = (rhs[inner] + lambda) / f_in;
    st.group_spin[outer] = (rhs[outer] - rho * lambda) / f_out;
    group_reaction[inner] -= lambda / n_in;
    group_reaction[outer] += rho * lambda / model.groups[outer].wheels.len() as f64;
}

/// Most passes of the stick/slide decision in [`solve_spins_coulomb`].
const COULOMB_PASSES: usize = 6;

/// The tangential result of one rigid tyre on rigid ground after the spin solve: forces along
/// and across the wheel \[N\], the new anchor deflections \[m\] and whether it slid.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CoulombResult {
    pub fx: f64,
    pub fy: f64,
    pub anchor_long: f64,
    pub anchor_lat: f64,
    pub sliding: bool,
}

/// [`solve_spins`] for a vehicle with rigid tyres: `base` holds every wheel's explicit spin
/// torque and the linearised forces of the wheels without a Coulomb contact (soil, air);
/// `coulomb[w]` is wheel `w`'s Coulomb contact on rigid ground, if it has one. Writes each
/// Coulomb wheel's tangential result to `out` and returns the reaction torques.
///
/// A Coulomb contact's force is linear in the new spin while it sticks and constant (μ·N in
/// the direction of the sticking force) while it slides, so each spin group's torque balance
/// is piecewise linear and monotone in its new spin. It is solved by trying a set of sliding
/// contacts, solving the linear system exactly (brakes included), and letting each contact
/// whose sticking force at that spin exceeds μ·N slide, until the set no longer changes (a
/// semismooth Newton iteration). Solving with every contact sticking and clamping afterwards
/// would let the wheel's spin ignore the clamp: a wheel driven harder than the ground can
/// take would never spin up. The first guess is the last step's set (`st.wheels[w].sliding`):
/// the answer does not depend on it, the number of passes does (mostly one).
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_spins_coulomb(
    spec: &VehicleSpec,
    model: &Model,
    st: &mut SimState,
    ctl: &Controls,
    wheel_torque: f64,
    base: &SpinLoads,
    coulomb: &[Option<CoulombTyre>; MAX_WHEELS],
    out: &mut [CoulombResult; MAX_WHEELS],
    h: f64,
) -> [f64; MAX_WHEELS] {
    let groups = model.groups.len();
    let mut spin0 = [0.0; MAX_WHEELS];
    spin0[..groups].copy_from_slice(&st.group_spin[..groups]);
    // each Coulomb wheel's longitudinal force while it slides (NaN: it sticks)
    let mut slide = [f64::NAN; MAX_WHEELS];
    for (w, m) in model.wheels.iter().enumerate() {
        if let Some(ct) = &coulomb[w]
            && st.wheels[w].sliding
        {
            let (fx, fy) = ct.trial(spin0[m.group]);
            let f = (fx * fx + fy * fy).sqrt();
            if f > 0.0 {
                slide[w] = ct.limit * fx / f;
            }
        }
    }
    let mut reaction = [0.0; MAX_WHEELS];
    // the sliding forces the last solve used: the forces must be the ones the spins saw
    let mut used = slide;
    for _ in 0..COULOMB_PASSES {
        let mut loads = *base;
        for (w, m) in model.wheels.iter().enumerate() {
            let Some(ct) = &coulomb[w] else { continue };
            if slide[w].is_nan() {
                // sticking: torque −r·(fx0 + dfx·ω) on the spin
                loads.stiffness[m.group] += ct.radius * ct.dfx;
                loads.torque[m.group] -= ct.radius * ct.fx0;
            } else {
                loads.torque[m.group] -= ct.radius * slide[w];
            }
        }
        st.group_spin[..groups].copy_from_slice(&spin0[..groups]);
        reaction = solve_spins(spec, model, st, ctl, wheel_torque, &loads, h);
        let mut changed = false;
        for (w, m) in model.wheels.iter().enumerate() {
            let Some(ct) = &coulomb[w] else { continue };
            let (fx, fy) = ct.trial(st.group_spin[m.group]);
            let f = (fx * fx + fy * fy).sqrt();
            let now = if f > ct.limit {
                ct.limit * fx / f
            } else {
                f64::NAN
            };
            changed |= match (slide[w].is_nan(), now.is_nan()) {
                (true, true) => false,
                (false, false) => (slide[w] - now).abs() > 1e-3 * ct.limit,
                _ => true,
            };
            used[w] = slide[w];
            slide[w] = now;
        }
        if !changed {
            break;
        }
    }
    for (w, m) in model.wheels.iter().enumerate() {
        if let Some(ct) = &coulomb[w] {
            let sliding = (!used[w].is_nan()).then_some(used[w]);
            let (fx, fy, ux, uy) = ct.resolve(st.group_spin[m.group], sliding);
            out[w] = CoulombResult {
                fx,
                fy,
                anchor_long: ux,
                anchor_lat: uy,
                sliding: sliding.is_some(),
            };
        }
    }
    reaction
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

    fn arrays(values: &[f64]) -> [f64; MAX_WHEELS] {
        let mut a = [0.0; MAX_WHEELS];
        a[..values.len()].copy_from_slice(values);
        a
    }

    /// One axle clutch between two wheels of spin inertia I over a step h (factor I/h):
    /// one wheel driven by 600 N m more than the other (a lifted wheel's missing ground
    /// torque). Below capacity the clutch makes the spins equal, passing half the difference;
    /// above it passes exactly its capacity and the wheels part.
    #[test]
    fn an_axle_clutch_holds_the_wheels_together_up_to_its_torque() {
        let f = arrays(&[8.3 / 0.005, 8.3 / 0.005]);
        let held = [false; MAX_WHEELS];
        let pair = |capacity| Coupling {
            a: vec![0],
            b: vec![1],
            capacity,
        };
        let (r0, r1) = (8.3 * 10.0 / 0.005 + 900.0, 8.3 * 10.0 / 0.005 + 300.0);
        // holds: 300 N m from wheel 0 to wheel 1
        let mut rhs = arrays(&[r0, r1]);
        let added = hold_couplings(&[pair(1000.0)], &mut rhs, &f, &held);
        assert!((rhs[0] / f[0] - rhs[1] / f[1]).abs() < 1e-12);
        assert!((added[0] + 300.0).abs() < 1e-9 && (added[1] - 300.0).abs() < 1e-9);
        // slips: 100 N m passes, the difference stays 400 N m
        let mut rhs = arrays(&[r0, r1]);
        let added = hold_couplings(&[pair(100.0)], &mut rhs, &f, &held);
        assert_eq!((added[0], added[1]), (-100.0, 100.0));
        assert!((rhs[0] - rhs[1] - 400.0).abs() < 1e-9);
        // a wheel the brakes hold still is left alone
        let mut rhs = arrays(&[r0, r1]);
        let still = arrays_bool(&[true, false]);
        assert_eq!(
            hold_couplings(&[pair(1000.0)], &mut rhs, &f, &still)[1],
            0.0
        );
    }

    fn arrays_bool(values: &[bool]) -> [bool; MAX_WHEELS] {
        let mut a = [false; MAX_WHEELS];
        a[..values.len()].copy_from_slice(values);
        a
    }

    /// Chrono's HMMWV layout: a clutch on each axle and a central one between the axles'
    /// mean spins. With capacities large enough all four spins end equal (a locked driveline);
    /// the central clutch passes torque from one axle to the other in equal parts per wheel.
    #[test]
    fn axle_and_central_clutches_together_lock_the_four_wheels_when_strong_enough() {
        let f = arrays(&[1000.0, 1200.0, 900.0, 1100.0]);
        let mut rhs = arrays(&[5000.0, 2000.0, 7000.0, 1000.0]);
        let held = [false; MAX_WHEELS];
        let clutches = [
            Coupling {
                a: vec![0],
                b: vec![1],
                capacity: 1e5,
            },
            Coupling {
                a: vec![2],
                b: vec![3],
                capacity: 1e5,
            },
            Coupling {
                a: vec![0, 1],
                b: vec![2, 3],
                capacity: 1e5,
            },
        ];
        let total: f64 = rhs[..4].iter().sum();
        let added = hold_couplings(&clutches, &mut rhs, &f, &held);
        let spins: Vec<f64> = (0..4).map(|g| rhs[g] / f[g]).collect();
        // a locked driveline: one spin, the total torque over the total factor
        let locked = total / f[..4].iter().sum::<f64>();
        for s in &spins {
            assert!((s - locked).abs() < 1e-6 * locked, "{spins:?} vs {locked}");
        }
        assert!(
            added[..4].iter().sum::<f64>().abs() < 1e-9,
            "internal torques only"
        );
    }
}
