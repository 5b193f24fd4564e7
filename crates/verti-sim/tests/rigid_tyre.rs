//! Validation of the rigid tyre (`tyre.model: rigid`, the built-in `hmmwv`): a rigid
//! cylinder with Coulomb friction, as Chrono's `ChRigidTire` under NSC contact. Every expected
//! number is derived on paper from the vehicle file (see the comment above each test); the
//! tolerance is stated in the test.

use std::sync::Arc;
use verti_core::{Rng, Vec3};
use verti_sim::spec::{TyreModel, VehicleSpec};
use verti_sim::testing::{self, RoughSurface};
use verti_sim::{Controls, Sim, SimState, StartPose, vehicles};
use verti_world::SoilParams;

mod common;
use common::{G, max_roll, run, sim_at};

fn rigid() -> VehicleSpec {
    vehicles::builtin("hmmwv").unwrap()
}

/// Load on each wheel at rest on flat ground \[N\] (front, rear): the sprung weight split by the
/// lever rule, plus the wheel's own unsprung weight.
fn wheel_loads(spec: &VehicleSpec) -> (f64, f64) {
    let (xf, xr) = (spec.axles[0].x, spec.axles[1].x);
    let w = spec.chassis.mass * G;
    let front = 0.5 * w * (spec.chassis.com[0] - xr) / (xf - xr);
    let rear = 0.5 * w - front;
    let unsprung = spec.axles[0].wheel.unsprung_mass * G;
    (front + unsprung, rear + unsprung)
}

// The preset is the HMMWV of Verti-Bench on Chrono's rigid tyres (physics_spec §2.4): R 0.467,
// W 0.254, μ 0.9, the tyre's 37.6 kg inside the unsprung mass, no rolling resistance, and
// everything but the tyre identical to `hmmwv-handling`. Its contact constants are the file's
// derivation: k = (m_total / 4)·(0.3 / h)², c = 2·√(k·m_unsprung), within 0.1 % (rounding).
#[test]
fn preset_matches_the_reference_configuration_and_its_derivation() {
    let spec = rigid();
    let base = vehicles::builtin("hmmwv-handling").unwrap();
    assert_eq!(spec.tyre.model, TyreModel::Rigid);
    assert_eq!(base.tyre.model, TyreModel::Handling);
    for ax in &spec.axles {
        assert_eq!((ax.wheel.radius, ax.wheel.width), (0.467, 0.254));
    }
    assert_eq!(spec.tyre.friction, 0.9);
    assert_eq!(spec.tyre.rolling_resistance, 0.0);
    let mut same = spec.clone();
    same.name = base.name.clone();
    same.description = base.description.clone();
    same.tyre = base.tyre;
    assert_eq!(same, base, "only the tyre may differ from hmmwv-handling");
    let h = spec.internal_step;
    let k = 0.25 * spec.total_mass() * (0.3 / h).powi(2);
    let c = 2.0 * (k * spec.axles[0].wheel.unsprung_mass).sqrt();
    println!(
        "k {k:.4e} (file {:.4e}), c {c:.1} (file {:.1})",
        spec.tyre.radial_stiffness, spec.tyre.radial_damping
    );
    assert!((spec.tyre.radial_stiffness - k).abs() / k < 1e-3);
    assert!((spec.tyre.radial_damping - c).abs() / c < 1e-3);
    // written files keep `model: rigid`, and a handling tyre's files do not mention a model
    assert!(spec.to_yaml().contains("model: rigid"));
    assert!(!base.to_yaml().contains("model:"));
    assert_eq!(
        VehicleSpec::from_yaml_str(&spec.to_yaml(), "round trip").unwrap(),
        spec
    );
}

// 1. At rest on flat ground each wheel carries its static load (lever rule + unsprung weight)
//    within 1 %, and sinks into the ground by load / k (the contact's equivalent deflection)
//    within 2 %: 2.8 mm front, 2.65 mm rear.
#[test]
fn wheel_at_rest_carries_its_load_with_penetration_mg_over_k() {
    let spec = rigid();
    let (sim, mut st) = sim_at(testing::flat_world(1.0, 0.8), &spec, 0.0, 0.0, 0.0);
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 3.0);
    let (front, rear) = wheel_loads(&spec);
    let k = spec.tyre.radial_stiffness;
    for (w, wheel) in st.wheels().iter().enumerate() {
        let load = if w < 2 { front } else { rear };
        println!(
            "wheel {w}: load {:.1} N vs {load:.1} N, penetration {:.5} m vs mg/k {:.5} m",
            wheel.normal_force,
            wheel.tyre_deflection,
            load / k
        );
        assert!((wheel.normal_force - load).abs() / load < 0.01);
        assert!((wheel.tyre_deflection - load / k).abs() / (load / k) < 0.02);
    }
}

/// Parked (brakes full) facing uphill on a plane of slope `deg` and friction `mu`; after 2 s to
/// settle, returns (distance moved along x over the next 3 s, final speed, the acceleration
/// along the slope over those 3 s, downhill positive).
fn parked(mu: f64, deg: f64) -> (f64, f64, f64) {
    let spec = rigid();
    let slope = deg.to_radians();
    let (sim, mut st) = sim_at(
        testing::plane_world(1.0, slope, 0.0, mu),
        &spec,
        0.0,
        0.0,
        0.0,
    );
    let brake = Controls::new(0.0, 1.0, 0.0);
    run(&sim, &mut st, brake, 2.0);
    let (x0, v0) = (st.com_position().x, st.velocity_world());
    run(&sim, &mut st, brake, 3.0);
    let v1 = st.velocity_world();
    let along = Vec3::new(-slope.cos(), 0.0, -slope.sin());
    (
        st.com_position().x - x0,
        v1.norm(),
        (v1 - v0).dot(along) / 3.0,
    )
}

// 2. Braked on a slope the ground must supply m·g·sin θ within μ·m·g·cos θ: below atan μ the
//    vehicle holds without creeping (the friction anchors are springs: < 1 mm in 3 s, at rest
//    to 1 mm/s); above it every wheel slides at μ·N and the vehicle accelerates downhill at
//    g·(sin θ − μ·cos θ), within 2 % (Coulomb friction is exact here; what is left is the
//    pitch settling of the suspension, which changes the normal loads by well under 1 %).
//    μ 0.4 and 0.7, 1.5° on either side of atan μ, and 5° above for the acceleration.
#[test]
fn braked_on_a_slope_holds_below_atan_mu_and_slides_at_g_sin_minus_mu_cos_above() {
    for mu in [0.4f64, 0.7] {
        let critical = mu.atan().to_degrees();
        let (moved, speed, _) = parked(mu, critical - 1.5);
        println!(
            "μ {mu}: {:.1}° moved {moved:.6} m, speed {speed:.6} m/s",
            critical - 1.5
        );
        assert!(
            moved.abs() < 1e-3 && speed < 1e-3,
            "μ {mu}: at {:.1}° it moved {moved:.5} m (should hold)",
            critical - 1.5
        );
        for above in [1.5, 5.0] {
            let deg = critical + above;
            let (moved, _, acc) = parked(mu, deg);
            let th = deg.to_radians();
            let expected = G * (th.sin() - mu * th.cos());
            println!("μ {mu}: {deg:.1}° moved {moved:.3} m, a {acc:.4} vs {expected:.4} m/s²");
            assert!(moved < 0.0, "μ {mu}: at {deg:.1}° it did not slide");
            assert!(
                (acc - expected).abs() / expected < 0.02,
                "μ {mu}: at {deg:.1}° a = {acc:.4} m/s², g(sin θ − μ cos θ) = {expected:.4}"
            );
        }
    }
}

// 3. A rigid wheel rolls without slip: coasting on flat ground, the hub speed is ω·R with R the
//    cylinder's radius (the contact's millimetre penetration is the penalty method's, not a
//    loaded radius), within 0.1 %: the spin is solved against the speed at the start of each
//    internal step, so under the engine's drag (0.44 m/s²) ω·R leads v by one step's
//    deceleration, 2 mm/s or 0.05 %.
#[test]
fn free_rolling_keeps_v_equal_omega_r() {
    let spec = rigid();
    let (sim, mut st) = sim_at(testing::flat_world(1.0, 0.8), &spec, 0.0, 0.0, 0.0);
    run(&sim, &mut st, Controls::IDLE, 0.5);
    st.set_velocity(&sim, Vec3::new(5.0, 0.0, 0.0));
    run(&sim, &mut st, Controls::IDLE, 2.0);
    let r = spec.axles[0].wheel.radius;
    let v = st.forward_speed();
    for (w, wheel) in st.wheels().iter().enumerate() {
        let ratio = v / (wheel.spin_rate * r);
        println!(
            "wheel {w}: v {v:.5} m/s, ω·R {:.5} m/s",
            wheel.spin_rate * r
        );
        assert!((ratio - 1.0).abs() < 1e-3, "wheel {w}: v/(ωR) = {ratio:.5}");
    }
    assert!(v > 3.0, "coasted down to {v:.2} m/s");
}

// 4. Braking from 10 m/s on μ 0.7 with full brakes: the brakes (4 x 4000 N m) exceed the
//    ground's μ·m·g·R, the wheels lock and slide at exactly μ·N, so the vehicle stops in
//    v²/(2 μ g) = 7.28 m; within 3 % (the wheels take about 0.1 s to lock, a few cm).
#[test]
fn braking_distance_is_v_squared_over_two_mu_g() {
    let spec = rigid();
    let mu = 0.7;
    let (sim, mut st) = sim_at(testing::flat_world(1.0, mu), &spec, 0.0, 0.0, 0.0);
    run(&sim, &mut st, Controls::IDLE, 1.0);
    let v0 = 10.0;
    st.set_velocity(&sim, Vec3::new(v0, 0.0, 0.0));
    let x0 = st.com_position().x;
    for _ in 0..1000 {
        sim.step(&mut st, Controls::new(0.0, 1.0, 0.0), 0.01)
            .unwrap();
        if st.velocity_world().norm() < 0.01 {
            break;
        }
    }
    let distance = st.com_position().x - x0;
    let expected = v0 * v0 / (2.0 * mu * G);
    println!("braking distance {distance:.3} m vs v²/2μg {expected:.3} m");
    assert!((distance - expected).abs() / expected < 0.03);
}

// 5. A wheel driven into a step meets the step's face, not only its top. Coasting at 1 m/s into
//    a 0.3 m box step (kinetic energy 1.2 kJ, less than the 3.7 kJ of lifting the front axle's
//    half of the weight 0.3 m), a front wheel touches the step's edge when its hub is
//    √(R² − (R − 0.3)²) = 0.436 m short of the face, the push there points from the edge to
//    the hub (62° from vertical), and the vehicle stops: the hubs never get closer than that
//    less 5 cm of contact compression, and it is not moving forward after 3 s. (The handling
//    tyre's single support point sees no edge, so it is pushed straight up once its hub is
//    over the step: printed for comparison.)
#[test]
fn a_wheel_driven_into_a_step_meets_its_face() {
    let face = 3.0;
    let height = 0.3;
    let r: f64 = 0.467;
    let touch = face - (r * r - (r - height) * (r - height)).sqrt();
    for name in ["hmmwv", "hmmwv-handling"] {
        let spec = vehicles::builtin(name).unwrap();
        let (sim, mut st) = sim_at(
            testing::rock_world(1.0, 0.8, face, Vec3::new(3.0, 4.0, height)),
            &spec,
            0.0,
            0.0,
            0.0,
        );
        st.set_velocity(&sim, Vec3::new(1.0, 0.0, 0.0));
        let mut furthest = f64::NEG_INFINITY;
        let mut touched = false;
        for _ in 0..300 {
            sim.step(&mut st, Controls::IDLE, 0.01).unwrap();
            let hubs = sim.wheel_centers(&st);
            furthest = furthest.max(hubs[0].x.max(hubs[1].x));
            touched |= st.contacts().wheel_obstacle_contacts > 0;
        }
        println!(
            "{name}: front hubs reached x = {furthest:.3} m (edge touched at {touch:.3} m, face at {face} m), \
             final speed {:.3} m/s",
            st.forward_speed()
        );
        if name == "hmmwv" {
            assert!(touched, "the wheels never touched the step");
            assert!(
                furthest < touch + 0.05,
                "a front hub reached x = {furthest:.3} m; the edge is touched at {touch:.3} m"
            );
            assert!(st.forward_speed() < 0.05, "still rolling on");
        }
    }
}

// 6. No energy gain: idle on bumpy ground (a rest state that is not an equilibrium) for 60 s,
//    the total mechanical energy (kinetic, gravity, springs, the contacts' and friction
//    anchors' springs) never rises above its start by more than 1 J per tonne of numerical
//    noise, and ends lower.
#[test]
fn no_energy_gain_on_bumpy_ground() {
    let spec = rigid();
    let (sim, mut st) = sim_at(
        testing::bumpy_world(1.0, 0.6, 10.0, 0.8),
        &spec,
        1.3,
        0.7,
        0.4,
    );
    sim.step(&mut st, Controls::IDLE, 0.01).unwrap();
    let e0 = sim.energy(&st);
    let tolerance = sim.total_mass() / 1000.0;
    let mut worst = f64::NEG_INFINITY;
    for _ in 0..6000 {
        sim.step(&mut st, Controls::IDLE, 0.01).unwrap();
        let e = sim.energy(&st);
        worst = worst.max(e - e0);
        assert!(
            e <= e0 + tolerance,
            "energy rose by {:.3} J at t = {:.2} s",
            e - e0,
            st.time()
        );
    }
    println!(
        "energy: start {e0:.1} J, end {:.1} J, largest rise {worst:.4} J",
        sim.energy(&st)
    );
    assert!(sim.energy(&st) < e0);
}

/// Height of the total centre of mass above flat ground at rest: sprung mass at the COM,
/// unsprung masses at the wheel centres (free-length height plus the static sag), the ground
/// one radius less the static penetration below the wheel centres (as `validation.rs`).
fn static_com_height(spec: &VehicleSpec) -> f64 {
    let w = spec.chassis.mass * G;
    let (xf, xr) = (spec.axles[0].x, spec.axles[1].x);
    let front = 0.5 * w * (spec.chassis.com[0] - xr) / (xf - xr);
    let rear = 0.5 * w - front;
    let hub = |i: usize, load: f64| spec.axles[i].z + load / spec.axles[i].suspension.stiffness;
    let (hf, hr) = (hub(0, front), hub(1, rear));
    let mu = spec.axles[0].wheel.unsprung_mass;
    let total = spec.total_mass();
    let com_z = (spec.chassis.mass * spec.chassis.com[2] + 2.0 * mu * (hf + hr)) / total;
    let penetration = 0.25 * total * G / spec.tyre.radial_stiffness;
    com_z - (0.5 * (hf + hr) - (spec.axles[0].wheel.radius - penetration))
}

/// Largest |roll| over 4 s parked (brakes on) across a side slope of `deg` of friction 2.
fn max_roll_on_side_slope(spec: &VehicleSpec, deg: f64) -> f64 {
    let world = testing::plane_world(1.0, 0.0, deg.to_radians(), 2.0);
    let (sim, mut st) = sim_at(world, spec, 0.0, 0.0, 0.0);
    max_roll(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 400)
}

// 7. Tilt table (validation test 3 for the rigid tyre): a rigid vehicle tips when the resultant
//    of gravity passes the downhill wheels, tan φ = t / (2h), h the static COM height from the
//    file (φ ≈ 56°). With tyre and ground friction 2, so it tips before sliding: across a slope
//    of 0.95·φ it stays upright (the body leans at most 10° beyond the slope on its springs),
//    at 1.05·φ it rolls over.
#[test]
fn tilt_table_rollover_angle() {
    let mut spec = rigid();
    spec.tyre.friction = 2.0;
    let h = static_com_height(&spec);
    let phi = (spec.axles[0].track / (2.0 * h)).atan().to_degrees();
    let below = max_roll_on_side_slope(&spec, 0.95 * phi).to_degrees();
    let above = max_roll_on_side_slope(&spec, 1.05 * phi).to_degrees();
    println!("φ {phi:.2}° (h {h:.4} m): max roll at 0.95φ {below:.1}°, at 1.05φ {above:.1}°");
    assert!(
        below < 0.95 * phi + 10.0,
        "at 0.95 φ the roll reached {below:.1}°"
    );
    assert!(above > 90.0, "at 1.05 φ it did not roll over ({above:.1}°)");
}

/// Bekker's closed form for a rigid wheel of width b and radius R at rest under load W
/// (contact arc as a parabola over both halves), as in `validation.rs`.
fn bekker_static_sinkage(load: f64, b: f64, r: f64, soil: &SoilParams) -> f64 {
    let n = soil.bekker_n;
    let k = soil.bekker_kc / b + soil.bekker_kphi;
    let i = std::f64::consts::PI.sqrt() * libm::tgamma(n + 1.0) / (2.0 * libm::tgamma(n + 1.5));
    (load / (2.0 * b * k * (2.0 * r).sqrt() * i)).powf(1.0 / (n + 0.5))
}

// 8. On deformable soil the rigid tyre is the SCM stage's rigid cylinder: at rest on mud it
//    sinks to Bekker's closed-form depth within 10 % (the set-up of validation test 5a: treads
//    0.3 m wide spanning three soil-node columns, heavy soil damping for a quasi-static load).
#[test]
fn sinkage_on_soil_matches_bekker() {
    let mut spec = rigid();
    for ax in &mut spec.axles {
        ax.wheel.width = 0.3;
        ax.track = 1.8;
    }
    let soil = SoilParams {
        damping: 3e6,
        ..SoilParams::MID
    };
    let (sim, mut st) = sim_at(testing::soil_world(1.0, soil, 0.0), &spec, 0.0, 0.0, 0.0);
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 6.0);
    let (front, rear) = wheel_loads(&spec);
    for (w, hub) in sim.wheel_centers(&st).iter().enumerate() {
        let load = if w < 2 { front } else { rear };
        let expected = bekker_static_sinkage(load, 0.3, spec.axles[0].wheel.radius, &soil);
        let sinkage = spec.axles[0].wheel.radius - hub.z;
        println!("sinkage wheel {w}: {sinkage:.4} m vs Bekker {expected:.4} m");
        assert!((sinkage - expected).abs() / expected < 0.10);
    }
    assert_eq!(st.contacts().wheels_on_soil, 4);
}

fn random_drive(sim: &Sim, st: &mut SimState, seed: u64, steps: usize) -> Vec<u64> {
    let mut rng = Rng::new(seed);
    let mut trace = Vec::new();
    let mut c = Controls::IDLE;
    for k in 0..steps {
        if k % 25 == 0 {
            c = Controls::new(rng.uniform(), 0.2 * rng.uniform(), rng.range(-1.0, 1.0));
        }
        sim.step(st, c, 0.02).unwrap();
        let p = st.com_position();
        let q = st.orientation();
        trace.extend([p.x, p.y, p.z, q.w, q.x, q.y, q.z].map(f64::to_bits));
        trace.extend(st.wheels().iter().flat_map(|w| {
            [w.compression, w.anchor_long, w.anchor_lat, w.spin_rate].map(f64::to_bits)
        }));
    }
    trace
}

// 9. Determinism: on a rough world of rigid and soil patches with rocks, the same inputs give
//    bit-identical trajectories, and a clone taken mid-run continues exactly like the original.
#[test]
fn bit_identical_trajectories_and_clones() {
    let world = Arc::new(testing::rough_world(1.0, 7, 8.0, RoughSurface::Mixed));
    let sim = Sim::new(&world, &rigid()).unwrap();
    let start = StartPose::new(0.0, 0.0, 0.5);
    let mut a = sim.state_at(start).unwrap();
    let mut b = sim.state_at(start).unwrap();
    let ta = random_drive(&sim, &mut a, 11, 500);
    let tb = random_drive(&sim, &mut b, 11, 500);
    assert_eq!(ta, tb);
    let mut c = a.clone();
    let tc = random_drive(&sim, &mut c, 12, 200);
    let ta2 = random_drive(&sim, &mut a, 12, 200);
    assert_eq!(ta2, tc);
}
