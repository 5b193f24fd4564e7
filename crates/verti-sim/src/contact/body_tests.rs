//! Tests of the chassis box against terrain: the lattice on planes is unchanged by the belly
//! contacts, a ridge between the lattice points holds the body, driving onto a ridge taller
//! than the ground clearance high-centres the vehicle, and all of it is deterministic.

use crate::contact::belly::belly_contacts;
use crate::contact::body::body_contacts;
use crate::integrate::Loads;
use crate::sim::Sim;
use crate::state::{ContactInfo, Controls, SimState, StartPose};
use crate::testing;
use crate::vehicles;
use std::sync::Arc;
use verti_core::{Quat, Vec3};
use verti_world::World;

fn hmmwv_on(world: World) -> Sim {
    Sim::new(&Arc::new(world), &vehicles::builtin("hmmwv").unwrap()).unwrap()
}

/// The body's contact force and torque (about the centre of mass) and contact count.
fn body_load(sim: &Sim, st: &SimState) -> (Vec3, Vec3, u32) {
    let mut loads = Loads::gravity(Vec3::ZERO, 0.0);
    let mut contacts = ContactInfo::default();
    body_contacts(
        &sim.terrain,
        &sim.model,
        sim.spec.chassis.friction,
        st,
        &[],
        &mut loads,
        &mut contacts,
    );
    (loads.force, loads.torque, contacts.chassis_terrain_points)
}

/// What the 18-point lattice alone gives at rest (the body contact law before the belly
/// contacts): k·depth along the terrain normal at every lattice point below the ground.
fn lattice_load(sim: &Sim, st: &SimState) -> (Vec3, Vec3, u32) {
    let (mut f, mut t, mut n) = (Vec3::ZERO, Vec3::ZERO, 0);
    for p in &sim.model.body_points {
        let arm = st.orientation.rotate(*p);
        let w = st.position + arm;
        let (h, gx, gy) = sim.terrain.ground.sample(w.x, w.y);
        if h > w.z {
            let nz = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
            let normal = Vec3::new(-gx * nz, -gy * nz, nz);
            let force = normal * (sim.model.body_stiffness * (h - w.z) * nz);
            f += force;
            t += arm.cross(force);
            n += 1;
        }
    }
    (f, t, n)
}

/// How many terrain vertices press on the belly in `st` (the belly pass alone).
fn belly_count(sim: &Sim, st: &SimState) -> u32 {
    let rm = st.orientation.to_mat3();
    let bottom: Vec<Vec3> = sim.model.body_points[..9]
        .iter()
        .map(|p| st.position + rm.mul_vec(*p))
        .collect();
    belly_contacts(
        &sim.terrain,
        &sim.model,
        &rm,
        &bottom,
        &[f64::NAN; 9],
        1.0,
        |_| true,
    )
}

/// A state at rest with the chassis at `orientation` and its bottom face's centre at `bottom`.
fn posed(sim: &Sim, orientation: Quat, bottom: Vec3) -> SimState {
    let mut st = sim.state_at(StartPose::new(0.0, 0.0, 0.0)).unwrap();
    let m = &sim.model;
    let face_centre = m.box_center - Vec3::Z * m.box_half.z;
    st.orientation = orientation;
    st.position = bottom - orientation.rotate(face_centre);
    st.velocity = Vec3::ZERO;
    st.omega = Vec3::ZERO;
    st
}

// A box resting on flat ground, sunk 1 cm, at any heading: the nine bottom points carry
// 9·k·0.01 (k from the model, the lattice law as before). The belly contacts add nothing: on a
// plane the terrain vertices stand exactly on the ground the lattice sees, and the rounding of
// that comparison (1e-14 m on 100 m coordinates) is below their 1e-9 m floor, so the sum is
// the lattice's own, to the rounding of adding nine forces (relative 1e-12 allowed). Tilted
// boxes on a sloping plane give the lattice's force and torque too.
#[test]
fn plane_contacts_are_the_lattice_alone() {
    let sim = hmmwv_on(testing::flat_world(1.0, 0.8));
    let k = sim.model.body_stiffness;
    for yaw in [0.0, 0.3, 0.785, 1.9, -2.6] {
        let q = Quat::from_axis_angle(Vec3::Z, yaw);
        let st = posed(&sim, q, Vec3::new(0.37, -0.21, -0.01));
        let (f, _, n) = body_load(&sim, &st);
        let expect = 9.0 * k * 0.01;
        println!(
            "yaw {yaw}: Fz {:.3} N, expected {expect:.3} N, {n} contacts",
            f.z
        );
        assert_eq!(n, 9);
        assert!((f.z - expect).abs() < 1e-12 * expect && f.x.abs() + f.y.abs() < 1e-6);
    }
    let plane = hmmwv_on(testing::plane_world(1.0, 0.2, -0.12, 0.8));
    let (tx, ty) = (0.2f64.tan(), (-0.12f64).tan());
    for (yaw, roll, pitch) in [(0.0, 0.05, -0.2), (1.1, -0.12, -0.25), (2.5, 0.1, 0.1)] {
        let q = Quat::from_axis_angle(Vec3::Z, yaw)
            .mul(Quat::from_axis_angle(Vec3::Y, pitch))
            .mul(Quat::from_axis_angle(Vec3::X, roll));
        let (x, y) = (3.0, -2.0);
        let st = posed(&plane, q, Vec3::new(x, y, tx * x + ty * y - 0.05));
        let (f, t, n) = body_load(&plane, &st);
        let (fl, tl, nl) = lattice_load(&plane, &st);
        println!("tilted: F {f:?} lattice {fl:?}, {n} / {nl} contacts");
        assert!(nl > 0 && n == nl);
        assert!((f - fl).norm() < 1e-9 * fl.norm() && (t - tl).norm() < 1e-9 * fl.norm());
    }
}

/// Largest penetration of the ridge's vertices (x = `ridge_x`) into the bottom face, and the
/// lowest clearance of the nine bottom lattice points above the ground under them.
fn ridge_state(sim: &Sim, st: &SimState, ridge_x: f64) -> (f64, f64) {
    let m = &sim.model;
    let up = st.orientation.rotate(Vec3::Z);
    let face = st.position + st.orientation.rotate(m.box_center - Vec3::Z * m.box_half.z);
    let mut into = f64::NEG_INFINITY;
    for y in [-2.0, -1.0, 0.0, 1.0, 2.0] {
        let v = Vec3::new(ridge_x, y, sim.terrain.world.terrain.height_at(ridge_x, y));
        let local = st.orientation.inverse_rotate(v - face);
        if local.x.abs() < m.box_half.x && local.y.abs() < m.box_half.y {
            into = into.max((v - face).dot(up));
        }
    }
    let clearance = m.body_points[..9]
        .iter()
        .map(|p| {
            let w = st.position + st.orientation.rotate(*p);
            w.z - sim.terrain.world.terrain.height_at(w.x, w.y)
        })
        .fold(f64::INFINITY, f64::min);
    (into, clearance)
}

// A HMMWV lowered onto a 1.2 m ridge (one raised row of vertices) that lies 1 m ahead of the
// box centre, between the lattice's middle and front points (2.3 m apart): the ridge holds the
// body. Before the belly contacts the lattice saw flat ground there and the body fell through
// the ridge onto its wheels. Settled (brakes on), the ridge pokes into the belly by its static
// penetration: the body rests on the ridge and the rear wheels (centre of mass 0.94 m behind
// the ridge, rear axle 2.7 m: ~65 % of 24.4 kN on the ridge), carried by the vertices under the
// face, 2.1 cells of share at 0.93 k: 16 kN / (2.1 · 0.93 · 560 kN/m) = 1.5 cm. Allowed: 4 cm.
// Every lattice point stays clear of the ground (the body pitches back onto its rear wheels,
// its rear lattice points ~0.25 m up), so the lattice held nothing.
#[test]
fn ridge_between_lattice_points_holds_the_body() {
    let ridge_x = 10.0;
    let sim = hmmwv_on(testing::ridge_world(1.0, 0.8, ridge_x, 1.2));
    let m = &sim.model;
    let bottom_x = ridge_x - 1.0;
    let mut st = posed(&sim, Quat::IDENTITY, Vec3::new(bottom_x, 0.0, 1.3));
    // the box centre is where it should be relative to the ridge
    let face = st.position + st.orientation.rotate(m.box_center - Vec3::Z * m.box_half.z);
    assert!((face.x - bottom_x).abs() < 1e-12);
    let brake = Controls::new(0.0, 1.0, 0.0);
    let mut deepest: f64 = 0.0;
    for k in 0..400 {
        sim.step(&mut st, brake, 0.01).unwrap();
        if k >= 300 {
            deepest = deepest.max(ridge_state(&sim, &st, ridge_x).0);
        }
    }
    let (_, clearance) = ridge_state(&sim, &st, ridge_x);
    let (_, pitch, _) = st.euler();
    println!(
        "ridge 1.2 m: penetration {deepest:.4} m, lattice clearance {clearance:.3} m, pitch \
         {:.1}°, wheel loads {:?}, {} body contacts",
        pitch.to_degrees(),
        st.wheels()
            .iter()
            .map(|w| w.normal_force.round())
            .collect::<Vec<_>>(),
        st.contacts().chassis_terrain_points
    );
    assert!(deepest < 0.04, "the ridge is {deepest:.3} m into the belly");
    assert!(
        clearance > 0.1,
        "a lattice point is {clearance:.3} m above ground"
    );
    assert!(st.wheels()[0].normal_force == 0.0 && st.wheels()[1].normal_force == 0.0);
}

fn drive_at_3(sim: &Sim, st: &mut SimState, seconds: f64) -> Vec<u64> {
    let mut trace = Vec::new();
    for _ in 0..(seconds / 0.01).round() as usize {
        let u = (3.0 - st.forward_speed()).clamp(-1.0, 1.0);
        let c = Controls::new(u.max(0.0), (-u).max(0.0), 0.0);
        sim.step(st, c, 0.01).unwrap();
        let p = st.com_position();
        let q = st.orientation();
        trace.extend([p.x, p.y, p.z, q.w, q.x, q.y, q.z].map(f64::to_bits));
    }
    trace
}

// High-centring: driving at 3 m/s over a 0.8 m ridge across the path, taller than the body's
// 0.43 m ground clearance (box bottom at hub height, hubs at r − sag). The front wheels climb
// it (1 m flanks of 39°, about what μ 0.8 holds: they roll over on momentum), then the ridge comes
// under the belly and stays there: after 30 s the vehicle is stopped with the ridge under the
// body, the front wheels in the air and most of the weight on the belly (the wheels carry less
// than a third of it), and it moved less than 1 m in the last 10 s (Verti-Bench's stuck rule)
// with the speed controller asking for full throttle. Before the belly contacts it drove on.
#[test]
fn ridge_under_the_belly_high_centres_the_vehicle() {
    let sim = hmmwv_on(testing::ridge_world(1.0, 0.8, 10.0, 0.8));
    let mut st = sim.state_at(StartPose::new(0.0, 0.0, 0.0)).unwrap();
    drive_at_3(&sim, &mut st, 20.0);
    let before = st.com_position();
    drive_at_3(&sim, &mut st, 10.0);
    let moved = (st.com_position() - before).norm();
    let wheels: f64 = st.wheels().iter().map(|w| w.normal_force).sum();
    let weight = sim.total_mass() * 9.81;
    let reference = sim.reference_pose(&st).position;
    println!(
        "0.8 m ridge at x = 10: reference at x = {:.2}, moved {moved:.3} m in 10 s, wheels \
         carry {:.0} % of the weight, throttle {:.2}, {} body contacts",
        reference.x,
        100.0 * wheels / weight,
        st.controls().throttle,
        st.contacts().chassis_terrain_points
    );
    assert!(moved < 1.0 && st.forward_speed().abs() < 0.1);
    assert!(
        (reference.x - 10.0).abs() < 2.3,
        "the ridge is not under the body"
    );
    assert!(st.wheels()[0].normal_force == 0.0 && st.wheels()[1].normal_force == 0.0);
    assert!(wheels < weight / 3.0 && st.contacts().chassis_terrain_points > 0);
    assert!(st.controls().throttle == 1.0);
}

// Determinism: the same drive over a jagged world (random vertex heights up to 0.7 m, like
// Verti-Bench's high worlds; the belly scrapes) gives the same bits twice, and the same in
// threads running side by side as alone.
#[test]
fn belly_contacts_are_deterministic() {
    let jagged = |x: f64, y: f64| {
        let (i, j) = (x.round() as i64 as u64, y.round() as i64 as u64);
        let hash = (i.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ j.wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
            .wrapping_mul(0x1656_67B1_9E37_79F9);
        0.7 * (hash >> 11) as f64 / (1u64 << 53) as f64
    };
    let world = testing::world_from_fn(
        "jagged",
        1.0,
        jagged,
        vec![testing::rigid_patch(0.8); 256],
        Vec::new(),
    );
    let sim = Arc::new(hmmwv_on(world));
    let run = |sim: &Sim| {
        let mut st = sim.state_at(StartPose::new(-20.0, 0.0, 0.2)).unwrap();
        let mut contacts = 0;
        let mut trace = Vec::new();
        for _ in 0..1000 {
            trace.extend(drive_at_3(sim, &mut st, 0.01));
            contacts += belly_count(sim, &st);
        }
        (trace, contacts)
    };
    let (a, contacts) = run(&sim);
    let (b, _) = run(&sim);
    assert_eq!(a, b);
    let threads: Vec<_> = (0..2)
        .map(|_| {
            let sim = Arc::clone(&sim);
            std::thread::spawn(move || run(&sim).0)
        })
        .collect();
    for t in threads {
        assert_eq!(t.join().unwrap(), a);
    }
    println!("jagged drive: {contacts} belly contacts over 1000 steps");
    assert!(contacts > 0, "the drive should scrape the belly");
}
