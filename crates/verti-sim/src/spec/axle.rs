//! What an axle's two wheels share besides the chassis: a beam (solid axles) or an anti-roll
//! bar.

use serde::{Deserialize, Serialize};

/// An anti-roll bar: a torsion bar whose arms push each wheel of the axle towards its
/// partner's travel, with force `rate`·(s_own − s_other). It leaves heave alone and adds
/// `rate`·t² to the axle's roll stiffness (N m/rad, track t).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AntiRollBarSpec {
    /// Force on each wheel per metre of travel difference between the two wheels \[N/m\].
    pub rate: f64,
}

/// A solid (beam) axle: the left and right wheels are the ends of one rigid beam, and the
/// springs and dampers sit on the beam inboard of the wheels. `suspension.stiffness` and
/// `suspension.damping` are then the rates of each spring and damper (vertical), at these
/// lateral spacings. With wheel compressions s_l, s_r and track t, a spring at ±d/2 compresses
/// by (s_l + s_r)/2 ± (d/t)(s_l − s_r)/2: the axle is as stiff as independent wheels of rate k
/// in heave and (d/t)² times as stiff in roll (cross-axle articulation), the defining property
/// of a beam axle. The beam's mass stays split between its ends (`wheel.unsprung_mass`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolidAxleSpec {
    /// Lateral distance between the two springs \[m\] (0 < d ≤ track).
    pub spring_track: f64,
    /// Lateral distance between the two dampers \[m\] (0 < d ≤ track).
    pub damper_track: f64,
    /// The beam as a body of its own. Absent, its mass is split between its two ends (in
    /// `wheel.unsprung_mass`), which gives it the roll inertia m·t²/4 of two point masses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beam: Option<BeamSpec>,
}

/// The beam of a solid axle: its mass (the part of the two wheels' `unsprung_mass` that is the
/// beam: tube, differential housing) and its roll inertia about its own centre. The two wheel
/// travels then share one mass matrix: heave moves the whole unsprung mass, articulation (the
/// beam rolling) moves the wheels' own masses plus I/(t/2)² of the beam.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamSpec {
    /// Mass of the beam \[kg\], at most the two wheels' unsprung masses together.
    pub mass: f64,
    /// Roll inertia of the beam about its centre \[kg m²\] (> 0).
    pub roll_inertia: f64,
}

impl BeamSpec {
    /// The 2 × 2 mass matrix of the axle's two wheel travels (diagonal, off-diagonal), with
    /// each wheel's unsprung mass `m_u` (half the beam included) on track `t`: kinetic energy
    /// ½·M_b·ż² + ½·I·θ̇² + ½·m_w·(ṡ_l² + ṡ_r²), z = (s_l + s_r)/2, θ = (s_l − s_r)/t,
    /// m_w = m_u − M_b/2. Two point masses at the ends (I = M_b·t²/4) give (m_u, 0).
    pub fn mass_matrix(&self, m_u: f64, t: f64) -> (f64, f64) {
        let (quarter, rot) = (0.25 * self.mass, self.roll_inertia / (t * t));
        (m_u - quarter + rot, quarter - rot)
    }
}

impl SolidAxleSpec {
    /// (self, cross) coefficients of a spring or damper at lateral spacing `d` on an axle of
    /// track `t`: the force on a wheel is rate·(self·s_own + cross·s_other), with
    /// self = (1 + r²)/2 and cross = (1 − r²)/2, r = d/t (the gradient of the two springs'
    /// energy ½k·Σ((s_l + s_r)/2 ± r(s_l − s_r)/2)² with respect to each wheel's travel).
    pub fn coefficients(d: f64, t: f64) -> (f64, f64) {
        let r2 = (d / t).powi(2);
        (0.5 * (1.0 + r2), 0.5 * (1.0 - r2))
    }
}
