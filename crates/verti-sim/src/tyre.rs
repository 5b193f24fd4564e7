//! Tangential wheel forces: a TMeasy-style combined-slip curve on rigid ground and the
//! Janosi–Hanamoto / Mohr–Coulomb traction curve on soil, both driven by *transient* slip.
//!
//! Why transient slip: the steady-state slip `(ωR − v)/|v|` is singular at standstill, which
//! makes explicit integration blow up or creep at low speed. Each wheel instead carries a slip
//! state κ that relaxes to the steady-state slip over the relaxation length σ:
//! `σ·dκ/dt = −v_slip − v_ref·κ`. At speed it is the steady-state slip with a short lag; at rest
//! it is the tyre's elastic deflection divided by σ, so a braked vehicle on a slope holds
//! exactly (a spring, not a creeping damper). The update is implicit in the decay term, so it
//! is stable for any step.

use crate::spec::TyreSpec;

/// Peak/sliding curve parameters for one direction, already scaled by friction.
#[derive(Clone, Copy, Debug)]
pub struct Curve {
    pub df0: f64,
    pub fm: f64,
    pub sm: f64,
    pub fs: f64,
    pub ss: f64,
}

/// TMeasy's normalised force curve F(s)/Fz for slip `s >= 0`.
#[inline]
pub fn tmeasy_curve(s: f64, c: &Curve) -> f64 {
    if s <= c.sm {
        // rational rise with initial slope df0 reaching fm at sm
        let sigma = s / c.sm;
        let a = c.df0 * c.sm / c.fm;
        c.df0 * c.sm * sigma / (1.0 + sigma * (sigma + a - 2.0))
    } else if s < c.ss {
        // smooth (cubic Hermite, zero end slopes) transition from the peak to sliding
        let t = (s - c.sm) / (c.ss - c.sm);
        c.fm - (c.fm - c.fs) * t * t * (3.0 - 2.0 * t)
    } else {
        c.fs
    }
}

/// Combined-slip force coefficients (Fx/Fz, Fy/Fz) for normalised slips, TMeasy's
/// direction-weighted blend of the longitudinal and lateral curves. `mu_scale` scales the
/// peak and sliding values (ground friction / tyre friction).
#[inline]
pub fn tmeasy_combined(kx: f64, ky: f64, t: &TyreSpec, mu_scale: f64) -> (f64, f64) {
    // TMeasy normalisation so both directions reach their peak at combined slip 1.
    let fxm = t.fxm * mu_scale;
    let fym = t.fym * mu_scale;
    let sx_hat = t.sxm / (t.sxm + t.sym) + (fxm / t.dfx0) / (fxm / t.dfx0 + fym / t.dfy0);
    let sy_hat = t.sym / (t.sxm + t.sym) + (fym / t.dfy0) / (fxm / t.dfx0 + fym / t.dfy0);
    let sxn = kx / sx_hat;
    let syn = ky / sy_hat;
    let sc = (sxn * sxn + syn * syn).sqrt();
    if sc < 1e-12 {
        return (0.0, 0.0);
    }
    let (cx, cy) = (sxn / sc, syn / sc);
    let curve = Curve {
        df0: ((t.dfx0 * sx_hat * cx).powi(2) + (t.dfy0 * sy_hat * cy).powi(2)).sqrt(),
        fm: ((fxm * cx).powi(2) + (fym * cy).powi(2)).sqrt(),
        sm: ((t.sxm / sx_hat * cx).powi(2) + (t.sym / sy_hat * cy).powi(2)).sqrt(),
        fs: ((t.fxs * mu_scale * cx).powi(2) + (t.fys * mu_scale * cy).powi(2)).sqrt(),
        ss: ((t.sxs / sx_hat * cx).powi(2) + (t.sys / sy_hat * cy).powi(2)).sqrt(),
    };
    let f = tmeasy_curve(sc, &curve);
    (f * cx, f * cy)
}

/// Combined normalised slip at which the rigid-ground curve reaches its sliding plateau in the
/// direction of (kx, ky): the transient slip is clamped there, so the state never winds up.
#[inline]
pub fn tmeasy_sliding_slip(kx: f64, ky: f64, t: &TyreSpec) -> f64 {
    let n = (kx * kx + ky * ky).sqrt();
    if n < 1e-12 {
        return t.sxs;
    }
    let (cx, cy) = (kx / n, ky / n);
    // ellipse through the two sliding slips
    1.0 / ((cx / t.sxs).powi(2) + (cy / t.sys).powi(2)).sqrt()
}

/// Wong's integral of Janosi–Hanamoto shear over a contact of length `l` at slip `s`:
/// the fraction of the Mohr–Coulomb limit the wheel develops, `1 − K/(s·l)·(1 − e^(−s·l/K))`.
#[inline]
pub fn janosi_fraction(s: f64, contact_length: f64, janosi_k: f64) -> f64 {
    let x = s * contact_length / janosi_k;
    if x < 1e-6 {
        0.5 * x
    } else {
        1.0 - (1.0 - libm::exp(-x)) / x
    }
}

/// Slip at which the soil curve is within 1 % of its plateau (the transient-slip clamp).
#[inline]
pub fn janosi_sliding_slip(contact_length: f64, janosi_k: f64) -> f64 {
    100.0 * janosi_k / contact_length.max(1e-6)
}
