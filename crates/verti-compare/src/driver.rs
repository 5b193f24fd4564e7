//! The reference runs' own driver law, as `chrono-reference/README.md` states it, for checking
//! how much verti's PID differs from it matter.
//!
//! It differs from verti's PID in three ways:
//! * the local goal is the first path point more than the lookahead *of arc length* beyond the
//!   path point nearest the vehicle (searched over the whole path), where the PID takes the
//!   first point at least the lookahead *away from the vehicle*, searching a window ahead of
//!   its progress, which never moves back;
//! * the steering input moves at most 0.05 per 5 ms (10 per second) toward its target;
//! * the steering input is the heading error itself, with no gain to set.

use verti_bench::path::heading_error;
use verti_bench::{Action, MobilitySystem, Observation, TaskInfo};

/// Steering input change per second the reference allows: 0.05 per 5 ms step.
pub const REFERENCE_STEER_SLEW: f64 = 10.0;

/// The reference's path follower.
#[derive(Clone, Debug)]
pub struct ReferenceDriver {
    /// Target speed, m/s; lookahead, m (both at full scale).
    pub speed: f64,
    pub lookahead: f64,
    /// Calls per second.
    pub rate: f64,
    path: Vec<[f64; 2]>,
    /// Arc length of the path at each point.
    arc: Vec<f64>,
    goal: [f64; 2],
    scale: f64,
    steer: f64,
    last_time: Option<f64>,
}

impl ReferenceDriver {
    pub fn new(speed: f64, lookahead: f64, rate: f64) -> ReferenceDriver {
        ReferenceDriver {
            speed,
            lookahead,
            rate,
            path: Vec::new(),
            arc: Vec::new(),
            goal: [0.0; 2],
            scale: 1.0,
            steer: 0.0,
            last_time: None,
        }
    }

    /// The local goal for a vehicle at (x, y).
    pub fn local_goal(&self, x: f64, y: f64) -> [f64; 2] {
        let Some(&last) = self.path.last() else {
            return self.goal;
        };
        let d2 = |p: &[f64; 2]| (p[0] - x).powi(2) + (p[1] - y).powi(2);
        let nearest = (0..self.path.len())
            .min_by(|&a, &b| d2(&self.path[a]).total_cmp(&d2(&self.path[b])))
            .expect("non-empty");
        let reach = self.arc[nearest] + self.lookahead * self.scale;
        self.arc[nearest..]
            .iter()
            .position(|&s| s > reach)
            .map_or(last, |k| self.path[nearest + k])
    }
}

impl MobilitySystem for ReferenceDriver {
    fn name(&self) -> &str {
        "reference-driver"
    }
    fn control_rate(&self) -> f64 {
        self.rate
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.path = task.global_path.clone();
        let mut s = 0.0;
        self.arc = Vec::with_capacity(self.path.len());
        for (i, p) in self.path.iter().enumerate() {
            if i > 0 {
                let q = self.path[i - 1];
                s += (p[0] - q[0]).hypot(p[1] - q[1]);
            }
            self.arc.push(s);
        }
        self.goal = task.goal;
        self.scale = task.world_scale;
        self.steer = 0.0;
        self.last_time = None;
    }
    fn act(&mut self, obs: &Observation) -> Action {
        let g = self.local_goal(obs.pose.x, obs.pose.y);
        let target = heading_error(obs.pose.x, obs.pose.y, obs.pose.yaw, g);
        // the slew per call follows the time actually elapsed, since the benchmark's inner
        // step may be longer than the control period
        let dt = self
            .last_time
            .map_or(1.0 / self.rate, |t| (obs.time - t).max(1.0 / self.rate));
        self.last_time = Some(obs.time);
        let step = REFERENCE_STEER_SLEW * dt;
        self.steer = target
            .clamp(self.steer - step, self.steer + step)
            .clamp(-1.0, 1.0);
        Action::HighLevel {
            speed: self.speed * self.scale.sqrt(),
            steering: self.steer,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_goal_counts_arc_length_from_the_nearest_point() {
        let mut d = ReferenceDriver::new(3.0, 10.0, 200.0);
        // an L-shaped path: 0..20 along x, then 20 up along y, points 1 m apart
        let mut path: Vec<[f64; 2]> = (0..=20).map(|i| [f64::from(i), 0.0]).collect();
        path.extend((1..=20).map(|j| [20.0, f64::from(j)]));
        d.path = path.clone();
        d.arc = (0..path.len()).map(|i| i as f64).collect();
        // nearest point (15, 0), arc 15: the first point beyond arc 25 is (20, 6)
        assert_eq!(d.local_goal(15.0, 1.0), [20.0, 6.0]);
        // beyond the end: the last point
        assert_eq!(d.local_goal(20.0, 19.0), [20.0, 20.0]);
        d.path.clear();
        d.goal = [7.0, 7.0];
        assert_eq!(d.local_goal(0.0, 0.0), [7.0, 7.0]);
    }
}
