//! The suspension degree of freedom of each wheel: its force law (spring, damper, bump and
//! rebound stops) and its implicit velocity update.

use crate::contact::WheelContact;
use crate::integrate::Accelerations;
use crate::model::WheelModel;
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
/// `wheels` holds every wheel's state at the start of the step: a wheel on a solid axle also
/// feels its partner's travel (explicitly; the derivatives returned are the wheel's own).
#[inline]
pub(crate) fn spring_force(m: &WheelModel, ws: &WheelState, wheels: &[WheelState]) -> SpringForce {
    let mut f_susp = m.spring * ws.compression + m.damper * ws.compression_rate;
    if let Some(sc) = &m.solid {
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
    let r = load.arm;
    let a_attach_vec = acc.linear + acc.angular.cross(r) + omega_w.cross(omega_w.cross(r));
    let a_attach = a_attach_vec.dot(up);
    let v_attach_new = chassis_velocity + omega_w.cross(r) + a_attach_vec * h;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
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
}
