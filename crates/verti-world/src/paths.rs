//! Global paths for a holonomic point mass (paper §III-D): A* on the heightfield's vertex grid
//! around obstacles inflated by a clearance, then smoothed by line-of-sight shortcuts and
//! resampled at one cell spacing.
//!
//! Unlike the reference planner (spec §8 item 7), diagonal moves cost √2 cells and the
//! heuristic is the octile distance, which is admissible and consistent, so the grid path is
//! a shortest one. A node is free when its distance to every obstacle footprint is at least
//! `clearance + 0.75 cell`; since the distance is 1-Lipschitz and every point of a grid edge is
//! within 0.71 cell of an end, every edge between free nodes keeps the full clearance, and the
//! shortcuts are checked against the exact clearance, so the final path never enters an
//! inflated obstacle.

use crate::obstacle::{Obstacle, segment_distance};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Default clearance from obstacle footprints at full scale: HMMWV half-width (1.1 m) plus a
/// margin. Multiplied by the world scale.
pub const DEFAULT_CLEARANCE: f64 = 2.5;

/// Occupancy of the vertex grid for one clearance.
#[derive(Clone, Debug)]
pub struct PlanningGrid<'a> {
    n: usize,
    cell: f64,
    half: f64,
    clearance: f64,
    blocked: Vec<bool>,
    obstacles: &'a [Obstacle],
}

impl<'a> PlanningGrid<'a> {
    pub fn new(n: usize, cell: f64, obstacles: &'a [Obstacle], clearance: f64) -> Self {
        let half = 0.5 * (n - 1) as f64 * cell;
        let margin = clearance + 0.75 * cell;
        let mut blocked = vec![false; n * n];
        for o in obstacles {
            // only vertices within the obstacle's bounding circle plus the margin can be blocked
            let p = o.position();
            let reach = o.radius_xy() + margin;
            let c0 = (((p.x - reach + half) / cell).floor().max(0.0)) as usize;
            let c1 = ((((p.x + reach + half) / cell).ceil()).max(0.0) as usize).min(n - 1);
            let r0 = (((half - (p.y + reach)) / cell).floor().max(0.0)) as usize;
            let r1 = ((((half - (p.y - reach)) / cell).ceil()).max(0.0) as usize).min(n - 1);
            for r in r0..=r1 {
                for c in c0..=c1 {
                    let x = c as f64 * cell - half;
                    let y = half - r as f64 * cell;
                    if o.footprint_distance(x, y) < margin {
                        blocked[r * n + c] = true;
                    }
                }
            }
        }
        PlanningGrid {
            n,
            cell,
            half,
            clearance,
            blocked,
            obstacles,
        }
    }

    pub fn is_blocked(&self, row: usize, col: usize) -> bool {
        self.blocked[row * self.n + col]
    }

    fn xy(&self, idx: usize) -> [f64; 2] {
        let (r, c) = (idx / self.n, idx % self.n);
        [
            c as f64 * self.cell - self.half,
            self.half - r as f64 * self.cell,
        ]
    }

    fn nearest(&self, p: [f64; 2]) -> usize {
        let m = (self.n - 1) as f64;
        let c = ((p[0] + self.half) / self.cell).round().clamp(0.0, m) as usize;
        let r = ((self.half - p[1]) / self.cell).round().clamp(0.0, m) as usize;
        r * self.n + c
    }

    /// Distance from (x, y) to the nearest obstacle footprint.
    pub fn clearance_at(&self, x: f64, y: f64) -> f64 {
        Self::clearance_among(self.obstacles.iter(), self.clearance + self.cell, x, y)
    }

    /// [`Self::clearance_at`] over some of the obstacles: the nearest footprint among those
    /// whose bounding circle is nearer than `reach`.
    fn clearance_among<'o>(
        obstacles: impl Iterator<Item = &'o Obstacle>,
        reach: f64,
        x: f64,
        y: f64,
    ) -> f64 {
        obstacles
            .filter(|o| {
                let p = o.position();
                let d = ((p.x - x).powi(2) + (p.y - y).powi(2)).sqrt();
                d - o.radius_xy() < reach
            })
            .map(|o| o.footprint_distance(x, y))
            .fold(f64::INFINITY, f64::min)
    }

    /// True when every point of the segment keeps the clearance. Samples are at most
    /// `step` apart and must clear `clearance + step / 2`: the footprint distance is
    /// 1-Lipschitz, so every point between two samples then clears `clearance` exactly.
    ///
    /// Only obstacles whose bounding circle comes within that of the segment are sampled: a
    /// footprint is no nearer to a point than its bounding circle, so the others clear every
    /// sample (by a millimetre's margin over rounding), and the answer is the one sampling
    /// them all gives. Path shortcutting tests thousands of segments per path, and this was
    /// most of the time it takes to build a world set.
    pub fn segment_clear(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        self.segment_clear_in(a, b, &mut Vec::new())
    }

    /// [`Self::segment_clear`] gathering the nearby obstacles in `near`, a buffer the caller
    /// keeps across the thousands of segments path shortcutting tests.
    fn segment_clear_in<'s>(
        &'s self,
        a: [f64; 2],
        b: [f64; 2],
        near: &mut Vec<&'s Obstacle>,
    ) -> bool {
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let steps = (len / (0.2 * self.cell)).ceil().max(1.0) as usize;
        let step = len / steps as f64;
        let needed = self.clearance + 0.5 * step;
        near.clear();
        near.extend(self.obstacles.iter().filter(|o| {
            let p = o.position();
            segment_distance(a, b, [p.x, p.y]) - o.radius_xy() < needed + 1e-3
        }));
        let reach = self.clearance + self.cell;
        (0..=steps).all(|i| {
            let t = i as f64 / steps as f64;
            let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            Self::clearance_among(near.iter().copied(), reach, x, y) >= needed
        })
    }

    /// Shortest 8-connected grid path between the vertices nearest `start` and `goal`, as world
    /// points with the exact start and goal at the ends. `None` when the goal is unreachable.
    pub fn astar(&self, start: [f64; 2], goal: [f64; 2]) -> Option<Vec<[f64; 2]>> {
        let n = self.n;
        let s = self.nearest(start);
        let g = self.nearest(goal);
        let (gr, gc) = ((g / n) as i64, (g % n) as i64);
        let octile = |idx: usize| {
            let dr = ((idx / n) as i64 - gr).unsigned_abs() as f64;
            let dc = ((idx % n) as i64 - gc).unsigned_abs() as f64;
            (dr.max(dc) + (std::f64::consts::SQRT_2 - 1.0) * dr.min(dc)) * self.cell
        };
        let mut best = vec![f64::INFINITY; n * n];
        let mut parent = vec![usize::MAX; n * n];
        let mut closed = vec![false; n * n];
        let mut open = BinaryHeap::new();
        best[s] = 0.0;
        open.push(Node {
            f: octile(s),
            h: octile(s),
            idx: s,
        });
        const MOVES: [(i64, i64, f64); 8] = [
            (0, 1, 1.0),
            (1, 0, 1.0),
            (0, -1, 1.0),
            (-1, 0, 1.0),
            (1, 1, std::f64::consts::SQRT_2),
            (1, -1, std::f64::consts::SQRT_2),
            (-1, 1, std::f64::consts::SQRT_2),
            (-1, -1, std::f64::consts::SQRT_2),
        ];
        while let Some(Node { idx, .. }) = open.pop() {
            if closed[idx] {
                continue;
            }
            closed[idx] = true;
            if idx == g {
                let mut cells = vec![g];
                while let Some(&last) = cells.last() {
                    if last == s {
                        break;
                    }
                    cells.push(parent[last]);
                }
                cells.reverse();
                let mut pts: Vec<[f64; 2]> = cells.iter().map(|&i| self.xy(i)).collect();
                pts[0] = start;
                let last = pts.len() - 1;
                if last == 0 {
                    pts.push(goal);
                } else {
                    pts[last] = goal;
                }
                return Some(pts);
            }
            let (r, c) = ((idx / n) as i64, (idx % n) as i64);
            for (dr, dc, cost) in MOVES {
                let (nr, nc) = (r + dr, c + dc);
                if nr < 0 || nc < 0 || nr >= n as i64 || nc >= n as i64 {
                    continue;
                }
                let j = nr as usize * n + nc as usize;
                if closed[j] || (self.blocked[j] && j != g) {
                    continue;
                }
                let cand = best[idx] + cost * self.cell;
                if cand < best[j] {
                    best[j] = cand;
                    parent[j] = idx;
                    let h = octile(j);
                    open.push(Node {
                        f: cand + h,
                        h,
                        idx: j,
                    });
                }
            }
        }
        None
    }

    /// Greedy line-of-sight shortcutting: from each kept point, jump to the farthest later
    /// point that can be reached in a straight line with full clearance.
    pub fn shortcut(&self, pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
        if pts.len() <= 2 {
            return pts.to_vec();
        }
        let mut out = vec![pts[0]];
        let mut near = Vec::new();
        let mut i = 0;
        while i < pts.len() - 1 {
            let mut j = i + 1;
            while j + 1 < pts.len() && self.segment_clear_in(pts[i], pts[j + 1], &mut near) {
                j += 1;
            }
            out.push(pts[j]);
            i = j;
        }
        out
    }

    /// A* + shortcuts + resampling at one cell: the global path from `start` to `goal`.
    pub fn plan(&self, start: [f64; 2], goal: [f64; 2]) -> Option<Vec<[f64; 2]>> {
        let raw = self.astar(start, goal)?;
        Some(resample(&self.shortcut(&raw), self.cell))
    }
}

/// Resamples a polyline at (at most) `spacing`, keeping every corner.
pub fn resample(pts: &[[f64; 2]], spacing: f64) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let k = (len / spacing).ceil().max(1.0) as usize;
        for i in 0..k {
            let t = i as f64 / k as f64;
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    if let Some(&last) = pts.last() {
        out.push(last);
    }
    out
}

#[derive(Clone, Copy, Debug)]
struct Node {
    f: f64,
    h: f64,
    idx: usize,
}
impl PartialEq for Node {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Node {}
impl PartialOrd for Node {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Node {
    /// Max-heap order reversed: smallest f first, then smallest h (deeper nodes), then index,
    /// so the search is fully deterministic.
    fn cmp(&self, o: &Self) -> Ordering {
        o.f.total_cmp(&self.f)
            .then(o.h.total_cmp(&self.h))
            .then(o.idx.cmp(&self.idx))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::obstacle::box_faces;
    use verti_core::Vec3;

    #[test]
    fn straight_line_when_free_and_optimal_lengths() {
        let grid = PlanningGrid::new(21, 1.0, &[], 1.0);
        let p = grid.plan([-8.0, -8.0], [8.0, 8.0]).unwrap();
        let len: f64 = p
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum();
        assert!((len - 16.0 * std::f64::consts::SQRT_2).abs() < 1e-9);
        // raw A* cost on a knight-like offset equals the octile distance
        let raw = grid.astar([0.0, 0.0], [5.0, 2.0]).unwrap();
        let raw_len: f64 = raw
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum();
        assert!((raw_len - (3.0 + 2.0 * std::f64::consts::SQRT_2)).abs() < 1e-9);
    }

    #[test]
    fn detours_around_a_wall_with_clearance() {
        let wall = Obstacle::rock(
            box_faces(Vec3::new(2.0, 30.0, 2.0)),
            1.0,
            Vec3::new(0.0, -5.0, 1.0),
            0.0,
        )
        .unwrap();
        let obstacles = vec![wall];
        let grid = PlanningGrid::new(41, 1.0, &obstacles, 1.5);
        let p = grid.plan([-10.0, 0.0], [10.0, 0.0]).unwrap();
        for w in p.windows(2) {
            assert!(grid.segment_clear(w[0], w[1]));
        }
        assert!(
            p.iter().any(|q| q[1] > 10.0 + 1.5),
            "path must go around the top of the wall"
        );
        assert_eq!(p[0], [-10.0, 0.0]);
        assert_eq!(*p.last().unwrap(), [10.0, 0.0]);
    }

    /// Sampling only the obstacles near a segment answers as sampling every obstacle does
    /// (the rule before), on random segments among random rocks and trees (a pre-filter 5 cm
    /// too tight fails it).
    #[test]
    fn segment_clear_answers_as_sampling_every_obstacle() {
        let mut rng = verti_core::Rng::new(7);
        let mut u = |lo: f64, hi: f64| lo + (hi - lo) * rng.uniform();
        let mut obstacles = Vec::new();
        for k in 0..40 {
            let at = Vec3::new(u(-30.0, 30.0), u(-30.0, 30.0), 1.0);
            obstacles.push(if k % 4 == 0 {
                Obstacle::tree(u(0.2, 0.6), 5.0, at).unwrap()
            } else {
                let size = Vec3::new(u(0.5, 3.0), u(0.5, 3.0), 2.0);
                Obstacle::rock(box_faces(size), 1.0, at, u(0.0, 6.3)).unwrap()
            });
        }
        let grid = PlanningGrid::new(65, 1.0, &obstacles, 2.5);
        let every_obstacle = |a: [f64; 2], b: [f64; 2]| {
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let steps = (len / 0.2).ceil().max(1.0) as usize;
            let needed = 2.5 + 0.5 * len / steps as f64;
            (0..=steps).all(|i| {
                let t = i as f64 / steps as f64;
                grid.clearance_at(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])) >= needed
            })
        };
        let (mut clear, mut blocked) = (0, 0);
        for _ in 0..3000 {
            let a = [u(-32.0, 32.0), u(-32.0, 32.0)];
            let b = [a[0] + u(-12.0, 12.0), a[1] + u(-12.0, 12.0)];
            let want = every_obstacle(a, b);
            assert_eq!(grid.segment_clear(a, b), want, "{a:?} -> {b:?}");
            if want { clear += 1 } else { blocked += 1 }
        }
        assert!(
            clear > 300 && blocked > 300,
            "{clear} clear, {blocked} blocked"
        );
    }

    #[test]
    fn unreachable_goal_gives_none() {
        // a ring of rocks around the goal
        let mut obstacles = Vec::new();
        for k in 0..16 {
            let a = k as f64 / 16.0 * std::f64::consts::TAU;
            obstacles.push(
                Obstacle::rock(
                    box_faces(Vec3::new(3.0, 3.0, 2.0)),
                    1.0,
                    Vec3::new(6.0 * a.cos(), 6.0 * a.sin(), 1.0),
                    a,
                )
                .unwrap(),
            );
        }
        let grid = PlanningGrid::new(41, 1.0, &obstacles, 1.0);
        assert!(grid.plan([-18.0, 0.0], [0.0, 0.0]).is_none());
    }
}
