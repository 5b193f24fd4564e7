//! Where a rigid patch meets soil: the rigid ground there is a block with a side wall, not
//! only a top surface.
//!
//! The contact stages measure how deep a point is in rigid ground vertically, through the
//! surface above it. That is the shortest way out everywhere but at the edge of a rigid patch
//! beside soil: a wheel sunk 0.3 m in snow, or a hull or track end below the snow surface
//! (they pass through soil down to a floor, see `contact::body_ground`), that moves across
//! the edge into the rigid patch is under its surface by the whole sinkage, a few centimetres
//! from its side. Pushed up by that depth, it was launched: an M113 with one track sunk in
//! snow beside clay climbed into the air and over backwards on flat ground, and an HMMWV
//! driving out of snow onto a rigid patch was thrown 0.4 m up by its rear wheels. The edge
//! is a step as high as the sinkage, and a collision detector (Chrono's Bullet against a
//! patch's mesh or box) pushes along the shortest way out:
//!
//! * a point of the hull or of a track end in a rigid patch takes the shorter of the way up
//!   through the surface and the way sideways through a side the patch shares with soil;
//! * a wheel in soil meets the side's top edge as a curb: its disc against the point where
//!   the edge crosses the wheel's plane, pushed along the line from that point to the hub, so
//!   it climbs a step lower than its radius (a step higher than the hub is a wall). The
//!   wheel's own tread samples cannot resolve this: between two of them the corner is already
//!   centimetres into the disc when either finds it.
//!
//! Only worlds with both kinds of patch have such sides; elsewhere nothing changes.

use verti_core::Vec3;
use verti_world::World;
use verti_world::surface::PATCHES_PER_SIDE;

/// Bits of a patch's sides across which the ground changes kind (rigid to soil or back).
const WEST: u8 = 1;
const EAST: u8 = 2;
const NORTH: u8 = 4;
const SOUTH: u8 = 8;

/// A wheel: hub, axle (unit), radius.
pub(crate) type Disc = (Vec3, Vec3, f64);

/// A wheel's contact with the top edge of a rigid patch beside the soil its hub is over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Curb {
    /// Penetration of the wheel's disc \[m\] and the normal pushing it out (toward the hub).
    pub depth: f64,
    pub normal: Vec3,
    /// Contact point relative to the hub.
    pub arm: Vec3,
}

/// For every patch, the sides across which the ground changes kind (row-major, as the patch
/// grid): a rigid patch's sides bordering soil, a soil patch's sides bordering rigid ground.
#[derive(Clone, Debug)]
pub(crate) struct SoilEdges {
    sides: Vec<u8>,
    rigid: Vec<bool>,
    patch_size: f64,
    /// Half the patch grid's extent: patch (row, col) spans x from col·size − half.
    half: f64,
}

impl SoilEdges {
    /// The edges of `world`, or `None` when no rigid patch borders soil.
    pub fn new(world: &World) -> Option<SoilEdges> {
        let patches = world.patches.patches();
        let n = PATCHES_PER_SIDE;
        let rigid: Vec<bool> = patches.iter().map(|p| !p.surface.is_deformable()).collect();
        let mut sides = vec![0u8; n * n];
        for r in 0..n {
            for c in 0..n {
                let kind = rigid[r * n + c];
                let s = &mut sides[r * n + c];
                if c > 0 && rigid[r * n + c - 1] != kind {
                    *s |= WEST;
                }
                if c + 1 < n && rigid[r * n + c + 1] != kind {
                    *s |= EAST;
                }
                if r > 0 && rigid[(r - 1) * n + c] != kind {
                    *s |= NORTH;
                }
                if r + 1 < n && rigid[(r + 1) * n + c] != kind {
                    *s |= SOUTH;
                }
            }
        }
        if sides.iter().all(|&s| s == 0) {
            return None;
        }
        let patch_size = world.patches.patch_size();
        Some(SoilEdges {
            sides,
            rigid,
            patch_size,
            half: 0.5 * n as f64 * patch_size,
        })
    }

    /// The sides of patch `patch` across which the ground changes kind, for a point `p` in
    /// it: how far inside each side `p` is and the horizontal normal pointing out through it.
    /// A point beyond a side (a patch index clamped at the map's edge) has no way out there.
    #[inline]
    fn sides_of(&self, p: Vec3, patch: usize) -> impl Iterator<Item = (f64, Vec3)> + '_ {
        let sides = self.sides[patch];
        let (r, c) = (patch / PATCHES_PER_SIDE, patch % PATCHES_PER_SIDE);
        let x0 = c as f64 * self.patch_size - self.half;
        let y1 = self.half - r as f64 * self.patch_size;
        [
            (WEST, p.x - x0, Vec3::new(-1.0, 0.0, 0.0)),
            (EAST, x0 + self.patch_size - p.x, Vec3::new(1.0, 0.0, 0.0)),
            (NORTH, y1 - p.y, Vec3::new(0.0, 1.0, 0.0)),
            (
                SOUTH,
                p.y - (y1 - self.patch_size),
                Vec3::new(0.0, -1.0, 0.0),
            ),
        ]
        .into_iter()
        .filter(move |&(bit, d, _)| sides & bit != 0 && d >= 0.0)
        .map(|(_, d, n)| (d, n))
    }

    /// The nearest side of rigid patch `patch` that borders soil, for a point `p` in it.
    #[inline]
    fn nearest_side(&self, p: Vec3, patch: usize) -> Option<(f64, Vec3)> {
        if self.sides[patch] == 0 || !self.rigid[patch] {
            return None;
        }
        self.sides_of(p, patch)
            .fold(None, |best: Option<(f64, Vec3)>, side| match best {
                Some(b) if b.0 <= side.0 => Some(b),
                _ => Some(side),
            })
    }

    /// The shortest way out of patch `patch` for a point `p` in it that is `depth` under its
    /// surface along `normal`: that, or, in a rigid patch, the way through a side bordering
    /// soil if shorter (its depth, and the horizontal normal pointing into the soil). For the
    /// hull's and the track ends' points.
    #[inline]
    pub fn exit(&self, p: Vec3, patch: usize, depth: f64, normal: Vec3) -> (f64, Vec3) {
        match self.nearest_side(p, patch) {
            Some(side) if side.0 < depth => side,
            _ => (depth, normal),
        }
    }

    /// How far a point `p` in rigid patch `patch`, `rise` under its surface of slopes
    /// `slope` (dz/dx, dz/dy), must move along the unit direction `u` to leave the patch's
    /// block, through its surface or a side bordering soil; `None` if `u` leads out of neither.
    /// For a track, which a sharp edge pokes along the track's own normal (`contact::track_run`).
    #[inline]
    pub fn exit_along(
        &self,
        p: Vec3,
        patch: usize,
        rise: f64,
        slope: (f64, f64),
        u: Vec3,
    ) -> Option<f64> {
        let mut t = f64::INFINITY;
        let climb = u.z - (slope.0 * u.x + slope.1 * u.y);
        if climb > 1e-9 {
            t = rise / climb;
        }
        if self.rigid[patch] {
            for (d, n) in self.sides_of(p, patch) {
                let c = u.dot(n);
                if c > 1e-9 {
                    t = t.min(d / c);
                }
            }
        }
        t.is_finite().then_some(t)
    }

    /// The same for a point `p` of a wheel's tread in rigid patch `patch`. Where the side is
    /// the shorter way out and the wheel's plane crosses the side's edge (within 60° of
    /// square), the wheel meets the edge as a curb, which [`SoilEdges::wheel_corner`] gives:
    /// `None` here. A wheel running along the edge meets the step's face with its sidewall:
    /// the way out sideways.
    #[inline]
    pub fn wheel_point(
        &self,
        p: Vec3,
        patch: usize,
        depth: f64,
        normal: Vec3,
        axle: Vec3,
    ) -> Option<(f64, Vec3)> {
        match self.nearest_side(p, patch) {
            Some((d, n)) if d < depth => {
                let along = Vec3::new(n.y.abs(), n.x.abs(), 0.0);
                (axle.dot(along).abs() < 0.5).then_some((d, n))
            }
            _ => Some((depth, normal)),
        }
    }

    /// A wheel whose hub is over soil (patch `hub_patch`) against the top edges of the rigid
    /// patches beside it: the deepest contact, if any. The edge's point in the wheel's plane is a curb: the disc
    /// is pushed along the line from it to the hub. An edge above the hub is a wall: the disc
    /// is pushed straight back from the side's face.
    pub fn wheel_corner(
        &self,
        height: impl Fn(f64, f64) -> f64,
        hub_patch: usize,
        wheel: Disc,
    ) -> Option<Curb> {
        let (hub, axle, r) = wheel;
        if self.sides[hub_patch] == 0 || self.rigid[hub_patch] {
            return None;
        }
        let mut best: Option<Curb> = None;
        for (d_h, n_out) in self.sides_of(hub, hub_patch) {
            if d_h >= r {
                continue;
            }
            // the edge runs along y for a west or east side, along x for a north or south one
            let along = Vec3::new(n_out.y.abs(), n_out.x.abs(), 0.0);
            let cross = axle.dot(along);
            if cross.abs() < 0.5 {
                continue; // running along the edge: the tread's points meet the face
            }
            // the edge's point in the wheel's plane: from the hub's foot on the edge, along the
            // edge until axle·(c − hub) = 0, at the edge's height there
            let mut c = hub + n_out * d_h;
            c.z = height(c.x, c.y);
            c += along * (-axle.dot(c - hub) / cross);
            c.z = height(c.x, c.y);
            let (depth, normal, arm) = if c.z >= hub.z {
                // the wheel's point furthest toward the face, in its plane
                let u = n_out - axle * axle.dot(n_out);
                let un = u.norm();
                if un < 1e-9 {
                    continue;
                }
                let reach = r * n_out.dot(u) / un;
                (reach - d_h, -n_out, u * (r / un))
            } else {
                let v = hub - c;
                let v = v - axle * axle.dot(v);
                let dist = v.norm();
                if dist < 1e-9 {
                    continue;
                }
                let n = v / dist;
                (r - dist, n, -n * r)
            };
            if depth > 0.0 && best.is_none_or(|b| depth > b.depth) {
                best = Some(Curb { depth, normal, arm });
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;
    use verti_world::SoilParams;

    /// Soil west of x = 0, rigid ground east of it (flat at z = 0), and its edges.
    fn half_soil() -> (World, SoilEdges) {
        let world = testing::half_soil_world(1.0, SoilParams::SOFT, 0.8);
        let edges = SoilEdges::new(&world).expect("the world has a rigid/soil edge");
        (world, edges)
    }

    fn patch_at(world: &World, x: f64, y: f64) -> usize {
        let size = world.patches.patch_size();
        let half = 0.5 * PATCHES_PER_SIDE as f64 * size;
        let c = ((x + half) / size) as usize;
        let r = ((half - y) / size) as usize;
        r * PATCHES_PER_SIDE + c
    }

    #[test]
    fn a_point_near_a_soil_side_leaves_sideways_and_elsewhere_upwards() {
        let (world, edges) = half_soil();
        let size = world.patches.patch_size();
        // 0.3 m under the surface, 5 cm east of the soil: out sideways, 5 cm, toward −x
        let p = Vec3::new(0.05, 1.0, -0.3);
        let (d, n) = edges.exit(p, patch_at(&world, p.x, p.y), 0.3, Vec3::Z);
        assert!((d - 0.05).abs() < 1e-12 && n == Vec3::new(-1.0, 0.0, 0.0));
        // 2 cm under the surface at the same place: out upwards
        let (d, n) = edges.exit(p, patch_at(&world, p.x, p.y), 0.02, Vec3::Z);
        assert!(d == 0.02 && n == Vec3::Z);
        // 0.3 m deep but 0.5 m from the soil: upwards
        let p = Vec3::new(0.5, 1.0, -0.3);
        let (d, n) = edges.exit(p, patch_at(&world, p.x, p.y), 0.3, Vec3::Z);
        assert!(d == 0.3 && n == Vec3::Z);
        // beside a rigid neighbour (the east side of the first rigid patch): upwards
        let p = Vec3::new(size - 0.05, 1.0, -0.3);
        let (d, n) = edges.exit(p, patch_at(&world, p.x, p.y), 0.3, Vec3::Z);
        assert!(d == 0.3 && n == Vec3::Z);
    }

    #[test]
    fn a_wheel_in_soil_meets_the_edge_as_a_curb_and_a_higher_one_as_a_wall() {
        let (world, edges) = half_soil();
        // the test world is flat at z = 0: the edge's height everywhere
        let ground = |_: f64, _: f64| 0.0;
        let hub_patch = |hub: Vec3| patch_at(&world, hub.x, hub.y);
        // heading +x (axle along y), radius 0.5, hub 0.3 m west of the edge and 0.3 m up: the
        // wheel is sunk 0.2 m; the edge (0, y, 0) is 0.3√2 from the hub, inside the disc by
        // 0.5 − 0.3√2, and pushes along (−1, 0, 1)/√2
        let hub = Vec3::new(-0.3, 2.0, 0.3);
        let curb = edges
            .wheel_corner(ground, hub_patch(hub), (hub, Vec3::Y, 0.5))
            .expect("the edge is inside the disc");
        let (d, n, arm) = (curb.depth, curb.normal, curb.arm);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!((d - (0.5 - 0.3 * 2f64.sqrt())).abs() < 1e-9, "{d}");
        assert!((n - Vec3::new(-s, 0.0, s)).norm() < 1e-9, "{n:?}");
        assert!((arm + n * 0.5).norm() < 1e-9);
        // hub below the edge (sunk deeper than its radius): a wall, pushed straight back by
        // how far the disc reaches past the side's face
        let hub = Vec3::new(-0.3, 2.0, -0.1);
        let curb = edges
            .wheel_corner(ground, hub_patch(hub), (hub, Vec3::Y, 0.5))
            .unwrap();
        let (d, n) = (curb.depth, curb.normal);
        assert!(
            (d - 0.2).abs() < 1e-9 && n == Vec3::new(-1.0, 0.0, 0.0),
            "{d} {n:?}"
        );
        // clear of the edge, and running along it: nothing
        let hub = Vec3::new(-0.45, 2.0, 0.3);
        assert!(
            edges
                .wheel_corner(ground, hub_patch(hub), (hub, Vec3::Y, 0.5))
                .is_none()
        );
        let hub = Vec3::new(-0.3, 2.0, 0.3);
        assert!(
            edges
                .wheel_corner(ground, hub_patch(hub), (hub, Vec3::X, 0.5))
                .is_none()
        );
        // a tread point inside the rigid patch next to the edge leaves that contact to the
        // curb when the wheel crosses the edge, and is pushed sideways when it runs along it
        let p = Vec3::new(0.05, 2.0, -0.2);
        let patch = patch_at(&world, p.x, p.y);
        assert!(edges.wheel_point(p, patch, 0.2, Vec3::Z, Vec3::Y).is_none());
        let (d, n) = edges.wheel_point(p, patch, 0.2, Vec3::Z, Vec3::X).unwrap();
        assert!((d - 0.05).abs() < 1e-12 && n == Vec3::new(-1.0, 0.0, 0.0));
    }

    #[test]
    fn a_track_leaves_the_block_along_its_own_normal() {
        let (world, edges) = half_soil();
        let p = Vec3::new(0.05, 2.0, -0.3);
        let patch = patch_at(&world, p.x, p.y);
        // straight up: through the surface, 0.3 m
        let t = edges
            .exit_along(p, patch, 0.3, (0.0, 0.0), Vec3::Z)
            .unwrap();
        assert!((t - 0.3).abs() < 1e-12);
        // up and back (0.8 up, 0.6 toward the soil): through the side first, 0.05 / 0.6
        let u = Vec3::new(-0.6, 0.0, 0.8);
        let t = edges.exit_along(p, patch, 0.3, (0.0, 0.0), u).unwrap();
        assert!((t - 0.05 / 0.6).abs() < 1e-12, "{t}");
        // straight down leads out of neither
        assert!(
            edges
                .exit_along(p, patch, 0.3, (0.0, 0.0), -Vec3::Z)
                .is_none()
        );
    }

    #[test]
    fn worlds_of_one_kind_have_no_soil_edges() {
        assert!(SoilEdges::new(&testing::flat_world(1.0, 0.8)).is_none());
        let soil = testing::soil_world(1.0, SoilParams::MID, 0.0);
        assert!(SoilEdges::new(&soil).is_none());
    }
}
