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

use crate::drivetrain::SpinLoads;
use crate::friction::{OBSTACLE_FRICTION, surface_mu};
use crate::integrate::Loads;
use crate::model::Model;
use crate::spec::MAX_WHEELS;
use crate::state::SimState;
use crate::terrain::Terrain;
use crate::track_runs::{MAX_PROFILE, ProfilePoint, TrackRuns};
use verti_core::Vec3;

/// A straight run's point is pushed along the run's normal only while that frees it within 4
/// times its shortest way out (the ground's or rock face's normal); beyond (the run's normal
/// nearly along the surface, e.g. a run pressed into a wall) the surface's normal takes over.
const MIN_EXIT_RATE: f64 = 0.25;

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
        for pt in &profile[..count] {
            let belt = rm.mul_vec(pt.belt());
            // A straight run is a flat belt: whatever pokes into it (a rock's edge, a ridge's
            // crest) pushes it along its own normal, by how far the point must move that way
            // to come free. Pushed along the rock face's normal instead, an edge under the
            // front run would hold the vehicle back horizontally where the run rides up it. A
            // roller is round and meets a surface along the surface's normal.
            let inward = rm.mul_vec(Vec3::new(-pt.nx, 0.0, -pt.nz));
            for &y in &side.lines {
                let arm = rm.mul_vec(Vec3::new(pt.x, y, pt.z));
                let p = st.position + arm;
                if p.z < terrain.bound.max_at(p.x, p.y) {
                    let (h, gx, gy) = terrain.ground.sample(p.x, p.y);
                    let surface = &patches[terrain.ground.patch_index(p.x, p.y)].surface;
                    let h = match surface {
                        verti_world::Surface::Deformable { .. } => h - model.soil_floor,
                        verti_world::Surface::Rigid { .. } => h,
                    };
                    if h > p.z {
                        let mu = surface_mu(surface).min(runs.mu);
                        // rise of the ground-relative height per unit move along `inward`
                        let rate = inward.z - gx * inward.x - gy * inward.y;
                        if pt.straight && rate >= MIN_EXIT_RATE {
                            touch(arm, belt, inward, (h - p.z) / rate, mu);
                        } else {
                            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                            let n = Vec3::new(-gx * nz, -gy * nz, nz);
                            touch(arm, belt, n, (h - p.z) * nz, mu);
                        }
                    }
                }
                for &k in near {
                    let fo = &terrain.fast_obstacles[k as usize];
                    if (p - fo.center).norm_sq() > fo.radius * fo.radius {
                        continue;
                    }
                    let (d, n) = fo.signed_distance(p);
                    if d >= 0.0 {
                        continue;
                    }
                    let mu = OBSTACLE_FRICTION.min(runs.mu);
                    match fo.exit_along(p, inward) {
                        Some(t) if pt.straight && t <= -d / MIN_EXIT_RATE => {
                            touch(arm, belt, inward, t, mu)
                        }
                        _ => touch(arm, belt, n, -d, mu),
                    }
                }
            }
        }
    }
    out
}
