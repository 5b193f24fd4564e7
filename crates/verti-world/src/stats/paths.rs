//! Global paths: how many tasks have one, their length, detour over the straight line and
//! waypoint count.

use super::Summary;
use crate::world::World;
use serde::Serialize;

/// Global path figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PathStats {
    /// Tasks that have a path (at least two waypoints).
    pub planned: usize,
    /// Tasks without a path (no path stored, or fewer than two waypoints).
    pub missing: usize,
    /// Path length, metres.
    pub length: Option<Summary>,
    /// Path length over the straight start-goal distance (1 = straight line).
    pub straight_ratio: Option<Summary>,
    /// Waypoints per path.
    pub waypoints: Option<Summary>,
}

pub(super) fn path_stats(worlds: &[World]) -> PathStats {
    let (mut lengths, mut ratios, mut waypoints) = (Vec::new(), Vec::new(), Vec::new());
    let mut missing = 0usize;
    for w in worlds {
        for (i, t) in w.tasks.iter().enumerate() {
            match w.paths.get(i).filter(|p| p.points.len() >= 2) {
                Some(p) => {
                    let len = p.length();
                    lengths.push(len);
                    waypoints.push(p.points.len() as f64);
                    let d = t.distance();
                    if d > 0.0 {
                        ratios.push(len / d);
                    }
                }
                None => missing += 1,
            }
        }
    }
    PathStats {
        planned: lengths.len(),
        missing,
        length: Summary::of(lengths),
        straight_ratio: Summary::of(ratios),
        waypoints: Summary::of(waypoints),
    }
}
