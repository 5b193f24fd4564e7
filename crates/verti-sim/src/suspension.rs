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
#[inline]
pub(crate) fn spring_force(m: &WheelModel, ws: &WheelState) -> SpringForce {
    let mut f_susp = m.spring * ws.compression + m.damper * ws.compression_rate;
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
