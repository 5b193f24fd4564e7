//! SCM under one wheel: visits the soil nodes under the lower part of the wheel, updates their
//! plastic memory and sums their pressure forces, their moment about the hub and the
//! Mohr–Coulomb shear limit of the patch (the storage and Bekker's law are in
//! [`crate::soil`]).

use super::bulldozing::{PatchNode, bulldoze};
use super::{WheelContact, WheelKinematics};
use crate::friction::{soil_shear_strength, soil_tan_phi};
use crate::math::{fast_ceil, fast_floor};
use crate::model::WheelModel;
use crate::soil::{SoilLayout, SoilState, bekker_pressure, bekker_slope};
use crate::terrain::Terrain;
use verti_core::Vec3;
use verti_world::Surface;

// The cap and `soil_as_rigid` (whether the soil grid acts under a wheel at all) are this
// stage's limits; both tyre models (`wheel`, `rigid`) ask them before handing a wheel here.

/// How far above a node's soil SCM's ray still finds the wheel (its `test_offset_up`) \[m\].
const RAY_REACH: f64 = 0.1;

/// The patch nodes of the wheels whose soil contact this step has computed, wheel after
/// wheel (`starts`: where each wheel's begin).
#[derive(Default)]
struct Patches {
    nodes: Vec<PatchNode>,
    starts: Vec<usize>,
}

thread_local! {
    static PATCHES: std::cell::RefCell<Patches> = std::cell::RefCell::new(Patches::default());
}

/// Safety cap on soil nodes visited per wheel per step.
pub(crate) const MAX_SOIL_NODES_PER_WHEEL: usize = 4096;

/// True when the soil grid cannot resolve this wheel, so the soil acts as rigid ground under
/// it: a tread narrower than the node spacing (a 1/10 vehicle on a full-scale world) could
/// fall between nodes, and a wheel far too big for the grid would visit thousands of nodes.
#[inline]
pub(crate) fn soil_as_rigid(terrain: &Terrain, m: &WheelModel) -> bool {
    let r = m.radius;
    terrain.soil.is_none_or(|l| {
        let span = (2.0 * r + 2.0 * m.half_width) / l.delta + 2.0;
        span * span > MAX_SOIL_NODES_PER_WHEEL as f64
            || 2.0 * m.half_width < l.delta
            || r < 1.5 * l.delta
    })
}

/// Adds the soil under one wheel to its contact `c`, and queues the wheel's patch for the
/// step's bulldozing ([`bulldoze_step`], once every wheel's contact is known, as SCM does).
/// `b`: the size of the wheel's last soil patch (Bekker's K_c/b term).
pub(crate) fn soil_contact(
    terrain: &Terrain,
    layout: &SoilLayout,
    soil_state: &mut SoilState,
    m: &WheelModel,
    b: f64,
    kin: &WheelKinematics,
    c: &mut WheelContact,
) {
    PATCHES.with_borrow_mut(|patches| {
        patches.starts.push(patches.nodes.len());
        soil_pressure(
            terrain,
            layout,
            soil_state,
            m,
            b,
            kin,
            c,
            &mut patches.nodes,
        );
    });
}

/// Empties the queue of patches: a step starts with none (a step abandoned half-way, or a
/// test that called [`soil_contact`] alone, must not leave patches to the next).
pub(crate) fn begin_soil_step() {
    PATCHES.with_borrow_mut(|patches| {
        patches.nodes.clear();
        patches.starts.clear();
    });
}

/// The step's bulldozing: heaps and erodes the soil every wheel queued by [`soil_contact`]
/// displaced ([`bulldoze`]), and empties the queue.
pub(crate) fn bulldoze_step(terrain: &Terrain, soil_state: &mut SoilState) {
    PATCHES.with_borrow_mut(|patches| {
        if let Some(layout) = terrain.soil {
            let n = patches.nodes.len();
            for (w, &start) in patches.starts.iter().enumerate() {
                let end = patches.starts.get(w + 1).copied().unwrap_or(n);
                let (own, others) = (start..end, [0..start, end..n]);
                bulldoze(terrain, &layout, soil_state, &patches.nodes, own, others);
            }
        }
        patches.nodes.clear();
        patches.starts.clear();
    });
}

/// The flat lower run of a track's belt under one road wheel ([`WheelModel::belt_plate`]): a
/// plane tangent to the bottom of the wheel, square to the hull's up axis, from `behind` to
/// `ahead` of the hub along the belt and as wide as the wheel. Between road wheels the belt,
/// tensioned over them, carries the soil's pressure as a plate, so the track sinks as Bekker's
/// plate does rather than as separate wheels.
struct BeltPlate {
    /// The plate's outward normal (the hull's up axis, square to the axle).
    normal: Vec3,
    /// Along the belt, forwards.
    along: Vec3,
    ahead: f64,
    behind: f64,
    /// max(ahead, behind) \[m\].
    reach: f64,
    /// The plate's point under the hub (the wheel's bottom).
    base: Vec3,
    hub: Vec3,
    axle: Vec3,
    half_width: f64,
}

impl BeltPlate {
    /// `None` for a wheel without a plate, or a hull on its side (the plate nearly vertical).
    fn new(m: &WheelModel, kin: &WheelKinematics) -> Option<BeltPlate> {
        let (ahead, behind) = m.belt_plate;
        if ahead <= 0.0 && behind <= 0.0 {
            return None;
        }
        let normal = (kin.up - kin.axle * kin.up.dot(kin.axle)).normalized();
        if normal.z < 0.3 {
            return None;
        }
        Some(BeltPlate {
            normal,
            along: kin.axle.cross(normal),
            ahead,
            behind,
            reach: ahead.max(behind),
            base: kin.hub - normal * m.radius,
            hub: kin.hub,
            axle: kin.axle,
            half_width: m.half_width,
        })
    }

    /// Height at which the vertical line through (x, y) meets the plate, if it meets it within
    /// the plate's extent.
    #[inline]
    fn height_over(&self, x: f64, y: f64) -> Option<f64> {
        let (n, base) = (self.normal, self.base);
        let t = base.z - (n.x * (x - base.x) + n.y * (y - base.y)) / n.z;
        let arm = Vec3::new(x, y, t) - self.hub;
        let along = arm.dot(self.along);
        let across = arm.dot(self.axle);
        (along <= self.ahead && along >= -self.behind && across.abs() <= self.half_width)
            .then_some(t)
    }
}

/// The pressure stage of [`soil_contact`]: the soil's forces on the wheel and the new plastic
/// sinkage of its nodes; the wheel's patch nodes go to `patch`.
#[allow(clippy::too_many_arguments)]
fn soil_pressure(
    terrain: &Terrain,
    layout: &SoilLayout,
    soil_state: &mut SoilState,
    m: &WheelModel,
    b: f64,
    kin: &WheelKinematics,
    c: &mut WheelContact,
    patch: &mut Vec<PatchNode>,
) {
    let patches = terrain.world.patches.patches();
    let ground = &terrain.ground;
    let (hub, axle, v_hub, up) = (kin.hub, kin.axle, kin.hub_velocity, kin.up);
    // the wheel body's angular velocity: the chassis' and the spin (for the tread's speed)
    let wheel_omega = kin.chassis_omega + axle * kin.spin;
    let r = m.radius;
    let delta = layout.delta;
    let area = delta * delta;
    let plate = BeltPlate::new(m, kin);
    let plate_reach = plate.as_ref().map_or(0.0, |p| p.reach);
    // the horizontal reach of what can touch the soil: the wheel, or the belt's plate
    let span = r.max(plate_reach);
    // Footprint bound: the part of the wheel below the highest undeformed level nearby.
    // heaped soil may stand above the undeformed ground, and SCM's rays see the wheel up to
    // RAY_REACH above the soil (the nodes bulldozing may not raise through the wheel)
    let reach = (
        fast_floor((hub.x - span) / delta) - 1,
        fast_ceil((hub.x + span) / delta) + 1,
        fast_floor((hub.y - span) / delta) - 1,
        fast_ceil((hub.y + span) / delta) + 1,
    );
    let ground_max = terrain
        .bound
        .max_in(hub.x - span, hub.y - span, hub.x + span, hub.y + span)
        + soil_state.max_heap_in(layout, reach);
    let drop = hub.z - ground_max - RAY_REACH;
    // (a plate tilted with the hull reaches at most its length lower than the wheel)
    if drop >= r + plate_reach {
        return;
    }
    let half_chord = match &plate {
        None => (r * r - drop.max(0.0).powi(2)).sqrt(),
        Some(p) => p.reach.max(r),
    };
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
            // the lowest point over the node: on the belt's plate where that covers the node
            // (the wheel lies above the plate, which is tangent to its bottom), else on the
            // wheel's tread
            let on_plate = plate.as_ref().and_then(|p| p.height_over(x, y));
            let t = match on_plate {
                Some(t) => t,
                None => {
                    let w = Vec3::new(x - hub.x, y - hub.y, -hub.z);
                    let wa = w.dot(axle);
                    let f = w - axle * wa;
                    let fe = f.dot(e);
                    let disc = fe * fe - ee * (f.norm_sq() - r * r);
                    if disc <= 0.0 {
                        continue;
                    }
                    let t = (-fe - disc.sqrt()) / ee; // lower intersection height
                    let lateral = wa + t * axle.z;
                    if lateral.abs() > m.half_width {
                        continue;
                    }
                    t
                }
            };
            // the wheel is above every terrain height around here: no sinkage possible
            if t >= ground_max + RAY_REACH {
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
            let node = soil_state.node(at);
            let (plastic, yield_p) = (node.plastic, node.yield_pressure);
            let sinkage = ca * (z0 + node.heap - t);
            if sinkage <= plastic {
                if sinkage > plastic - RAY_REACH * ca {
                    patch.push(PatchNode {
                        i,
                        j,
                        sigma: 0.0,
                        flow: 0.0,
                        hit: t,
                    });
                }
                continue;
            }
            let ke = soil.elastic_k.max(soil.bekker_kphi);
            let mut sigma = ke * (sinkage - plastic);
            let mut slope = ke;
            let mut flow = 0.0;
            if sigma > yield_p {
                sigma = bekker_pressure(&soil, b, sinkage);
                slope = bekker_slope(&soil, sigma, sinkage).min(ke);
                let new_plastic = (sinkage - sigma / ke).max(plastic);
                flow = new_plastic - plastic;
                soil_state.set_node(at, new_plastic, sigma);
            }
            let normal = Vec3::new(-gx * ca, -gy * ca, ca);
            let point = Vec3::new(x, y, t);
            let arm = point - hub;
            // SCM damping on the normal speed of the wheel's surface at the node, spin
            // included, as Chrono's SCM takes it (the contactable's point speed): at speed the
            // tread plunges into the front of the patch and lifts out of its rear, so the
            // front carries more than Bekker's pressure and the wheel rides higher in soft
            // soil. Like Chrono, not clamped: at the rear it may pull. (verti used the hub's
            // translation alone until issue 34: its HMMWV then sank deeper at speed than
            // Chrono's and stopped on snow where Chrono's drives on; snow agreement with the
            // reference went from 33 % to 60 % with this alone.)
            let v_point = v_hub + wheel_omega.cross(arm);
            sigma -= v_point.dot(normal) * soil.damping;
            patch.push(PatchNode {
                i,
                j,
                sigma,
                flow,
                hit: t,
            });
            let fnode = normal * (sigma * area);
            c.force += fnode;
            let moment = arm.cross(fnode);
            c.soil_moment += moment;
            if on_plate.is_some() {
                c.belt_axle_moment += moment.dot(axle);
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::terrain::Terrain;
    use std::sync::Arc;
    use verti_world::SoilParams;

    /// The discrete closed form (what SCM's node grid makes of Bekker's law): the load the soil
    /// nodes under a level cylinder carry with its lowest line `z0` deep, and the deepest node's
    /// sinkage. Node i along the wheel, at x from the hub, sinks z0 − (R − √(R² − x²)); every
    /// row across the tread alike; b = 2A/L of the rectangle of hit nodes.
    fn closed_form(soil: &SoilParams, hub: Vec3, r: f64, half_width: f64, z0: f64) -> (f64, f64) {
        let d = 0.1;
        let rows = (((hub.y - half_width) / d).ceil() as i64
            ..=((hub.y + half_width) / d).floor() as i64)
            .count() as f64;
        let sink: Vec<f64> = (((hub.x - r) / d).ceil() as i64..=((hub.x + r) / d).floor() as i64)
            .map(|i| i as f64 * d - hub.x)
            .map(|x| z0 - (r - (r * r - x * x).max(0.0).sqrt()))
            .filter(|z| *z > 0.0)
            .collect();
        let (length, width) = (sink.len() as f64 * d, rows * d);
        let b = (2.0 * length * width / (2.0 * (length + width))).max(0.5 * d);
        let k = soil.bekker_kc / b + soil.bekker_kphi;
        let load = sink.iter().map(|z| k * z.powf(soil.bekker_n)).sum::<f64>() * rows * d * d;
        (load, sink.iter().cloned().fold(0.0, f64::max))
    }

    /// The model's first wheel pressed quasi-statically into fresh `soil` at `hub` (x, y) until
    /// it carries `load`: the contact kinematics, the soil state and the patch size reached.
    fn pressed(
        terrain: &Terrain,
        model: &Model,
        hub: Vec3,
        load: f64,
    ) -> (WheelKinematics, SoilState, f64, WheelContact) {
        pressed_wheel(terrain, model, 0, hub, load)
    }

    /// [`pressed`] for wheel `w` of the model.
    fn pressed_wheel(
        terrain: &Terrain,
        model: &Model,
        w: usize,
        mut hub: Vec3,
        load: f64,
    ) -> (WheelKinematics, SoilState, f64, WheelContact) {
        let layout = terrain.soil.unwrap();
        let mut state = SoilState::new(Some(&layout));
        let (mut b, mut c) = (0.3, WheelContact::default());
        let mut kin = WheelKinematics::at_rest(hub);
        while c.force.z < load {
            hub.z -= 1e-5;
            kin.hub = hub;
            c = WheelContact::default();
            soil_pressure(
                terrain,
                &layout,
                &mut state,
                &model.wheels[w],
                b,
                &kin,
                &mut c,
                &mut Vec::new(),
            );
            if c.soil_nodes > 0 {
                b = c.soil_b;
            }
        }
        (kin, state, b, c)
    }

    /// SCM's damping acts on the normal speed of the wheel's surface, spin included (Chrono's
    /// contact point speed): a wheel spinning at ω in place over flat soil sees its tread move
    /// down at ω·x at x ahead of the hub and up behind it, so node i gains R·ω·xᵢ of pressure
    /// and the wheel a moment −R·ω·Σxᵢ²·A about its axle (resisting the spin) and a lift
    /// R·ω·Σxᵢ·A — exactly, on top of the pressures at rest.
    #[test]
    fn soil_damping_sees_the_spinning_tread() {
        let spec = crate::vehicles::builtin("hmmwv").unwrap();
        let model = Model::compile(&spec, 1.0);
        let soil = SoilParams::MID;
        let world = Arc::new(crate::testing::soil_world(1.0, soil, 0.0));
        let terrain = Terrain::new(&world, model.reach).unwrap();
        let layout = terrain.soil.unwrap();
        let (kin, state, b, _) = pressed(&terrain, &model, Vec3::new(0.03, 0.02, 0.467), 6000.0);
        let at_rest = |spin: f64| {
            let mut st = state.clone();
            let mut c = WheelContact::default();
            let kin = WheelKinematics { spin, ..kin };
            soil_pressure(
                &terrain,
                &layout,
                &mut st,
                &model.wheels[0],
                b,
                &kin,
                &mut c,
                &mut Vec::new(),
            );
            c
        };
        let still = at_rest(0.0);
        let omega = 3.0;
        let spinning = at_rest(omega);
        // the nodes under the wheel, as offsets from the hub along it
        let (d, r) = (0.1, model.wheels[0].radius);
        let z0 = r - kin.hub.z;
        let xs: Vec<f64> = (((kin.hub.x - r) / d).ceil() as i64..=((kin.hub.x + r) / d) as i64)
            .map(|i| i as f64 * d - kin.hub.x)
            .filter(|x| z0 - (r - (r * r - x * x).max(0.0).sqrt()) > 0.0)
            .collect();
        let rows = 3.0;
        let area = d * d;
        let (sx, sxx) = (
            xs.iter().sum::<f64>() * rows,
            xs.iter().map(|x| x * x).sum::<f64>() * rows,
        );
        assert_eq!(still.soil_nodes as usize, xs.len() * 3);
        let moment = (spinning.soil_moment - still.soil_moment).dot(Vec3::Y);
        let lift = spinning.force.z - still.force.z;
        let (want_moment, want_lift) = (
            -soil.damping * omega * sxx * area,
            soil.damping * omega * sx * area,
        );
        assert!(
            (moment - want_moment).abs() < 1e-9 * want_moment.abs(),
            "moment {moment} vs {want_moment}"
        );
        assert!(
            (lift - want_lift).abs() < 1e-6,
            "lift {lift} vs {want_lift}"
        );
        assert!(moment < -100.0, "a noticeable resistance: {moment} N m");
    }

    /// A wheel lowered slowly into fresh soil until it carries `load`: SCM's pressure-sinkage
    /// law alone (no vehicle dynamics, so no overshoot, and no bulldozing), against the closed
    /// form above.
    #[test]
    fn a_wheel_pressed_into_soil_sinks_as_the_node_grid_carries_bekker_pressure() {
        let spec = crate::vehicles::builtin("hmmwv").unwrap();
        let model = Model::compile(&spec, 1.0);
        let m = &model.wheels[0];
        let (r, load) = (m.radius, 6000.0);
        for soil in [SoilParams::SOFT, SoilParams::MID, SoilParams::HARD] {
            let world = Arc::new(crate::testing::soil_world(1.0, soil, 0.0));
            let terrain = Terrain::new(&world, model.reach).unwrap();
            // off the grid lines: three node rows across the tread, then two
            for hub in [Vec3::new(0.03, 0.02, r), Vec3::new(0.03, 0.06, r)] {
                let (kin, _, _, c) = pressed(&terrain, &model, hub, load);
                let hub = kin.hub;
                let z0 = r - hub.z;
                let (carried, deepest) = closed_form(&soil, hub, r, m.half_width, z0);
                assert!(
                    (c.force.z - carried).abs() < 0.01 * carried,
                    "{soil:?} at {hub:?}: {} N carried, {carried} N on paper",
                    c.force.z
                );
                assert!(
                    (c.sinkage - deepest).abs() < 1e-9,
                    "{} vs {deepest}",
                    c.sinkage
                );
                // and the load's sinkage is the closed form's (within the 0.01 mm steps)
                let mut lo = 0.0;
                let mut hi = r;
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if closed_form(&soil, hub, r, m.half_width, mid).0 < load {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                assert!((z0 - lo).abs() < 2e-5, "{soil:?}: z0 {z0} vs {lo}");
            }
        }
    }

    /// A road wheel of the M113 between two others bears on soil through the belt's plate: the
    /// nodes under a flat rectangle one road-wheel spacing long (0.667 m) and the track's width
    /// (0.413 m), all at the plate's depth. Pressed quasi-statically until it carries 10 kN, it
    /// sinks as the node grid carries Bekker's pressure over that rectangle (the nodes whose
    /// centres it covers), to the 0.01 mm steps; no pressure moment reaches the road wheel's
    /// spin (the belt is not part of the wheel), all of it is the belt's.
    #[test]
    fn a_road_wheel_bears_on_soil_through_the_belt_plate() {
        let spec = crate::vehicles::builtin("m113").unwrap();
        let model = Model::compile(&spec, 1.0);
        let w = 2; // the second road wheel on the left
        let m = &model.wheels[w];
        let (ahead, behind) = m.belt_plate;
        assert!(
            (ahead - 0.3335).abs() < 1e-9 && (behind - 0.3335).abs() < 1e-9,
            "{ahead} {behind}"
        );
        let (first, last) = (model.wheels[0].belt_plate, model.wheels[8].belt_plate);
        assert!(first.0 == 0.0 && last.1 == 0.0, "{first:?} {last:?}");
        let (r, load) = (m.radius, 10_000.0);
        for (name, soil) in [
            ("snow", SoilParams::SOFT),
            ("mud", SoilParams::MID),
            ("sand", SoilParams::HARD),
        ] {
            let world = Arc::new(crate::testing::soil_world(1.0, soil, 0.0));
            let terrain = Terrain::new(&world, model.reach).unwrap();
            let hub = Vec3::new(0.03, 0.02, r);
            let (kin, _, _, c) = pressed_wheel(&terrain, &model, w, hub, load);
            let z0 = r - kin.hub.z;
            let d = 0.1;
            let count =
                |lo: f64, hi: f64| ((lo / d).ceil() as i64..=(hi / d).floor() as i64).count();
            let nodes = count(kin.hub.x - behind, kin.hub.x + ahead)
                * count(kin.hub.y - m.half_width, kin.hub.y + m.half_width);
            let (length, width) = (ahead + behind, 2.0 * m.half_width);
            let b = c.soil_b;
            let k = soil.bekker_kc / b + soil.bekker_kphi;
            let carried = nodes as f64 * d * d * k * z0.powf(soil.bekker_n);
            assert_eq!(c.soil_nodes as usize, nodes, "{soil:?}");
            assert!(
                (c.force.z - carried).abs() < 0.01 * carried,
                "{soil:?}: {} N carried, {carried} N on paper",
                c.force.z
            );
            assert!((c.sinkage - z0).abs() < 1e-9, "{} vs {z0}", c.sinkage);
            assert!(
                (c.soil_moment.dot(kin.axle) - c.belt_axle_moment).abs() < 1e-9,
                "{soil:?}: {} of the moment about the axle is not the belt's",
                c.soil_moment.dot(kin.axle) - c.belt_axle_moment
            );
            println!(
                "{name}: {length:.3} x {width:.3} m plate, {nodes} nodes, {z0:.4} m under {:.0} N",
                c.force.z
            );
        }
    }
}

#[cfg(test)]
mod rig {
    use super::*;
    use crate::model::Model;
    use std::sync::Arc;
    use verti_world::SoilParams;

    /// One HMMWV wheel on a carrier of `load` newtons moved along x at `v`, spun at v/r, free
    /// to move up and down (explicit Euler, as Chrono applies SCM's forces): the mean sinkage
    /// r − z over 10 m of steady rolling after 2 s at rest, a 1-s run-up and 5 m.
    fn rolling_sinkage(soil: SoilParams, v: f64, load: f64) -> f64 {
        rolling_sinkage_slip(soil, v, 0.0, load)
    }

    /// As [`rolling_sinkage`], the wheel spun at v/(r(1 − slip)).
    fn rolling_sinkage_slip(soil: SoilParams, v: f64, slip: f64, load: f64) -> f64 {
        let spec = crate::vehicles::builtin("hmmwv").unwrap();
        let model = Model::compile(&spec, 1.0);
        let m = &model.wheels[0];
        let r = m.radius;
        let world = Arc::new(crate::testing::soil_world(1.0, soil, 0.0));
        let terrain = Terrain::new(&world, model.reach).unwrap();
        let layout = terrain.soil.unwrap();
        let mut state = SoilState::new(Some(&layout));
        let (dt, mass) = (0.005, load / 9.81);
        let (x0, settle, ramp) = (-20.0, 2.0, 1.0);
        let (mut hub, mut vz, mut b) = (Vec3::new(x0, 0.0, r), 0.0, 0.3);
        let (mut t, mut sum, mut n) = (0.0f64, 0.0, 0);
        while hub.x < x0 + 15.0 + v * (settle + ramp) {
            let vx = v * ((t - settle) / ramp).clamp(0.0, 1.0);
            let kin = WheelKinematics {
                hub_velocity: Vec3::new(vx, 0.0, vz),
                spin: vx / (r * (1.0 - slip)),
                ..WheelKinematics::at_rest(hub)
            };
            let mut c = WheelContact::default();
            soil_contact(&terrain, &layout, &mut state, m, b, &kin, &mut c);
            bulldoze_step(&terrain, &mut state);
            if c.soil_nodes > 0 {
                b = c.soil_b;
            }
            vz += (c.force.z - load) / mass * dt;
            hub.z += vz * dt;
            hub.x += vx * dt;
            t += dt;
            if hub.x > x0 + 5.0 + v * (settle + ramp) {
                sum += r - hub.z;
                n += 1;
            }
        }
        sum / f64::from(n)
    }

    /// Chrono 9.0.1's rigid HMMWV wheel (a cylinder of radius 0.467 m and width 0.254 m, 6100 N,
    /// spun at v/(r(1 − slip))) rolling over SCM soil with Verti-Bench's parameters and bulldozing, 5 ms
    /// steps: `scripts/chrono/wheel_rig.cpp SOIL V SLIP 6100`. Its sinkage falls with speed (SCM's
    /// damping on the tread's normal speed) and with the soil heaped ahead of the wheel; without
    /// bulldozing Chrono's wheel sinks 0.158 m in snow at 3 m/s and verti's did 0.173 m.
    /// The table of docs/src/results/chrono.md ("One wheel rolling on soil"):
    /// `cargo test -p verti-sim --release --lib rolling_sinkage_table -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn rolling_sinkage_table() {
        for (name, soil) in [
            ("snow", SoilParams::SOFT),
            ("mud", SoilParams::MID),
            ("sand", SoilParams::HARD),
        ] {
            for v in [0.5, 1.0, 2.0, 3.0, 4.0] {
                println!("{name} {v} m/s: {:.4} m", rolling_sinkage(soil, v, 6100.0));
            }
            for slip in [0.2, 0.5] {
                let z = rolling_sinkage_slip(soil, 1.0, slip, 6100.0);
                println!("{name} 1 m/s, slip {slip}: {z:.4} m");
            }
        }
    }

    #[test]
    fn a_rolling_wheel_sinks_as_chronos_scm_wheel() {
        // (soil, speed, slip, Chrono's sinkage): a driven wheel slipping 50 % rides higher
        for (soil, v, slip, chrono) in [
            (SoilParams::SOFT, 1.0, 0.0, 0.2215),
            (SoilParams::SOFT, 3.0, 0.0, 0.1240),
            (SoilParams::SOFT, 1.0, 0.5, 0.1723),
            (SoilParams::MID, 1.0, 0.0, 0.0502),
            (SoilParams::MID, 3.0, 0.0, 0.0426),
            (SoilParams::MID, 1.0, 0.5, 0.0472),
            (SoilParams::HARD, 1.0, 0.0, 0.0085),
            (SoilParams::HARD, 3.0, 0.0, 0.0071),
        ] {
            let verti = rolling_sinkage_slip(soil, v, slip, 6100.0);
            assert!(
                (verti - chrono).abs() < 0.003f64.max(0.12 * chrono),
                "{soil:?} at {v} m/s, slip {slip}: verti sinks {verti:.4} m, Chrono {chrono} m"
            );
        }
    }
}
