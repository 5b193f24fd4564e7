//! Replays one episode of `verti sim soak` and prints its trace:
//! `cargo run -p verti-sim --release --example replay -- VEHICLE WORLD EPISODE_SEED [EVERY]`
//! WORLD is `SET:INDEX` (a soak failure's world, e.g. `verti-100/017` → `verti-100:17`; it is
//! generated at the vehicle's scale, as the soak does) or `rough-rigid|rough-soil|rough-mixed`
//! (synthetic rough worlds at the vehicle's scale, seeds 10–12).
//!
//! The episode below mirrors `soak_episode` in `crates/verti-cli/src/sim_tools/soak.rs` draw for
//! draw (the engine library carries no soak code, and an example cannot use the CLI's modules):
//! change the two together, or a reported episode seed no longer replays the failing episode.
use std::sync::Arc;
use verti_core::Rng;
use verti_sim::testing::{self, RoughSurface};
use verti_sim::{Controls, Sim, SimError, SimState, StartPose, VehicleSpec, vehicles};
use verti_world::World;

/// Control step of the soak \[s\].
const SOAK_CONTROL_DT: f64 = 0.01;

/// One soak episode, fully determined by `episode_seed`: a random start on the map (clear of
/// obstacles), then random throttle/brake/steering held for 0.1–2 s, `max_steps` control
/// steps of 10 ms at most, ending early on an error or when the vehicle leaves the map.
/// `on_step` sees the state after every step. Returns the steps taken and the error, if any.
fn soak_episode(
    world: &Arc<World>,
    spec: &VehicleSpec,
    episode_seed: u64,
    max_steps: u64,
    mut on_step: impl FnMut(&SimState, &Controls),
) -> (u64, Option<(f64, SimError)>) {
    let control_dt = SOAK_CONTROL_DT;
    let mut rng = Rng::new(episode_seed);
    let half = world.terrain.half_extent() * 0.8;
    let started = Sim::new(world, spec).and_then(|sim| {
        // random starts, redrawn (up to 100 times) while they fall inside an obstacle
        let mut state = Err(SimError::InvalidStart("no start drawn".into()));
        for _ in 0..100 {
            let (x, y, yaw) = (
                rng.range(-half, half),
                rng.range(-half, half),
                rng.range(-std::f64::consts::PI, std::f64::consts::PI),
            );
            state = sim.state_at(StartPose::new(x, y, yaw));
            if state.is_ok() {
                break;
            }
        }
        Ok((sim, state?))
    });
    let (sim, mut state) = match started {
        Ok(s) => s,
        Err(e) => return (1, Some((0.0, e))),
    };
    let mut steps = 0;
    let mut controls = Controls::IDLE;
    let mut hold = 0.0;
    for _ in 0..max_steps {
        if hold <= 0.0 {
            let brake = if rng.uniform() < 0.15 {
                rng.uniform()
            } else {
                0.0
            };
            controls = Controls {
                throttle: rng.uniform(),
                brake,
                steering: rng.range(-1.0, 1.0),
            };
            hold = rng.range(0.1, 2.0);
        }
        hold -= control_dt;
        steps += 1;
        if let Err(e) = sim.step(&mut state, controls, control_dt) {
            return (steps, Some((state.time(), e)));
        }
        on_step(&state, &controls);
        let p = state.com_position();
        if !world.terrain.contains(p.x, p.y) {
            break; // drove off the map: the soak's next episode starts elsewhere
        }
    }
    (steps, None)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let spec = vehicles::builtin(&args[1]).unwrap();
    let s = spec.scale;
    let world = Arc::new(match args[2].as_str() {
        "rough-rigid" => testing::rough_world(s, 10, 16.0, RoughSurface::Rigid),
        "rough-soil" => testing::rough_world(s, 11, 16.0, RoughSurface::Soil),
        "rough-mixed" => testing::rough_world(s, 12, 16.0, RoughSurface::Mixed),
        other => verti_world::sets::resolve_world(other, s).unwrap(),
    });
    let seed: u64 = args[3].parse().unwrap();
    let every: u64 = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(10);
    let mut k = 0u64;
    // 6000 steps of 10 ms: the soak's longest episode (60 s)
    let (steps, error) = soak_episode(&world, &spec, seed, 6000, |st, c| {
        k += 1;
        if k.is_multiple_of(every) {
            let p = st.com_position();
            let (r, pi, y) = st.euler();
            let w: Vec<String> = st
                .wheels()
                .iter()
                .map(|w| {
                    format!(
                        "{:.0}/{:.3}/{:.1}",
                        w.normal_force, w.compression, w.spin_rate
                    )
                })
                .collect();
            let ct = st.contacts();
            println!(
                "t {:6.2} p ({:7.2} {:7.2} {:6.2}) rpy ({:6.1} {:6.1} {:6.1}) |v| {:7.2} c {:.2}/{:.2}/{:.2} cont ({} {} {} {}) w {}",
                st.time(),
                p.x,
                p.y,
                p.z,
                r.to_degrees(),
                pi.to_degrees(),
                y.to_degrees(),
                st.velocity_world().norm(),
                c.throttle,
                c.brake,
                c.steering,
                ct.chassis_terrain_points,
                ct.chassis_obstacle_points,
                ct.wheel_obstacle_contacts,
                ct.soil_nodes_in_contact,
                w.join(" ")
            );
        }
    });
    println!("{steps} steps, error {error:?}");
}
