//! The chassis collision box against terrain (rigid ground; soil only as a floor far below its
//! surface, since in Chrono's SCM the chassis passes through soil) and
//! obstacles: a compliant normal force plus regularised Coulomb friction at each contact point.
//! Against terrain: the 18 lattice points of the box, and the terrain vertices under its
//! bottom face that stand above the ground the lattice sees ([`super::belly`]).

use crate::contact::belly::{Push, belly_contacts};
use crate::contact::body_ground;
use crate::friction::{OBSTACLE_FRICTION, body_friction, surface_mu};
use crate::integrate::Loads;
use crate::model::Model;
use crate::state::{ContactInfo, SimState};
use crate::terrain::Terrain;
use verti_core::Vec3;

/// Body-contact stiffness against obstacles relative to terrain (damping scales with √).
/// Obstacle contacts are few points hit at speed, where a soft contact would let a thin trunk
/// sink half a metre into the body; against terrain many points rest at once (a rolled
/// vehicle on its roof) and the softer value keeps that stable.
const OBSTACLE_STIFFENING: f64 = 4.0;

/// Applies the chassis contacts with terrain and the obstacles `near` to `loads`; counts the
/// contact points in `contacts`. `mu_body`: the chassis' own friction coefficient.
#[inline]
pub(crate) fn body_contacts(
    terrain: &Terrain,
    model: &Model,
    mu_body: f64,
    st: &SimState,
    near: &[u32],
    loads: &mut Loads,
    contacts: &mut ContactInfo,
) {
    let world = &*terrain.world;
    let q = st.orientation;
    let omega_w = q.rotate(st.omega);
    let rm = q.to_mat3();
    let mut pts = [Vec3::ZERO; 18];
    let (mut x0, mut y0, mut z0) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for (k, p) in model.body_points.iter().enumerate() {
        let w = st.position + rm.mul_vec(*p);
        pts[k] = w;
        x0 = x0.min(w.x);
        y0 = y0.min(w.y);
        z0 = z0.min(w.z);
        x1 = x1.max(w.x);
        y1 = y1.max(w.y);
    }
    // `k_scale`, `c_scale`: the contact's stiffness and damping relative to one lattice point
    // against terrain (1, 1); obstacles are a stiffer material (OBSTACLE_STIFFENING and its
    // root: the same damping ratio), belly contacts a share of the face (the same factor for
    // both: damping per area, see `belly`)
    let mut apply = |point: Vec3, n: Vec3, depth: f64, mu: f64, k_scale: f64, c_scale: f64| {
        let arm = point - st.position;
        let v = st.velocity + omega_w.cross(arm);
        let vn = v.dot(n);
        let fnorm = k_scale * model.body_stiffness * depth - c_scale * model.body_damping * vn;
        if fnorm <= 0.0 {
            return false;
        }
        let ft = body_friction(v - n * vn, mu, fnorm, model.friction_speed);
        let f = n * fnorm + ft;
        loads.force += f;
        loads.torque += arm.cross(f);
        true
    };
    let box_bound = terrain.bound.max_in(x0, y0, x1, y1);
    if z0 < box_bound {
        let patches = world.patches.patches();
        // ground heights under the bottom points, where sampled (the belly pass reuses them)
        let mut bottom_h = [f64::NAN; 9];
        for (k, p) in pts.iter().enumerate() {
            // cheap compare against the whole box's bound first, then the point's own block
            if p.z >= box_bound || p.z >= terrain.bound.max_at(p.x, p.y) {
                continue;
            }
            let (h, gx, gy) = terrain.ground.sample(p.x, p.y);
            if k < 9 {
                bottom_h[k] = h;
            }
            if h <= p.z {
                continue;
            }
            let patch = terrain.ground.patch_index(p.x, p.y);
            let surface = &patches[patch].surface;
            // soil holds the chassis only at a floor far below its surface
            let h = body_ground(h, surface, model);
            if h <= p.z {
                continue;
            }
            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
            let n = Vec3::new(-gx * nz, -gy * nz, nz);
            // (a soil patch has no side to leave through: the surface's way out)
            let (depth, n) = terrain.rigid_exit(*p, patch, (h - p.z) * nz, n);
            let mu = surface_mu(surface).min(mu_body);
            if apply(*p, n, depth, mu, 1.0, 1.0) {
                contacts.chassis_terrain_points += 1;
            }
        }
        // the terrain between the lattice points: ridges and step edges under the belly
        contacts.chassis_terrain_points += belly_contacts(
            terrain,
            model,
            &rm,
            &pts[..9],
            &bottom_h,
            mu_body,
            |c: Push| apply(c.point, c.normal, c.depth, c.mu, c.share, c.share),
        );
    }
    let mu_obs = OBSTACLE_FRICTION.min(mu_body);
    let (k_obs, c_obs) = (OBSTACLE_STIFFENING, OBSTACLE_STIFFENING.sqrt());
    for &k in near {
        let o = &world.obstacles[k as usize];
        let op = o.position();
        let reach = o.radius_xy() + model.reach;
        if (st.position.x - op.x).powi(2) + (st.position.y - op.y).powi(2) > reach * reach {
            continue;
        }
        let (oz0, oz1) = o.z_range();
        if st.position.z - model.reach > oz1 || st.position.z + model.reach < oz0 {
            continue;
        }
        // Separating planes: if the whole box lies outside one face plane of the rock (the
        // box's support along the face normal), nothing touches; most nearby obstacles are
        // ruled out this way before any per-point work.
        let fo = &terrain.fast_obstacles[k as usize];
        let box_world = st.position + rm.mul_vec(model.box_center);
        if fo.separated_from_box(box_world, &rm, model.box_half) {
            continue;
        }
        if let Some((cx, cy, radius, tz0, tz1)) = fo.tree {
            // A trunk is thinner than a body contact's penetration at speed, and a point that
            // passes its axis would be pulled through. Test the trunk's axis (at the box's
            // height) against the box grown by the radius instead: the box face it is nearest
            // to gives a normal that cannot flip.
            let axis_point = Vec3::new(cx, cy, box_world.z.clamp(tz0, tz1));
            let local = q.inverse_rotate(axis_point - box_world);
            let d = Vec3::new(
                model.box_half.x + radius - local.x.abs(),
                model.box_half.y + radius - local.y.abs(),
                model.box_half.z - local.z.abs(),
            );
            if d.x > 0.0 && d.y > 0.0 && d.z > 0.0 {
                let v_local =
                    -q.inverse_rotate(st.velocity + omega_w.cross(axis_point - st.position));
                let (depth, n_local) = box_penetration(local, v_local, d);
                let n = q.rotate(n_local);
                // contact on the trunk's surface facing the box
                if apply(axis_point + n * radius, n, depth, mu_obs, k_obs, c_obs) {
                    contacts.chassis_obstacle_points += 1;
                }
            }
            continue;
        }
        // chassis points inside the obstacle (outside its bounding sphere: skip)
        let r2 = fo.radius * fo.radius;
        for p in &pts {
            if (*p - fo.center).norm_sq() > r2 {
                continue;
            }
            let (d, n) = fo.signed_distance(*p);
            if d < 0.0 && apply(*p, n, -d, mu_obs, k_obs, c_obs) {
                contacts.chassis_obstacle_points += 1;
            }
        }
        // obstacle vertices inside the chassis box (a rock edge poking into a flat side)
        let rt = rm.transpose();
        for v in o.vertices() {
            let local = rt.mul_vec(*v - st.position) - model.box_center;
            let d = Vec3::new(
                model.box_half.x - local.x.abs(),
                model.box_half.y - local.y.abs(),
                model.box_half.z - local.z.abs(),
            );
            if d.x <= 0.0 || d.y <= 0.0 || d.z <= 0.0 {
                continue;
            }
            let v_local = -q.inverse_rotate(st.velocity + omega_w.cross(*v - st.position));
            let (depth, n_local) = box_penetration(local, v_local, d);
            if apply(*v, q.rotate(n_local), depth, mu_obs, k_obs, c_obs) {
                contacts.chassis_obstacle_points += 1;
            }
        }
    }
}

/// Penetration of a point into a box, given its box-frame position `local`, its velocity
/// relative to the box `v_local` and its depths `d` below the three face pairs (all positive).
/// Returns the depth and the box-frame outward normal of the face it entered through: among
/// the faces it crossed within the last 0.2 s (depth / inward speed), the most recent one.
/// The smallest depth alone would switch to a side face once a thin obstacle is pushed deep
/// into a long box (and let the body slide past a tree it hit head-on); without a recent
/// crossing (resting contact, slow creep) it is the right choice and is used.
#[inline]
fn box_penetration(local: Vec3, v_local: Vec3, d: Vec3) -> (f64, Vec3) {
    const RECENT: f64 = 0.2;
    let axes = [
        (
            d.x,
            local.x,
            v_local.x,
            Vec3::new(-local.x.signum(), 0.0, 0.0),
        ),
        (
            d.y,
            local.y,
            v_local.y,
            Vec3::new(0.0, -local.y.signum(), 0.0),
        ),
        (
            d.z,
            local.z,
            v_local.z,
            Vec3::new(0.0, 0.0, -local.z.signum()),
        ),
    ];
    let mut recent: Option<(f64, f64, Vec3)> = None;
    let mut shallowest = axes[0];
    for axis in axes {
        let (depth, pos, vel, n) = axis;
        if depth < shallowest.0 {
            shallowest = axis;
        }
        // inward speed: moving toward the box centre along this axis
        let inward = -vel * pos.signum();
        if inward > 0.0 && depth < RECENT * inward {
            let since = depth / inward;
            if recent.is_none_or(|(best, _, _)| since < best) {
                recent = Some((since, depth, n));
            }
        }
    }
    match recent {
        Some((_, depth, n)) => (depth, n),
        None => (shallowest.0, shallowest.3),
    }
}
