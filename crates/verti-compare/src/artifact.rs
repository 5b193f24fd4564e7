//! Reference trials that record an artifact of the reference engine rather than physics, and so
//! are left out of the comparison (and listed) instead of being taken as a target.
//!
//! The one known so far is Chrono's SCM letting the chassis fall through soft soil: SCM holds
//! only the wheels (each has its own soil domain), so once a capsized or high-centred body's
//! wheels no longer carry it, nothing stops the chassis. In the shared snow set one trial's
//! chassis ends 3.3 m below the undeformed ground, still sinking at about 4 m/s, and the trial
//! is scored a rollover. Soft snow does sink a vehicle, but by less than its wheels' size: the
//! other reference trials' chassis reach at most 0.73 m below the ground. The rule below draws
//! the line at one wheel diameter, the depth at which verti's own soil floor holds a body
//! (`Model::soil_floor`): deeper than that the wheels are wholly under the surface and cannot be
//! what holds the vehicle.

use crate::reference::{RefTask, Sample};
use serde::Serialize;

/// A reference trial left out of the comparison, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Excluded {
    pub world: String,
    pub world_index: u32,
    pub pair: u32,
    /// The ground the trial was run on.
    pub ground: String,
    /// How the reference scored the trial.
    pub reference_outcome: verti_bench::Outcome,
    /// What is wrong with it, in words with the numbers.
    pub reason: String,
}

/// The first sample at which the chassis reference is more than `depth` metres below the
/// undeformed ground (`agl`, when the trajectory records it), described; `None` when there is
/// none.
pub fn fall_through(trajectory: &[Sample], depth: f64) -> Option<String> {
    let first = trajectory.iter().position(|s| s.agl < -depth)?;
    let deepest = trajectory[first..]
        .iter()
        .map(|s| s.agl)
        .filter(|a| a.is_finite())
        .fold(f64::INFINITY, f64::min);
    Some(format!(
        "the chassis falls through the ground: {:.2} m below it at {:.1} s (deeper than one wheel \
         diameter, {depth:.2} m), {:.2} m at the deepest",
        -trajectory[first].agl, trajectory[first].t, -deepest
    ))
}

/// Splits `tasks` into those to compare and those whose reference trial is an artifact (see
/// the module's documentation); `depth` is one wheel diameter of the vehicle.
pub fn split_artifacts(tasks: Vec<&RefTask>, depth: f64) -> (Vec<&RefTask>, Vec<Excluded>) {
    let mut kept = Vec::new();
    let mut excluded = Vec::new();
    for t in tasks {
        match fall_through(&t.trajectory, depth) {
            None => kept.push(t),
            Some(reason) => {
                let o = &t.outcome;
                excluded.push(Excluded {
                    world: o.world.clone(),
                    world_index: o.world_index,
                    pair: o.pair,
                    ground: o.ground.name(),
                    reference_outcome: o.outcome,
                    reason,
                });
            }
        }
    }
    (kept, excluded)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(t: f64, agl: f64) -> Sample {
        let mut s = Sample::pose(t, 0.0, 0.0, 0.0, 0.0);
        s.agl = agl;
        s
    }

    #[test]
    fn only_a_chassis_below_one_wheel_diameter_is_a_fall_through() {
        let sinking = [at(0.1, 0.9), at(0.2, 0.2), at(0.3, -0.73), at(0.4, -0.5)];
        assert_eq!(
            fall_through(&sinking, 0.934),
            None,
            "deep sinkage is physics"
        );
        let falling = [at(0.1, 0.5), at(0.2, -0.6), at(0.3, -1.2), at(0.4, -3.32)];
        assert_eq!(
            fall_through(&falling, 0.934).unwrap(),
            "the chassis falls through the ground: 1.20 m below it at 0.3 s (deeper than one \
             wheel diameter, 0.93 m), 3.32 m at the deepest"
        );
        let unrecorded = [at(0.1, f64::NAN), at(0.2, f64::NAN)];
        assert_eq!(fall_through(&unrecorded, 0.934), None, "no agl, no finding");
    }
}
