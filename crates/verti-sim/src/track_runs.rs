//! The geometry of a track's raised ends: where the track leaves the ground at the first road
//! wheel, runs straight up to the sprocket and wraps it, and likewise from the last road wheel
//! to the idler. Those runs meet a rock or a ridge before the road wheels do, and the moving
//! track carries the vehicle over it; `contact::track_run` turns the points below into forces.
//!
//! Each side is a profile in the chassis' x–z plane: the straight run is the lower common
//! tangent of the road wheel's circle (centre at the wheel's current travel, so the run follows
//! the suspension) and the roller's circle, the arc the part of the roller's circle from that
//! tangent point round to 50° above the horizontal. Every profile point has its outward normal
//! `n`; the track's surface there moves along `(n_z, −n_x)` relative to the hull at the road
//! wheels' rim speed (a loop turning the same way everywhere: backward along the bottom, down
//! the front run, up the rear one). Between neighbouring road wheels the track spans their
//! common tangent, a little inside it ([`SPAN_INSET`]), so that it carries the vehicle only
//! where something pokes up between two road wheels. The profile repeats on two lines across
//! the track, at a quarter of its width either side of its centre (each line stands for half
//! the width).

use crate::spec::VehicleSpec;
use verti_core::Vec3;

/// Largest number of profile points on one side (one line): both ends, and the spans between
/// up to 8 road wheels.
pub(crate) const MAX_PROFILE: usize = 2 * (MAX_RUN_POINTS + ARC_POINTS) + 7 * MAX_RUN_POINTS;
/// Straight-run points per end at most (their spacing grows on a longer run).
const MAX_RUN_POINTS: usize = 12;
/// Arc points per roller: every 20° from straight down to 50° above the horizontal (11 cm
/// apart on the M113's sprocket).
const ARC_POINTS: usize = 8;
/// Wanted spacing of the straight run's points at full scale \[m\] (a third of a road wheel's
/// radius: a rock's right-angled edge under a run inclined 20–30° sinks at most about a fifth
/// of the spacing, 2 cm, into the run before a point meets it). The spans between road wheels
/// take half as many.
const RUN_SPACING: f64 = 0.1;
/// How far the track between two road wheels lies inside their common tangent \[m at full
/// scale\]: four times a road wheel's static tyre deflection (M113: 9.8 kN on 2e6 N/m, 5 mm),
/// so that on flat ground the road wheels alone carry the vehicle (a real track bends freely
/// at its pins between them) while a rock edge or a crest that pokes up between two road
/// wheels meets the track and the track carries the vehicle over it.
const SPAN_INSET: f64 = 0.02;

/// The two ends of one side's track, fixed parts in the chassis frame about the centre of mass.
#[derive(Clone, Debug)]
pub(crate) struct TrackSide {
    /// The side's spin group (its road wheels and track).
    pub group: usize,
    /// The side's road wheels (wheel indices) from front to rear.
    pub wheels: Vec<usize>,
    /// Lateral positions of the two contact lines.
    pub lines: [f64; 2],
}

/// Both sides' raised ends and their contact constants.
#[derive(Clone, Debug)]
pub(crate) struct TrackRuns {
    pub sides: Vec<TrackSide>,
    /// Sprocket and idler centres (x, z about the centre of mass) and radii.
    pub sprocket: (f64, f64, f64),
    pub idler: (f64, f64, f64),
    /// The road wheels' radius: the track's speed is the side's spin times it.
    pub wheel_radius: f64,
    /// Wanted spacing of the points on a straight span, and the inset of the spans between
    /// road wheels \[m\].
    pub spacing: f64,
    pub inset: f64,
    /// Outward normals (x, z) of the arc points, sprocket turning forward from straight down,
    /// idler backward.
    pub sprocket_arc: [(f64, f64); ARC_POINTS],
    pub idler_arc: [(f64, f64); ARC_POINTS],
    /// Normal stiffness \[N/m\] and damping \[N s/m\] of one profile point on one line.
    pub stiffness: f64,
    pub damping: f64,
    /// The track pads' friction coefficient.
    pub mu: f64,
}

/// One point of a side's profile: position (x, z about the centre of mass) and outward normal.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ProfilePoint {
    pub x: f64,
    pub z: f64,
    pub nx: f64,
    pub nz: f64,
}

impl ProfilePoint {
    /// The track surface's direction of motion here, relative to the hull, per unit of forward
    /// track speed (chassis frame).
    #[inline]
    pub fn belt(&self) -> Vec3 {
        Vec3::new(self.nz, 0.0, -self.nx)
    }
}

impl TrackRuns {
    /// The raised ends of a validated tracked `spec` whose track gives `runs`; `com` the
    /// centre of mass, `groups` each wheel's spin group, `wheels` each wheel's (x, y) in the
    /// reference frame; `body_stiffness`, `body_damping` the hull's per-point contact constants.
    pub fn compile(
        spec: &VehicleSpec,
        com: Vec3,
        group_of: &[usize],
        wheels: &[(f64, f64)],
        body_stiffness: f64,
        body_damping: f64,
    ) -> Option<TrackRuns> {
        let runs = spec.track?.runs?;
        let r = spec.axles[0].wheel.radius;
        let spacing = RUN_SPACING * spec.scale;
        let arc = |turn: f64| {
            std::array::from_fn(|k| {
                let a = -std::f64::consts::FRAC_PI_2 + turn * (k as f64) * 20f64.to_radians();
                (libm::cos(a), libm::sin(a))
            })
        };
        // the sides: their groups, and their road wheels from front to rear
        let mut sides: Vec<TrackSide> = Vec::new();
        for (w, &(_, y)) in wheels.iter().enumerate() {
            let g = group_of[w];
            let quarter = 0.25 * spec.axles[w / 2].wheel.width;
            match sides.iter_mut().find(|s| s.group == g) {
                Some(s) => s.wheels.push(w),
                None => sides.push(TrackSide {
                    group: g,
                    wheels: vec![w],
                    lines: [y - com.y - quarter, y - com.y + quarter],
                }),
            }
        }
        for s in &mut sides {
            s.wheels
                .sort_by(|&a, &b| wheels[b].0.total_cmp(&wheels[a].0).then(a.cmp(&b)));
        }
        Some(TrackRuns {
            sides,
            sprocket: (
                runs.sprocket.x - com.x,
                runs.sprocket.z - com.z,
                runs.sprocket.radius,
            ),
            idler: (
                runs.idler.x - com.x,
                runs.idler.z - com.z,
                runs.idler.radius,
            ),
            wheel_radius: r,
            spacing,
            inset: SPAN_INSET * spec.scale,
            sprocket_arc: arc(1.0),
            idler_arc: arc(-1.0),
            // One point across the track's width (its two lines together) is as stiff as one
            // point of the hull's lattice; damped at a quarter of the hull's rate, so that even
            // all four ends pressed flat at once stay within the explicit step's damping limit
            // (c·h/m < 2 with ~130 points).
            stiffness: 0.5 * body_stiffness,
            damping: 0.25 * body_damping,
            mu: spec.tyre.friction,
        })
    }

    /// One side's profile with its road wheels' centres at `hubs` (x, z about the centre of
    /// mass at their current travel, front to rear): writes the points to `out` and returns
    /// how many.
    pub fn profile(&self, hubs: &[(f64, f64)], out: &mut [ProfilePoint; MAX_PROFILE]) -> usize {
        let r = self.wheel_radius;
        let mut n = 0;
        let mut push = |x: f64, z: f64, nx: f64, nz: f64| {
            out[n] = ProfilePoint { x, z, nx, nz };
            n += 1;
        };
        let (Some(&front), Some(&rear)) = (hubs.first(), hubs.last()) else {
            return 0;
        };
        // the spans between neighbouring road wheels, inset (their ends are the wheels' own)
        for pair in hubs.windows(2) {
            let (nx, nz) = lower_tangent(pair[0], r, pair[1], r);
            let a = (
                pair[0].0 + (r - self.inset) * nx,
                pair[0].1 + (r - self.inset) * nz,
            );
            let b = (
                pair[1].0 + (r - self.inset) * nx,
                pair[1].1 + (r - self.inset) * nz,
            );
            // a span bridges a rock edge only now and then: half as many points
            let count = self.points_on(a, b).div_ceil(2).max(2);
            for k in 1..count {
                let t = k as f64 / count as f64;
                push(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, nx, nz);
            }
        }
        let ends = [
            (front, self.sprocket, &self.sprocket_arc, 1.0),
            (rear, self.idler, &self.idler_arc, -1.0),
        ];
        for (hub, (cx, cz, rc), arc, turn) in ends {
            let (nx, nz) = lower_tangent(hub, r, (cx, cz), rc);
            let a = (hub.0 + r * nx, hub.1 + r * nz);
            let b = (cx + rc * nx, cz + rc * nz);
            let count = self.points_on(a, b);
            for k in 1..=count {
                let t = k as f64 / count as f64;
                push(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, nx, nz);
            }
            // the roller's arc beyond the run's tangent point (turning forward round the
            // sprocket, backward round the idler)
            for &(mx, mz) in arc.iter() {
                if turn * (nx * mz - nz * mx) > 1e-9 {
                    push(cx + rc * mx, cz + rc * mz, mx, mz);
                }
            }
        }
        n
    }

    /// Intervals on a straight span from `a` to `b`: its length over the wanted spacing.
    #[inline]
    fn points_on(&self, a: (f64, f64), b: (f64, f64)) -> usize {
        let span = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        ((span / self.spacing).ceil() as usize).clamp(2, MAX_RUN_POINTS)
    }
}

/// The outward normal (x, z) of the lower common tangent of two circles (centres `a`, `b`,
/// radii `ra`, `rb`; validation keeps them from containing one another): the unit `n` with
/// n·(b − a) = ra − rb and a negative z component, so that a + ra·n and b + rb·n lie on one
/// line perpendicular to `n`.
#[inline]
pub(crate) fn lower_tangent(a: (f64, f64), ra: f64, b: (f64, f64), rb: f64) -> (f64, f64) {
    let (dx, dz) = (b.0 - a.0, b.1 - a.1);
    let d = (dx * dx + dz * dz).sqrt();
    let (ux, uz) = (dx / d, dz / d);
    let s = ((ra - rb) / d).clamp(-1.0, 1.0);
    let c = (1.0 - s * s).sqrt();
    // the perpendicular pointing down
    let (px, pz) = if ux >= 0.0 { (uz, -ux) } else { (-uz, ux) };
    (ux * s + px * c, uz * s + pz * c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lower_tangent_touches_both_circles() {
        for (a, ra, b, rb) in [
            ((-0.655, -0.266), 0.305, (0.0, 0.0), 0.32),
            ((-3.322, -0.266), 0.305, (-3.95, -0.12), 0.315),
            ((0.0, 0.0), 0.5, (1.0, 0.3), 0.1),
        ] {
            let (nx, nz) = lower_tangent(a, ra, b, rb);
            assert!((nx * nx + nz * nz - 1.0).abs() < 1e-12);
            assert!(nz < 0.0);
            // both tangent points on one line perpendicular to n
            let pa = (a.0 + ra * nx, a.1 + ra * nz);
            let pb = (b.0 + rb * nx, b.1 + rb * nz);
            let along = (pb.0 - pa.0) * nx + (pb.1 - pa.1) * nz;
            assert!(along.abs() < 1e-12, "{along}");
            // and every other point of either circle on the inner side of that line
            for k in 0..72 {
                let t = k as f64 * 5f64.to_radians();
                for (c, r) in [(a, ra), (b, rb)] {
                    let q = (c.0 + r * t.cos(), c.1 + r * t.sin());
                    let s = (q.0 - pa.0) * nx + (q.1 - pa.1) * nz;
                    assert!(s <= 1e-12, "{s}");
                }
            }
        }
    }
}
