//! Test fixtures shared by the tests of the report modules.

use crate::episode::{Outcome, Rules, TrialResult};
use crate::metrics::{AngleStats, SignalStats};
use ElevationLevel::*;
use ObstacleDensity::*;
use Outcome::*;
use TerrainType::*;
use verti_world::{ElevationLevel, ObstacleDensity, TerrainType};

/// A trial whose per-trial mean |roll| is `roll` and mean |pitch| is `pitch` (one sample
/// each, so mean = max = the value).
pub(super) fn trial(
    system: &str,
    task: u32,
    (level, terrain, density): (ElevationLevel, TerrainType, ObstacleDensity),
    outcome: Outcome,
    roll: f64,
    pitch: f64,
) -> TrialResult {
    let mut r = AngleStats::default();
    r.push_rad(roll.to_radians());
    let mut p = AngleStats::default();
    p.push_rad(pitch.to_radians());
    let mut throttle = SignalStats::default();
    for x in [0.5, 1.0] {
        throttle.push(x);
    }
    TrialResult {
        task,
        world: 1,
        pair: 1,
        world_name: "w".into(),
        level,
        terrain_type: terrain,
        density,
        system: system.into(),
        vehicle: "hmmwv".into(),
        rules: Rules::Paper,
        outcome,
        time: 60.0,
        traversal_time: None,
        roll: r,
        pitch: p,
        throttle,
        steering: SignalStats::default(),
        path_length: 10.0 * f64::from(task),
        final_distance: 0.0,
        final_roll: 0.0,
        error: None,
        wall_time: 0.0,
    }
}

pub(super) fn close(a: Option<f64>, b: f64) -> bool {
    a.is_some_and(|a| (a - b).abs() < 1e-9)
}

/// System A: 4 trials (2 successes, 1 rollover, 1 stuck); system B: 1 timeout, 1 error.
pub(super) fn sample() -> Vec<TrialResult> {
    let mut a1 = trial("A", 1, (Low, Rigid, Sparse), Success, 2.0, 4.0);
    a1.traversal_time = Some(20.0);
    let mut a2 = trial("A", 2, (Low, Deformable, Dense), Success, 4.0, 8.0);
    a2.traversal_time = Some(30.0);
    let a3 = trial("A", 3, (High, Rigid, Sparse), Rollover, 40.0, 10.0);
    let b1 = trial("B", 1, (Mid, Mixed, Medium), Timeout, 1.0, 1.0);
    let a4 = trial("A", 4, (Mid, Mixed, Medium), Stuck, 6.0, 2.0);
    let mut b2 = trial("B", 2, (Mid, Mixed, Medium), Error, 0.0, 0.0);
    // an error before the first step: no angle samples at all
    b2.roll = AngleStats::default();
    b2.pitch = AngleStats::default();
    vec![a1, a2, a3, b1, a4, b2]
}
