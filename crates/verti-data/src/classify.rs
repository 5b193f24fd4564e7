//! The paper's failure classes (Verti-Bench §III-G.3): a failure is a *rollover* when the
//! vehicle's |roll| exceeds 30° at the end of the trial, and *stuck* when it moved no more than
//! 1 m during the last 10 s (with |roll| ≤ 30°). A pure function of the trajectory, so it can be
//! tested on hand-made trajectories and applied to any recorded trial.

use serde::{Deserialize, Serialize};

/// One sample of a trajectory: time (s), planar position (m), roll (rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrajectoryPoint {
    pub t: f64,
    pub x: f64,
    pub y: f64,
    pub roll: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FailureKind {
    Rollover,
    Stuck,
}

/// The thresholds of the rule; [`FailureRule::PAPER`] is the paper's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FailureRule {
    /// |roll| beyond this at the end is a rollover, degrees.
    pub rollover_deg: f64,
    /// Window (s) and distance (m, already scaled to the world) of the stuck rule.
    pub window: f64,
    pub distance: f64,
}

impl FailureRule {
    pub const PAPER: FailureRule = FailureRule {
        rollover_deg: 30.0,
        window: 10.0,
        distance: 1.0,
    };

    /// The paper's rule on a world of length scale `scale` (distances scale, angles do not).
    pub fn scaled(scale: f64) -> FailureRule {
        FailureRule {
            distance: FailureRule::PAPER.distance * scale,
            ..FailureRule::PAPER
        }
    }
}

/// Classifies the end of `trajectory` (samples in time order): `Rollover` when |roll| at the
/// last sample exceeds the threshold; else `Stuck` when the trajectory covers the whole window
/// and every sample of the last `window` seconds lies within `distance` of the final position
/// ("did not move more than 1 m", the same test as the benchmark's stuck rule); else `None`.
/// A trajectory shorter than the window can be a rollover but never stuck.
pub fn classify_failure(trajectory: &[TrajectoryPoint], rule: FailureRule) -> Option<FailureKind> {
    let end = trajectory.last()?;
    if end.roll.to_degrees().abs() > rule.rollover_deg {
        return Some(FailureKind::Rollover);
    }
    // 1 µs of slack so a window that starts exactly on a sample counts as covered
    let from = end.t - rule.window;
    if trajectory[0].t > from + 1e-6 {
        return None;
    }
    let still = trajectory
        .iter()
        .rev()
        .take_while(|p| p.t >= from - 1e-6)
        .all(|p| ((p.x - end.x).powi(2) + (p.y - end.y).powi(2)).sqrt() <= rule.distance);
    still.then_some(FailureKind::Stuck)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 10 Hz samples for `seconds`, moving at `speed` m/s along x with roll `roll_deg(t)`.
    fn drive(seconds: f64, speed: f64, roll_deg: impl Fn(f64) -> f64) -> Vec<TrajectoryPoint> {
        (0..=(seconds * 10.0).round() as usize)
            .map(|k| {
                let t = k as f64 * 0.1;
                TrajectoryPoint {
                    t,
                    x: speed * t,
                    y: 0.0,
                    roll: roll_deg(t).to_radians(),
                }
            })
            .collect()
    }

    const RULE: FailureRule = FailureRule::PAPER;

    #[test]
    fn rollover_at_the_end() {
        let tipping = drive(12.0, 2.0, |t| if t > 11.0 { 80.0 } else { 5.0 });
        assert_eq!(
            classify_failure(&tipping, RULE),
            Some(FailureKind::Rollover)
        );
        // negative roll counts by magnitude, and a short trial can roll over
        let short = drive(3.0, 2.0, |t| -12.0 * t);
        assert_eq!(classify_failure(&short, RULE), Some(FailureKind::Rollover));
    }

    #[test]
    fn stuck_when_still_for_the_window() {
        let mut traj = drive(5.0, 2.0, |_| 0.0);
        let x = traj.last().unwrap().x;
        // then 10.5 s creeping 0.05 m/s: 0.525 m in total
        for k in 1..=105 {
            let t = 5.0 + k as f64 * 0.1;
            traj.push(TrajectoryPoint {
                t,
                x: x + 0.05 * (t - 5.0),
                y: 0.0,
                roll: 20f64.to_radians(),
            });
        }
        assert_eq!(classify_failure(&traj, RULE), Some(FailureKind::Stuck));
    }

    #[test]
    fn neither_when_moving_and_upright() {
        let traj = drive(20.0, 1.0, |_| 10.0);
        assert_eq!(classify_failure(&traj, RULE), None);
        // still, but for less than the window: not (yet) stuck
        let still = drive(9.0, 0.0, |_| 0.0);
        assert_eq!(classify_failure(&still, RULE), None);
        assert_eq!(classify_failure(&[], RULE), None);
    }

    #[test]
    fn borderline_cases() {
        // exactly 30° is not a rollover (the rule is "> 30°"); just above is
        let at = drive(12.0, 0.0, |_| 30.0);
        assert_eq!(classify_failure(&at, RULE), Some(FailureKind::Stuck));
        let above = drive(12.0, 2.0, |_| 30.001);
        assert_eq!(classify_failure(&above, RULE), Some(FailureKind::Rollover));
        // exactly 1 m in exactly 10 s is stuck ("not more than 1 m"); 1.01 m is not
        let one = drive(10.0, 0.1, |_| 0.0);
        assert_eq!(classify_failure(&one, RULE), Some(FailureKind::Stuck));
        let more = drive(10.0, 0.101, |_| 0.0);
        assert_eq!(classify_failure(&more, RULE), None);
        // distances scale with the world: 0.1 m in 10 s at 1/10 scale is at the limit
        let small = drive(10.0, 0.0101, |_| 0.0);
        assert_eq!(classify_failure(&small, FailureRule::scaled(0.1)), None);
        assert_eq!(
            classify_failure(&drive(10.0, 0.0099, |_| 0.0), FailureRule::scaled(0.1)),
            Some(FailureKind::Stuck)
        );
    }
}
