//! The settled start (`Sim::state_at`): set down at rest on the plane fitted under the wheels,
//! and raised where something the plane does not see (a bump under the hull, a hill under an
//! overhang) would push the vehicle up harder than twice its weight.

use std::sync::Arc;
use verti_core::Vec3;
use verti_sim::testing;
use verti_sim::{Controls, Sim, StartPose, vehicles};

fn sim(world: verti_world::World, vehicle: &str) -> Sim {
    Sim::new(&Arc::new(world), &vehicles::builtin(vehicle).unwrap()).unwrap()
}

const PARKED: Controls = Controls {
    throttle: 0.0,
    brake: 1.0,
    steering: 0.0,
};

/// The fastest upward speed of the centre of mass over the first 30 ms, brakes on.
fn thrown_at(sim: &Sim, start: StartPose) -> f64 {
    let mut st = sim.state_at(start).unwrap();
    let mut up = 0.0f64;
    for _ in 0..6 {
        sim.step(&mut st, PARKED, 0.005).unwrap();
        up = up.max(st.velocity_world().z);
    }
    up
}

#[test]
fn on_flat_ground_the_tyres_carry_the_vehicle_at_their_static_deflection() {
    for name in ["hmmwv", "m113", "sedan"] {
        let spec = vehicles::builtin(name).unwrap();
        let sim = sim(testing::flat_world(1.0, 0.8), name);
        let st = sim.state_at(StartPose::new(0.0, 0.0, 0.4)).unwrap();
        // not raised: the deepest rim is its tyre's static deflection (an equal share of the
        // weight) into the ground, the others less
        let weight = spec.chassis.mass
            + spec.track.map_or(0.0, |t| 2.0 * t.track_mass)
            + spec
                .axles
                .iter()
                .map(|a| 2.0 * a.wheel.unsprung_mass)
                .sum::<f64>();
        let deflection = weight * 9.81 / spec.wheel_count() as f64 / spec.tyre.radial_stiffness;
        let deepest = sim
            .wheel_centers(&st)
            .iter()
            .zip(spec.axles.iter().flat_map(|a| [a, a]))
            .map(|(c, ax)| c.z - ax.wheel.radius)
            .fold(f64::INFINITY, f64::min);
        assert!(
            (deepest + deflection).abs() < 1e-4,
            "{name}: deepest rim {deepest} m, static deflection {deflection} m"
        );
        let up = thrown_at(&sim, StartPose::new(0.0, 0.0, 0.4));
        assert!(up < 0.01, "{name} moves up at {up} m/s");
    }
}

/// A ridge 0.6 m high along the M113's centre line, between its tracks, reaches 0.23 m into
/// its hull (0.37 m above the ground): set down on its road wheels, the hull's contacts would throw it up at metres per
/// second. It is raised instead until the hull carries the weight, resting on the ridge.
#[test]
fn a_hull_over_a_ridge_is_raised_onto_it_and_not_thrown() {
    let ridge = 0.6;
    let sim = sim(testing::ridge_world(1.0, 0.8, 0.0, ridge), "m113");
    let flat = self::sim(testing::flat_world(1.0, 0.8), "m113");
    let along = StartPose::new(0.0, -0.3, std::f64::consts::FRAC_PI_2);
    let spec = vehicles::builtin("m113").unwrap();
    let bx = spec.chassis.collision_box;
    let belly = Vec3::new(bx.center[0], 0.0, bx.center[2] - 0.5 * bx.size[2]);
    let on_flat = flat.state_at(along).unwrap();
    let clearance = flat.point_world(&on_flat, belly).z;
    let mut st = sim.state_at(along).unwrap();
    let raised = sim.point_world(&st, belly).z - clearance;
    // onto the ridge, less the few centimetres its contacts sink in carrying the weight
    let into = ridge - clearance;
    assert!(
        into > 0.1 && raised > into - 0.05 && raised <= into,
        "belly {clearance} m up on flat ground, raised by {raised} m on the {ridge} m ridge"
    );
    let up = thrown_at(&sim, along);
    assert!(up < 0.1, "thrown up at {up} m/s");
    // it rests there (tilting onto one track, at most): no bounce
    let z0 = sim.point_world(&st, belly).z;
    sim.step(&mut st, PARKED, 1.0).unwrap();
    let dz = sim.point_world(&st, belly).z - z0;
    assert!(dz.abs() < 0.05, "the belly moved {dz} m in 1 s");
}
