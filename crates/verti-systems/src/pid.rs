//! PID path follower (paper §IV-A): a local goal 10 m ahead on the global path, steering from
//! the heading error (proportional, Kp = 1 on the road-wheel angle), constant 3 m/s.

use crate::path::{PathFollower, heading_error};
use verti_bench::{Action, MobilitySystem, Observation, TaskInfo};

#[derive(Clone, Debug, PartialEq)]
pub struct PidParams {
    /// Target speed at full scale, m/s (scaled by √s).
    pub speed: f64,
    /// Local-goal lookahead at full scale, m (scaled by s).
    pub lookahead: f64,
    /// Steering gain: road-wheel angle per radian of heading error.
    pub kp: f64,
    /// Integral and derivative gains (0 by default, as in the reference).
    pub ki: f64,
    pub kd: f64,
    /// Control rate, Hz.
    pub rate: f64,
}

impl Default for PidParams {
    fn default() -> Self {
        PidParams {
            speed: 3.0,
            lookahead: 10.0,
            kp: 1.0,
            ki: 0.0,
            kd: 0.0,
            rate: 20.0,
        }
    }
}

pub struct Pid {
    params: PidParams,
    follower: PathFollower,
    goal: [f64; 2],
    scale: f64,
    max_steer: f64,
    integral: f64,
    last_error: Option<f64>,
}

impl Pid {
    pub fn new(params: PidParams) -> Self {
        Pid {
            params,
            follower: PathFollower::default(),
            goal: [0.0; 2],
            scale: 1.0,
            max_steer: 0.5,
            integral: 0.0,
            last_error: None,
        }
    }

    /// Heading error toward the local goal (used by EH too).
    pub fn path_heading_error(&mut self, obs: &Observation) -> f64 {
        let g = self.follower.local_goal(
            obs.pose.x,
            obs.pose.y,
            self.params.lookahead * self.scale,
            self.goal,
        );
        heading_error(obs.pose.x, obs.pose.y, obs.pose.yaw, g)
    }

    /// Steering input for a heading error.
    pub fn steer(&mut self, error: f64) -> f64 {
        let dt = 1.0 / self.params.rate;
        self.integral = (self.integral + error * dt).clamp(-1.0, 1.0);
        let derivative = self.last_error.map_or(0.0, |l| (error - l) / dt);
        self.last_error = Some(error);
        let angle =
            self.params.kp * error + self.params.ki * self.integral + self.params.kd * derivative;
        (angle / self.max_steer).clamp(-1.0, 1.0)
    }

    pub fn target_speed(&self) -> f64 {
        self.params.speed * self.scale.sqrt()
    }
}

impl MobilitySystem for Pid {
    fn name(&self) -> &str {
        "pid"
    }
    fn control_rate(&self) -> f64 {
        self.params.rate
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.follower = PathFollower::new(task.global_path.clone());
        self.goal = task.goal;
        self.scale = task.world_scale;
        self.max_steer = task.max_steer_angle.max(1e-3);
        self.integral = 0.0;
        self.last_error = None;
    }
    fn act(&mut self, obs: &Observation) -> Action {
        let e = self.path_heading_error(obs);
        Action::HighLevel {
            speed: self.target_speed(),
            steering: self.steer(e),
        }
    }
}
