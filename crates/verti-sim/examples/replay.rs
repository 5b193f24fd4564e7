//! Replays one soak episode and prints its trace:
//! `cargo run -p verti-sim --release --example replay -- VEHICLE WORLD EPISODE_SEED [EVERY]`
//! WORLD is `rough-rigid|rough-soil|rough-mixed` (the soak example's synthetic worlds at the
//! vehicle's scale) or `SET:INDEX` for a generated world.
use std::sync::Arc;
use verti_sim::testing::{self, RoughSurface};
use verti_sim::tools::soak_episode;
use verti_sim::vehicles;

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
    let ep = soak_episode(&world, &spec, seed, 6000, |_, st, c| {
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
    println!("{} steps, error {:?}", ep.steps, ep.error);
}
