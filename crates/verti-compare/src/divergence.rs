//! How far two runs of one task drift apart.
//!
//! * **Lateral offset**: for each sample of the compared run, its planar distance to the
//!   reference trajectory taken as a polyline. It is a distance to the path, not to where the
//!   reference was at the same moment, so a run that follows the same line at a different
//!   speed has offset 0; only leaving the reference's line counts.
//! * **Roll error**: |roll − roll_ref| at the same times, over the time both runs last.
//!
//! Both are summarised over a window from the start (the first 10 s, before differences have
//! compounded) and over the whole trial.

use crate::reference::Sample;
use serde::Serialize;

/// Samples closer in time than this are taken as simultaneous (both are on a 0.1 s grid).
const SAME_TIME: f64 = 1e-6;

/// Divergence over one window of time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Window {
    /// End of the window, s from the start; `None` for the whole trial.
    pub until: Option<f64>,
    /// Lateral offset of the compared run from the reference trajectory, m (mean, max).
    pub mean_lateral: f64,
    pub max_lateral: f64,
    /// |roll error| at common times, degrees (mean, max).
    pub mean_roll_error: f64,
    pub max_roll_error: f64,
    /// Samples of the compared run in the window, and of those, how many have a
    /// simultaneous reference sample.
    pub samples: usize,
    pub common_samples: usize,
}

/// Planar distance from `p` to the polyline `path` (to its point when it has one; NaN when
/// empty).
pub fn distance_to_polyline(path: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let point = |a: [f64; 2]| (p[0] - a[0]).hypot(p[1] - a[1]);
    match path {
        [] => f64::NAN,
        [a] => point(*a),
        _ => path
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
                let len2 = ex * ex + ey * ey;
                let s = if len2 > 0.0 {
                    (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (p[0] - a[0] - s * ex).hypot(p[1] - a[1] - s * ey)
            })
            .fold(f64::INFINITY, f64::min),
    }
}

/// Divergence of `run` from `reference` over the samples of `run` at times up to `until`
/// (`None`: all of them). Empty windows give NaN statistics.
pub fn divergence(reference: &[Sample], run: &[Sample], until: Option<f64>) -> Window {
    let end = until.unwrap_or(f64::INFINITY);
    let line: Vec<[f64; 2]> = reference.iter().map(|s| [s.x, s.y]).collect();
    let in_window: Vec<&Sample> = run.iter().filter(|s| s.t <= end + SAME_TIME).collect();
    let lateral: Vec<f64> = in_window
        .iter()
        .map(|s| distance_to_polyline(&line, [s.x, s.y]))
        .collect();
    // both are sorted by time: walk them together
    let mut roll_error = Vec::new();
    let mut k = 0;
    for s in &in_window {
        while k < reference.len() && reference[k].t < s.t - SAME_TIME {
            k += 1;
        }
        if let Some(r) = reference.get(k)
            && (r.t - s.t).abs() <= SAME_TIME
        {
            roll_error.push((s.roll - r.roll).abs());
        }
    }
    let (mean_lateral, max_lateral) = mean_max(&lateral);
    let (mean_roll_error, max_roll_error) = mean_max(&roll_error);
    Window {
        until,
        mean_lateral,
        max_lateral,
        mean_roll_error,
        max_roll_error,
        samples: in_window.len(),
        common_samples: roll_error.len(),
    }
}

/// Mean and maximum; NaN for none.
fn mean_max(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    (mean, v.iter().copied().fold(f64::NEG_INFINITY, f64::max))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(points: &[(f64, f64, f64, f64)]) -> Vec<Sample> {
        points
            .iter()
            .map(|&(t, x, y, roll)| Sample::pose(t, x, y, roll, 0.0))
            .collect()
    }

    #[test]
    fn a_parallel_offset_of_2_m_is_a_lateral_offset_of_2() {
        // reference: straight east along y = 0 at 3 m/s for 20 s; compared: 2 m to the north,
        // at another speed (which must not count), with 1° more roll
        let reference = run(&(1..=200)
            .map(|k| (0.1 * f64::from(k), 0.3 * f64::from(k), 0.0, 5.0))
            .collect::<Vec<_>>());
        let compared = run(&(1..=150)
            .map(|k| (0.1 * f64::from(k), 0.35 * f64::from(k), 2.0, 6.0))
            .collect::<Vec<_>>());
        let w = divergence(&reference, &compared, Some(10.0));
        assert!((w.mean_lateral - 2.0).abs() < 1e-12, "{w:?}");
        assert!((w.max_lateral - 2.0).abs() < 1e-12);
        assert!((w.mean_roll_error - 1.0).abs() < 1e-12);
        assert_eq!((w.samples, w.common_samples), (100, 100));
        let all = divergence(&reference, &compared, None);
        assert_eq!((all.samples, all.common_samples), (150, 150));
        assert!((all.mean_lateral - 2.0).abs() < 1e-12);
    }

    #[test]
    fn offsets_beyond_the_reference_end_and_partial_overlap() {
        // the reference stops at x = 10 after 1 s; the run goes on to x = 14 on the line,
        // 2 s long: offsets 0 up to x = 10, then 1, 2, 3, 4 m past the end
        let reference = run(&(1..=10)
            .map(|k| (0.1 * f64::from(k), f64::from(k), 0.0, 0.0))
            .collect::<Vec<_>>());
        let compared = run(&(1..=14)
            .map(|k| (0.1 * f64::from(k), f64::from(k), 0.0, 3.0))
            .collect::<Vec<_>>());
        let w = divergence(&reference, &compared, None);
        assert_eq!(w.max_lateral, 4.0);
        assert!((w.mean_lateral - 10.0 / 14.0).abs() < 1e-12);
        // roll compared only while both run
        assert_eq!((w.common_samples, w.max_roll_error), (10, 3.0));
        // an empty window
        let none = divergence(&reference, &[], Some(10.0));
        assert!(none.mean_lateral.is_nan() && none.samples == 0);
        assert_eq!(distance_to_polyline(&[[0.0, 0.0]], [3.0, 4.0]), 5.0);
        assert!(distance_to_polyline(&[], [0.0, 0.0]).is_nan());
    }
}
