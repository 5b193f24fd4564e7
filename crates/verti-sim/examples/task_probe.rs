//! Development probe: a vehicle at one task's start on a saved world, idle for 0.1 s and then at
//! full throttle with a fixed steering input for 1.9 s, printing every 0.2 s its speed, gear,
//! engine torque, contacts and each wheel's load, forces and spin (where a vehicle stops:
//! wheels spinning, its body on the ground, a wheel on an obstacle).
//!
//!     verti world generate --out /tmp/verti-100     # the built-in set, saved
//!     cargo run --release -p verti-sim --example task_probe -- /tmp/verti-100/world-061 8 sedan 0.3
//!
//! Arguments: world directory, pair (0–9), built-in vehicle, steering input in [−1, 1].
use std::sync::Arc;
use verti_sim::{Controls, Sim, StartPose, vehicles};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 5 {
        eprintln!("usage: task_probe WORLD_DIR PAIR VEHICLE STEERING");
        std::process::exit(2);
    }
    let world = match verti_world::format::load_world(std::path::Path::new(&args[1])) {
        Ok(w) => Arc::new(w),
        Err(e) => {
            eprintln!("{}: {e}", args[1]);
            std::process::exit(1);
        }
    };
    let (Ok(pair), Ok(steer)) = (args[2].parse::<usize>(), args[4].parse::<f64>()) else {
        eprintln!("PAIR must be a task number of the world and STEERING a number");
        std::process::exit(2);
    };
    let Some(task) = world.tasks.get(pair).copied() else {
        eprintln!("{}: no pair {pair} ({} tasks)", args[1], world.tasks.len());
        std::process::exit(2);
    };
    let spec = vehicles::builtin(&args[3]).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2);
    });
    let sim = Sim::new(&world, &spec).unwrap();
    let start = StartPose::new(task.start[0], task.start[1], task.start_yaw());
    let mut st = sim.state_at(start).unwrap();
    let dt = 0.005;
    for k in 0..400 {
        let c = if k < 20 {
            Controls::IDLE
        } else {
            Controls::new(1.0, 0.0, steer)
        };
        if let Err(e) = sim.step(&mut st, c, dt) {
            eprintln!("error {e}");
            break;
        }
        if k % 40 == 39 {
            let (_, engine_torque) = st.engine();
            println!(
                "t {:.2} s, speed {:.3} m/s, gear {}, engine {:.0} N m, {:?}",
                st.time(),
                st.forward_speed(),
                st.gear(),
                engine_torque,
                st.contacts()
            );
            for w in st.wheels() {
                println!(
                    "    load {:7.0} N  long {:7.0} N  lat {:7.0} N  spin {:7.2} rad/s  on obstacle {}",
                    w.normal_force, w.long_force, w.lat_force, w.spin_rate, w.touches_obstacle
                );
            }
        }
    }
}
