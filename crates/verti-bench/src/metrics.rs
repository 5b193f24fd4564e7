//! Per-trial statistics and the aggregation of trials into the paper's tables and figures.

use serde::{Deserialize, Serialize};

/// Running mean, population variance and maximum (Welford's update; the sum of squared
/// deviations is `var · count`, so nothing hidden is needed to continue after a round trip).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    pub count: u64,
    #[serde(with = "crate::nullable")]
    pub mean: f64,
    /// Population variance.
    #[serde(with = "crate::nullable")]
    pub var: f64,
    #[serde(with = "crate::nullable")]
    pub max: f64,
}

impl Stats {
    pub fn push(&mut self, x: f64) {
        self.max = if self.count == 0 { x } else { self.max.max(x) };
        let m2 = self.var * self.count as f64;
        self.count += 1;
        let d = x - self.mean;
        self.mean += d / self.count as f64;
        self.var = (m2 + d * (x - self.mean)) / self.count as f64;
    }

    pub fn of(xs: impl IntoIterator<Item = f64>) -> Stats {
        let mut s = Stats::default();
        for x in xs {
            s.push(x);
        }
        s
    }
}

/// Mean absolute value and total variation (sum of |Δ|) of a command signal: effort and
/// smoothness.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SignalStats {
    pub samples: u64,
    #[serde(with = "crate::nullable")]
    pub mean_abs: f64,
    #[serde(with = "crate::nullable")]
    pub total_variation: f64,
    /// The latest sample (needed to continue the total variation).
    #[serde(with = "crate::nullable")]
    pub last: f64,
}

impl SignalStats {
    pub fn push(&mut self, x: f64) {
        if self.samples > 0 {
            self.total_variation += (x - self.last).abs();
        }
        self.samples += 1;
        self.mean_abs += (x.abs() - self.mean_abs) / self.samples as f64;
        self.last = x;
    }
}

/// An angle signal summarised raw and absolute (degrees).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AngleStats {
    pub raw: Stats,
    pub abs: Stats,
}

impl AngleStats {
    pub fn push_rad(&mut self, a: f64) {
        let d = a.to_degrees();
        self.raw.push(d);
        self.abs.push(d.abs());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_match_definitions() {
        let s = Stats::of([1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.mean, 2.5);
        assert!((s.var - 1.25).abs() < 1e-12);
        assert_eq!(s.max, 4.0);
        let mut sig = SignalStats::default();
        for x in [0.0, 1.0, -1.0, -1.0] {
            sig.push(x);
        }
        assert_eq!(sig.total_variation, 3.0);
        assert_eq!(sig.mean_abs, 0.75);
        let mut a = AngleStats::default();
        a.push_rad(-std::f64::consts::FRAC_PI_2);
        a.push_rad(std::f64::consts::FRAC_PI_2);
        assert!(
            a.raw.mean.abs() < 1e-12
                && (a.abs.mean - 90.0).abs() < 1e-12
                && (a.abs.max - 90.0).abs() < 1e-12
        );
    }
}
