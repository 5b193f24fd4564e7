//! Development probe: prints a short drive of a vehicle on a test world.
//! `cargo run -p verti-sim --release --example probe -- hmmwv flat`
use std::sync::Arc;
use verti_sim::{Controls, Sim, StartPose, testing, vehicles};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("hmmwv", |s| s.as_str());
    let kind = args.get(2).map_or("flat", |s| s.as_str());
    let throttle: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.5);
    let steer: f64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let spec = vehicles::builtin(name).unwrap();
    let s = spec.scale;
    let world = Arc::new(match kind {
        "bumpy" => testing::bumpy_world(s, 0.5, 10.0, 0.8),
        "snow" => testing::soil_world(s, verti_world::SoilParams::SOFT, 0.0),
        "mud" => testing::soil_world(s, verti_world::SoilParams::MID, 0.0),
        "sand" => testing::soil_world(s, verti_world::SoilParams::HARD, 0.0),
        "rough" => testing::rough_world(s, 1, 16.0, testing::RoughSurface::Rigid),
        "roughsoil" => testing::rough_world(s, 2, 4.8, testing::RoughSurface::Soil),
        _ => testing::flat_world(s, 0.8),
    });
    let sim = Sim::new(&world, &spec).unwrap();
    let mut st = sim.state_at(StartPose::new(0.0, 0.0, 0.0)).unwrap();
    println!(
        "start z {:.4} energy {:.1}",
        st.com_position().z,
        sim.energy(&st)
    );
    for k in 0..200 {
        let c = if k < 20 {
            Controls::IDLE
        } else {
            Controls::new(throttle, 0.0, steer)
        };
        if let Err(e) = sim.step(&mut st, c, 0.05) {
            println!("error {e}");
            break;
        }
        if k % 10 == 9 {
            let p = st.com_position();
            let (r, pi, y) = st.euler();
            let w: Vec<String> = st
                .wheels()
                .iter()
                .map(|w| {
                    format!(
                        "{:.0}/{:.3}/{:.3}",
                        w.normal_force, w.compression, w.sinkage
                    )
                })
                .collect();
            println!(
                "t {:5.2} p ({:7.2} {:7.2} {:6.3}) rpy ({:5.1} {:5.1} {:6.1}) v {:6.2} gear {} E {:.0} wheels {}",
                st.time(),
                p.x,
                p.y,
                p.z,
                r.to_degrees(),
                pi.to_degrees(),
                y.to_degrees(),
                st.forward_speed(),
                st.gear(),
                sim.energy(&st),
                w.join(" ")
            );
        }
    }
}
