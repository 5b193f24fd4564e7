//! The suspension degree of freedom of each wheel: its force law (spring, damper, bump and
//! rebound stops) and its implicit velocity update.

use crate::contact::WheelContact;
use crate::integrate::{Accelerations, Loads};
use crate::model::{AxleCoupling, Model, WheelModel};
use crate::spec::MAX_WHEELS;
use crate::state::WheelState;
use verti_core::Vec3;

/// The suspension force of one wheel (pushes the chassis up and the wheel down) \[N\], and its
/// derivatives with respect to compression and compression rate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpringForce {
    pub force: f64,
    pub stiffness: f64,
    pub damping: f64,
}

/// Spring and damper, plus the stop (a stiff spring-damper) past the bump or rebound travel.
/// `wheels` holds every wheel's state at the start of the step: a wheel on a solid axle or
/// with an anti-roll bar also feels its partner's travel (explicitly; the derivatives returned
/// are the wheel's own).
#[inline]
pub(crate) fn spring_force(m: &WheelModel, ws: &WheelState, wheels: &[WheelState]) -> SpringForce {
    let mut f_susp = m.spring * ws.compression + m.damper * ws.compression_rate;
    if let Some(sc) = &m.coupling {
        let other = &wheels[sc.partner];
        f_susp += sc.spring_cross * other.compression + sc.damper_cross * other.compression_rate;
    }
    let mut k_extra = m.spring;
    let mut c_extra = m.damper;
    if ws.compression > m.bump {
        f_susp += m.stop * (ws.compression - m.bump) + m.stop_damping * ws.compression_rate;
        k_extra += m.stop;
        c_extra += m.stop_damping;
    } else if ws.compression < -m.rebound {
        f_susp += m.stop * (ws.compression + m.rebound) + m.stop_damping * ws.compression_rate;
        k_extra += m.stop;
        c_extra += m.stop_damping;
    }
    SpringForce {
        force: f_susp,
        stiffness: k_extra,
        damping: c_extra,
    }
}

/// The links' share of the lateral ground forces, on axles whose roll centre is off the
/// ground. `lateral[w]` is the ground's force on wheel `w` along the chassis' lateral axis.
///
/// A wheel that slides straight up and down passes the whole lateral force at the contact
/// patch to the chassis, and the springs resist all of its roll moment: its roll centre is on
/// the ground. A linkage swings an independent wheel about an instant centre, so its contact
/// patch moves outward by 2h/t per unit of travel (h the roll-centre height, where the line
/// from the patch through the instant centre crosses the centre line; t the track): by virtual
/// work the wheel's lateral force F then pushes on its travel with F·2h/t, and the chassis
/// takes the opposite at the wheel. Equal forces on the two wheels of an axle make a pair that
/// carries the moment F_y·h of the axle's force F_y past the springs; unequal ones also jack the
/// chassis up (the outer wheel's larger force), as swing axles do. A beam axle's locating link
/// (Panhard rod, triangle) passes the whole axle's lateral force at its height h instead: a
/// vertical pair F_y·h/t up on the left wheel and down on the right, no jacking. Either way the
/// roll centre is fixed (it does not migrate with travel).
#[inline]
pub(crate) fn roll_centre_links(
    model: &Model,
    lateral: &[f64; MAX_WHEELS],
    up: Vec3,
    axis_loads: &mut [AxisLoad; MAX_WHEELS],
    loads: &mut Loads,
) {
    for (w, m) in model.wheels.iter().enumerate() {
        if m.jacking != 0.0 {
            let jack = m.jacking * lateral[w];
            axis_loads[w].external += jack;
            loads.wheel_axis_force += jack;
            loads.torque += axis_loads[w].arm.cross(up * -jack);
        } else if m.link_share != 0.0 {
            let right = w + 1;
            let f = (lateral[w] + lateral[right]) * m.link_share;
            axis_loads[w].external += f;
            axis_loads[right].external -= f;
            loads.torque += (axis_loads[right].arm - axis_loads[w].arm).cross(up * f);
        }
    }
}

/// What the implicit update needs of one wheel, gathered by the force stages.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AxisLoad {
    /// Hub position relative to the centre of mass.
    pub arm: Vec3,
    /// External force on the wheel along the suspension axis (gravity, ground, tyre) \[N\].
    pub external: f64,
    /// Suspension force \[N\].
    pub spring: f64,
    /// Stiffness and damping against the compression: suspension plus contact.
    pub stiffness: f64,
    pub damping: f64,
    /// How the contact's axis force depends on the chassis' motion (see [`WheelContact`]).
    pub k_vec: Vec3,
    pub c_vec: Vec3,
}

impl AxisLoad {
    #[inline]
    pub fn new(arm: Vec3, external: f64, spring: &SpringForce, contact: &WheelContact) -> Self {
        AxisLoad {
            arm,
            external,
            spring: spring.force,
            stiffness: spring.stiffness + contact.k_axis,
            damping: spring.damping + contact.c_axis,
            k_vec: contact.k_vec,
            c_vec: contact.c_vec,
        }
    }
}

/// How a wheel's attachment at `arm` (from the centre of mass) moves this step: its
/// acceleration with the chassis', and its velocity after the step.
#[inline(always)]
fn attachment(
    arm: Vec3,
    acc: &Accelerations,
    chassis_velocity: Vec3,
    omega_w: Vec3,
    h: f64,
) -> (Vec3, Vec3) {
    let a = acc.linear + acc.angular.cross(arm) + omega_w.cross(omega_w.cross(arm));
    (a, chassis_velocity + omega_w.cross(arm) + a * h)
}

/// Staggered implicit update of one wheel's compression. The chassis has just been advanced
/// explicitly (`acc`); the wheel's absolute velocity along the suspension axis is then solved
/// implicitly against its spring, damper and contact stiffness, with the contact acting on the
/// wheel's *absolute* motion (chassis velocity after this step plus compression rate).
/// Linearising the contact in the compression rate alone gains energy in the heave mode.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn update_wheel(
    ws: &mut WheelState,
    m: &WheelModel,
    load: &AxisLoad,
    acc: &Accelerations,
    chassis_velocity: Vec3,
    omega_w: Vec3,
    up: Vec3,
    h: f64,
) {
    let (a_attach_vec, v_attach_new) = attachment(load.arm, acc, chassis_velocity, omega_w, h);
    let a_attach = a_attach_vec.dot(up);
    let f0 = load.external
        - load.spring
        - m.unsprung_mass * a_attach
        - h * load.k_vec.dot(v_attach_new)
        - h * load.c_vec.dot(a_attach_vec);
    let mc = m.unsprung_mass + h * load.damping;
    let rate = (mc * ws.compression_rate + h * f0) / (mc + h * h * load.stiffness);
    ws.compression_rate = rate;
    ws.compression += h * rate;
}

/// The implicit update of the two wheels of a beam axle with its own roll inertia: as
/// [`update_wheel`], but the two travels share the beam's mass matrix M, and the beam's cross
/// stiffness and damping are implicit too: (M + h·C + h²·K)·v' = (M + h·C)·v + h·f₀, a 2 × 2
/// solve, with f₀ the forces at the start of the step less M times the attachments'
/// accelerations.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn update_axle_pair(
    pair: [&mut WheelState; 2],
    coupling: &AxleCoupling,
    loads: [&AxisLoad; 2],
    (diagonal, cross): (f64, f64),
    acc: &Accelerations,
    chassis_velocity: Vec3,
    omega_w: Vec3,
    up: Vec3,
    h: f64,
) {
    let mut a_attach = [0.0; 2];
    let mut f0 = [0.0; 2];
    for i in 0..2 {
        let (a_vec, v_attach_new) = attachment(loads[i].arm, acc, chassis_velocity, omega_w, h);
        a_attach[i] = a_vec.dot(up);
        f0[i] = loads[i].external
            - loads[i].spring
            - h * loads[i].k_vec.dot(v_attach_new)
            - h * loads[i].c_vec.dot(a_vec);
    }
    // the inertia of the attachments' motion, through the full mass matrix
    f0[0] -= diagonal * a_attach[0] + cross * a_attach[1];
    f0[1] -= cross * a_attach[0] + diagonal * a_attach[1];
    let (k_x, c_x) = (coupling.spring_cross, coupling.damper_cross);
    // (M + h·C) and the system matrix A = M + h·C + h²·K
    let mc = [
        [diagonal + h * loads[0].damping, cross + h * c_x],
        [cross + h * c_x, diagonal + h * loads[1].damping],
    ];
    let a = [
        [
            mc[0][0] + h * h * loads[0].stiffness,
            mc[0][1] + h * h * k_x,
        ],
        [
            mc[1][0] + h * h * k_x,
            mc[1][1] + h * h * loads[1].stiffness,
        ],
    ];
    let v = [pair[0].compression_rate, pair[1].compression_rate];
    let b = [
        mc[0][0] * v[0] + mc[0][1] * v[1] + h * f0[0],
        mc[1][0] * v[0] + mc[1][1] * v[1] + h * f0[1],
    ];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let rates = [
        (b[0] * a[1][1] - a[0][1] * b[1]) / det,
        (a[0][0] * b[1] - a[1][0] * b[0]) / det,
    ];
    for (ws, rate) in pair.into_iter().zip(rates) {
        ws.compression_rate = rate;
        ws.compression += h * rate;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::SolidAxleSpec;

    // A beam axle of track t with springs of rate k at ±d/2 and dampers of rate c at ±e/2
    // (derived on paper from the two springs' energy ½k·Σ((s_l + s_r)/2 ± (d/t)(s_l − s_r)/2)²):
    // in heave (s, s) each wheel carries k·s, as on independent springs; in articulation
    // (s, −s) each carries ±k·(d/t)²·s; the dampers likewise with (e/t)². Independent wheels
    // (no `solid_axle`) are untouched: their force is k·s whatever the other wheel does.
    #[test]
    fn solid_axle_heave_and_articulation_rates() {
        let mut spec = crate::vehicles::builtin("hmmwv-handling").unwrap();
        let t = spec.axles[0].track;
        let (d, e) = (0.6 * t, 0.8 * t);
        spec.axles[0].solid_axle = Some(SolidAxleSpec {
            spring_track: d,
            damper_track: e,
            beam: None,
        });
        let model = Model::compile(&spec, 1.0);
        let (k, c) = (
            spec.axles[0].suspension.stiffness,
            spec.axles[0].suspension.damping,
        );
        let (s, v) = (0.01, 0.2);
        let force = |wheels: &[WheelState], w: usize| {
            spring_force(&model.wheels[w], &wheels[w], wheels).force
        };
        let mut wheels = vec![WheelState::default(); model.wheels.len()];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
        // heave
        for ws in wheels.iter_mut().take(4) {
            ws.compression = s;
            ws.compression_rate = v;
        }
        for w in 0..2 {
            assert!(close(force(&wheels, w), k * s + c * v), "heave wheel {w}");
        }
        // articulation: left up, right down (rear axle independent)
        for (w, sign) in [(0, 1.0), (1, -1.0), (2, 1.0), (3, -1.0)] {
            wheels[w].compression = sign * s;
            wheels[w].compression_rate = sign * v;
        }
        let (r2, q2) = ((d / t).powi(2), (e / t).powi(2));
        assert!(close(force(&wheels, 0), k * r2 * s + c * q2 * v));
        assert!(close(force(&wheels, 1), -(k * r2 * s + c * q2 * v)));
        let (kr, cr) = (
            spec.axles[1].suspension.stiffness,
            spec.axles[1].suspension.damping,
        );
        assert!(close(force(&wheels, 2), kr * s + cr * v));
        assert!(close(force(&wheels, 3), -(kr * s + cr * v)));
        // the implicit update's own stiffness is the self term (1 + r²)/2·k
        let own = spring_force(&model.wheels[0], &wheels[0], &wheels).stiffness;
        assert!(close(own, 0.5 * (1.0 + r2) * k));
        // the forces are the gradient of the springs' energy (checked at an arbitrary pose)
        wheels[0].compression = 0.013;
        wheels[1].compression = -0.004;
        for ws in wheels.iter_mut().take(2) {
            ws.compression_rate = 0.0;
        }
        let energy = |sl: f64, sr: f64| {
            let (h, a) = (0.5 * (sl + sr), 0.5 * (d / t) * (sl - sr));
            0.5 * k * ((h + a).powi(2) + (h - a).powi(2))
        };
        let eps = 1e-7;
        let (sl, sr) = (wheels[0].compression, wheels[1].compression);
        let dl = (energy(sl + eps, sr) - energy(sl - eps, sr)) / (2.0 * eps);
        let dr = (energy(sl, sr + eps) - energy(sl, sr - eps)) / (2.0 * eps);
        assert!((force(&wheels, 0) - dl).abs() < 1e-4 * dl.abs());
        assert!((force(&wheels, 1) - dr).abs() < 1e-4 * dr.abs());
    }

    // A beam with its own roll inertia, free of the chassis (no gravity, no ground, no
    // damping): its two modes oscillate at the closed-form periods. Heave moves the whole
    // unsprung mass m_u against k; articulation moves m_u − M_b/2 + 2I/t² against k·(d/t)²
    // (T = 2π√(m/k)). The implicit step shortens nothing measurable at h = 0.1 ms.
    #[test]
    fn beam_modes_oscillate_at_their_closed_form_periods() {
        use crate::integrate::Accelerations;
        use crate::spec::BeamSpec;
        let mut spec = crate::vehicles::builtin("uaz").unwrap();
        let (t, m_u) = (spec.axles[0].track, spec.axles[0].wheel.unsprung_mass);
        let beam = BeamSpec {
            mass: 124.0,
            roll_inertia: 22.2,
        };
        spec.axles[0].suspension.damping = 0.0;
        let sa = spec.axles[0].solid_axle.as_mut().unwrap();
        sa.beam = Some(beam);
        let d = sa.spring_track;
        let model = Model::compile(&spec, 1.0);
        let k = spec.axles[0].suspension.stiffness;
        let h = 1e-4;
        let still = Accelerations {
            linear: Vec3::ZERO,
            angular: Vec3::ZERO,
        };
        let period = |sign: f64| {
            let mut wheels = vec![WheelState::default(); model.wheels.len()];
            wheels[0].compression = 0.01;
            wheels[1].compression = sign * 0.01;
            let (mut crossings, mut first, mut last) = (0, 0.0, 0.0);
            let mut prev = wheels[0].compression;
            for step in 1..200_000 {
                let mut loads = [AxisLoad::default(); 2];
                for (w, load) in loads.iter_mut().enumerate() {
                    let f = spring_force(&model.wheels[w], &wheels[w], &wheels);
                    *load = AxisLoad {
                        arm: model.wheels[w].attach,
                        external: 0.0,
                        spring: f.force,
                        stiffness: f.stiffness,
                        damping: f.damping,
                        k_vec: Vec3::ZERO,
                        c_vec: Vec3::ZERO,
                    };
                }
                let coupling = model.wheels[0].coupling.unwrap();
                let masses = coupling.beam.unwrap();
                let (left, right) = wheels.split_at_mut(1);
                let pair = [&mut left[0], &mut right[0]];
                let zero = Vec3::ZERO;
                update_axle_pair(
                    pair,
                    &coupling,
                    [&loads[0], &loads[1]],
                    masses,
                    &still,
                    zero,
                    zero,
                    Vec3::Z,
                    h,
                );
                let s = wheels[0].compression;
                // upward zero crossings
                if prev < 0.0 && s >= 0.0 {
                    let at = (step as f64 - s / (s - prev)) * h;
                    if crossings == 0 {
                        first = at;
                    }
                    last = at;
                    crossings += 1;
                    if crossings == 6 {
                        break;
                    }
                }
                prev = s;
            }
            (last - first) / (crossings - 1) as f64
        };
        let tau = std::f64::consts::TAU;
        let heave = tau * (m_u / k).sqrt();
        let m_art = m_u - 0.5 * beam.mass + 2.0 * beam.roll_inertia / (t * t);
        let articulation = tau * (m_art / (k * (d / t).powi(2))).sqrt();
        let (th, ta) = (period(1.0), period(-1.0));
        assert!((th - heave).abs() < 1e-3 * heave, "heave {th} vs {heave}");
        assert!(
            (ta - articulation).abs() < 1e-3 * articulation,
            "articulation {ta} vs {articulation}"
        );
        // and the beam as two point masses (I = M_b t²/4) is the uncoupled model exactly
        let points = BeamSpec {
            mass: 124.0,
            roll_inertia: 0.25 * 124.0 * t * t,
        };
        let (diagonal, cross) = points.mass_matrix(m_u, t);
        assert!((diagonal - m_u).abs() < 1e-12 && cross.abs() < 1e-12);
    }
}
