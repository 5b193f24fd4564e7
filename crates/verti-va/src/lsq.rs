//! Least-squares coefficients of a function encoder (VertiAdaptor eq. 1) and their recursive
//! form.
//!
//! The basis outputs at one example point form a k × d matrix Φ (k basis functions, d output
//! values); the target is y ∈ R^d. With the inner product ⟨f, g⟩ = (1/M) Σ_m f(x_m)ᵀ g(x_m)
//! (sum over outputs, mean over the M points) the Gram matrix is G_ij = ⟨G_i, G_j⟩ and the
//! right-hand side F_i = ⟨y, G_i⟩; the coefficients are α = (G + λI)⁻¹ F with λ = 1e-3, the
//! minimiser of (1/M) Σ_m ‖y_m − Φ_mᵀ α‖² + λ‖α‖².
//!
//! [`Rls`] is the paper's stated future work: the same problem solved one point at a time with
//! a forgetting factor μ ≤ 1, so the coefficients track terrain that changes within an episode
//! instead of being recomputed from a window every few seconds.

/// Gram regularisation λ (VertiAdaptor Table I).
pub const LAMBDA: f64 = 1e-3;
/// Example points per accumulation batch (Table I): basis outputs are computed and added in
/// batches of this many, which bounds memory; the sums, and so the solution, do not change.
pub const EXAMPLE_BATCH: usize = 256;

/// Running sums Σ Φ Φᵀ and Σ Φ y over example points.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalEquations {
    k: usize,
    d: usize,
    gram: Vec<f64>,
    rhs: Vec<f64>,
    points: usize,
}

impl NormalEquations {
    /// Empty sums for `k` basis functions with `d` outputs each.
    pub fn new(k: usize, d: usize) -> NormalEquations {
        NormalEquations {
            k,
            d,
            gram: vec![0.0; k * k],
            rhs: vec![0.0; k],
            points: 0,
        }
    }

    pub fn points(&self) -> usize {
        self.points
    }

    /// Adds one example: `phi` is k × d row-major (basis i's outputs in row i), `y` has d values.
    pub fn add(&mut self, phi: &[f64], y: &[f64]) {
        let (k, d) = (self.k, self.d);
        debug_assert_eq!((phi.len(), y.len()), (k * d, d));
        for i in 0..k {
            let pi = &phi[i * d..(i + 1) * d];
            self.rhs[i] += dot(pi, y);
            for j in i..k {
                self.gram[i * k + j] += dot(pi, &phi[j * d..(j + 1) * d]);
            }
        }
        self.points += 1;
    }

    /// Adds the sums of another accumulator (a batch).
    pub fn merge(&mut self, other: &NormalEquations) {
        debug_assert_eq!((self.k, self.d), (other.k, other.d));
        for (a, b) in self.gram.iter_mut().zip(&other.gram) {
            *a += b;
        }
        for (a, b) in self.rhs.iter_mut().zip(&other.rhs) {
            *a += b;
        }
        self.points += other.points;
    }

    /// The Gram matrix G (k × k, full) and right-hand side F: the sums divided by M.
    pub fn gram_and_rhs(&self) -> (Vec<f64>, Vec<f64>) {
        let k = self.k;
        let m = self.points.max(1) as f64;
        let mut g = vec![0.0; k * k];
        for i in 0..k {
            for j in i..k {
                let v = self.gram[i * k + j] / m;
                g[i * k + j] = v;
                g[j * k + i] = v;
            }
        }
        (g, self.rhs.iter().map(|v| v / m).collect())
    }

    /// α = (G + λI)⁻¹ F. Without points the answer is zero (the regulariser alone).
    pub fn solve(&self, lambda: f64) -> Result<Vec<f64>, String> {
        let (mut g, f) = self.gram_and_rhs();
        for i in 0..self.k {
            g[i * self.k + i] += lambda;
        }
        cholesky_solve(&g, self.k, &f).ok_or_else(|| {
            format!(
                "the regularised Gram matrix of {} points is not positive definite (λ = {lambda})",
                self.points
            )
        })
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves A x = b for a symmetric positive-definite n × n `a` (row-major) by Cholesky
/// factorisation; `None` when A is not positive definite.
pub fn cholesky_solve(a: &[f64], n: usize, b: &[f64]) -> Option<Vec<f64>> {
    let l = cholesky(a, n)?;
    // forward: L z = b; back: Lᵀ x = z
    let mut z = vec![0.0; n];
    for i in 0..n {
        let s: f64 = (0..i).map(|j| l[i * n + j] * z[j]).sum();
        z[i] = (b[i] - s) / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| l[j * n + i] * x[j]).sum();
        x[i] = (z[i] - s) / l[i * n + i];
    }
    Some(x)
}

/// Lower-triangular L with L Lᵀ = A.
pub fn cholesky(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|p| l[i * n + p] * l[j * n + p]).sum();
            if i == j {
                let v = a[i * n + i] - s;
                if !(v > 0.0 && v.is_finite()) {
                    return None;
                }
                l[i * n + i] = v.sqrt();
            } else {
                l[i * n + j] = (a[i * n + j] - s) / l[j * n + j];
            }
        }
    }
    Some(l)
}

/// Recursive least squares over example points with exponential forgetting.
///
/// After points 1..n it holds α_n = argmin Σ_m μ^(n−m) ‖y_m − Φ_mᵀ α‖² + μ^n (α − α_0)ᵀ P_0⁻¹
/// (α − α_0): with μ = 1, α_0 = 0 and P_0 = I / (Mλ) it reaches exactly the batch solution
/// (G + λI)⁻¹ F of M points. Each point's d outputs are taken one scalar at a time (the
/// standard update, no matrix inverse), and the forgetting is applied once per point.
#[derive(Clone, Debug, PartialEq)]
pub struct Rls {
    k: usize,
    d: usize,
    alpha: Vec<f64>,
    /// Inverse of the (weighted) information matrix, k × k.
    p: Vec<f64>,
    forgetting: f64,
    gain: Vec<f64>,
}

impl Rls {
    /// Starts from `alpha0` with P_0 = I / `information0`: the larger `information0`, the more
    /// points it takes to move away from `alpha0`.
    pub fn new(alpha0: Vec<f64>, d: usize, information0: f64, forgetting: f64) -> Rls {
        let k = alpha0.len();
        let mut p = vec![0.0; k * k];
        for i in 0..k {
            p[i * k + i] = 1.0 / information0;
        }
        Rls {
            k,
            d,
            alpha: alpha0,
            p,
            forgetting,
            gain: vec![0.0; k],
        }
    }

    pub fn alpha(&self) -> &[f64] {
        &self.alpha
    }

    /// Takes in one example (Φ k × d row-major, y with d values).
    pub fn update(&mut self, phi: &[f64], y: &[f64]) {
        let (k, d) = (self.k, self.d);
        debug_assert_eq!((phi.len(), y.len()), (k * d, d));
        for o in 0..d {
            let mu = if o == 0 { self.forgetting } else { 1.0 };
            // φ: column o of Φ (basis i's output o)
            let phi_o = |i: usize| phi[i * d + o];
            // g = P φ / (μ + φᵀ P φ)
            for i in 0..k {
                self.gain[i] = (0..k).map(|j| self.p[i * k + j] * phi_o(j)).sum();
            }
            let denom = mu + (0..k).map(|i| phi_o(i) * self.gain[i]).sum::<f64>();
            let err = y[o] - (0..k).map(|i| phi_o(i) * self.alpha[i]).sum::<f64>();
            // P ← (P − P φ φᵀ P / denom) / μ, using P symmetric (P φ = gain before scaling)
            for i in 0..k {
                for j in 0..k {
                    self.p[i * k + j] =
                        (self.p[i * k + j] - self.gain[i] * self.gain[j] / denom) / mu;
                }
            }
            for i in 0..k {
                self.alpha[i] += self.gain[i] / denom * err;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_core::Rng;

    /// Random example points from known coefficients plus noise.
    fn synthetic(k: usize, d: usize, m: usize, seed: u64) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let mut rng = Rng::new(seed);
        let truth: Vec<f64> = (0..k).map(|_| rng.range(-2.0, 2.0)).collect();
        let mut phis = Vec::new();
        let mut ys = Vec::new();
        for _ in 0..m {
            let phi: Vec<f64> = (0..k * d).map(|_| rng.range(-1.0, 1.0)).collect();
            let y: Vec<f64> = (0..d)
                .map(|o| (0..k).map(|i| phi[i * d + o] * truth[i]).sum::<f64>())
                .map(|v| v + 0.01 * rng.range(-1.0, 1.0))
                .collect();
            phis.push(phi);
            ys.push(y);
        }
        (phis, ys)
    }

    /// (G + λI)⁻¹F by Gauss–Jordan elimination on the explicit sums: an independent route.
    fn closed_form(
        phis: &[Vec<f64>],
        ys: &[Vec<f64>],
        k: usize,
        d: usize,
        lambda: f64,
    ) -> Vec<f64> {
        let m = phis.len() as f64;
        let mut a = vec![vec![0.0; k + 1]; k];
        for (phi, y) in phis.iter().zip(ys) {
            for i in 0..k {
                for j in 0..k {
                    a[i][j] += (0..d).map(|o| phi[i * d + o] * phi[j * d + o]).sum::<f64>() / m;
                }
                a[i][k] += (0..d).map(|o| phi[i * d + o] * y[o]).sum::<f64>() / m;
            }
        }
        for (i, row) in a.iter_mut().enumerate() {
            row[i] += lambda;
        }
        for c in 0..k {
            let piv = (c..k)
                .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
                .unwrap();
            a.swap(c, piv);
            for r in 0..k {
                if r != c {
                    let f = a[r][c] / a[c][c];
                    let pivot_row = a[c].clone();
                    for (v, p) in a[r].iter_mut().zip(pivot_row) {
                        *v -= f * p;
                    }
                }
            }
        }
        (0..k).map(|i| a[i][k] / a[i][i]).collect()
    }

    #[test]
    fn batched_solution_matches_the_closed_form() {
        let (k, d, m) = (24, 6, 700);
        let (phis, ys) = synthetic(k, d, m, 3);
        // accumulate in batches of 256, as VertiAdaptor does
        let mut total = NormalEquations::new(k, d);
        for chunk in phis.chunks(EXAMPLE_BATCH).zip(ys.chunks(EXAMPLE_BATCH)) {
            let mut batch = NormalEquations::new(k, d);
            for (phi, y) in chunk.0.iter().zip(chunk.1) {
                batch.add(phi, y);
            }
            total.merge(&batch);
        }
        let alpha = total.solve(LAMBDA).unwrap();
        let expected = closed_form(&phis, &ys, k, d, LAMBDA);
        for (a, e) in alpha.iter().zip(&expected) {
            assert!((a - e).abs() < 1e-9, "{a} vs {e}");
        }
    }

    #[test]
    fn exact_bases_recover_the_coefficients() {
        // noiseless targets and a small λ: the coefficients come back
        let (k, d) = (5, 3);
        let mut rng = Rng::new(9);
        let truth = [0.5, -1.0, 2.0, 0.0, 1.5];
        let mut ne = NormalEquations::new(k, d);
        for _ in 0..200 {
            let phi: Vec<f64> = (0..k * d).map(|_| rng.range(-1.0, 1.0)).collect();
            let y: Vec<f64> = (0..d)
                .map(|o| (0..k).map(|i| phi[i * d + o] * truth[i]).sum())
                .collect();
            ne.add(&phi, &y);
        }
        let alpha = ne.solve(1e-9).unwrap();
        for (a, t) in alpha.iter().zip(truth) {
            assert!((a - t).abs() < 1e-6, "{a} vs {t}");
        }
    }

    #[test]
    fn rls_without_forgetting_reaches_the_batch_solution() {
        let (k, d, m) = (24, 6, 300);
        let (phis, ys) = synthetic(k, d, m, 5);
        let mut ne = NormalEquations::new(k, d);
        let mut rls = Rls::new(vec![0.0; k], d, m as f64 * LAMBDA, 1.0);
        for (phi, y) in phis.iter().zip(&ys) {
            ne.add(phi, y);
            rls.update(phi, y);
        }
        let batch = ne.solve(LAMBDA).unwrap();
        for (a, b) in rls.alpha().iter().zip(&batch) {
            assert!((a - b).abs() < 1e-8, "{a} vs {b}");
        }
    }

    #[test]
    fn rls_with_forgetting_tracks_a_change() {
        // the coefficients switch halfway; with μ = 0.95 the estimate follows the new ones,
        // without forgetting it stays between the two
        let (k, d) = (4, 2);
        let mut rng = Rng::new(11);
        let before = [1.0, 0.0, -1.0, 0.5];
        let after = [-1.0, 1.0, 0.0, 2.0];
        let mut forgetful = Rls::new(vec![0.0; k], d, 1e-3, 0.95);
        let mut stubborn = Rls::new(vec![0.0; k], d, 1e-3, 1.0);
        for n in 0..400 {
            let truth = if n < 200 { before } else { after };
            let phi: Vec<f64> = (0..k * d).map(|_| rng.range(-1.0, 1.0)).collect();
            let y: Vec<f64> = (0..d)
                .map(|o| (0..k).map(|i| phi[i * d + o] * truth[i]).sum())
                .collect();
            forgetful.update(&phi, &y);
            stubborn.update(&phi, &y);
        }
        let dist = |a: &[f64], b: &[f64; 4]| -> f64 {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        // the old points still weigh μ^200 ≈ 3.5e-5 of the new ones
        let d = dist(forgetful.alpha(), &after);
        assert!(d < 1e-3, "{d}");
        assert!(dist(stubborn.alpha(), &after) > 0.5);
    }

    #[test]
    fn indefinite_matrices_are_refused() {
        assert!(cholesky_solve(&[1.0, 2.0, 2.0, 1.0], 2, &[1.0, 1.0]).is_none());
        let x = cholesky_solve(&[4.0, 2.0, 2.0, 3.0], 2, &[2.0, 1.0]).unwrap();
        assert!((4.0 * x[0] + 2.0 * x[1] - 2.0).abs() < 1e-12);
        assert!((2.0 * x[0] + 3.0 * x[1] - 1.0).abs() < 1e-12);
    }
}
