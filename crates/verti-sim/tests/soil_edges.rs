//! Driving out of soil onto a rigid patch: the wheels, sunk in the soil, meet the patch's edge
//! as a curb as high as their sinkage. Chrono (its HMMWV on an SCM patch beside a rigid box
//! patch, `verti-bench`'s driver law at 3 m/s) slows at each axle's crossing and lifts the
//! vehicle by the sinkage, overshooting its height on the rigid side by 0.07 m
//! (docs/src/reference/engine.md, "Where rigid ground meets soil"). Before the edge was a
//! curb, the rigid patch pushed a sunk wheel straight up by its whole sinkage: no slowing,
//! and the rear thrown 0.37 m above its rest height.

use std::sync::Arc;
use verti_sim::{Controls, Sim, StartPose, testing, vehicles};
use verti_world::SoilParams;

/// Built-in `vehicle` driven straight along +x from x = −25 m on `soil` (x < 0) onto rigid
/// ground for `steps` steps of 5 ms: (x, z of the centre of mass, forward speed) every 0.1 s.
fn drive_out(vehicle: &str, soil: SoilParams, steps: usize) -> Vec<(f64, f64, f64)> {
    let world = Arc::new(testing::half_soil_world(1.0, soil, 0.8));
    let spec = vehicles::builtin(vehicle).unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    let mut st = sim.state_at(StartPose::new(-25.0, 0.0, 0.0)).unwrap();
    let dt = 0.005;
    let mut trace = Vec::new();
    for k in 0..steps {
        let p = st.com_position();
        let (_, _, yaw) = st.euler();
        // the reference's driver law: throttle 3 − v, steering to a point 10 m ahead on y = 0
        let err = (-p.y).atan2(10.0) - yaw;
        let u = (3.0 - st.forward_speed()).clamp(-1.0, 1.0);
        let c = Controls::new(u.max(0.0), (-u).max(0.0), err.clamp(-1.0, 1.0));
        sim.step(&mut st, c, dt).unwrap();
        if (k + 1) % 20 == 0 {
            trace.push((st.com_position().x, st.com_position().z, st.forward_speed()));
        }
    }
    trace
}

#[test]
fn a_wheel_sunk_in_snow_climbs_onto_rigid_ground_as_onto_a_curb() {
    let trace = drive_out("hmmwv", SoilParams::SOFT, 4400);
    let last = *trace.last().unwrap();
    assert!(last.0 > 15.0, "did not get across: {last:?}");
    // cruising in the snow before the edge, and the rest height on the rigid side
    let before = trace.iter().filter(|s| s.0 > -8.0 && s.0 < -4.0);
    let cruise = before.clone().map(|s| s.2).fold(f64::INFINITY, f64::min);
    let rest = trace.iter().filter(|s| s.0 > 8.0).map(|s| s.1).sum::<f64>()
        / trace.iter().filter(|s| s.0 > 8.0).count() as f64;
    // the crossing: the front axle meets the edge with the centre of mass 1.7 m short of it,
    // the rear axle 1.6 m past it
    let crossing: Vec<_> = trace.iter().filter(|s| s.0 > -3.0 && s.0 < 4.0).collect();
    let slowest = crossing.iter().map(|s| s.2).fold(f64::INFINITY, f64::min);
    let highest = crossing
        .iter()
        .map(|s| s.1)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(cruise > 2.7, "cruise {cruise}");
    // a curb slows the vehicle (Chrono: to 2.2-2.4 m/s on steps of 0.13-0.22 m)
    assert!(slowest < 2.6, "no step was felt: slowest {slowest} m/s");
    assert!(slowest > 1.0, "stopped at the step: slowest {slowest} m/s");
    // and lifts it by the sinkage without throwing it (Chrono: 0.07 m over its rest height)
    assert!(
        highest < rest + 0.15,
        "thrown up: {highest} against rest {rest}"
    );
}

#[test]
fn a_tracked_vehicle_climbs_out_of_snow_onto_rigid_ground() {
    let trace = drive_out("m113", SoilParams::SOFT, 6000);
    let last = *trace.last().unwrap();
    // its belt, not its road wheels, meets the edge: it rides up it as up a rock's edge
    assert!(last.0 > 10.0, "{last:?}");
}
