//! A tracked vehicle's raised track ends ([`crate::track_runs`]) against rigid ground and
//! obstacles: a compliant normal force at every profile point that is inside something, and
//! regularised Coulomb friction against the *moving* track's surface. A driven track that
//! meets a rock with its front run slides down along the rock's edge, so the friction pushes
//! the vehicle up and forward: that is how a tracked vehicle climbs a step higher than its
//! road wheels' radius, which its road wheels alone cannot.
//!
//! The friction at one point opposes the sliding velocity v_t = v_hull,t + ω R b_t (the hull
//! point's tangential velocity plus the track surface's, b_t its direction in the contact's
//! tangent plane, ω the side's spin, R the road wheels' radius). Its magnitude grows with the
//! track's speed, which makes the spin stiff: the coefficient c = μ N / max(|v_t|, v_reg) is
//! taken at the step's start and the force f = −c (v_hull,t + ω_new R b_t) at the new spin,
//! so the spin solve gets it implicitly (torque R f·b on the spin, as a tyre's force has) and
//! the hull gets exactly the force the spin saw. Soil does not hold the runs: like the hull,
//! they meet a floor one wheel diameter below a soil surface (`contact::body`).

use crate::contact::body_ground;
use crate::drivetrain::SpinLoads;
use crate::friction::{OBSTACLE_FRICTION, surface_mu};
use crate::integrate::Loads;
use crate::model::Model;
use crate::spec::MAX_WHEELS;
use crate::state::SimState;
use crate::terrain::Terrain;
use crate::track_runs::{MAX_PROFILE, ProfilePoint, TrackRuns};
use verti_core::Vec3;

/// A point is pushed along the track's normal only while that frees it within 4 times its
/// shortest way out (the rock face's normal); beyond (the track's normal nearly along the
/// face, e.g. a run pressed flat against a rock's side) the face's normal takes over.
const MIN_EXIT_RATE: f64 = 0.25;

/// A rock face whose normal points more than 30° across the vehicle (|n·y| ≥ 0.5) meets the
/// track's outer corner or side rather than its running surface.
const MAX_ACROSS: f64 = 0.5;

/// Obstacles one side's points test (those whose bounding sphere reaches the points' box; a
/// side meets a handful at a time, and beyond this many it tests every obstacle near).
const MAX_CANDIDATES: usize = 16;

/// The runs' forces on the hull, linear in the sides' new spins: F = F₀ + Σ_g ω_g F_g (and
/// the same for the moment about the centre of mass).
pub(crate) struct RunLoads {
    force: Vec3,
    torque: Vec3,
    force_per_spin: [Vec3; MAX_WHEELS],
    torque_per_spin: [Vec3; MAX_WHEELS],
    /// Profile points in contact (with terrain or an obstacle).
    pub points: u32,
}

impl RunLoads {
    /// Adds the forces at the new spins `group_spin` to `loads`.
    #[inline]
    pub fn apply(&self, group_spin: &[f64], loads: &mut Loads) {
        let mut f = self.force;
        let mut t = self.torque;
        for (g, &w) in group_spin.iter().enumerate().take(MAX_WHEELS) {
            f += self.force_per_spin[g] * w;
            t += self.torque_per_spin[g] * w;
        }
        loads.force += f;
        loads.torque += t;
    }
}

/// The contacts of both sides' raised ends with the terrain and the obstacles `near`: adds
/// their friction's torque and stiffness on each side's spin to `spin` and returns their
/// forces on the hull, to apply at the new spins.
pub(crate) fn track_run_contacts(
    terrain: &Terrain,
    model: &Model,
    runs: &TrackRuns,
    st: &SimState,
    near: &[u32],
    spin: &mut SpinLoads,
) -> RunLoads {
    let world = &*terrain.world;
    let patches = world.patches.patches();
    let rm = st.orientation.to_mat3();
    let omega_w = st.orientation.rotate(st.omega);
    let r = runs.wheel_radius;
    let mut out = RunLoads {
        force: Vec3::ZERO,
        torque: Vec3::ZERO,
        force_per_spin: [Vec3::ZERO; MAX_WHEELS],
        torque_per_spin: [Vec3::ZERO; MAX_WHEELS],
        points: 0,
    };
    let mut profile = [ProfilePoint::default(); MAX_PROFILE];
    for side in &runs.sides {
        let mut hubs = [(0.0, 0.0); MAX_WHEELS];
        for (hub, &w) in hubs.iter_mut().zip(&side.wheels) {
            let m = &model.wheels[w];
            *hub = (m.attach.x, m.attach.z + st.wheels[w].compression);
        }
        let count = runs.profile(&hubs[..side.wheels.len()], &mut profile);
        let g = side.group;
        let spin0 = st.group_spin[g];
        // one contact: normal force along `n`, friction against the track moving along `belt`
        let mut touch = |arm: Vec3, belt: Vec3, n: Vec3, depth: f64, mu: f64| {
            let v = st.velocity + omega_w.cross(arm);
            let vn = v.dot(n);
            let fnorm = runs.stiffness * depth - runs.damping * vn;
            if fnorm <= 0.0 {
                return;
            }
            let vt_hull = v - n * vn;
            let bt = belt - n * n.dot(belt);
            let vt0 = vt_hull + bt * (spin0 * r);
            let c = mu * fnorm / vt0.norm().max(model.friction_speed);
            let f0 = n * fnorm - vt_hull * c;
            let f1 = bt * (-c * r);
            out.force += f0;
            out.torque += arm.cross(f0);
            out.force_per_spin[g] += f1;
            out.torque_per_spin[g] += arm.cross(f1);
            // the spin's torque R f·b, linear in the new spin
            spin.torque[g] -= c * r * vt_hull.dot(belt);
            spin.stiffness[g] += c * r * r * bt.dot(belt);
            out.points += 1;
        };
        // where every point is (both lines), the box around them, and the obstacles whose
        // bounding sphere reaches that box: the points test only those
        let mut arms = [Vec3::ZERO; 2 * MAX_PROFILE];
        let inf = f64::INFINITY;
        let (mut lo, mut hi) = (Vec3::new(inf, inf, inf), Vec3::new(-inf, -inf, -inf));
        for (k, pt) in profile[..count].iter().enumerate() {
            for (j, &y) in side.lines.iter().enumerate() {
                let arm = rm.mul_vec(Vec3::new(pt.x, y, pt.z));
                let p = st.position + arm;
                lo = Vec3::new(lo.x.min(p.x), lo.y.min(p.y), lo.z.min(p.z));
                hi = Vec3::new(hi.x.max(p.x), hi.y.max(p.y), hi.z.max(p.z));
                arms[2 * k + j] = arm;
            }
        }
        let mut candidates = [0u32; MAX_CANDIDATES];
        let mut n_candidates = 0;
        let mut overflow = false;
        for &k in near {
            let fo = &terrain.fast_obstacles[k as usize];
            let c = fo.center;
            let gap = Vec3::new(
                (lo.x - c.x).max(c.x - hi.x).max(0.0),
                (lo.y - c.y).max(c.y - hi.y).max(0.0),
                (lo.z - c.z).max(c.z - hi.z).max(0.0),
            );
            if gap.norm_sq() <= fo.radius * fo.radius {
                if n_candidates == MAX_CANDIDATES {
                    overflow = true;
                } else {
                    candidates[n_candidates] = k;
                    n_candidates += 1;
                }
            }
        }
        let tested = if overflow {
            near
        } else {
            &candidates[..n_candidates]
        };
        let across = rm.mul_vec(Vec3::Y);
        let ground_near = lo.z < terrain.bound.max_in(lo.x, lo.y, hi.x, hi.y);
        for (k, pt) in profile[..count].iter().enumerate() {
            let belt = rm.mul_vec(pt.belt());
            // Against a rock, the track's own normal: whatever sharp edge pokes into the
            // track's smooth, convex surface pushes along that surface's normal, by how far the
            // point must move that way to come free. Pushed along the rock face's normal
            // instead, an edge under the front run or the sprocket would hold the vehicle back
            // horizontally where the track rides up it (against a flat face the deepest
            // points' normals are the face's anyway). The ground is smooth (a triangulated
            // heightfield whose kinks are obtuse): the ground's normal there.
            let inward = rm.mul_vec(Vec3::new(-pt.nx, 0.0, -pt.nz));
            for &arm in &arms[2 * k..2 * k + 2] {
                let p = st.position + arm;
                if ground_near && p.z < terrain.bound.max_at(p.x, p.y) {
                    let (h, gx, gy) = terrain.ground.sample(p.x, p.y);
                    // the patch only where the surface reaches the point (a soil floor is lower)
                    if h > p.z {
                        let patch = terrain.ground.patch_index(p.x, p.y);
                        let surface = &patches[patch].surface;
                        let h = body_ground(h, surface, model);
                        if h > p.z {
                            let mu = surface_mu(surface).min(runs.mu);
                            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                            let n = Vec3::new(-gx * nz, -gy * nz, nz);
                            let top = (h - p.z) * nz;
                            // (on soil: the surface's way out, as no side is crossed)
                            let (depth, face) = terrain.rigid_exit(p, patch, top, n);
                            if depth < top {
                                // the edge of a rigid patch beside soil pokes into the track:
                                // along the track's normal, as a rock's edge does
                                let along =
                                    terrain.rigid_exit_along(p, patch, h - p.z, (gx, gy), inward);
                                match along {
                                    Some(t) if t <= depth / MIN_EXIT_RATE => {
                                        touch(arm, belt, inward, t, mu)
                                    }
                                    _ => touch(arm, belt, face, depth, mu),
                                }
                            } else {
                                touch(arm, belt, n, top, mu);
                            }
                        }
                    }
                }
                for &k in tested {
                    let fo = &terrain.fast_obstacles[k as usize];
                    if (p - fo.center).norm_sq() > fo.radius * fo.radius {
                        continue;
                    }
                    let (d, n) = fo.signed_distance(p);
                    if d >= 0.0 {
                        continue;
                    }
                    let mu = OBSTACLE_FRICTION.min(runs.mu);
                    // a face turned across the track (a rock met at an angle or scraped
                    // past) meets the track's corner or side, which it pushes along its own
                    // normal, sideways too
                    let exit = if n.dot(across).abs() < MAX_ACROSS {
                        fo.exit_along(p, inward)
                    } else {
                        None
                    };
                    match exit {
                        Some(t) if t <= -d / MIN_EXIT_RATE => touch(arm, belt, inward, t, mu),
                        _ => touch(arm, belt, n, -d, mu),
                    }
                }
            }
        }
    }
    out
}
