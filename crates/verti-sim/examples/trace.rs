//! Development trace of the benchmark drive: `cargo run -p verti-sim --release --example trace -- hmmwv soil`
use verti_sim::tools::{BenchWorlds, bench_controls, bench_route};
use verti_sim::{Sim, StartPose, vehicles};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let spec = vehicles::builtin(args.get(1).map_or("hmmwv", |s| s.as_str())).unwrap();
    let worlds = if std::env::var("SYNTHETIC").is_ok() {
        BenchWorlds::synthetic(&[spec.scale])
    } else {
        BenchWorlds::generated(&[spec.scale]).unwrap()
    };
    let pair = &worlds.pairs[0];
    let world = if args.get(2).map(|s| s.as_str()) == Some("soil") {
        &pair.soil
    } else {
        &pair.rigid
    };
    let (from, to) = bench_route(world);
    let yaw0 = (to[1] - from[1]).atan2(to[0] - from[0]);
    let sim = Sim::new(world, &spec).unwrap();
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
