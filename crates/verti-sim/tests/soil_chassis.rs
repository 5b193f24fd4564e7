//! Soil does not hold the chassis up (issue 34): in Chrono's SCM only the wheels meet the soil
//! and the chassis passes through it. A ridge under the belly, between the wheels, lifts the
//! chassis on rigid ground and not on soil; a floor one wheel diameter down still catches it.

use std::sync::Arc;
use verti_sim::testing::{rigid_patch, soil_patch, world_from_fn};
use verti_sim::{Controls, Sim, StartPose, vehicles};
use verti_world::{Patch, SoilParams};

/// Flat ground with a ridge `height` high across the path, 2 m wide, centred on x = 0: the
/// HMMWV (wheelbase 3.3 m) straddles it with its wheels on the flat.
fn ridge(patch: Patch, height: f64) -> Arc<verti_world::World> {
    Arc::new(world_from_fn(
        "ridge",
        1.0,
        move |x, _| if x.abs() < 1.0 { height } else { 0.0 },
        vec![patch; 256],
        Vec::new(),
    ))
}

/// Chassis-terrain contact points and the chassis centre's height after 4 s at rest (the
/// start may place the vehicle on the ridge's top; it then settles).
fn straddle(world: &Arc<verti_world::World>) -> (u32, f64) {
    let spec = vehicles::builtin("hmmwv").unwrap();
    let sim = Sim::new(world, &spec).unwrap();
    let mut st = sim.state_at(StartPose::new(0.0, 0.3, 0.0)).unwrap();
    for _ in 0..80 {
        sim.step(&mut st, Controls::new(0.0, 1.0, 0.0), 0.05)
            .unwrap();
    }
    (st.contacts().chassis_terrain_points, st.com_position().z)
}

#[test]
fn a_ridge_of_soil_under_the_belly_does_not_hold_the_chassis() {
    // 0.8 m: above the HMMWV's belly (about 0.4 m of ground clearance)
    let (rigid_points, rigid_top) = straddle(&ridge(rigid_patch(0.8), 0.8));
    let (soil_points, soil_top) = straddle(&ridge(soil_patch(SoilParams::MID), 0.8));
    assert!(rigid_points > 0, "the rigid ridge should touch the chassis");
    assert_eq!(soil_points, 0, "the chassis met the soil ridge");
    // held up by the rigid ridge; on soil it rests on its wheels
    assert!(rigid_top > soil_top + 0.2, "{rigid_top} vs {soil_top}");
    // a ridge taller than a wheel diameter above the belly reaches the floor under the soil
    let (deep_points, _) = straddle(&ridge(soil_patch(SoilParams::MID), 2.0));
    assert!(
        deep_points > 0,
        "the floor under the soil should catch the chassis"
    );
}
