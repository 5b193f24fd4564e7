//! Start poses: seating a vehicle on the terrain at a spot and heading, and the state at rest
//! there. Pure functions of the world, the vehicle and the spot: nothing in a [`crate::Sim`]
//! depends on where a vehicle starts.

use crate::error::SimError;
use crate::friction::static_slip;
use crate::model::{GRAVITY, Model, static_compressions};
use crate::soil::SoilState;
use crate::spec::VehicleSpec;
use crate::state::{ContactInfo, Controls, Pose, SimState, StartPose, WheelState};
use crate::terrain::Terrain;
use verti_core::{Quat, Vec3};
use verti_world::{SoilParams, Surface, World};

/// Places a vehicle at (x, y) with heading `yaw`, pitched and rolled to the terrain plane fitted
/// under its wheels, springs at their static compression and tyres at their static deflection
/// (on soil the wheels then start slightly sunk and settle by the soil's sinkage). Refuses a
/// start off the map or inside an obstacle.
pub(crate) fn seat(world: &World, spec: &VehicleSpec, start: StartPose) -> Result<Pose, SimError> {
    let StartPose { x, y, yaw } = start;
    if !(x.is_finite() && y.is_finite() && yaw.is_finite()) {
        return Err(SimError::InvalidStart(format!(
            "({x}, {y}, yaw {yaw}) is not finite"
        )));
    }
    if !world.terrain.contains(x, y) {
        return Err(SimError::InvalidStart(format!(
            "({x:.2}, {y:.2}) is off the map (half extent {:.2} m)",
            world.terrain.half_extent()
        )));
    }
    let hf = &world.terrain;
    let (s, c) = libm::sincos(yaw);
    let comp = static_compressions(spec);
    // Least-squares plane z = a + b·x' + c·y' in heading coordinates through the wheel spots.
    let mut rows = Vec::new();
    for (k, ax) in spec.axles.iter().enumerate() {
        for side in [1.0, -1.0] {
            let (lx, ly) = (ax.x, side * 0.5 * ax.track);
            let h = hf.height_at(x + c * lx - s * ly, y + s * lx + c * ly);
            rows.push((lx, ly, h, k));
        }
    }
    let n = rows.len() as f64;
    let mx = rows.iter().map(|r| r.0).sum::<f64>() / n;
    let my = rows.iter().map(|r| r.1).sum::<f64>() / n;
    let mh = rows.iter().map(|r| r.2).sum::<f64>() / n;
    let sxx: f64 = rows.iter().map(|r| (r.0 - mx).powi(2)).sum();
    let syy: f64 = rows.iter().map(|r| (r.1 - my).powi(2)).sum();
    let sxh: f64 = rows.iter().map(|r| (r.0 - mx) * (r.2 - mh)).sum();
    let syh: f64 = rows.iter().map(|r| (r.1 - my) * (r.2 - mh)).sum();
    let slope_x = if sxx > 1e-12 { sxh / sxx } else { 0.0 };
    let slope_y = if syy > 1e-12 { syh / syy } else { 0.0 };
    let orientation = quat_from_euler(libm::atan(slope_y), -libm::atan(slope_x), yaw);
    // Seat every tyre at its static deflection under an equal share of the weight (so a
    // vehicle set down on flat ground barely moves), and no tyre deeper than that.
    let weight = (spec.chassis.mass
        + spec.track.map_or(0.0, |t| 2.0 * t.track_mass)
        + spec
            .axles
            .iter()
            .map(|a| 2.0 * a.wheel.unsprung_mass)
            .sum::<f64>())
        * GRAVITY;
    let load = weight / spec.wheel_count() as f64;
    let deflection = load / spec.tyre.radial_stiffness;
    let mut z = f64::NEG_INFINITY;
    for (lx, ly, _, k) in &rows {
        let ax = &spec.axles[*k];
        let local = Vec3::new(*lx, *ly, ax.z + comp[*k]);
        let hub = orientation.rotate(local);
        let (hx, hy) = (x + hub.x, y + hub.y);
        let (h, gx, gy) = hf.sample(hx, hy);
        let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
        // On soil, seat the wheel at its static Bekker sinkage instead: dropped onto the
        // undeformed surface it would overshoot, and the plastic memory would keep the ruts of
        // that first bounce (deep enough to high-centre a HMMWV in snow).
        let sunk = match world.patches.at(hx, hy).surface {
            Surface::Deformable { soil } if world.terrain.contains(hx, hy) => {
                // a track's road wheels bear on soil through the belt's plates
                // (`WheelModel::belt_plate`)
                let (ahead, behind) = spec.belt_plate(*k);
                match ahead + behind {
                    l if l > 0.0 => plate_sinkage(load * nz, ax.wheel.width, l, &soil),
                    _ => static_sinkage(load * nz, ax.wheel.width, ax.wheel.radius, &soil),
                }
                .min(0.8 * ax.wheel.radius)
            }
            _ => deflection,
        };
        z = z.max(h + (ax.wheel.radius - sunk) / nz - hub.z);
    }
    let pose = Pose {
        position: Vec3::new(x, y, z),
        orientation,
    };
    check_clear(world, spec, pose, (x, y))?;
    Ok(pose)
}

/// Verti-Bench's spawn: the chassis reference frame `height` above the ground at (x, y), level
/// (no roll or pitch) and heading `yaw`, springs at their static compression, to be dropped.
/// The HMMWV's reference frame is at its wheel centres, so a 1 m drop height leaves its tyres
/// about 0.5 m in the air. Refuses a start off the map or inside an obstacle.
pub(crate) fn dropped(
    world: &World,
    spec: &VehicleSpec,
    start: StartPose,
    height: f64,
) -> Result<Pose, SimError> {
    let StartPose { x, y, yaw } = start;
    if !(x.is_finite() && y.is_finite() && yaw.is_finite()) {
        return Err(SimError::InvalidStart(format!(
            "({x}, {y}, yaw {yaw}) is not finite"
        )));
    }
    if !(height.is_finite() && height >= 0.0) {
        return Err(SimError::InvalidStart(format!(
            "drop height {height} must be a finite number of metres, at least 0"
        )));
    }
    if !world.terrain.contains(x, y) {
        return Err(SimError::InvalidStart(format!(
            "({x:.2}, {y:.2}) is off the map (half extent {:.2} m)",
            world.terrain.half_extent()
        )));
    }
    let mut pose = Pose {
        position: Vec3::new(x, y, world.terrain.height_at(x, y) + height),
        orientation: quat_from_euler(0.0, 0.0, yaw),
    };
    // Level and `height` above the ground under the reference point, a vehicle on a steep spot
    // can have its body or a wheel inside the ground beside it; the stiff contact then throws
    // it (up at 3 m/s within 20 ms on Verti-Bench's config2_high, pair 0). Chrono's HMMWV,
    // whose only chassis shape is a small slab at hub height, overlaps nothing there and just
    // falls, so lift the spawn until nothing starts inside rigid ground.
    pose.position.z += rigid_overlap(world, spec, pose);
    check_clear(world, spec, pose, (x, y))?;
    Ok(pose)
}

/// How deep the lowest part of the vehicle at `pose` (the chassis box's bottom face and the
/// wheels' lower rims, springs at static compression, tyres undeflected) lies below rigid ground,
/// or 0 if nothing does. Sampled, not exact: the face every half cell (a terrain vertex between
/// samples can still poke a few centimetres into it), each rim every 10° along its edges and
/// middle. Soil does not count: a wheel starts sunk in it and the hull passes through it anyway.
fn rigid_overlap(world: &World, spec: &VehicleSpec, pose: Pose) -> f64 {
    let comp = static_compressions(spec);
    let bx = &spec.chassis.collision_box;
    let step = 0.5 * world.terrain.cell();
    let mut points: Vec<Vec3> = Vec::new();
    let (nx, ny) = (
        (bx.size[0] / step).ceil().max(1.0) as usize,
        (bx.size[1] / step).ceil().max(1.0) as usize,
    );
    for i in 0..=nx {
        for j in 0..=ny {
            points.push(Vec3::new(
                bx.center[0] + bx.size[0] * (i as f64 / nx as f64 - 0.5),
                bx.center[1] + bx.size[1] * (j as f64 / ny as f64 - 0.5),
                bx.center[2] - 0.5 * bx.size[2],
            ));
        }
    }
    for (k, ax) in spec.axles.iter().enumerate() {
        let r = ax.wheel.radius;
        for side in [1.0, -1.0] {
            let hub = Vec3::new(ax.x, side * 0.5 * ax.track, ax.z + comp[k]);
            for edge in [-0.5, 0.0, 0.5] {
                // the lower half of the rim, every 10 degrees
                for a in 0..=18 {
                    let angle = std::f64::consts::PI * (1.0 + f64::from(a) / 18.0);
                    points.push(
                        hub + Vec3::new(r * angle.cos(), edge * ax.wheel.width, r * angle.sin()),
                    );
                }
            }
        }
    }
    points
        .into_iter()
        .map(|local| pose.position + pose.orientation.rotate(local))
        .filter(|p| {
            world.terrain.contains(p.x, p.y)
                && !matches!(
                    world.patches.at(p.x, p.y).surface,
                    Surface::Deformable { .. }
                )
        })
        .map(|p| world.terrain.height_at(p.x, p.y) - p.z)
        .fold(0.0, f64::max)
}

/// Refuses a pose whose chassis box or wheels overlap an obstacle: a start inside a rock or
/// tree would be an explosion, not a drive.
fn check_clear(
    world: &World,
    spec: &VehicleSpec,
    pose: Pose,
    (x, y): (f64, f64),
) -> Result<(), SimError> {
    let orientation = pose.orientation;
    let comp = static_compressions(spec);
    let bx = &spec.chassis.collision_box;
    let (c, half) = (
        Vec3::new(bx.center[0], bx.center[1], bx.center[2]),
        Vec3::new(bx.size[0], bx.size[1], bx.size[2]) * 0.5,
    );
    let mut probes: Vec<(Vec3, f64)> = Vec::new();
    for ix in [-1.0, 0.0, 1.0] {
        for iy in [-1.0, 0.0, 1.0] {
            for iz in [-1.0, 0.0, 1.0] {
                probes.push((c + Vec3::new(ix * half.x, iy * half.y, iz * half.z), 0.0));
            }
        }
    }
    for (k, ax) in spec.axles.iter().enumerate() {
        for side in [1.0, -1.0] {
            probes.push((
                Vec3::new(ax.x, side * 0.5 * ax.track, ax.z + comp[k]),
                ax.wheel.radius,
            ));
        }
    }
    for (local, clearance) in probes {
        let p = pose.position + orientation.rotate(local);
        for (k, o) in world.obstacles.iter().enumerate() {
            if (p.x - o.position().x).hypot(p.y - o.position().y) > o.radius_xy() + clearance {
                continue;
            }
            if o.signed_distance(p).0 < clearance {
                return Err(SimError::InvalidStart(format!(
                    "at ({x:.2}, {y:.2}) the vehicle would start inside obstacle {k} at ({:.2}, {:.2})",
                    o.position().x,
                    o.position().y
                )));
            }
        }
    }
    Ok(())
}

/// The state at rest with the chassis reference frame at `pose`, springs at their static
/// compression.
pub(crate) fn state_at_rest(
    model: &Model,
    spec: &VehicleSpec,
    terrain: &Terrain,
    pose: Pose,
) -> Result<SimState, SimError> {
    if !(pose.position.is_finite() && pose.orientation.is_finite()) {
        return Err(SimError::InvalidStart("pose is not finite".into()));
    }
    let orientation = pose.orientation.normalized();
    let position = pose.position + orientation.rotate(model.com);
    // A vehicle at rest on a slope has deflected tyres: preload each tyre's transient slip
    // with its share of the downhill pull (linear part of the slip curve), so a start on a
    // slope begins near static equilibrium instead of sliding until the tyres wind up.
    let n_wheels = model.wheels.len() as f64;
    let wheels = model
        .wheels
        .iter()
        .map(|w| {
            let hub = position + orientation.rotate(w.attach + Vec3::Z * w.static_compression);
            let (_, gx, gy) = terrain.ground.sample(hub.x, hub.y);
            let n = Vec3::new(-gx, -gy, 1.0).normalized();
            let axle = orientation.rotate(Vec3::Y);
            let e_long = axle.cross(n).normalized();
            let e_lat = n.cross(e_long);
            let weight = Vec3::new(0.0, 0.0, -GRAVITY * model.total_mass / n_wheels);
            let fz = -weight.dot(n);
            let (mut kx, mut ky) = (0.0, 0.0);
            if fz > 0.0 && e_long.is_finite() {
                (kx, ky) = static_slip(
                    -weight.dot(e_long) / fz,
                    -weight.dot(e_lat) / fz,
                    &spec.tyre,
                );
            }
            WheelState {
                compression: w.static_compression,
                slip_long: kx,
                slip_lat: ky,
                soil_patch_b: 2.0 * w.half_width,
                ..Default::default()
            }
        })
        .collect();
    Ok(SimState {
        time: 0.0,
        position,
        orientation,
        velocity: Vec3::ZERO,
        omega: Vec3::ZERO,
        wheels,
        group_spin: vec![0.0; model.groups.len()],
        steer: 0.0,
        gear: 0,
        engine_speed: 0.0,
        engine_torque: 0.0,
        controls: Controls::IDLE,
        contacts: ContactInfo::default(),
        soil: SoilState::new(terrain.soil.as_ref()),
    })
}

/// Bekker's closed-form sinkage of a rigid wheel (width b, radius r) at rest under `load`,
/// parabolic contact arc over both halves:
/// W = 2·b·k·√(2r)·z^(n+½)·I(n), k = K_c/b + K_φ, I(n) = √π·Γ(n+1) / (2·Γ(n+3/2)).
fn static_sinkage(load: f64, b: f64, r: f64, soil: &SoilParams) -> f64 {
    let n = soil.bekker_n;
    let k = soil.bekker_kc / b + soil.bekker_kphi;
    let i = std::f64::consts::PI.sqrt() * libm::tgamma(n + 1.0) / (2.0 * libm::tgamma(n + 1.5));
    let z = load.max(0.0) / (2.0 * b * k * (2.0 * r).sqrt() * i);
    let z = libm::pow(z, 1.0 / (n + 0.5));
    if z.is_finite() { z } else { 0.0 }
}

/// Bekker's sinkage of a plate (width b, length l) under `load`: z = (p / (K_c/b + K_φ))^(1/n)
/// with p = load / (b·l).
fn plate_sinkage(load: f64, b: f64, l: f64, soil: &SoilParams) -> f64 {
    let k = soil.bekker_kc / b + soil.bekker_kphi;
    let z = libm::pow(load.max(0.0) / (b * l) / k, 1.0 / soil.bekker_n);
    if z.is_finite() { z } else { 0.0 }
}

/// `Quat::from_euler` with libm's sine and cosine, so a start pose has the same bits on every
/// platform (the engine uses libm wherever a transcendental function enters the dynamics).
fn quat_from_euler(roll: f64, pitch: f64, yaw: f64) -> Quat {
    let axis = |x: f64, y: f64, z: f64, angle: f64| {
        let (s, c) = libm::sincos(0.5 * angle);
        Quat {
            w: c,
            x: x * s,
            y: y * s,
            z: z * s,
        }
    };
    axis(0.0, 0.0, 1.0, yaw)
        .mul(axis(0.0, 1.0, 0.0, pitch))
        .mul(axis(1.0, 0.0, 0.0, roll))
}
