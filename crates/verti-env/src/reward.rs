//! The default reward of the navigation environment.

use verti_bench::episode::Outcome;
use verti_bench::observation::Pose6;

/// The default reward: the reference RL reward of Verti-Bench (spec §6.4) with its z-target
/// bug fixed. The reference measures progress as the 3-D distance to the local goal placed at
/// z = 0, so climbing or descending changes the reward as much as driving toward the goal;
/// here the distance is planar (the goal taken at the vehicle's own height). The local goal is
/// also held fixed over a step (the one chosen before it), so a lookahead jump is not paid as
/// progress.
///
/// Per control step: `progress · (d_before − d_after)`; `−no_progress_penalty` when the
/// progress is slower than `no_progress_speed` (full-scale m/s, scaled by √scale: the
/// reference's 0.01 m per 5 ms step is 2 m/s); for roll and pitch beyond `tilt_threshold_deg`
/// a penalty `−w · (|a| / threshold) · (|a| − threshold)` (radians); and at the end of an
/// episode a bonus or penalty by outcome (the timeout one grows by `timeout_per_metre` per
/// metre left to the goal). The reference applies the per-step terms every 5 ms; here they
/// apply once per control step.
#[derive(Clone, Debug, PartialEq)]
pub struct RewardConfig {
    pub progress: f64,
    pub no_progress_penalty: f64,
    pub no_progress_speed: f64,
    pub roll_weight: f64,
    pub pitch_weight: f64,
    pub tilt_threshold_deg: f64,
    pub success: f64,
    pub timeout: f64,
    pub timeout_per_metre: f64,
    pub stuck: f64,
    pub rollover: f64,
    pub error: f64,
}

impl Default for RewardConfig {
    fn default() -> Self {
        RewardConfig {
            progress: 50.0,
            no_progress_penalty: 10.0,
            no_progress_speed: 2.0,
            roll_weight: 20.0,
            pitch_weight: 20.0,
            tilt_threshold_deg: 30.0,
            success: 3000.0,
            timeout: -100.0,
            timeout_per_metre: -10.0,
            stuck: -300.0,
            // the reference has no rollover class: a rolled vehicle ends stuck (-300) there
            rollover: -300.0,
            // the reference's harshest penalty (leaving the map, -600) for a blown-up simulation
            error: -600.0,
        }
    }
}

impl RewardConfig {
    pub(crate) fn validate(&self) -> Result<(), String> {
        let all = [
            ("progress", self.progress),
            ("no_progress_penalty", self.no_progress_penalty),
            ("no_progress_speed", self.no_progress_speed),
            ("roll_weight", self.roll_weight),
            ("pitch_weight", self.pitch_weight),
            ("tilt_threshold_deg", self.tilt_threshold_deg),
            ("success", self.success),
            ("timeout", self.timeout),
            ("timeout_per_metre", self.timeout_per_metre),
            ("stuck", self.stuck),
            ("rollover", self.rollover),
            ("error", self.error),
        ];
        for (name, v) in all {
            if !v.is_finite() {
                return Err(format!("reward weight {name} = {v} is not a finite number"));
            }
        }
        if !(self.tilt_threshold_deg > 0.0 && self.tilt_threshold_deg < 180.0) {
            return Err(format!(
                "reward tilt_threshold_deg = {} must be in (0, 180)",
                self.tilt_threshold_deg
            ));
        }
        Ok(())
    }
}

/// The parts of one step's default reward (their sum is the reward).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RewardTerms {
    pub progress: f64,
    pub no_progress: f64,
    pub roll: f64,
    pub pitch: f64,
    pub terminal: f64,
}

impl RewardTerms {
    pub fn total(&self) -> f64 {
        self.progress + self.no_progress + self.roll + self.pitch + self.terminal
    }
}

/// What one control step did, as the reward sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepProgress {
    /// Planar distance to the local goal (held over the step) before and after the step, m.
    pub local_goal_before: f64,
    pub local_goal_after: f64,
    /// Pose after the step.
    pub pose: Pose6,
    /// How the episode ended in this step, if it did.
    pub outcome: Option<Outcome>,
    /// Planar distance to the goal after the step, m.
    pub goal_distance: f64,
    /// Length scale of the world.
    pub world_scale: f64,
    /// Length of the control step, s.
    pub period: f64,
}

impl RewardConfig {
    /// The reward terms of one control step.
    pub fn terms(&self, s: &StepProgress) -> RewardTerms {
        let gained = s.local_goal_before - s.local_goal_after;
        let threshold = self.tilt_threshold_deg.to_radians();
        let tilt = |a: f64, weight: f64| {
            let a = a.abs();
            if a > threshold {
                -weight * (a / threshold) * (a - threshold)
            } else {
                0.0
            }
        };
        let terminal = match s.outcome {
            None => 0.0,
            Some(Outcome::Success) => self.success,
            Some(Outcome::Timeout) => self.timeout + self.timeout_per_metre * s.goal_distance,
            Some(Outcome::Stuck) => self.stuck,
            Some(Outcome::Rollover) => self.rollover,
            Some(Outcome::Error) => self.error,
        };
        RewardTerms {
            progress: self.progress * gained,
            no_progress: if gained.abs() < self.no_progress_speed * s.world_scale.sqrt() * s.period
            {
                -self.no_progress_penalty
            } else {
                0.0
            },
            roll: tilt(s.pose.roll, self.roll_weight),
            pitch: tilt(s.pose.pitch, self.pitch_weight),
            terminal,
        }
    }
}
