//! Helpers shared by the engine's validation tests (`validation.rs`, `rigid_tyre.rs`,
//! `nine_vehicles.rs`): each test binary uses some of them.
#![allow(dead_code)]

use std::sync::Arc;
use verti_sim::spec::VehicleSpec;
use verti_sim::{Controls, Sim, SimState, StartPose};
use verti_world::World;

pub const G: f64 = 9.81;

/// The vehicle standing at (x, y) heading `yaw` on `world`.
pub fn sim_at(world: World, spec: &VehicleSpec, x: f64, y: f64, yaw: f64) -> (Sim, SimState) {
    let world = Arc::new(world);
    let sim = Sim::new(&world, spec).unwrap();
    let state = sim.state_at(StartPose::new(x, y, yaw)).unwrap();
    (sim, state)
}

/// Holds `controls` for `seconds` in 10-ms steps.
pub fn run(sim: &Sim, state: &mut SimState, controls: Controls, seconds: f64) {
    for _ in 0..(seconds / 0.01).round() as usize {
        sim.step(state, controls, 0.01).unwrap();
    }
}

/// Largest |roll| (rad) over `steps` 10-ms steps holding `controls`; π as soon as the vehicle
/// has rolled over (a tipping vehicle goes on to 180°).
pub fn max_roll(sim: &Sim, state: &mut SimState, controls: Controls, steps: usize) -> f64 {
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        sim.step(state, controls, 0.01).unwrap();
        worst = worst.max(state.euler().0.abs());
        if state.is_rolled_over() {
            return std::f64::consts::PI;
        }
    }
    worst
}

/// Sprung load per corner of a two-axle vehicle by the lever rule \[N\] (front, rear).
pub fn corner_loads(spec: &VehicleSpec) -> (f64, f64) {
    let (xf, xr) = (spec.axles[0].x, spec.axles[1].x);
    let w = spec.chassis.mass * G;
    let front = w * (spec.chassis.com[0] - xr) / (xf - xr);
    (0.5 * front, 0.5 * (w - front))
}

/// Radius of the least-squares circle through `points` (Kåsa's algebraic fit).
pub fn fit_circle(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut suu, mut svv, mut suv, mut suuu, mut svvv, mut suvv, mut svuu) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for &(x, y) in points {
        let (u, v) = (x - mx, y - my);
        suu += u * u;
        svv += v * v;
        suv += u * v;
        suuu += u * u * u;
        svvv += v * v * v;
        suvv += u * v * v;
        svuu += v * u * u;
    }
    let (b1, b2) = (0.5 * (suuu + suvv), 0.5 * (svvv + svuu));
    let det = suu * svv - suv * suv;
    let uc = (b1 * svv - b2 * suv) / det;
    let vc = (suu * b2 - suv * b1) / det;
    (uc * uc + vc * vc + (suu + svv) / n).sqrt()
}
