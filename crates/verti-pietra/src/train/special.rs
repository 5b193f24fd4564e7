//! The losses of PIETRA and its baselines as differentiable tensor expressions: EMD² between
//! PMFs on ordered bins, its expectation under a Dirichlet (UEMD², closed form), and the
//! Dirichlet entropy with the log-gamma and digamma functions it needs (burn has neither).
//! `crate::emd` holds the same formulas in f64; the tests hold the two together.

use crate::bins::B;
use burn::tensor::{Device, Tensor, TensorData};

/// Upper-triangular ones [B, B]: `p.matmul(U)` is the cumulative sum of every row of `p`.
pub fn cumsum_matrix(device: &Device) -> Tensor<2> {
    let mut u = vec![0.0f32; B * B];
    for j in 0..B {
        for i in j..B {
            u[j * B + i] = 1.0;
        }
    }
    Tensor::from_data(TensorData::new(u, [B, B]), device)
}

/// EMD²(p, y) = Σ_i (cs(p)_i − cs(y)_i)² per row of `p`, `y` [N, B] → \[N\].
pub fn emd2(p: Tensor<2>, y: Tensor<2>, cs: &Tensor<2>) -> Tensor<1> {
    let [n, _] = p.dims();
    (p - y)
        .matmul(cs.clone())
        .powi_scalar(2)
        .sum_dim(1)
        .reshape([n])
}

/// UEMD²(Dir(β), y) = E_{p ~ Dir(β)} EMD²(p, y) in closed form (spec §A.4): with A = cs(β),
/// β0 = Σβ, Y = cs(y): Σ_i [A_i(A_i + 1)/(β0(β0 + 1)) − 2 (A_i/β0) Y_i + Y_i²]. Written with
/// ratios so that evidence of 10¹³ stays finite in f32.
pub fn uemd2(beta: Tensor<2>, y: Tensor<2>, cs: &Tensor<2>) -> Tensor<1> {
    let [n, _] = beta.dims();
    let a = beta.matmul(cs.clone());
    let b0 = a.clone().narrow(1, B - 1, 1); // [N, 1]
    let yc = y.matmul(cs.clone());
    let mean = a.clone() / b0.clone();
    let second = mean.clone() * ((a + 1.0) / (b0 + 1.0));
    (second - mean * yc.clone() * 2.0 + yc.powi_scalar(2))
        .sum_dim(1)
        .reshape([n])
}

/// ln Γ(x) for x > 0 (elementwise): shifted by six with the recurrence, then Stirling's
/// series, accurate to ~1e-7 relative in f32.
pub fn ln_gamma(x: Tensor<2>) -> Tensor<2> {
    let z = x.clone() + 6.0;
    let mut shift = x.clone().log();
    for k in 1..6 {
        shift = shift + (x.clone() + f64::from(k)).log();
    }
    let zi = z.clone().recip();
    let zi2 = zi.clone().powi_scalar(2);
    let series = zi.clone() * (((zi2.clone() * (1.0 / 1260.0)) - 1.0 / 360.0) * zi2 + 1.0 / 12.0);
    (z.clone() - 0.5) * z.clone().log() - z + 0.5 * (2.0 * std::f64::consts::PI).ln() + series
        - shift
}

/// ψ(x) = d ln Γ(x)/dx for x > 0 (elementwise), by the same shift and the asymptotic series.
pub fn digamma(x: Tensor<2>) -> Tensor<2> {
    let z = x.clone() + 6.0;
    let mut shift = x.clone().recip();
    for k in 1..6 {
        shift = shift + (x.clone() + f64::from(k)).recip();
    }
    let zi = z.clone().recip();
    let zi2 = zi.clone().powi_scalar(2);
    let series = zi2.clone() * ((zi2.clone() * (1.0 / 120.0 - zi2 * (1.0 / 252.0))) - 1.0 / 12.0);
    z.log() - zi * 0.5 + series - shift
}

/// Concentrations beyond which the entropy uses NatPN's large-β0 form: the exact one cancels
/// terms of 10⁵ and more, past what f32 resolves.
pub const ENTROPY_APPROX_BETA0: f64 = 1e4;

/// Entropy of Dir(β) per row of β [N, K] → \[N\]:
/// Σ lnΓ(β_b) − lnΓ(β0) + (β0 − K) ψ(β0) − Σ (β_b − 1) ψ(β_b); for β0 ≥ 10⁴ the asymptotic
/// ½(K−1)(1 + ln 2π) + ½ Σ ln β_b − (K − ½) ln β0.
pub fn dirichlet_entropy(beta: Tensor<2>) -> Tensor<1> {
    let [n, k] = beta.dims();
    let kf = k as f64;
    let beta0 = beta.clone().sum_dim(1); // [N, 1]
    let big = beta0.clone().greater_equal_elem(ENTROPY_APPROX_BETA0);
    // the exact branch sees harmless ones where the approximation is used, so neither its
    // value nor its gradient can overflow there
    let safe = beta
        .clone()
        .mask_where(big.clone().expand([n, k]), beta.ones_like());
    let safe0 = safe.clone().sum_dim(1);
    let exact = ln_gamma(safe.clone()).sum_dim(1) - ln_gamma(safe0.clone())
        + (safe0.clone() - kf) * digamma(safe0)
        - ((safe.clone() - 1.0) * digamma(safe)).sum_dim(1);
    let approx = beta.log().sum_dim(1) * 0.5 - beta0.log() * (kf - 0.5)
        + 0.5 * (kf - 1.0) * (1.0 + (2.0 * std::f64::consts::PI).ln());
    exact.mask_where(big, approx).reshape([n])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emd;

    fn dev() -> Device {
        Device::default()
    }

    fn t2(rows: &[Vec<f64>]) -> Tensor<2> {
        let k = rows[0].len();
        let v: Vec<f32> = rows.iter().flatten().map(|x| *x as f32).collect();
        Tensor::from_data(TensorData::new(v, [rows.len(), k]), &dev())
    }

    fn vals(t: Tensor<1>) -> Vec<f64> {
        verti_nn::train::seq::values(t)
            .into_iter()
            .map(f64::from)
            .collect()
    }

    fn pmf(seed: u64, lo: f64) -> Vec<f64> {
        let mut rng = verti_core::Rng::new(seed);
        let v: Vec<f64> = (0..B).map(|_| lo + rng.uniform()).collect();
        let s: f64 = v.iter().sum();
        v.iter().map(|x| x / s).collect()
    }

    #[test]
    fn special_functions_match_known_values() {
        let x = t2(&[vec![0.5, 1.0, 2.0, 10.0, 1234.5]]);
        let lg = verti_nn::train::seq::values(ln_gamma(x.clone()));
        let dg = verti_nn::train::seq::values(digamma(x));
        let want_lg = [
            0.5 * std::f64::consts::PI.ln(),
            0.0,
            0.0,
            362_880f64.ln(),
            emd::ln_gamma(1234.5),
        ];
        let want_dg = [
            -0.577_215_664_901_532_9 - 2.0 * 2f64.ln(),
            -0.577_215_664_901_532_9,
            1.0 - 0.577_215_664_901_532_9,
            emd::digamma(10.0),
            emd::digamma(1234.5),
        ];
        for i in 0..5 {
            let tol = 2e-6 * want_lg[i].abs().max(1.0);
            assert!((f64::from(lg[i]) - want_lg[i]).abs() < tol, "lnΓ #{i}");
            assert!((f64::from(dg[i]) - want_dg[i]).abs() < 2e-6, "ψ #{i}");
        }
    }

    #[test]
    fn losses_match_the_f64_formulas() {
        let cs = cumsum_matrix(&dev());
        let mut betas = Vec::new();
        let mut ys = Vec::new();
        for s in 0..4u64 {
            let scale = [0.5, 3.0, 40.0, 900.0][s as usize];
            betas.push(
                pmf(s, 0.2)
                    .iter()
                    .map(|p| p * scale * B as f64)
                    .collect::<Vec<_>>(),
            );
            ys.push(pmf(100 + s, 0.0));
        }
        ys[0] = emd_one_hot(3);
        let got = vals(uemd2(t2(&betas), t2(&ys), &cs));
        let got_emd = vals(emd2(t2(&ys), t2(&betas), &cs));
        let got_h = vals(dirichlet_entropy(t2(&betas)));
        for i in 0..4 {
            let b: [f64; B] = betas[i].clone().try_into().unwrap();
            let y: [f64; B] = ys[i].clone().try_into().unwrap();
            let want = emd::uemd2(&b, &y);
            assert!((got[i] - want).abs() < 1e-4 * want.max(1.0), "UEMD² #{i}");
            let e = emd::emd2(&y, &b);
            assert!((got_emd[i] - e).abs() < 1e-3 * e.max(1.0), "EMD² #{i}");
            let h = emd::dirichlet_entropy(&betas[i]);
            assert!(
                (got_h[i] - h).abs() < 2e-3 * h.abs().max(1.0),
                "H #{i}: {} vs {h}",
                got_h[i]
            );
        }
    }

    fn emd_one_hot(k: usize) -> Vec<f64> {
        let mut v = vec![0.0; B];
        v[k] = 1.0;
        v
    }

    #[test]
    fn entropy_branches_agree_where_they_meet() {
        // just below and above the switch: the asymptotic form is the exact one's limit
        let p = pmf(7, 0.3);
        let below: Vec<f64> = p.iter().map(|x| x * 0.999 * ENTROPY_APPROX_BETA0).collect();
        let above: Vec<f64> = p.iter().map(|x| x * 1.001 * ENTROPY_APPROX_BETA0).collect();
        let h = vals(dirichlet_entropy(t2(&[below.clone(), above])));
        assert!((h[0] - emd::dirichlet_entropy(&below)).abs() < 0.05);
        assert!((h[0] - h[1]).abs() < 0.05, "{h:?}");
    }
}
