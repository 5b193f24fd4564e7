//! Following a global path: progress along it and the local goal a lookahead ahead.

/// Tracks progress along a polyline so the local goal never jumps backwards.
#[derive(Clone, Debug, Default)]
pub struct PathFollower {
    path: Vec<[f64; 2]>,
    /// Index of the path point closest to the vehicle (only moves forward).
    progress: usize,
}

impl PathFollower {
    pub fn new(path: Vec<[f64; 2]>) -> Self {
        PathFollower { path, progress: 0 }
    }

    pub fn path(&self) -> &[[f64; 2]] {
        &self.path
    }

    /// The local goal: the first path point beyond the closest one (searched a window ahead)
    /// that is at least `lookahead` away; the last point near the end; `fallback` when the path
    /// is empty.
    pub fn local_goal(&mut self, x: f64, y: f64, lookahead: f64, fallback: [f64; 2]) -> [f64; 2] {
        if self.path.is_empty() {
            return fallback;
        }
        let d2 = |p: &[f64; 2]| (p[0] - x).powi(2) + (p[1] - y).powi(2);
        // closest point within a forward window of 3 lookaheads of path points
        let window_end =
            (self.progress + 1 + (3.0 * lookahead).ceil() as usize * 4).min(self.path.len());
        let mut best = self.progress;
        for i in self.progress..window_end {
            if d2(&self.path[i]) < d2(&self.path[best]) {
                best = i;
            }
        }
        self.progress = best;
        let l2 = lookahead * lookahead;
        self.path[self.progress..]
            .iter()
            .find(|p| d2(p) >= l2)
            .copied()
            .unwrap_or(*self.path.last().expect("non-empty"))
    }
}

/// Heading error from yaw to the direction of `target`, wrapped to [-π, π).
pub fn heading_error(x: f64, y: f64, yaw: f64, target: [f64; 2]) -> f64 {
    verti_core::math::wrap_angle((target[1] - y).atan2(target[0] - x) - yaw)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_goal_is_lookahead_ahead_and_monotone() {
        let path: Vec<[f64; 2]> = (0..=100).map(|i| [i as f64, 0.0]).collect();
        let mut f = PathFollower::new(path);
        assert_eq!(f.local_goal(0.0, 0.0, 10.0, [0.0; 2]), [10.0, 0.0]);
        // from (20.2, 1), point 30 is sqrt(9.8² + 1) = 9.85 m away, so the goal is point 31
        assert_eq!(f.local_goal(20.2, 1.0, 10.0, [0.0; 2]), [31.0, 0.0]);
        // moving backwards does not pull the goal behind the progress point (20, now 15 m away)
        assert_eq!(f.local_goal(5.0, 0.0, 10.0, [0.0; 2]), [20.0, 0.0]);
        assert_eq!(f.local_goal(95.0, 0.0, 10.0, [0.0; 2]), [100.0, 0.0]);
        let mut empty = PathFollower::new(vec![]);
        assert_eq!(empty.local_goal(0.0, 0.0, 10.0, [7.0, 7.0]), [7.0, 7.0]);
        assert!(
            (heading_error(0.0, 0.0, 0.0, [0.0, 1.0]) - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
    }
}
