//! The classical fourth-order Runge–Kutta step, as VertiAdaptor integrates each basis vector
//! field over one model step: controls and terrain embeddings are held, only the state moves
//! through the four stages, and what comes back is the *change* of the state.

/// The change x(t + dt) − x(t) of ẋ = f(x) after one RK4 step from `x`:
/// k1 = f(x), k2 = f(x + dt/2·k1), k3 = f(x + dt/2·k2), k4 = f(x + dt·k3),
/// Δx = dt/6·(k1 + 2k2 + 2k3 + k4).
pub fn rk4_delta<const N: usize>(
    x: &[f64; N],
    dt: f64,
    mut f: impl FnMut(&[f64; N]) -> [f64; N],
) -> [f64; N] {
    let shifted = |k: &[f64; N], h: f64| -> [f64; N] { std::array::from_fn(|i| x[i] + h * k[i]) };
    let k1 = f(x);
    let k2 = f(&shifted(&k1, 0.5 * dt));
    let k3 = f(&shifted(&k2, 0.5 * dt));
    let k4 = f(&shifted(&k3, dt));
    std::array::from_fn(|i| dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integrates the harmonic oscillator ẋ = −y, ẏ = x (exact: a rotation) to t = 1 with
    /// `steps` steps and returns the error at the end.
    fn oscillator_error(steps: usize) -> f64 {
        let dt = 1.0 / steps as f64;
        let mut s = [1.0, 0.0];
        for _ in 0..steps {
            let d = rk4_delta(&s, dt, |v| [-v[1], v[0]]);
            s = [s[0] + d[0], s[1] + d[1]];
        }
        ((s[0] - 1f64.cos()).powi(2) + (s[1] - 1f64.sin()).powi(2)).sqrt()
    }

    #[test]
    fn global_error_is_fourth_order() {
        // halving the step divides a fourth-order method's global error by 2^4 = 16
        let (e1, e2, e3) = (
            oscillator_error(8),
            oscillator_error(16),
            oscillator_error(32),
        );
        for ratio in [e1 / e2, e2 / e3] {
            assert!(
                (ratio - 16.0).abs() < 1.0,
                "error ratio {ratio}, expected ~16"
            );
        }
    }

    #[test]
    fn exact_for_cubic_time_polynomials() {
        // ẋ = 3 t² written autonomously with t as a state: RK4 integrates polynomials of
        // degree ≤ 3 in t exactly (Simpson's rule)
        let d = rk4_delta(&[0.0, 0.5], 0.3, |v| [3.0 * v[1] * v[1], 1.0]);
        let exact = 0.8f64.powi(3) - 0.5f64.powi(3);
        assert!((d[0] - exact).abs() < 1e-12, "{} vs {exact}", d[0]);
        assert!((d[1] - 0.3).abs() < 1e-15);
    }

    #[test]
    fn linear_decay_matches_the_taylor_polynomial() {
        // for ẋ = a x one RK4 step multiplies x by 1 + h + h²/2 + h³/6 + h⁴/24, h = a dt
        let (a, dt, x0) = (-2.0, 0.1, 1.5);
        let d = rk4_delta(&[x0], dt, |v| [a * v[0]]);
        let h: f64 = a * dt;
        let factor = 1.0 + h + h * h / 2.0 + h.powi(3) / 6.0 + h.powi(4) / 24.0;
        assert!((x0 + d[0] - x0 * factor).abs() < 1e-14);
    }
}
