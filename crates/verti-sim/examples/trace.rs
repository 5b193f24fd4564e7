//! Development trace of the benchmark drive (for profiling, e.g. under callgrind):
//! `cargo run -p verti-sim --release --example trace -- VEHICLE [WORLD]`
//! WORLD is `rough-rigid` (default) or `rough-soil` (synthetic rough worlds at the vehicle's
//! scale), or `SET:INDEX`, e.g. a world `verti sim bench --json` names (`verti-100/003` →
//! `verti-100:3`). `FINE=1` also prints the last 100 steps.
//!
//! The route and the driver below mirror `bench_route` and `bench_controls` in
//! `crates/verti-cli/src/sim_tools/bench.rs` (the engine library carries no benchmark code, and
//! an example cannot use the CLI's modules): change the two together.
use std::sync::Arc;
use verti_sim::testing::{self, RoughSurface};
use verti_sim::{Controls, Sim, SimState, StartPose, vehicles};
use verti_world::World;

/// The benchmark's route: the first task's start and goal, or, for worlds without tasks, a
/// chord through the map centre.
fn bench_route(world: &World) -> ([f64; 2], [f64; 2]) {
    match world.tasks.first() {
        Some(t) => (t.start, t.goal),
        None => {
            let r = 0.4 * world.terrain.half_extent();
            ([-r, 0.0], [r, 0.0])
        }
    }
}

/// The benchmark's scripted driver: proportional speed control toward 4 m/s (scaled by
/// √scale) and proportional steering toward `target`.
fn bench_controls(state: &SimState, target: [f64; 2], scale: f64) -> Controls {
    let u = (4.0 * scale.sqrt() - state.forward_speed()).clamp(-1.0, 1.0);
    let p = state.com_position();
    let (_, _, yaw) = state.euler();
    let bearing = (target[1] - p.y).atan2(target[0] - p.x);
    let steering = (2.0 * verti_core::math::wrap_angle(bearing - yaw)).clamp(-1.0, 1.0);
    Controls {
        throttle: u.max(0.0),
        brake: (-u).max(0.0),
        steering,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let spec = vehicles::builtin(args.get(1).map_or("hmmwv", |s| s.as_str())).unwrap();
    let s = spec.scale;
    // the benchmark's synthetic worlds (the seeds and reliefs it used for them)
    let world = Arc::new(match args.get(2).map_or("rough-rigid", |s| s.as_str()) {
        "rough-rigid" => testing::rough_world(s, 1, 16.0, RoughSurface::Rigid),
        "rough-soil" => testing::rough_world(s, 2, 4.8, RoughSurface::Soil),
        other => verti_world::sets::resolve_world(other, s).unwrap(),
    });
    let (from, to) = bench_route(&world);
    let yaw0 = (to[1] - from[1]).atan2(to[0] - from[0]);
    let sim = Sim::new(&world, &spec).unwrap();
    let mut st = sim
        .state_at(StartPose::new(from[0], from[1], yaw0))
        .unwrap();
    for k in 0..3000 {
        let c = bench_controls(&st, to, world.meta.scale);
        if let Err(e) = sim.step(&mut st, c, 0.02) {
            println!("error {e}");
            break;
        }
        if (k % 100 == 99) || (std::env::var("FINE").is_ok() && k > 2900) {
            let p = st.com_position();
            let (r, pi, y) = st.euler();
            let w: Vec<String> = st
                .wheels()
                .iter()
                .map(|w| {
                    format!(
                        "{:.0}/{:.0}/{:.0}/{:.2}/{:.3}",
                        w.normal_force, w.long_force, w.lat_force, w.spin_rate, w.slip_long
                    )
                })
                .collect();
            println!(
                "t {:5.1} p ({:7.2} {:7.2} {:6.2}) rpy ({:6.1} {:6.1} {:6.1}) v {:6.2} |v| {:6.2} c {:.2}/{:.2} cont {:?} w {}",
                st.time(),
                p.x,
                p.y,
                p.z,
                r.to_degrees(),
                pi.to_degrees(),
                y.to_degrees(),
                st.forward_speed(),
                st.velocity_world().norm(),
                c.throttle,
                c.brake,
                (
                    st.contacts().chassis_terrain_points,
                    st.contacts().chassis_obstacle_points,
                    st.contacts().wheel_obstacle_contacts
                ),
                w.join(" ")
            );
        }
    }
}
