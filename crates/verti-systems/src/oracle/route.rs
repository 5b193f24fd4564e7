//! The oracle's route: the world's global path (or the straight line to the goal), resampled,
//! with the path length left to the goal at each point. It gives the planner two things:
//!
//! * a **cost-to-go** `g(x, y) = min_i (|(x, y) − p_i| + L_i)`: the distance to some path point
//!   plus the path length from there to the goal. Its decrease over a rollout is the rollout's
//!   progress. Note: since `L_i` is at least the straight distance from `p_i` to the goal, the
//!   triangle inequality makes `g` equal (up to rounding) to the planar distance to the goal,
//!   the minimum being at the goal point itself. The path does not shape the progress term;
//!   it shapes the candidates (tracking, below). This form is kept because it is what the
//!   measured defaults ran with (`docs/oracle.md`); a path-shaped progress term (e.g. a
//!   weight > 1 on the distance to the path point) is untried.
//! * **tracking**: the steering that aims at a point a lookahead ahead on the path, shifted
//!   sideways by an offset. Tracking segments let a candidate follow the path (offset 0, what
//!   PID does) or a parallel lane beside it (offset ≠ 0, around a mound on the path), and they
//!   are closed-loop, so a few of them cover what many piecewise-constant steerings would.
//!
//! Everything here is a pure function of the pose, so a rollout and the executed trial compute
//! the same steering from the same state.

use verti_core::math::wrap_angle;

/// The resampled route and its cost-to-go.
#[derive(Clone, Debug, Default)]
pub struct Route {
    /// Points about `spacing` apart, ending at the goal.
    points: Vec<[f64; 2]>,
    /// Unit tangent at each point.
    tangents: Vec<[f64; 2]>,
    /// Arc length from the start of the route to each point.
    arc: Vec<f64>,
    /// Total length.
    length: f64,
}

impl Route {
    /// The route along `path` (the world's global path; the straight line from `start` when it
    /// is empty) to `goal`, resampled every `spacing` metres.
    pub fn new(path: &[[f64; 2]], start: [f64; 2], goal: [f64; 2], spacing: f64) -> Route {
        let mut raw: Vec<[f64; 2]> = if path.is_empty() {
            vec![start]
        } else {
            path.to_vec()
        };
        let last = *raw.last().expect("non-empty");
        if dist(last, goal) > 1e-9 {
            raw.push(goal);
        }
        let mut points = vec![raw[0]];
        let mut carry = 0.0; // distance along the raw path since the last emitted point
        for w in raw.windows(2) {
            let d = dist(w[0], w[1]);
            if d <= 0.0 {
                continue;
            }
            let mut s = spacing - carry;
            while s < d {
                let f = s / d;
                points.push([
                    w[0][0] + f * (w[1][0] - w[0][0]),
                    w[0][1] + f * (w[1][1] - w[0][1]),
                ]);
                s += spacing;
            }
            carry = d - (s - spacing);
        }
        if dist(*points.last().expect("non-empty"), goal) > 1e-9 {
            points.push(goal);
        }
        let n = points.len();
        let mut arc = vec![0.0; n];
        for i in 1..n {
            arc[i] = arc[i - 1] + dist(points[i - 1], points[i]);
        }
        let tangents = (0..n)
            .map(|i| {
                let (a, b) = if n < 2 {
                    (start, goal)
                } else if i + 1 < n {
                    (points[i], points[i + 1])
                } else {
                    (points[i - 1], points[i])
                };
                let d = dist(a, b).max(1e-12);
                [(b[0] - a[0]) / d, (b[1] - a[1]) / d]
            })
            .collect();
        Route {
            length: arc[n - 1],
            points,
            tangents,
            arc,
        }
    }

    /// Index of the route point nearest to (x, y).
    fn nearest(&self, x: f64, y: f64) -> usize {
        let mut best = (f64::INFINITY, 0);
        for (i, p) in self.points.iter().enumerate() {
            let d2 = (p[0] - x).powi(2) + (p[1] - y).powi(2);
            if d2 < best.0 {
                best = (d2, i);
            }
        }
        best.1
    }

    /// Cost-to-go from (x, y), metres: equal, up to rounding, to the planar distance to the
    /// goal (see the module doc).
    pub fn cost_to_go(&self, x: f64, y: f64) -> f64 {
        self.points
            .iter()
            .zip(&self.arc)
            .map(|(p, s)| dist(*p, [x, y]) + (self.length - s))
            .fold(f64::INFINITY, f64::min)
    }

    /// Normalised steering in [-1, 1] that turns a vehicle at (x, y) heading `yaw` toward the
    /// point `lookahead` ahead along the route (from the nearest point), shifted `offset`
    /// metres to the left of the route (negative: right). The road-wheel angle is the heading
    /// error (gain 1, PID's), divided by `max_steer`.
    pub fn track(
        &self,
        x: f64,
        y: f64,
        yaw: f64,
        lookahead: f64,
        offset: f64,
        max_steer: f64,
    ) -> f64 {
        let i = self.nearest(x, y);
        let target_s = self.arc[i] + lookahead;
        let j = self.arc[i..]
            .iter()
            .position(|&s| s >= target_s)
            .map_or(self.points.len() - 1, |k| i + k);
        let (p, t) = (self.points[j], self.tangents[j]);
        // near the goal the lane narrows onto it, so an offset lane still ends at the goal
        let taper = ((self.length - self.arc[j]) / lookahead.max(1e-9)).clamp(0.0, 1.0);
        let o = offset * taper;
        let target = [p[0] - o * t[1], p[1] + o * t[0]];
        let error = wrap_angle((target[1] - y).atan2(target[0] - x) - yaw);
        (error / max_steer.max(1e-3)).clamp(-1.0, 1.0)
    }
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_to_go_follows_the_path_and_tracking_aims_along_it() {
        // an L-shaped path: east 20 m, then north 20 m
        let path = [[0.0, 0.0], [20.0, 0.0], [20.0, 20.0]];
        let r = Route::new(&path, [0.0, 0.0], [20.0, 20.0], 1.0);
        // the cost-to-go is the straight distance to the goal (triangle inequality), not the
        // 40 m of path: see the module doc
        for (x, y) in [(0.0, 0.0), (20.0, 20.0), (22.0, 0.0), (5.0, -7.0)] {
            let d = ((x - 20.0f64).powi(2) + (y - 20.0f64).powi(2)).sqrt();
            assert!((r.cost_to_go(x, y) - d).abs() < 1e-9, "({x}, {y})");
        }
        // at the start facing east: straight ahead is on the path; an offset lane to the left
        // (north) needs a left (positive) turn
        assert!(r.track(0.0, 0.0, 0.0, 5.0, 0.0, 0.5).abs() < 1e-9);
        assert!(r.track(0.0, 0.0, 0.0, 5.0, 3.0, 0.5) > 0.5);
        assert!(r.track(0.0, 0.0, 0.0, 5.0, -3.0, 0.5) < -0.5);
        // no global path: the straight line to the goal
        let r = Route::new(&[], [0.0, 0.0], [10.0, 0.0], 1.0);
        assert!((r.cost_to_go(0.0, 0.0) - 10.0).abs() < 1e-9);
        // off the line too
        assert!((r.cost_to_go(0.0, 3.0) - 109f64.sqrt()).abs() < 1e-9);
    }
}
