//! The direction of the raised track ends' contact force against a rock: along the track's
//! own normal where a rock's edge pokes into its running surface (so the driven track rides up
//! the edge), along the rock face's normal where a face turned across the vehicle meets the
//! track's corner (so a rock met at an angle deflects the vehicle sideways).

use crate::contact::track_run::track_run_contacts;
use crate::drivetrain::SpinLoads;
use crate::integrate::Loads;
use crate::sim::Sim;
use crate::state::{SimState, StartPose};
use crate::testing;
use crate::track_runs::lower_tangent;
use crate::vehicles;
use std::sync::Arc;
use verti_core::Vec3;
use verti_world::World;

/// The M113 at rest at the origin heading +x, and the runs' total force on it (no motion,
/// so no friction: normal forces only), every obstacle of the world counted as near.
fn m113_force(world: World) -> (Sim, SimState, Vec3) {
    let sim = Sim::new(&Arc::new(world), &vehicles::builtin("m113").unwrap()).unwrap();
    let st = sim.state_at(StartPose::new(0.0, 0.0, 0.0)).unwrap();
    let force = force_of(&sim, &st);
    (sim, st, force)
}

fn force_of(sim: &Sim, st: &SimState) -> Vec3 {
    let runs = sim.model.track_runs.as_ref().unwrap();
    let mut spin = SpinLoads::ZERO;
    let near: Vec<u32> = (0..sim.terrain.world.obstacles.len() as u32).collect();
    let out = track_run_contacts(&sim.terrain, &sim.model, runs, st, &near, &mut spin);
    let mut loads = Loads::gravity(Vec3::ZERO, 0.0);
    out.apply(&st.group_spin, &mut loads);
    loads.force
}

fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    (a.dot(b) / (a.norm() * b.norm()))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// A box rock across the path whose top front edge pokes 2 cm into the middle of the
/// front run (placed from the run's geometry at rest): the force is along the run's inward
/// normal (up and back, the run's slope off the vertical) within 1°, with no sideways part.
#[test]
fn a_rock_edge_pushes_the_run_along_its_normal() {
    // first the vehicle alone, to find where its front run lies
    let (sim, st, _) = m113_force(testing::flat_world(1.0, 0.8));
    let runs = sim.model.track_runs.as_ref().unwrap();
    let w = runs.sides[0].wheels[0];
    let hub = (
        sim.model.wheels[w].attach.x,
        sim.model.wheels[w].attach.z + st.wheels[w].compression,
    );
    let (sx, sz, sr) = runs.sprocket;
    let (nx, nz) = lower_tangent(hub, runs.wheel_radius, (sx, sz), sr);
    let a = (
        hub.0 + runs.wheel_radius * nx,
        hub.1 + runs.wheel_radius * nz,
    );
    let b = (sx + sr * nx, sz + sr * nz);
    let mid = Vec3::new(0.5 * (a.0 + b.0), 0.0, 0.5 * (a.1 + b.1));
    // the edge 2 cm inside the run, along its inward normal; then the rock's size from it
    let edge = st.position + st.orientation.rotate(mid - Vec3::new(nx, 0.0, nz) * 0.02);
    let height = edge.z;
    assert!((0.05..0.6).contains(&height), "edge at {height} m");
    let world = testing::rock_world(1.0, 0.8, edge.x, Vec3::new(2.0, 4.0, height));
    let sim = Sim::new(&Arc::new(world), sim.spec()).unwrap();
    let f = force_of(&sim, &st);
    let inward = st.orientation.rotate(Vec3::new(-nx, 0.0, -nz));
    println!(
        "edge at ({:.3}, {height:.3}) m: force {f:?}, {:.2}° from the run's normal",
        edge.x,
        angle_deg(f, inward)
    );
    assert!(f.norm() > 1e3, "{f:?}");
    assert!(angle_deg(f, inward) < 1.0);
    assert!(f.y.abs() < 1e-6 * f.norm());
}

/// A tall rock turned 45° across the path, its face 2 cm into the left sprocket's front: the
/// force is along the face's normal (half of it sideways) within 1°, not in the vehicle's
/// plane as the track's normal would be.
#[test]
fn a_face_across_the_track_pushes_it_sideways() {
    let (sim, st, _) = m113_force(testing::flat_world(1.0, 0.8));
    // the left sprocket's foremost point at rest, on the track's inner line (the one the face
    // turned back to the left meets first)
    let y = sim.model.track_runs.as_ref().unwrap().sides[0].lines[0];
    let (sx, sz, sr) = sim.model.track_runs.as_ref().unwrap().sprocket;
    let front = st.position + st.orientation.rotate(Vec3::new(sx + sr, y, sz));
    // a 1-m-thick, 6-m-long wall turned 45° (its face normal (−1, 1)/√2 facing the vehicle),
    // placed so that its face passes 2 cm behind that point and it reaches 0.5 m to the
    // vehicle's side of it (not on through the hull and the other track)
    let yaw = -std::f64::consts::FRAC_PI_4;
    let normal = Vec3::new(-1.0, 1.0, 0.0) * std::f64::consts::FRAC_1_SQRT_2;
    let along = Vec3::new(1.0, 1.0, 0.0) * std::f64::consts::FRAC_1_SQRT_2;
    let centre = front - normal * (0.5 - 0.02) + along * 2.5;
    let world = testing::yawed_rock_world(
        1.0,
        0.8,
        (centre.x, centre.y),
        Vec3::new(1.0, 6.0, 2.0),
        yaw,
    );
    let sim = Sim::new(&Arc::new(world), sim.spec()).unwrap();
    let f = force_of(&sim, &st);
    println!(
        "face at 45°: force {f:?}, {:.2}° from the face's normal",
        angle_deg(f, normal)
    );
    assert!(f.norm() > 1e3, "{f:?}");
    assert!(angle_deg(f, normal) < 1.0);
}
