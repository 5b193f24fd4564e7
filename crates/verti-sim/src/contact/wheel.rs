//! One wheel against rigid ground and obstacles: a radial spring-damper tyre (stiffer once it
//! bottoms out on the rim) at the deepest of a few points on the wheel, plus the soil under it.

use super::soil::soil_as_rigid;
use super::{WheelContact, WheelKinematics};
use crate::friction::{OBSTACLE_FRICTION, surface_mu, tyre_mu_scale};
use crate::model::WheelModel;
use crate::soil::SoilState;
use crate::spec::TyreSpec;
use crate::terrain::Terrain;
use verti_core::Vec3;

/// Contact of one wheel with rigid terrain, obstacles (indices `near`) and soil. Writes the
/// soil's plastic memory under the wheel. `soil_b`: the size of the wheel's last soil patch.
#[inline]
pub(crate) fn wheel_contact(
    terrain: &Terrain,
    soil: &mut SoilState,
    tyre: &TyreSpec,
    m: &WheelModel,
    soil_b: f64,
    kin: &WheelKinematics,
    near: &[u32],
) -> WheelContact {
    let world = &*terrain.world;
    let hf = &world.terrain;
    let ground = &terrain.ground;
    let patches = world.patches.patches();
    let (hub, axle, v_hub, up) = (kin.hub, kin.axle, kin.hub_velocity, kin.up);
    let mut c = WheelContact::default();
    let r = m.radius;

    // Quick reject: the lowest point of the wheel is above every terrain height around it.
    let down = {
        let d = Vec3::new(0.0, 0.0, -1.0) - axle * (-axle.z);
        let n = d.norm();
        if n > 1e-6 {
            d / n
        } else {
            Vec3::new(0.0, 0.0, -1.0)
        }
    };
    let lowest_z = hub.z + r * down.z - m.half_width * axle.z.abs();
    let ground_max = terrain
        .bound
        .max_in(hub.x - r, hub.y - r, hub.x + r, hub.y + r);
    let near_ground = lowest_z < ground_max;

    let soil_as_rigid = soil_as_rigid(terrain, m);
    let mut best_depth = 0.0;
    let mut best_normal = Vec3::Z;
    let mut best_mu = 1.0;
    let mut soil_here = false;
    if near_ground {
        // (1) disc-vs-plane lowest point under the hub, (2) four rim samples fore and aft so
        // steps and rock edges are seen before the hub reaches them.
        let (_, gx, gy) = ground.sample(hub.x, hub.y);
        let n0 = Vec3::new(-gx, -gy, 1.0).normalized();
        let np = n0 - axle * n0.dot(axle);
        let npn = np.norm();
        let extreme = if npn > 1e-6 {
            hub - np * (r / npn) - axle * (m.half_width * n0.dot(axle).signum())
        } else {
            hub - n0 * m.half_width
        };
        let fwd = down.cross(axle);
        let samples = [
            extreme,
            hub + (down * 0.8253 + fwd * 0.5646) * r, // ±34.4°
            hub + (down * 0.8253 - fwd * 0.5646) * r,
            hub + (down * 0.3624 + fwd * 0.9320) * r, // ±68.8°
            hub + (down * 0.3624 - fwd * 0.9320) * r,
        ];
        for (k, p) in samples.iter().enumerate() {
            if k > 0 && (p.z >= ground_max || p.z >= terrain.bound.max_at(p.x, p.y)) {
                continue;
            }
            let (h, gx, gy) = ground.sample(p.x, p.y);
            if h <= p.z {
                continue;
            }
            let patch = ground.patch_index(p.x, p.y);
            let surface = &patches[patch].surface;
            // Soil on the map that the grid resolves is the soil stage's (below). Beyond the
            // map edge there are no soil nodes, and a grid that cannot resolve this wheel (see
            // `soil_as_rigid`) does not act: there the soil is rigid ground of friction tan φ.
            if surface.is_deformable() && !soil_as_rigid && hf.contains(p.x, p.y) {
                soil_here = true;
                continue;
            }
            let mu = surface_mu(surface);
            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
            let top = Vec3::new(-gx * nz, -gy * nz, nz);
            // near a side bordering soil the way out may be sideways, or the edge a curb (below)
            let Some((depth, normal)) =
                terrain.wheel_rigid_point(*p, patch, (h - p.z) * nz, top, axle)
            else {
                continue;
            };
            if depth > best_depth {
                best_depth = depth;
                best_normal = normal;
                best_mu = mu;
            }
        }
        // a wheel in soil against the top edge of a rigid patch beside it: a curb
        if let Some(curb) = (!m.belted)
            .then(|| terrain.wheel_corner((hub, axle, r)))
            .flatten()
            && curb.depth > best_depth
        {
            // the rigid patch: just beyond the contact point, away from the hub
            let at = hub - curb.normal * (r + 0.01);
            best_depth = curb.depth;
            best_normal = curb.normal;
            best_mu = surface_mu(&patches[ground.patch_index(at.x, at.y)].surface);
        }
        if !soil_here && terrain.soil.is_some() {
            // the wheel may be sunk in soil with its rim samples above the undeformed level
            soil_here = patches[ground.patch_index(hub.x, hub.y)]
                .surface
                .is_deformable();
        }
    }
    let k_t = tyre.radial_stiffness;
    let c_t = tyre.radial_damping;
    let add_rigid = |c: &mut WheelContact, depth: f64, n: Vec3, mu: f64| {
        let rate = -v_hub.dot(n);
        let mut f = k_t * depth + c_t * rate;
        let mut k = k_t;
        if depth > m.rim_depth {
            // tyre bottomed out on the rim: much stiffer
            f += 10.0 * k_t * (depth - m.rim_depth);
            k += 10.0 * k_t;
        }
        if f <= 0.0 {
            return;
        }
        let nu = n.dot(up);
        c.force += n * f;
        c.k_axis += k * nu * nu;
        c.c_axis += c_t * nu * nu;
        c.k_vec += n * (k * nu);
        c.c_vec += n * (c_t * nu);
        c.mu_scale = (c.mu_scale * c.rigid_load + tyre_mu_scale(mu, tyre) * f) / (c.rigid_load + f);
        c.rigid_load += f;
        c.depth = c.depth.max(depth);
    };
    if best_depth > 0.0 {
        add_rigid(&mut c, best_depth, best_normal, best_mu);
    }

    // Obstacles: the cylinder's support point toward the nearest face.
    let mut obstacle_best: Option<(f64, Vec3)> = None;
    for &k in near {
        let Some(fo) = super::obstacle_in_reach(terrain, k, hub, r, m.half_width) else {
            continue;
        };
        let (d_hub, n_hub) = fo.signed_distance(hub);
        if d_hub > r + m.half_width {
            continue;
        }
        let np = n_hub - axle * n_hub.dot(axle);
        let npn = np.norm();
        let support = if npn > 1e-6 {
            hub - np * (r / npn) - axle * (m.half_width * n_hub.dot(axle).signum())
        } else {
            hub - n_hub * m.half_width
        };
        let (d, n) = fo.signed_distance(support);
        if d < 0.0 && obstacle_best.is_none_or(|(bd, _)| -d > bd) {
            obstacle_best = Some((-d, n));
        }
    }
    if let Some((depth, n)) = obstacle_best {
        add_rigid(&mut c, depth, n, OBSTACLE_FRICTION);
        c.obstacle = true;
    }

    if soil_here
        && !soil_as_rigid
        && let Some(layout) = terrain.soil
    {
        super::soil::soil_contact(terrain, &layout, soil, m, soil_b, kin, &mut c);
    }
    c
}
