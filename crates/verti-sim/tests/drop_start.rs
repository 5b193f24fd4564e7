//! Verti-Bench's spawn (`Sim::state_dropped`): level, the chassis reference frame a given
//! height above the ground, dropped at rest.

use std::sync::Arc;
use verti_core::Vec3;
use verti_sim::testing;
use verti_sim::{Controls, Sim, StartPose, vehicles};

fn sim(world: verti_world::World, vehicle: &str) -> Sim {
    Sim::new(&Arc::new(world), &vehicles::builtin(vehicle).unwrap()).unwrap()
}

#[test]
fn a_dropped_hmmwv_falls_and_settles_where_a_settled_one_starts() {
    let sim = sim(testing::plane_world(1.0, 0.0, 0.0, 0.8), "hmmwv");
    let start = StartPose::new(0.0, 0.0, 0.3);
    let settled = sim.state_at(start).unwrap();
    let mut st = sim.state_dropped(start, 1.0).unwrap();
    // the chassis reference frame starts exactly 1 m above the ground, level, at rest
    let pose = sim.reference_pose(&st);
    assert!((pose.position.z - 1.0).abs() < 1e-12, "{:?}", pose.position);
    let up = pose.orientation.rotate(Vec3::Z);
    assert!((up.z - 1.0).abs() < 1e-12, "not level: {up:?}");
    // nothing touches the ground for the first 0.1 s: the chassis falls (a little less than
    // g t²/2 = 4.9 cm, as the unloaded springs push the wheels down and the chassis up)
    sim.step(&mut st, Controls::IDLE, 0.1).unwrap();
    let fell: f64 = 1.0 - sim.reference_pose(&st).position.z;
    let free = 0.5 * 9.81 * 0.1 * 0.1;
    assert!(
        fell > 0.8 * free && fell < free + 1e-3,
        "fell {fell} m in 0.1 s"
    );
    // after landing it comes to rest at the settled start's height
    sim.step(&mut st, Controls::IDLE, 4.9).unwrap();
    let (a, b) = (
        sim.reference_pose(&st).position,
        sim.reference_pose(&settled).position,
    );
    assert!(
        (a.z - b.z).abs() < 0.02,
        "rests at {} m, settled {} m",
        a.z,
        b.z
    );
    assert!(
        st.velocity_world().norm() < 0.05,
        "still moving: {:?}",
        st.velocity_world()
    );
}

#[test]
fn a_drop_start_is_checked_like_any_start() {
    let sim = sim(
        testing::rock_world(1.0, 0.8, 1.0, Vec3::new(2.0, 2.0, 2.0)),
        "hmmwv",
    );
    for bad in [-0.1, f64::NAN, f64::INFINITY] {
        let e = sim
            .state_dropped(StartPose::new(-20.0, 0.0, 0.0), bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("drop height"), "{e}");
    }
    let e = sim
        .state_dropped(StartPose::new(2.0, 0.0, 0.0), 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("inside obstacle"), "{e}");
    let e = sim
        .state_dropped(StartPose::new(500.0, 0.0, 0.0), 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("off the map"), "{e}");
}

/// Level and 1 m up, a HMMWV spawned across a 45.8° slope has its uphill wheels half a metre
/// inside the ground, and the stiff contact would throw it. The spawn is lifted until nothing starts inside
/// rigid ground (just touching), so the vehicle falls as on level ground instead.
#[test]
fn a_drop_start_on_a_steep_spot_is_lifted_clear_of_the_ground_and_not_thrown() {
    let slope = 0.8;
    let sim = sim(testing::plane_world(1.0, 0.0, slope, 0.8), "hmmwv");
    let mut st = sim
        .state_dropped(StartPose::new(0.0, 0.0, 0.0), 1.0)
        .unwrap();
    let pose = sim.reference_pose(&st);
    // the ground is z = tan(slope) * y; the uphill wheels' lowest rim points touch first
    let spec = vehicles::builtin("hmmwv").unwrap();
    let lowest_gap = sim
        .wheel_centers(&st)
        .iter()
        .zip(spec.axles.iter().flat_map(|a| [a, a]))
        .map(|(c, ax)| {
            // the rim's lowest point over the wheel's width, against the plane
            let uphill = c.y + 0.5 * ax.wheel.width;
            c.z - ax.wheel.radius - slope.tan() * uphill
        })
        .fold(f64::INFINITY, f64::min);
    assert!(pose.position.z > 1.15, "not lifted: {:?}", pose.position);
    assert!(
        lowest_gap > -1e-3 && lowest_gap < 0.03,
        "the lowest wheel should just touch: gap {lowest_gap} m"
    );
    // it falls, not flies: after 20 ms its centre of mass moves down
    sim.step(&mut st, Controls::IDLE, 0.02).unwrap();
    let vz = st.velocity_world().z;
    assert!(vz < 0.05, "thrown up at {vz} m/s");
}
