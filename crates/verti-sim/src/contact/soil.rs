//! SCM under one wheel: visits the soil nodes under the lower part of the wheel, updates their
//! plastic memory and sums their pressure forces, their moment about the hub and the
//! Mohr–Coulomb shear limit of the patch (the storage and Bekker's law are in
//! [`crate::soil`]).

use super::wheel::MAX_SOIL_NODES_PER_WHEEL;
use super::{WheelContact, WheelKinematics};
use crate::friction::{soil_shear_strength, soil_tan_phi};
use crate::math::{fast_ceil, fast_floor};
use crate::model::WheelModel;
use crate::soil::{SoilLayout, SoilState, bekker_pressure, bekker_slope};
use crate::terrain::Terrain;
use verti_core::Vec3;
use verti_world::Surface;

/// Adds the soil under one wheel to its contact `c`. `b`: the size of the wheel's last soil
/// patch (Bekker's K_c/b term).
pub(crate) fn soil_contact(
    terrain: &Terrain,
    layout: &SoilLayout,
    soil_state: &mut SoilState,
    m: &WheelModel,
    b: f64,
    kin: &WheelKinematics,
    c: &mut WheelContact,
) {
    let patches = terrain.world.patches.patches();
    let ground = &terrain.ground;
    let (hub, axle, v_hub, up) = (kin.hub, kin.axle, kin.hub_velocity, kin.up);
    let r = m.radius;
    let delta = layout.delta;
    let area = delta * delta;
    // Footprint bound: the part of the wheel below the highest undeformed level nearby.
    let ground_max = terrain
        .bound
        .max_in(hub.x - r, hub.y - r, hub.x + r, hub.y + r);
    let drop = hub.z - ground_max;
    if drop >= r {
        return;
    }
    let half_chord = (r * r - drop.max(0.0).powi(2)).sqrt();
    let fwd = Vec3::Z.cross(axle).normalized();
    let ext_x = half_chord * fwd.x.abs() + m.half_width * axle.x.abs() + 0.5 * delta;
    let ext_y = half_chord * fwd.y.abs() + m.half_width * axle.y.abs() + 0.5 * delta;
    let i0 = fast_ceil((hub.x - ext_x) / delta);
    let i1 = fast_floor((hub.x + ext_x) / delta);
    let j0 = fast_ceil((hub.y - ext_y) / delta);
    let j1 = fast_floor((hub.y + ext_y) / delta);
    if i1 < i0 || j1 < j0 || ((i1 - i0 + 1) * (j1 - j0 + 1)) as usize > MAX_SOIL_NODES_PER_WHEEL {
        return;
    }
    // Vertical ray vs cylinder: |f + t·e|² = r², e = Z − (Z·a)a, f = w − (w·a)a.
    let e = Vec3::Z - axle * axle.z;
    let ee = e.norm_sq();
    if ee < 1e-6 {
        return; // wheel lying flat: the tread cannot meet a vertical ray
    }
    let mut along_min = f64::INFINITY;
    let mut along_max = f64::NEG_INFINITY;
    let mut across_min = f64::INFINITY;
    let mut across_max = f64::NEG_INFINITY;
    let mut shear_limit = 0.0;
    let mut janosi_weighted = 0.0;
    let mut load = 0.0;
    let mut cached_patch = usize::MAX;
    let mut cached_soil: Option<(verti_world::SoilParams, f64)> = None;
    for j in j0..=j1 {
        let y = j as f64 * delta;
        let row = ground.row(y);
        for i in i0..=i1 {
            let x = i as f64 * delta;
            let w = Vec3::new(x - hub.x, y - hub.y, -hub.z);
            let wa = w.dot(axle);
            let f = w - axle * wa;
            let fe = f.dot(e);
            let disc = fe * fe - ee * (f.norm_sq() - r * r);
            if disc <= 0.0 {
                continue;
            }
            let t = (-fe - disc.sqrt()) / ee; // lower intersection height
            // the wheel is above every terrain height around here: no sinkage possible
            if t >= ground_max {
                continue;
            }
            let lateral = wa + t * axle.z;
            if lateral.abs() > m.half_width {
                continue;
            }
            let pk = ground.patch_index(x, y);
            if pk != cached_patch {
                cached_patch = pk;
                cached_soil = match patches[pk].surface {
                    Surface::Deformable { soil } => Some((soil, soil_tan_phi(&soil))),
                    Surface::Rigid { .. } => None,
                };
            }
            let Some((soil, tan_phi)) = cached_soil else {
                continue;
            };
            let Some(at) = layout.locate(i, j) else {
                continue;
            };
            let (z0, gx, gy) = row.sample(x);
            let ca = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
            let sinkage = ca * (z0 - t);
            let (plastic, yield_p) = soil_state.node(at);
            if sinkage <= plastic {
                continue;
            }
            let ke = soil.elastic_k.max(soil.bekker_kphi);
            let mut sigma = ke * (sinkage - plastic);
            let mut slope = ke;
            if sigma > yield_p {
                sigma = bekker_pressure(&soil, b, sinkage);
                slope = bekker_slope(&soil, sigma, sinkage).min(ke);
                let new_plastic = (sinkage - sigma / ke).max(plastic);
                soil_state.set_node(at, new_plastic, sigma);
            }
            let normal = Vec3::new(-gx * ca, -gy * ca, ca);
            let point = Vec3::new(x, y, t);
            let arm = point - hub;
            // SCM damping on the normal speed of the wheel body. Chrono uses the speed of the
            // contact point including the wheel's spin; a wheel spinning at high slip then
            // sees its rotating tread as a fast plunge at the front of the patch and a lift at
            // the rear (hundreds of kPa at R = 3e4), which is not soil physics. Deliberate
            // fix: the hub's translation only. Like Chrono, it may pull.
            sigma -= v_hub.dot(normal) * soil.damping;
            let fnode = normal * (sigma * area);
            c.force += fnode;
            c.soil_moment += arm.cross(fnode);
            let nu = normal.dot(up);
            c.k_axis += slope * area * nu * nu;
            c.c_axis += soil.damping * area * nu * nu;
            c.k_vec += normal * (slope * area * nu);
            c.c_vec += normal * (soil.damping * area * nu);
            shear_limit += soil_shear_strength(&soil, sigma.max(0.0), tan_phi) * area;
            janosi_weighted += soil.janosi_k * sigma.abs() * area;
            load += sigma * area;
            c.sinkage = c.sinkage.max(sinkage);
            c.soil_nodes += 1;
            let along = arm.dot(fwd);
            let across = arm.dot(axle);
            along_min = along_min.min(along);
            along_max = along_max.max(along);
            across_min = across_min.min(across);
            across_max = across_max.max(across);
        }
    }
    if c.soil_nodes > 0 {
        let length = along_max - along_min + delta;
        let width = across_max - across_min + delta;
        c.soil_load += load.max(0.0);
        c.soil_shear_limit += shear_limit;
        c.soil_length = length;
        c.soil_janosi_k = if load.abs() > 0.0 {
            janosi_weighted / load.abs().max(1e-9)
        } else {
            0.01
        };
        // b = 2A/L of the patch (rectangle of the hit extents) for Bekker's K_c/b next time
        let a_patch = f64::from(c.soil_nodes) * area;
        let perimeter = 2.0 * (length + width);
        c.soil_b = (2.0 * a_patch / perimeter).max(0.5 * delta);
    }
}
