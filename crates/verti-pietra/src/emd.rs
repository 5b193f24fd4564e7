//! EMD² between PMFs on ordered bins, its expectation under a Dirichlet (UEMD², eq. 13) and the
//! Dirichlet entropy regulariser, with the special functions they need.
//!
//! These are the f64 reference implementations: the trainer (`train::special`) re-implements them on
//! tensors and checks itself against these, and evaluation reports EMD² with them (spec §A.4).

use crate::bins::{B, Pmf};

/// Cumulative sums of a PMF (the cs operator of eq. 12): the CDF on the bins, which is what makes
/// EMD² aware of the bin order, unlike a per-bin loss such as cross-entropy.
pub fn cumsum(p: &Pmf) -> Pmf {
    let mut c = [0.0; B];
    let mut acc = 0.0;
    for (ci, &pi) in c.iter_mut().zip(p) {
        acc += pi;
        *ci = acc;
    }
    c
}

/// EMD²(p, y) = Σ_i (cs(p)_i − cs(y)_i)² (eq. 12 without its constant factor): the squared
/// Earth mover's distance on ordered bins, so predicting a neighbouring bin costs less than a far
/// one. This is the evaluation metric of PIETRA's Table I.
pub fn emd2(p: &Pmf, y: &Pmf) -> f64 {
    let (cp, cy) = (cumsum(p), cumsum(y));
    cp.iter().zip(&cy).map(|(a, b)| (a - b) * (a - b)).sum()
}

/// UEMD²(Dir(β), y) = E_{p∼Dir(β)}[EMD²(p, y)] in closed form (eq. 13, EVORA Thm. 1), the data
/// and physics terms of PIETRA's UPI loss (eq. 14). By Dirichlet aggregation cs(p)_i is
/// Beta(A_i, β0 − A_i) with A_i = Σ_{j≤i} β_j, so with Y_i = cs(y)_i the value is
/// Σ_i [A_i(A_i+1)/(β0(β0+1)) − 2(A_i/β0)Y_i + Y_i²] = EMD²(β/β0, y) + Σ_i Var(cs(p)_i).
/// `beta` must be positive; a non-positive β0 returns NaN rather than panicking.
pub fn uemd2(beta: &Pmf, y: &Pmf) -> f64 {
    let b0: f64 = beta.iter().sum();
    if b0.is_nan() || b0 <= 0.0 {
        return f64::NAN;
    }
    let (ca, cy) = (cumsum(beta), cumsum(y));
    ca.iter()
        .zip(&cy)
        .map(|(&a, &yi)| a * (a + 1.0) / (b0 * (b0 + 1.0)) - 2.0 * (a / b0) * yi + yi * yi)
        .sum()
}

/// Coefficients of the Stirling series for lnΓ: B_{2k} / (2k(2k−1)), k = 1..5.
const STIRLING: [f64; 5] = [
    1.0 / 12.0,
    -1.0 / 360.0,
    1.0 / 1260.0,
    -1.0 / 1680.0,
    1.0 / 1188.0,
];

/// Coefficients of the asymptotic series of ψ: B_{2k} / (2k), k = 1..5.
const DIGAMMA_ASYM: [f64; 5] = [
    1.0 / 12.0,
    -1.0 / 120.0,
    1.0 / 252.0,
    -1.0 / 240.0,
    1.0 / 132.0,
];

/// Arguments below this are shifted up by the recurrence before the asymptotic series is used;
/// at 10 the first omitted term is below 1e-13.
const SHIFT: f64 = 10.0;

/// lnΓ(x) for x > 0, accurate to ~1e-12 absolute for moderate x. Needed by the Dirichlet entropy
/// and log-density; std has no stable lnΓ. Uses lnΓ(x) = lnΓ(x+n) − ln Π(x+k) to reach x ≥ 10,
/// then Stirling's series. Returns NaN for x ≤ 0 or NaN and +∞ for x = +∞.
pub fn ln_gamma(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return f64::NAN;
    }
    if x.is_infinite() {
        return f64::INFINITY;
    }
    let mut z = x;
    let mut prod = 1.0;
    while z < SHIFT {
        prod *= z;
        z += 1.0;
    }
    let inv = 1.0 / z;
    let inv2 = inv * inv;
    let mut series = 0.0;
    let mut pow = inv;
    for c in STIRLING {
        series += c * pow;
        pow *= inv2;
    }
    let half_ln_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
    (z - 0.5) * z.ln() - z + half_ln_2pi + series - prod.ln()
}

/// Digamma ψ(x) = d lnΓ(x)/dx for x > 0, accurate to ~1e-12. Needed by the Dirichlet entropy
/// regulariser. Uses ψ(x) = ψ(x+1) − 1/x to reach x ≥ 10, then the asymptotic series.
/// Returns NaN for x ≤ 0 or NaN and +∞ for x = +∞.
pub fn digamma(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return f64::NAN;
    }
    if x.is_infinite() {
        return f64::INFINITY;
    }
    let mut z = x;
    let mut shift = 0.0;
    while z < SHIFT {
        shift += 1.0 / z;
        z += 1.0;
    }
    let inv2 = 1.0 / (z * z);
    let mut series = 0.0;
    let mut pow = inv2;
    for c in DIGAMMA_ASYM {
        series += c * pow;
        pow *= inv2;
    }
    z.ln() - 0.5 / z - series - shift
}

/// Differential entropy of Dir(β) on the (K−1)-simplex, K = `beta.len()`:
/// Σ lnΓ(β_b) − lnΓ(β0) + (β0 − K)ψ(β0) − Σ(β_b − 1)ψ(β_b). PIETRA (following NatPN) adds
/// −w·H to the loss to reward smooth, not over-confident, posteriors. Returns NaN for an empty
/// slice or any β_b that is not positive and finite. In f64 it stays accurate well beyond the
/// β0 = 1e4 where NatPN switches to an approximation for f32.
pub fn dirichlet_entropy(beta: &[f64]) -> f64 {
    if beta.is_empty() || beta.iter().any(|&b| !(b > 0.0 && b.is_finite())) {
        return f64::NAN;
    }
    let k = beta.len() as f64;
    let b0: f64 = beta.iter().sum();
    let per_bin: f64 = beta
        .iter()
        .map(|&b| ln_gamma(b) - (b - 1.0) * digamma(b))
        .sum();
    per_bin - ln_gamma(b0) + (b0 - k) * digamma(b0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_core::Rng;

    const EULER: f64 = 0.577_215_664_901_532_9;

    /// Gamma(shape, 1) by Marsaglia–Tsang, with the U^{1/a} boost for shape < 1.
    fn gamma(rng: &mut Rng, shape: f64) -> f64 {
        if shape < 1.0 {
            let u = rng.uniform().max(1e-300);
            return gamma(rng, shape + 1.0) * u.powf(1.0 / shape);
        }
        let d = shape - 1.0 / 3.0;
        let c = 1.0 / (9.0 * d).sqrt();
        loop {
            let x = rng.normal();
            let v = (1.0 + c * x).powi(3);
            if v <= 0.0 {
                continue;
            }
            let u = rng.uniform();
            if u.ln() < 0.5 * x * x + d - d * v + d * v.ln() {
                return d * v;
            }
        }
    }

    fn dirichlet(rng: &mut Rng, beta: &[f64]) -> Vec<f64> {
        let g: Vec<f64> = beta.iter().map(|&b| gamma(rng, b)).collect();
        let s: f64 = g.iter().sum();
        g.iter().map(|x| x / s).collect()
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn emd2_by_hand() {
        let mut p = [0.0; B];
        let mut y = [0.0; B];
        // One-hot two bins apart: cs differs by 1 on bins 0 and 1 → 2.
        p[0] = 1.0;
        y[2] = 1.0;
        assert!(close(emd2(&p, &y), 2.0, 1e-15));
        // p = (0.5, 0.5, 0, …), y = δ_2: cs(p) = (0.5, 1, 1, …), cs(y) = (0, 0, 1, …)
        // → 0.25 + 1 = 1.25.
        p[1] = 0.5;
        p[0] = 0.5;
        assert!(close(emd2(&p, &y), 1.25, 1e-15));
        assert!(close(emd2(&y, &p), 1.25, 1e-15));
        assert_eq!(emd2(&y, &y), 0.0);
        // One-hot at distance d costs d.
        let (mut a, mut b) = ([0.0; B], [0.0; B]);
        a[1] = 1.0;
        b[9] = 1.0;
        assert!(close(emd2(&a, &b), 8.0, 1e-15));
    }

    fn beta_cases() -> Vec<Pmf> {
        let mut v = vec![[1.0; B]];
        v.push(std::array::from_fn(|k| 0.3 + 0.4 * k as f64));
        v.push(std::array::from_fn(|k| if k == 4 { 20.0 } else { 0.5 }));
        v.push(std::array::from_fn(|k| 2.0 + ((k * 7) % 5) as f64));
        v
    }

    fn targets() -> Vec<Pmf> {
        let mut one_hot = [0.0; B];
        one_hot[3] = 1.0;
        let soft: Pmf = std::array::from_fn(|k| (k as f64 + 1.0) / 78.0);
        vec![one_hot, soft]
    }

    #[test]
    fn uemd2_matches_monte_carlo() {
        let mut rng = Rng::new(7);
        let n = 100_000;
        for beta in beta_cases() {
            for y in targets() {
                let (mut sum, mut sq) = (0.0, 0.0);
                for _ in 0..n {
                    let s = dirichlet(&mut rng, &beta);
                    let p: Pmf = std::array::from_fn(|k| s[k]);
                    let e = emd2(&p, &y);
                    sum += e;
                    sq += e * e;
                }
                let mean = sum / n as f64;
                let se = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
                let exact = uemd2(&beta, &y);
                let rel = (mean - exact).abs() / exact;
                assert!(
                    rel < 1e-2 && (mean - exact).abs() < 5.0 * se,
                    "beta {beta:?}: MC {mean} ± {se} vs closed form {exact}"
                );
            }
        }
    }

    #[test]
    fn uemd2_is_emd2_of_mean_plus_variance() {
        for beta in beta_cases() {
            let b0: f64 = beta.iter().sum();
            let mean: Pmf = std::array::from_fn(|k| beta[k] / b0);
            for y in targets() {
                let u = uemd2(&beta, &y);
                let e = emd2(&mean, &y);
                assert!(u >= e, "variance term must be non-negative");
                // Scaling β up shrinks the variance like 1/β0 towards EMD² of the mean.
                let big: Pmf = std::array::from_fn(|k| beta[k] * 1e6);
                let ub = uemd2(&big, &y);
                assert!(ub >= e - 1e-12 && ub - e < 1e-5, "{ub} vs {e}");
                assert!(ub - e < (u - e) * 1e-5);
            }
        }
    }

    #[test]
    fn uemd2_rejects_empty_evidence() {
        assert!(uemd2(&[0.0; B], &[1.0 / B as f64; B]).is_nan());
    }

    #[test]
    fn ln_gamma_known_values() {
        let pi = std::f64::consts::PI;
        assert!(close(ln_gamma(0.5), 0.5 * pi.ln(), 1e-12));
        assert!(close(ln_gamma(1.0), 0.0, 1e-12));
        assert!(close(ln_gamma(2.0), 0.0, 1e-12));
        assert!(close(ln_gamma(10.0), 362_880f64.ln(), 1e-12));
        assert!(close(ln_gamma(100.0), 359.134_205_369_575_4, 1e-10));
        // Γ(1.5) = √π / 2.
        assert!(close(ln_gamma(1.5), (pi.sqrt() / 2.0).ln(), 1e-12));
        // lnΓ(x) ≈ −ln x for tiny x.
        assert!(close(ln_gamma(1e-8), -(1e-8f64).ln() - EULER * 1e-8, 1e-12));
        let mut x = 0.05;
        while x < 30.0 {
            assert!(
                close(ln_gamma(x + 1.0), ln_gamma(x) + x.ln(), 1e-11),
                "x = {x}"
            );
            x += 0.37;
        }
        assert!(ln_gamma(0.0).is_nan() && ln_gamma(-1.0).is_nan() && ln_gamma(f64::NAN).is_nan());
    }

    #[test]
    fn digamma_known_values() {
        assert!(close(digamma(1.0), -EULER, 1e-12));
        assert!(close(digamma(0.5), -EULER - 2.0 * 2f64.ln(), 1e-12));
        assert!(close(digamma(10.0), 2.251_752_589_066_721, 1e-12));
        let mut x = 0.05;
        while x < 30.0 {
            assert!(
                close(digamma(x + 1.0), digamma(x) + 1.0 / x, 1e-11),
                "x = {x}"
            );
            // ψ is the derivative of lnΓ (central difference, h = 1e-5).
            let h = 1e-5;
            let fd = (ln_gamma(x + h) - ln_gamma(x - h)) / (2.0 * h);
            assert!(close(digamma(x), fd, 1e-6), "x = {x}");
            x += 0.37;
        }
        assert!(digamma(-2.0).is_nan());
    }

    #[test]
    fn dirichlet_entropy_of_uniform_densities() {
        // Dir(1, 1) is uniform on [0, 1] (density 1): entropy 0.
        assert!(close(dirichlet_entropy(&[1.0, 1.0]), 0.0, 1e-12));
        // Dir(1, …, 1) has density (K−1)! on the simplex: entropy −ln((K−1)!).
        for k in 2..=12usize {
            let fact: f64 = (1..k).map(|i| i as f64).product();
            let h = dirichlet_entropy(&vec![1.0; k]);
            assert!(close(h, -fact.ln(), 1e-10), "K = {k}: {h}");
        }
        // Dir(2, 2) is Beta(2, 2), density 6p(1−p); the Beta entropy ln B(a,b) − (a−1)ψ(a)
        // − (b−1)ψ(b) + (a+b−2)ψ(a+b) with ψ(2) = 1 − γ, ψ(4) = 11/6 − γ gives 5/3 − ln 6.
        assert!(close(
            dirichlet_entropy(&[2.0, 2.0]),
            5.0 / 3.0 - 6f64.ln(),
            1e-12
        ));
    }

    #[test]
    fn dirichlet_entropy_matches_monte_carlo() {
        let mut rng = Rng::new(11);
        let beta = [2.0, 3.5, 1.5, 5.0, 1.2, 2.7];
        let b0: f64 = beta.iter().sum();
        let norm = ln_gamma(b0) - beta.iter().map(|&b| ln_gamma(b)).sum::<f64>();
        let n = 100_000;
        let (mut sum, mut sq) = (0.0, 0.0);
        for _ in 0..n {
            let p = dirichlet(&mut rng, &beta);
            let log_density = norm
                + beta
                    .iter()
                    .zip(&p)
                    .map(|(&b, &x)| (b - 1.0) * x.ln())
                    .sum::<f64>();
            sum -= log_density;
            sq += log_density * log_density;
        }
        let mean = sum / n as f64;
        let se = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
        let exact = dirichlet_entropy(&beta);
        assert!(
            (mean - exact).abs() < 5.0 * se && (mean - exact).abs() < 0.02,
            "MC {mean} ± {se} vs closed form {exact}"
        );
    }

    #[test]
    fn dirichlet_entropy_large_concentration() {
        // NatPN's large-β0 approximation: ½(K−1)(1 + ln 2π) + ½Σ ln β_b − (K − ½) ln β0,
        // whose error is O(1/β_b).
        let beta: Vec<f64> = (0..B).map(|k| 1e5 * (1.0 + k as f64)).collect();
        let k = B as f64;
        let b0: f64 = beta.iter().sum();
        let approx = 0.5 * (k - 1.0) * (1.0 + (2.0 * std::f64::consts::PI).ln())
            + 0.5 * beta.iter().map(|b| b.ln()).sum::<f64>()
            - (k - 0.5) * b0.ln();
        let h = dirichlet_entropy(&beta);
        assert!(close(h, approx, 1e-4), "{h} vs {approx}");
        assert!(dirichlet_entropy(&[]).is_nan());
        assert!(dirichlet_entropy(&[1.0, 0.0]).is_nan());
        assert!(dirichlet_entropy(&[1.0, f64::NAN]).is_nan());
    }
}
