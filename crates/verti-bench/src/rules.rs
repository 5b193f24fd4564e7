//! The rules of a trial: its settings ([`EpisodeConfig`]), how it ends ([`Outcome`]) and the
//! success and failure rules checked step by step ([`Termination`]).
//!
//! Paper rules (§III-F, §III-G.3): success is reaching within 10 m (scaled with the world) of
//! the goal, planar, in under 60 s. A trial also ends when the vehicle is stuck: it has stayed
//! within 1 m (scaled) of its current position for the last 10 s. A failed trial is a
//! *rollover* if |roll| > 30° at its end, otherwise *stuck* or *timeout*.
//!
//! `Rules::VertiBench` reproduces the reference code instead (spec §5): success inside an 8 m
//! sphere (not scaled) around the goal raised 2 m (scaled) above the ground; stuck when the
//! vehicle has been slower than 2 m/s (0.01 m per 5 ms step) for 10 s; no rollover class.
//!
//! These settings and rules sit below the [`Trial`](crate::Trial) that applies them, so that
//! the trial and the episode driver that runs it (`crate::episode`) both import them and the
//! trial never imports the driver; `crate::episode` re-exports every item at its old path.

use crate::perception::PerceptionModel;
use crate::pose::Pose6;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use verti_world::World;

/// Which success and failure rules apply.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rules {
    #[default]
    Paper,
    VertiBench,
}

/// How a trial's vehicle starts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StartMode {
    /// Settled on the ground at rest (springs and tyres at their static load, body fitted to
    /// the terrain under the wheels): the trial measures driving, not landing. The default,
    /// with either rules; the paper does not describe its spawn.
    #[default]
    Settled,
    /// Verti-Bench's spawn: level, the chassis reference frame 1 m (scaled) above the ground,
    /// dropped at t = 0 (its reference code, `vehicles/HMMWV.py`). Used to compare with it: on
    /// steep ground the landing alone can tip a vehicle over.
    Drop,
}

impl StartMode {
    /// Verti-Bench's drop height at full scale, metres.
    pub const DROP_HEIGHT: f64 = 1.0;

    pub fn name(self) -> &'static str {
        match self {
            StartMode::Settled => "settled",
            StartMode::Drop => "drop",
        }
    }

    pub fn from_name(s: &str) -> Option<StartMode> {
        [StartMode::Settled, StartMode::Drop]
            .into_iter()
            .find(|m| m.name() == s)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct EpisodeConfig {
    pub rules: Rules,
    /// Time limit, simulated seconds.
    pub max_time: f64,
    /// Success radius at full scale, metres (paper rules; multiplied by the world scale).
    pub success_radius: f64,
    /// Stuck: window (s) and distance at full scale (m).
    pub stuck_window: f64,
    pub stuck_distance: f64,
    /// Rollover threshold, degrees of |roll|.
    pub rollover_deg: f64,
    /// A vehicle tilted further than this from upright (degrees) has capsized: the trial ends
    /// at once as a rollover (paper rules). None of the vehicles can right itself, and without
    /// this a tumble down a slope that lands on its wheels would end later as merely "stuck".
    pub capsize_deg: f64,
    /// Period of the inner loop (speed controller, metrics, termination checks), seconds.
    pub inner_dt: f64,
    /// Keep a per-step log: `None` keeps nothing, `Some(s)` keeps the last `s` seconds
    /// (`f64::INFINITY` keeps everything).
    pub log_seconds: Option<f64>,
    /// Run seed; each trial's system seed is derived from it and the task.
    pub seed: u64,
    /// How the vehicle starts.
    pub start: StartMode,
    /// Perception noise on what the system observes (None: ground truth, the paper's setting).
    pub perception: Option<std::sync::Arc<PerceptionModel>>,
}

impl Default for EpisodeConfig {
    fn default() -> Self {
        EpisodeConfig {
            rules: Rules::Paper,
            max_time: 60.0,
            success_radius: 10.0,
            stuck_window: 10.0,
            stuck_distance: 1.0,
            rollover_deg: 30.0,
            capsize_deg: 90.0,
            inner_dt: 0.01,
            log_seconds: None,
            seed: 0,
            start: StartMode::Settled,
            perception: None,
        }
    }
}

impl EpisodeConfig {
    pub fn validate(&self) -> Result<(), String> {
        let checks = [
            ("max_time", self.max_time, 0.1, 3600.0),
            ("success_radius", self.success_radius, 0.0, 1000.0),
            ("stuck_window", self.stuck_window, 0.1, 3600.0),
            ("stuck_distance", self.stuck_distance, 0.0, 1000.0),
            ("rollover_deg", self.rollover_deg, 1.0, 180.0),
            ("capsize_deg", self.capsize_deg, 1.0, 180.0),
            ("inner_dt", self.inner_dt, 1e-4, 0.1),
        ];
        for (name, v, lo, hi) in checks {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(format!(
                    "episode setting {name} = {v} is outside [{lo}, {hi}]"
                ));
            }
        }
        Ok(())
    }
}

/// How a trial ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    Success,
    Rollover,
    Stuck,
    Timeout,
    /// The simulation or the system failed (non-finite state, invalid action); see `error`.
    Error,
}

impl Outcome {
    pub const ALL: [Outcome; 5] = [
        Outcome::Success,
        Outcome::Rollover,
        Outcome::Stuck,
        Outcome::Timeout,
        Outcome::Error,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Success => "success",
            Outcome::Rollover => "rollover",
            Outcome::Stuck => "stuck",
            Outcome::Timeout => "timeout",
            Outcome::Error => "error",
        }
    }
}

/// The success and failure rules of one trial, checked step by step. [`run_episode`](crate::episode::run_episode) drives it
/// after every inner step; step-wise users (the Python gym environment) drive the very same
/// rules between their own physics steps, so the rules exist once.
#[derive(Clone, Debug)]
pub struct Termination {
    rules: Rules,
    goal: [f64; 2],
    /// Reference rules: the goal point is raised 2 m (scaled) above the ground.
    goal_z: f64,
    /// Scaled success radius and stuck distance, metres.
    success_radius: f64,
    stuck_distance: f64,
    stuck_window: f64,
    max_time: f64,
    rollover_deg: f64,
    /// cos of the capsize tilt: the body z axis's vertical component below this is a capsize.
    capsize_cos: f64,
    /// Paper stuck rule: (t, x, y) sampled every 0.1 s over the last window.
    history: VecDeque<(f64, f64, f64)>,
    next_sample: f64,
    /// Reference stuck rule: how long the vehicle has been slower than 2 m/s.
    slow_time: f64,
    last_xyz: (f64, f64, f64),
}

impl Termination {
    /// The rules of `cfg` for driving to `goal` on `world`, starting at `start` (time 0).
    pub fn new(world: &World, goal: [f64; 2], cfg: &EpisodeConfig, start: &Pose6) -> Termination {
        let scale = world.meta.scale;
        Termination {
            rules: cfg.rules,
            goal,
            goal_z: world.terrain.height_at(goal[0], goal[1]) + 2.0 * scale,
            success_radius: cfg.success_radius * scale,
            stuck_distance: cfg.stuck_distance * scale,
            stuck_window: cfg.stuck_window,
            max_time: cfg.max_time,
            rollover_deg: cfg.rollover_deg,
            capsize_cos: cfg.capsize_deg.to_radians().cos(),
            history: VecDeque::new(),
            next_sample: 0.0,
            slow_time: 0.0,
            last_xyz: (start.x, start.y, start.z),
        }
    }

    /// Planar distance from `pose` to the goal, metres.
    pub fn goal_distance(&self, pose: &Pose6) -> f64 {
        ((pose.x - self.goal[0]).powi(2) + (pose.y - self.goal[1]).powi(2)).sqrt()
    }

    /// Checks the rules after a physics step of `dt` seconds that ended at simulated time `t`
    /// with the vehicle at `pose`. Returns how the trial ends if it ends now: `Success`,
    /// `Rollover` (capsized, paper rules), `Stuck` or `Timeout`. Whether another failure is a
    /// rollover is decided at the end by [`Termination::classify`]. Call it after every step, in order, from the first one.
    pub fn check(&mut self, t: f64, dt: f64, pose: &Pose6) -> Option<Outcome> {
        let planar_goal = self.goal_distance(pose);
        match self.rules {
            Rules::Paper => {
                if planar_goal < self.success_radius {
                    return Some(Outcome::Success);
                }
                // vertical component of the body z axis (Z-Y-X Euler angles)
                if pose.roll.cos() * pose.pitch.cos() < self.capsize_cos {
                    return Some(Outcome::Rollover);
                }
                if t + 1e-9 >= self.next_sample {
                    self.history.push_back((t, pose.x, pose.y));
                    self.next_sample += 0.1;
                    while self
                        .history
                        .front()
                        .is_some_and(|h| h.0 < t - self.stuck_window - 1e-9)
                    {
                        self.history.pop_front();
                    }
                    let full_window = self
                        .history
                        .front()
                        .is_some_and(|h| h.0 <= t - self.stuck_window + 0.1 + 1e-9);
                    if full_window
                        && self.history.iter().all(|h| {
                            ((h.1 - pose.x).powi(2) + (h.2 - pose.y).powi(2)).sqrt()
                                < self.stuck_distance
                        })
                    {
                        return Some(Outcome::Stuck);
                    }
                }
                if t >= self.max_time - 1e-9 {
                    return Some(Outcome::Timeout);
                }
            }
            Rules::VertiBench => {
                let last = self.last_xyz;
                let step = ((pose.x - last.0).powi(2)
                    + (pose.y - last.1).powi(2)
                    + (pose.z - last.2).powi(2))
                .sqrt();
                self.last_xyz = (pose.x, pose.y, pose.z);
                // 0.01 m per 5 ms step is 2 m/s
                if step / dt < 2.0 {
                    self.slow_time += dt;
                } else {
                    self.slow_time = 0.0;
                }
                if self.slow_time >= self.stuck_window - 1e-9 {
                    return Some(Outcome::Stuck);
                }
                let d3 = (planar_goal.powi(2) + (pose.z - self.goal_z).powi(2)).sqrt();
                if d3 < 8.0 {
                    return Some(Outcome::Success);
                }
                if t >= self.max_time - 1e-9 {
                    return Some(Outcome::Timeout);
                }
            }
        }
        None
    }

    /// The final class of a trial that ended as `ended` with |roll| = `final_roll_deg` degrees
    /// at its end: under the paper rules a failed trial beyond the rollover threshold is a
    /// rollover; the reference rules have no rollover class.
    pub fn classify(&self, ended: Outcome, final_roll_deg: f64) -> Outcome {
        match ended {
            Outcome::Success | Outcome::Error => ended,
            _ if self.rules == Rules::Paper && final_roll_deg > self.rollover_deg => {
                Outcome::Rollover
            }
            other => other,
        }
    }
}
