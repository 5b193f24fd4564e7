//! One rigid tyre against rigid ground, obstacles and soil: a rigid cylinder of the wheel's
//! radius and width, the shape Chrono's `ChRigidTire` gives the collision system.
//!
//! Chrono solves that contact as a complementarity constraint (NSC). This engine is penalty
//! based, so each contact is a stiff spring-damper along the contact normal; the stiffness and
//! damping are the tyre's `radial_stiffness` and `radial_damping` (the vehicle file derives
//! them from the internal step, see `vehicles/hmmwv.yaml`).
//!
//! Where the cylinder meets things:
//! * **Terrain** (the heightfield's triangles): along the tread's centre circle, the point
//!   deepest toward the ground (found from one sample below the hub and the ground's plane
//!   there) plus points 30° and 60° on either side of it. On a plane only the deepest point
//!   touches; where the ground rises ahead (a bank, a ditch's far side) the forward points
//!   meet it with its own normal. At each point the two edges of the tread meet the ground's
//!   local plane and carry half the stiffness each: a line contact across the tread, exact
//!   for any tilt of the ground across the wheel.
//! * **Rocks** (convex polytopes): the rock is cut by the planes of three circles across the
//!   tread (edges and centre, weights ¼ ½ ¼, the trapezoid rule over the width) and each
//!   circle meets its cut polygon exactly: the penetration is the radius minus the distance
//!   from the circle's centre to the polygon, along the line through the centre. So a wheel
//!   driven into a step meets the step's edge with a normal through the hub (mostly
//!   horizontal), not only the top face. A rock face parallel to the wheel (scraping along a
//!   rock's side) pushes along the axle instead.
//! * **Trees** (upright cylinders): the wheel's point nearest the trunk, one contact.
//! * **Soil**: the SCM stage ([`super::soil`]) already treats the wheel as this cylinder (rays
//!   from the soil nodes against it), so it is used unchanged.
//!
//! Every contact's normal force acts at the hub; its moment about the hub, less the part along
//! the axle (zero for a cylinder's radial normals), reaches the chassis through the bearing.

use super::soil::{soil_as_rigid, soil_contact};
use super::{RigidContact, WheelContact, WheelKinematics};
use crate::friction::{OBSTACLE_FRICTION, surface_mu};
use crate::model::WheelModel;
use crate::soil::SoilState;
use crate::spec::TyreSpec;
use crate::terrain::{FastObstacle, Terrain};
use verti_core::Vec3;

/// (cos, sin) of the terrain samples' angles from the deepest point along the tread's circle.
const ARC: [(f64, f64); 5] = [
    (1.0, 0.0),
    (0.866_025_403_784_438_6, 0.5),
    (0.866_025_403_784_438_6, -0.5),
    (0.5, 0.866_025_403_784_438_6),
    (0.5, -0.866_025_403_784_438_6),
];

/// Most rock faces the exact circle–polygon test handles (generated rocks have 17, imported
/// ones 6); a rock with more meets the wheel at its point nearest the rock instead.
const MAX_FACES: usize = 64;

/// Sums one contact into the wheel's contact.
struct Sum<'a> {
    c: &'a mut WheelContact,
    rc: &'a mut RigidContact,
    /// Σ w·δ² (the elastic energy is ½·k·Σ w·δ²).
    depth_sq: f64,
    k: f64,
    damping: f64,
    tyre_mu: f64,
    v_hub: Vec3,
    up: Vec3,
    axle: Vec3,
}

impl Sum<'_> {
    /// A contact of weight `w` (its share of the stiffness) at `arm` from the hub, `depth`
    /// along the outward normal `n` of the thing touched, of friction `mu`.
    #[inline]
    fn add(&mut self, w: f64, arm: Vec3, depth: f64, n: Vec3, mu: f64) {
        let rate = -self.v_hub.dot(n);
        let f = w * (self.k * depth + self.damping * rate);
        if f <= 0.0 {
            return; // separating faster than the spring pushes: a contact never pulls
        }
        self.sum(w, f, arm * f, depth * depth * w, n, mu);
    }

    /// Two contacts of weight ½ with one normal `n`: the tread's edges at `arm ± offset`,
    /// `depth ± tilt` deep (the pair [`Sum::add`] would make, summed once).
    #[inline]
    fn add_edges(&mut self, arm: Vec3, offset: Vec3, depth: f64, tilt: f64, n: Vec3, mu: f64) {
        let rate = -self.v_hub.dot(n);
        let edge = |d: f64| {
            let f = 0.5 * (self.k * d + self.damping * rate);
            if d > 0.0 && f > 0.0 {
                (f, 0.5)
            } else {
                (0.0, 0.0)
            }
        };
        let (da, db) = (depth + tilt, depth - tilt);
        let ((fa, wa), (fb, wb)) = (edge(da), edge(db));
        let f = fa + fb;
        if f <= 0.0 {
            return;
        }
        let sq = wa * da * da + wb * db * db;
        self.sum(wa + wb, f, arm * f + offset * (fa - fb), sq, n, mu);
    }

    /// Adds contacts of total weight `w` and force `f` along `n`, whose force-weighted arms
    /// sum to `moment_arm` and whose weighted squared depths sum to `sq`.
    #[inline]
    fn sum(&mut self, w: f64, f: f64, moment_arm: Vec3, sq: f64, n: Vec3, mu: f64) {
        let (kw, cw) = (w * self.k, w * self.damping);
        let nu = n.dot(self.up);
        let c = &mut *self.c;
        c.force += n * f;
        c.k_axis += kw * nu * nu;
        c.c_axis += cw * nu * nu;
        c.k_vec += n * (kw * nu);
        c.c_vec += n * (cw * nu);
        // (the friction limit below replaces the handling tyre's load-weighted `mu_scale`)
        let mu = mu.min(self.tyre_mu);
        c.rigid_load += f;
        let rc = &mut *self.rc;
        rc.friction_limit += mu * f;
        rc.arm += moment_arm;
        let moment = moment_arm.cross(n);
        rc.moment += moment - self.axle * moment.dot(self.axle);
        self.depth_sq += sq;
    }
}

/// Contact of one rigid tyre with rigid terrain, obstacles (indices `near`) and soil. Writes
/// the soil's plastic memory under the wheel. `soil_b`: the size of the wheel's last soil
/// patch. `depth` of the result is the equivalent deflection √(Σ w·δ²), whose spring energy
/// ½·k·depth² is the contact's.
#[inline]
pub(crate) fn rigid_wheel_contact(
    terrain: &Terrain,
    soil: &mut SoilState,
    tyre: &TyreSpec,
    m: &WheelModel,
    soil_b: f64,
    kin: &WheelKinematics,
    near: &[u32],
) -> (WheelContact, RigidContact) {
    let world = &*terrain.world;
    let hf = &world.terrain;
    let ground = &terrain.ground;
    let patches = world.patches.patches();
    let (hub, axle) = (kin.hub, kin.axle);
    let (r, hw) = (m.radius, m.half_width);
    let mut c = WheelContact::default();
    let mut rc = RigidContact::default();
    let mut sum = Sum {
        c: &mut c,
        rc: &mut rc,
        depth_sq: 0.0,
        k: tyre.radial_stiffness,
        damping: tyre.radial_damping,
        tyre_mu: tyre.friction,
        v_hub: kin.hub_velocity,
        up: kin.up,
        axle,
    };

    // World "down" within the wheel's plane (with axle × down it spans that plane).
    let down = {
        let d = Vec3::new(0.0, 0.0, -1.0) - axle * (-axle.z);
        let n = d.norm();
        if n > 1e-6 {
            d / n
        } else {
            // wheel lying flat: any direction in its plane
            let d = Vec3::X - axle * axle.x;
            d / d.norm().max(1e-12)
        }
    };
    let soil_rigid = soil_as_rigid(terrain, m);
    let mut soil_here = false;
    // How far the tread's edges reach below its centre line, measured vertically.
    let edge_drop = hw * axle.z.abs();
    // The lowest point of the wheel in its plane toward the chassis floor, and the ground
    // there. On a plane whose normal is that sample's, the deepest point of the tread's
    // circle is at d0 (in the wheel's plane, against the plane's normal), deeper than the
    // sample by R·(d·n + |n_p|): the same as sampling the ground under the hub for its normal
    // first, for one sample less.
    let d_up = {
        let u = kin.up - axle * kin.up.dot(axle);
        let n = u.norm();
        if n > 1e-6 { -u / n } else { down }
    };
    let mut d0 = d_up;
    {
        let p = hub + d_up * r;
        let (h, gx, gy) = ground.sample(p.x, p.y);
        let patch = ground.patch_index(p.x, p.y);
        let surface = &patches[patch].surface;
        // Soil the grid resolves is the soil stage's; off the map, or where the grid cannot
        // resolve this wheel, soil is rigid ground of friction tan φ.
        if surface.is_deformable() && !soil_rigid && hf.contains(p.x, p.y) {
            soil_here = true;
        } else {
            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
            let top = Vec3::new(-gx * nz, -gy * nz, nz);
            // near a side bordering soil the way out may be sideways, or the edge a curb (below)
            let (depth, n) = terrain
                .wheel_rigid_point(p, patch, (h - p.z) * nz, top, axle)
                .unwrap_or((f64::NEG_INFINITY, top));
            let np = n - axle * n.dot(axle);
            let npn = np.norm();
            if npn > 1e-6 {
                d0 = -np / npn;
            }
            let deepest = depth + r * (d_up.dot(n) + npn);
            // The two edges of the tread against the ground's plane (the heightfield is
            // planar over a triangle, and the tread is a quarter of a cell wide): each
            // carries half the stiffness, so a line contact sums to k·δ and a wheel tilted
            // across the ground loads its lower edge (the edge at −axle·hw is deeper than the
            // centre line by hw·(axle·n)).
            if deepest + hw * axle.dot(n).abs() > 0.0 {
                let tilt = hw * axle.dot(n);
                sum.add_edges(d0 * r, -axle * hw, deepest, tilt, n, surface_mu(surface));
            }
        }
    }
    // the fan: 30° and 60° either side of the lowest point
    let t0 = d0.cross(axle);
    for &(ca, sa) in &ARC[1..] {
        let dir = d0 * ca + t0 * sa;
        let p = hub + dir * r;
        let low = p.z - edge_drop;
        // most points of the fan are above the ground: probe the height first
        if ground.height(p.x, p.y) <= low {
            continue;
        }
        let (h, gx, gy) = ground.sample(p.x, p.y);
        let patch = ground.patch_index(p.x, p.y);
        let surface = &patches[patch].surface;
        if surface.is_deformable() && !soil_rigid && hf.contains(p.x, p.y) {
            soil_here = true;
            continue;
        }
        let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
        let top = Vec3::new(-gx * nz, -gy * nz, nz);
        let Some((depth, n)) = terrain.wheel_rigid_point(p, patch, (h - p.z) * nz, top, axle)
        else {
            continue;
        };
        let tilt = hw * axle.dot(n);
        sum.add_edges(dir * r, -axle * hw, depth, tilt, n, surface_mu(surface));
    }
    // a wheel in soil against the top edge of a rigid patch beside it: a curb
    if let Some(curb) = (!m.belted)
        .then(|| terrain.wheel_corner((hub, axle, r)))
        .flatten()
    {
        // the rigid patch: just beyond the contact point, away from the hub
        let (n, at) = (curb.normal, hub + curb.arm - curb.normal * 0.01);
        let mu = surface_mu(&patches[ground.patch_index(at.x, at.y)].surface);
        sum.add_edges(curb.arm, -axle * hw, curb.depth, hw * axle.dot(n), n, mu);
    }
    if !soil_here && terrain.soil.is_some() {
        // the wheel may be sunk in soil with its samples above the undeformed level
        soil_here = patches[ground.patch_index(hub.x, hub.y)]
            .surface
            .is_deformable();
    }

    // Obstacles. (e1, e2) = (axle × down, −down): an orthonormal basis of the wheel's plane.
    let e1 = axle.cross(down);
    for &k in near {
        let Some(fo) = super::obstacle_in_reach(terrain, k, hub, r, hw) else {
            continue;
        };
        // a lower bound of the hub's distance to the obstacle
        let (d_hub, n_hub) = fo.signed_distance(hub);
        if d_hub > r + hw {
            continue;
        }
        let before = sum.c.rigid_load;
        if fo.tree.is_none() && fo.faces.len() <= MAX_FACES {
            for (side, w) in [(-hw, 0.25), (0.0, 0.5), (hw, 0.25)] {
                let centre = hub + axle * side;
                if let Some((depth, n, point)) = circle_vs_rock(fo, centre, axle, e1, -down, r) {
                    sum.add(w, point - hub, depth, n, OBSTACLE_FRICTION);
                }
            }
        } else {
            // the wheel's point deepest toward the obstacle's nearest face
            let np = n_hub - axle * n_hub.dot(axle);
            let npn = np.norm();
            let support = if npn > 1e-6 {
                hub - np * (r / npn) - axle * (hw * n_hub.dot(axle).signum())
            } else {
                hub - n_hub * hw
            };
            let (d, n) = fo.signed_distance(support);
            if d < 0.0 {
                sum.add(1.0, support - hub, -d, n, OBSTACLE_FRICTION);
            }
        }
        if sum.c.rigid_load > before {
            sum.c.obstacle = true;
        }
    }
    let depth = sum.depth_sq.sqrt();
    c.depth = depth;
    if c.rigid_load > 0.0 {
        rc.arm = rc.arm / c.rigid_load;
    }

    if soil_here
        && !soil_rigid
        && let Some(layout) = terrain.soil
    {
        soil_contact(terrain, &layout, soil, m, soil_b, kin, &mut c);
    }
    (c, rc)
}

/// Contact of a circle (centre `centre`, radius `r`, in the plane spanned by the unit vectors
/// `e1`, `e2`, normal `axle`) with a convex rock: (depth, outward normal, the circle's point
/// deepest in the rock), or None when they do not touch.
///
/// The rock's faces cut the circle's plane in half-planes; clipping the square that bounds the
/// circle by them gives the rock's section near the circle (a convex polygon). The circle
/// meets it where the polygon comes nearest its centre, along the line through the centre: a
/// face meets the circle with the face's normal, an edge (a step's rim) with the direction from
/// the edge to the centre. The square's own sides lie at least `r` from the centre, so they
/// never make a contact.
fn circle_vs_rock(
    fo: &FastObstacle,
    centre: Vec3,
    axle: Vec3,
    e1: Vec3,
    e2: Vec3,
    r: f64,
) -> Option<(f64, Vec3, Vec3)> {
    let mut lines = [(0.0, 0.0, 0.0); MAX_FACES];
    let mut count = 0;
    let mut centre_inside = true;
    for &(n, d) in &fo.faces {
        let (a, b) = (n.dot(e1), n.dot(e2));
        let g = d - n.dot(centre);
        // the whole circle lies outside this face: no contact
        if g + r * (a * a + b * b).sqrt() < 0.0 {
            return None;
        }
        centre_inside &= g >= 0.0;
        lines[count] = (a, b, g);
        count += 1;
    }
    if centre_inside {
        // The circle's centre is inside the rock (a deep hit): push out through the face the
        // centre is nearest, by that distance plus the circle's reach toward the face.
        let (d, n) = fo.signed_distance(centre);
        let np = n - axle * n.dot(axle);
        let reach = r * np.norm();
        return Some((reach - d, n, centre - np.normalized() * r));
    }
    let l = r * 1.000_001;
    let mut a_buf = [[0.0f64; 2]; MAX_FACES + 8];
    let mut b_buf = [[0.0f64; 2]; MAX_FACES + 8];
    a_buf[..4].copy_from_slice(&[[-l, -l], [l, -l], [l, l], [-l, l]]);
    let mut len = 4;
    let (mut src, mut dst) = (&mut a_buf, &mut b_buf);
    for &(a, b, g) in &lines[..count] {
        if a * a + b * b < 1e-18 {
            continue; // a face parallel to the plane: the centre is on its inner side here
        }
        len = clip(&src[..len], dst, a, b, g);
        if len == 0 {
            return None;
        }
        std::mem::swap(&mut src, &mut dst);
    }
    // the polygon's point nearest the centre (the origin of the plane's coordinates)
    let mut best = f64::INFINITY;
    let mut q = [0.0, 0.0];
    for i in 0..len {
        let p0 = src[i];
        let p1 = src[(i + 1) % len];
        let e = [p1[0] - p0[0], p1[1] - p0[1]];
        let ee = e[0] * e[0] + e[1] * e[1];
        let t = if ee > 0.0 {
            (-(p0[0] * e[0] + p0[1] * e[1]) / ee).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let x = [p0[0] + t * e[0], p0[1] + t * e[1]];
        let dd = x[0] * x[0] + x[1] * x[1];
        if dd < best {
            best = dd;
            q = x;
        }
    }
    let rho = best.sqrt();
    if rho >= r || rho < 1e-12 {
        return None;
    }
    let n = -(e1 * q[0] + e2 * q[1]) / rho;
    let depth = r - rho;
    // The contact point is the wheel's deepest point, on the cylinder: its lever about the
    // axle is the radius, as for a rigid cylinder whose contact does not penetrate.
    let deepest = centre - n * r;
    // A rock face alongside the wheel (its normal along the axle) that the circle's plane has
    // just crossed: the wheel's side meets it, and the way out is along the axle.
    let (d3, n3) = fo.signed_distance(deepest);
    if d3 < 0.0 && -d3 < depth && n3.dot(axle).abs() > std::f64::consts::FRAC_1_SQRT_2 {
        return Some((-d3, n3, deepest));
    }
    Some((depth, n, deepest))
}

/// Sutherland–Hodgman: clips the convex polygon `poly` (counter-clockwise) by the half-plane
/// a·u + b·v ≤ g into `out`; returns the new vertex count (at most one more).
#[inline]
fn clip(poly: &[[f64; 2]], out: &mut [[f64; 2]], a: f64, b: f64, g: f64) -> usize {
    let mut n = 0;
    let len = poly.len();
    for i in 0..len {
        let p = poly[i];
        let q = poly[(i + 1) % len];
        let dp = a * p[0] + b * p[1] - g;
        let dq = a * q[0] + b * q[1] - g;
        if dp <= 0.0 {
            out[n] = p;
            n += 1;
        }
        if (dp <= 0.0) != (dq <= 0.0) {
            let t = dp / (dp - dq);
            out[n] = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
            n += 1;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use std::sync::Arc;

    /// The rigid HMMWV's front-left wheel at rest at `hub`, upright, axle along +y.
    fn touch(world: verti_world::World, hub: Vec3) -> (WheelContact, RigidContact, f64) {
        let spec = crate::vehicles::builtin("hmmwv").unwrap();
        let model = Model::compile(&spec, 1.0);
        let terrain = Terrain::new(&Arc::new(world), model.reach).unwrap();
        let mut soil = SoilState::new(terrain.soil.as_ref());
        let kin = WheelKinematics::at_rest(hub);
        let near = terrain.obstacles.near(hub.x, hub.y).to_vec();
        let m = &model.wheels[0];
        let (c, rc) = rigid_wheel_contact(&terrain, &mut soil, &spec.tyre, m, 0.3, &kin, &near);
        (c, rc, spec.tyre.radial_stiffness)
    }

    // On flat ground a wheel whose lowest line is δ = 1 mm deep is pushed straight up with
    // k·δ (the two edge circles carry half each), its contact point is on the cylinder one
    // radius below the hub, and its equivalent deflection is δ.
    #[test]
    fn flat_ground_pushes_up_with_k_delta() {
        let r = 0.467;
        let (c, rc, k) = touch(
            crate::testing::flat_world(1.0, 0.8),
            Vec3::new(0.3, 0.2, r - 1e-3),
        );
        assert!((c.force.z - k * 1e-3).abs() < 1e-6 * k, "{:?}", c.force);
        assert!(c.force.x.abs() < 1e-9 && c.force.y.abs() < 1e-9);
        assert!(
            (rc.arm - Vec3::new(0.0, 0.0, -r)).norm() < 1e-9,
            "{:?}",
            rc.arm
        );
        assert!((c.depth - 1e-3).abs() < 1e-12);
        assert!((rc.friction_limit - 0.8 * c.force.z).abs() < 1e-9);
    }

    // A wheel held 1 cm above flat ground against the top edge of a 0.3 m box step, the edge
    // 1 mm inside the tyre: the only contact is the edge, pushing with k·1 mm along the line
    // from the edge to the hub (62° from vertical, mostly horizontal), within 0.1 % and 0.1°.
    #[test]
    fn a_step_edge_pushes_along_the_line_to_the_hub() {
        let (r, delta, face, height) = (0.467f64, 1e-3, 3.0, 0.3);
        let world = crate::testing::rock_world(1.0, 0.8, face, Vec3::new(3.0, 4.0, height));
        let hz = r + 0.01;
        let dz = hz - height;
        let dx = ((r - delta).powi(2) - dz * dz).sqrt();
        let hub = Vec3::new(face - dx, 0.5, hz);
        let (c, rc, k) = touch(world, hub);
        let expected = Vec3::new(-dx, 0.0, dz) / (r - delta);
        let f = c.force.norm();
        let angle = (c.force / f)
            .dot(expected)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        assert!(
            (f - k * delta).abs() < 1e-3 * k * delta,
            "force {f} vs {}",
            k * delta
        );
        assert!(
            angle < 0.1,
            "force {:?} is {angle:.3}° off {expected:?}",
            c.force
        );
        assert!(c.obstacle && c.force.x < -0.8 * f);
        // the contact point is the wheel's point on that line, one radius from the hub
        assert!((rc.arm + expected * r).norm() < 1e-9, "{:?}", rc.arm);
        assert!((rc.friction_limit - 0.6 * f).abs() < 1e-6 * f);
    }
}
