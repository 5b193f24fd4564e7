//! The engine's contract: vehicle files, errors instead of panics, every shipped vehicle
//! driving every kind of test world, cheap clones.

use std::sync::Arc;
use verti_core::Vec3;
use verti_sim::testing::{self, RoughSurface};
use verti_sim::{Controls, Sim, SimError, SpecError, StartPose, VehicleSpec, vehicles};
use verti_world::SoilParams;

#[test]
fn builtin_vehicles_load_and_unknown_names_list_the_known_ones() {
    let names = vehicles::builtin_names();
    assert_eq!(
        names,
        [
            "hmmwv",
            "hmmwv-handling",
            "artcar",
            "verti4",
            "truck6",
            "truck8",
            "m113",
            "uaz",
            "gator",
            "sedan"
        ]
    );
    for name in &names {
        let spec = vehicles::builtin(name).unwrap();
        assert_eq!(&spec.name, name);
        assert!(!spec.summary().is_empty());
        // YAML round trip
        let again = VehicleSpec::from_yaml_str(&spec.to_yaml(), "round trip").unwrap();
        assert_eq!(again, spec);
    }
    assert_eq!(vehicles::builtin("m113").unwrap().wheel_count(), 10);
    assert!(vehicles::builtin("m113").unwrap().is_tracked());
    let err = vehicles::builtin("tank").unwrap_err().to_string();
    assert!(
        err.contains("tank") && err.contains("hmmwv") && err.contains("m113"),
        "{err}"
    );
}

/// A vehicle file's origin is the point systems see as the vehicle's position (they steer it
/// along the path; the rules judge the goal there): on every shipped vehicle it lies mid-way
/// between the first and last axles, the span systems are given as the wheelbase (the HMMWV's,
/// Chrono's own, 2.4 mm behind it). A change here moves every result of that vehicle.
#[test]
fn every_vehicle_origin_is_mid_way_along_its_wheelbase() {
    for name in vehicles::builtin_names() {
        let spec = vehicles::builtin(name).unwrap();
        let (first, last) = (spec.axles[0].x, spec.axles[spec.axles.len() - 1].x);
        let mid = (first + last) / 2.0;
        assert!(mid.abs() < 0.003, "{name}: mid-span at x = {mid}");
        assert!((first - last - spec.wheelbase()).abs() < 1e-12);
        // `verti vehicle show` says where the point is
        let summary = spec.summary();
        assert!(
            summary.contains("mid-way between the first and last axles"),
            "{summary}"
        );
    }
}

#[test]
fn bad_vehicle_files_name_the_file_and_the_field() {
    let dir = std::env::temp_dir().join(format!("verti-sim-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.yaml");
    let text = vehicles::builtin_yaml("hmmwv")
        .unwrap()
        .replace("stiffness: 167071.0", "stiffness: -5.0");
    std::fs::write(&path, text).unwrap();
    let err = VehicleSpec::from_file(&path).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SpecError::Invalid { .. }), "{msg}");
    assert!(
        msg.contains("bad.yaml") && msg.contains("axles[0].suspension.stiffness"),
        "{msg}"
    );

    let text = vehicles::builtin_yaml("hmmwv")
        .unwrap()
        .replace("friction: 0.9", "friction: 0.9\n  colour: red");
    std::fs::write(&path, text).unwrap();
    let msg = VehicleSpec::from_file(&path).unwrap_err().to_string();
    assert!(msg.contains("bad.yaml") && msg.contains("colour"), "{msg}");

    // a different vehicle may not pass for a built-in one; a renamed one or an exact copy loads
    let text = vehicles::builtin_yaml("hmmwv")
        .unwrap()
        .replace("stiffness: 167071.0", "stiffness: 150000.0");
    std::fs::write(&path, &text).unwrap();
    let msg = VehicleSpec::from_file(&path).unwrap_err().to_string();
    assert!(
        msg.contains("bad.yaml") && msg.contains("`hmmwv` is the name of a built-in vehicle"),
        "{msg}"
    );
    std::fs::write(&path, text.replace("name: hmmwv", "name: soft-hmmwv")).unwrap();
    assert_eq!(VehicleSpec::from_file(&path).unwrap().name, "soft-hmmwv");
    std::fs::write(&path, vehicles::builtin_yaml("hmmwv").unwrap()).unwrap();
    assert_eq!(
        VehicleSpec::from_file(&path).unwrap(),
        vehicles::builtin("hmmwv").unwrap()
    );

    let msg = VehicleSpec::from_file(dir.join("missing.yaml"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("missing.yaml"), "{msg}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn nested_or_huge_vehicle_yaml_is_refused_before_parsing() {
    let dir = std::env::temp_dir().join(format!("verti-sim-yaml-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("deep.yaml");
    // 200 KB of nested lists: the parser took close to a minute on this
    let deep = format!("name: {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
    std::fs::write(&path, &deep).unwrap();
    let t0 = std::time::Instant::now();
    let msg = VehicleSpec::from_file(&path).unwrap_err().to_string();
    assert!(t0.elapsed().as_millis() < 500, "{:?}", t0.elapsed());
    assert!(
        msg.contains("deep.yaml") && msg.contains("nesting depth") && msg.contains("64"),
        "{msg}"
    );
    let msg = VehicleSpec::from_yaml_str(&deep, "python text")
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("python text") && msg.contains("nesting"),
        "{msg}"
    );
    // a file over the cap is refused without being read
    let big = dir.join("big.yaml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(5 << 20).unwrap();
    let msg = VehicleSpec::from_file(&big).unwrap_err().to_string();
    assert!(
        msg.contains("big.yaml") && msg.contains("at most 4.0 MiB"),
        "{msg}"
    );
    // a vehicle scale outside the world range is refused like a world scale
    let text = vehicles::builtin_yaml("hmmwv")
        .unwrap()
        .replace("scale: 1.0", "scale: 1.0e-8");
    let msg = VehicleSpec::from_yaml_str(&text, "tiny")
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("`scale`") && msg.contains("[1/1000, 10]"),
        "{msg}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let world = Arc::new(testing::flat_world(1.0, 0.8));
    let spec = vehicles::builtin("hmmwv").unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    assert!(matches!(
        sim.state_at(StartPose::new(500.0, 0.0, 0.0)),
        Err(SimError::InvalidStart(_))
    ));
    assert!(matches!(
        sim.state_at(StartPose::new(f64::NAN, 0.0, 0.0)),
        Err(SimError::InvalidStart(_))
    ));
    let start = StartPose::new(0.0, 0.0, 0.0);
    let mut st = sim.state_at(start).unwrap();
    for (c, name) in [
        (Controls::new(f64::NAN, 0.0, 0.0), "throttle"),
        (Controls::new(0.0, 1.5, 0.0), "brake"),
        (Controls::new(0.0, 0.0, -1.01), "steering"),
        (Controls::new(0.0, 0.0, f64::INFINITY), "steering"),
    ] {
        let e = sim.step(&mut st, c, 0.01).unwrap_err();
        assert!(
            matches!(e, SimError::InvalidControl { .. }) && e.to_string().contains(name),
            "{e}"
        );
    }
    for dt in [0.0, -1.0, f64::NAN, 100.0] {
        assert!(matches!(
            sim.step(&mut st, Controls::IDLE, dt),
            Err(SimError::InvalidStep(_))
        ));
    }
    // a non-finite state is reported by name, and stays an error
    st.set_velocity(&sim, Vec3::new(f64::NAN, 0.0, 0.0));
    let e = sim.step(&mut st, Controls::IDLE, 0.01).unwrap_err();
    assert!(
        matches!(e, SimError::NonFinite { .. }) && e.to_string().contains("velocity"),
        "{e}"
    );
    // a fresh state is unaffected
    let mut fresh = sim.state_at(start).unwrap();
    sim.step(&mut fresh, Controls::IDLE, 0.01).unwrap();
}

#[test]
fn every_vehicle_drives_every_kind_of_world() {
    for spec in vehicles::all_builtin() {
        let s = spec.scale;
        let worlds = [
            testing::flat_world(s, 0.8),
            testing::bumpy_world(s, 0.4, 8.0, 0.7),
            testing::soil_world(s, SoilParams::MID, 0.0),
            testing::rough_world(s, 3, 8.0, RoughSurface::Mixed),
        ];
        for world in worlds {
            let name = world.meta.name.clone();
            let world = Arc::new(world);
            let sim = Sim::new(&world, &spec).unwrap();
            let start = StartPose::new(0.0, 0.0, 0.2);
            let mut st = sim.state_at(start).unwrap();
            let start = sim.reference_pose(&st).position;
            for k in 0..300 {
                let c = Controls::new(0.5, 0.0, if k > 150 { 0.3 } else { 0.0 });
                sim.step(&mut st, c, 0.02)
                    .unwrap_or_else(|e| panic!("{} on {name}: {e}", spec.name));
            }
            let moved = (sim.reference_pose(&st).position - start).norm_xy();
            if name == "test/flat" {
                assert!(!st.is_rolled_over(), "{} rolled over on {name}", spec.name);
                // at least a metre per second of scale-adjusted speed on average over 6 s
                assert!(
                    moved > 3.0 * s.sqrt(),
                    "{} moved only {moved:.2} m on {name}",
                    spec.name
                );
            }
        }
    }
}

#[test]
fn state_accessors_are_consistent() {
    let world = Arc::new(testing::flat_world(1.0, 0.8));
    let spec = vehicles::builtin("hmmwv").unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    let start = StartPose::new(2.0, -3.0, 1.0);
    let mut st = sim.state_at(start).unwrap();
    for _ in 0..100 {
        sim.step(&mut st, Controls::new(0.5, 0.0, 0.0), 0.02)
            .unwrap();
    }
    assert!((st.time() - 2.0).abs() < 1e-9);
    let (_, _, yaw) = st.euler();
    assert!((yaw - 1.0).abs() < 0.05, "yaw {yaw}");
    let v = st.velocity_world();
    let vb = st.velocity_body();
    assert!((v.norm() - vb.norm()).abs() < 1e-9 && (st.forward_speed() - vb.x).abs() < 1e-12);
    assert!(st.forward_speed() > 1.0);
    assert_eq!(st.wheels().len(), 4);
    assert_eq!(st.contacts().wheels_in_contact, 4);
    assert!(
        st.wheels()
            .iter()
            .all(|w| w.normal_force > 0.0 && w.spin_rate > 0.0)
    );
    let centers = sim.wheel_centers(&st);
    let pose = sim.reference_pose(&st);
    // wheel centres sit about one radius above the flat ground
    for c in &centers {
        assert!((c.z - 0.45).abs() < 0.03, "{c:?}");
    }
    assert!((pose.position - st.com_position()).norm() < 0.3);
}

#[test]
fn soil_is_copy_on_write_and_ruts_persist() {
    let world = Arc::new(testing::soil_world(1.0, SoilParams::SOFT, 0.0));
    let spec = vehicles::builtin("hmmwv").unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    let start = StartPose::new(0.0, 0.0, 0.0);
    let mut st = sim.state_at(start).unwrap();
    for _ in 0..100 {
        sim.step(&mut st, Controls::new(0.6, 0.0, 0.0), 0.02)
            .unwrap();
    }
    assert!(st.contacts().wheels_on_soil == 4 && st.soil().deformed_nodes() > 50);
    // the start spot is now a rut (the wheels sat there) and stays one
    let front_start = sim.point_world(
        &sim.state_at(start).unwrap(),
        Vec3::new(spec.axles[0].x, 0.0, 0.0),
    );
    let side = 0.5 * spec.axles[0].track;
    let rut = sim.ground_height_at(&st, front_start.x, front_start.y + side);
    assert!(rut < -0.05, "rut depth {rut:.3} m");
    // a clone shares the soil until one of them steps
    let mut other = st.clone();
    assert!(other.soil().shares_storage_with(st.soil()));
    let before = st.clone();
    sim.step(&mut other, Controls::new(0.6, 0.0, 0.0), 0.02)
        .unwrap();
    assert!(!other.soil().shares_storage_with(st.soil()));
    assert_eq!(st, before, "stepping a clone must not touch the original");
}

#[test]
fn a_vehicle_too_big_for_the_soil_grid_drives_on_it_as_rigid_ground() {
    // HMMWV on a 1/10-scale soil world: 1 cm nodes, tens of thousands under each wheel
    let world = Arc::new(testing::soil_world(0.1, SoilParams::MID, 0.0));
    let spec = vehicles::builtin("hmmwv").unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    let start = StartPose::new(0.0, 0.0, 0.0);
    let mut st = sim.state_at(start).unwrap();
    for _ in 0..100 {
        sim.step(&mut st, Controls::new(0.3, 0.0, 0.0), 0.02)
            .unwrap();
    }
    assert_eq!(st.contacts().wheels_in_contact, 4);
    assert!(
        st.com_position().z > 0.4,
        "sank to {:.3} m",
        st.com_position().z
    );
}

#[test]
fn a_vehicle_too_small_for_the_soil_grid_does_not_fall_through() {
    // 1/10 crawler on a full-scale soil world: 0.1 m nodes, a 4 cm tread
    let world = Arc::new(testing::soil_world(1.0, SoilParams::SOFT, 0.0));
    let spec = vehicles::builtin("verti4").unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    let start = StartPose::new(0.0, 0.0, 0.0);
    let mut st = sim.state_at(start).unwrap();
    for _ in 0..100 {
        sim.step(&mut st, Controls::new(0.3, 0.0, 0.0), 0.02)
            .unwrap();
    }
    assert_eq!(st.contacts().wheels_in_contact, 4);
    assert!(
        st.com_position().z > 0.05,
        "sank to {:.3} m",
        st.com_position().z
    );
}

#[test]
fn positive_steering_turns_left_for_wheeled_and_tracked_vehicles() {
    for name in ["hmmwv", "artcar", "truck8", "m113"] {
        let spec = vehicles::builtin(name).unwrap();
        let world = Arc::new(testing::flat_world(spec.scale, 0.8));
        let sim = Sim::new(&world, &spec).unwrap();
        let start = StartPose::new(0.0, 0.0, 0.0);
        for steer in [0.5, -0.5] {
            let mut st = sim.state_at(start).unwrap();
            for _ in 0..200 {
                sim.step(&mut st, Controls::new(0.6, 0.0, steer), 0.02)
                    .unwrap();
            }
            let (_, _, yaw) = st.euler();
            assert!(
                yaw * steer.signum() > 0.2,
                "{name}: steering {steer} gave yaw {yaw:.3} rad after 4 s"
            );
        }
    }
}

#[test]
fn model_and_state_can_cross_threads() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Sim>();
    assert_send_sync::<verti_sim::SimState>();
    assert_send_sync::<VehicleSpec>();
}
