use std::sync::Arc;
use verti_sim::{Controls, Sim, start_pose, testing, vehicles};
#[test]
fn scratch_tilt() {
    let mut spec = vehicles::builtin("hmmwv").unwrap();
    let k = 2.0 / spec.tyre.friction;
    spec.tyre.dfx0 *= k; spec.tyre.dfy0 *= k; spec.tyre.friction = 2.0; spec.tyre.fxm = 2.0; spec.tyre.fxs = 2.0; spec.tyre.fym = 2.0; spec.tyre.fys = 2.0;
    let world = Arc::new(testing::twisting_slope_world(1.0, 35.0, 0.25, 2.0));
    let sim = Sim::new(&world, &spec, start_pose(&world, &spec, -40.0, 0.0, 0.0).unwrap()).unwrap();
    let mut st = sim.initial_state();
    let mut last = 0.0;
    for _ in 0..40000 {
        let u = (0.5 * (0.5 - st.forward_speed())).clamp(-1.0, 1.0);
        let steer = (-3.0 * st.euler().2).clamp(-1.0, 1.0);
        sim.step(&mut st, Controls::new(u.max(0.0), (-u).max(0.0), steer), 0.01).unwrap();
        let slope = 35.0 + 0.25 * st.com_position().x;
        if slope > last + 1.0 || st.euler().0.to_degrees() > slope + 25.0 {
            last = slope;
            let (r, p, y) = st.euler();
            let w: Vec<String> = st.wheels().iter().map(|w| format!("{:.0}/{:.0}/{:.3}", w.normal_force, w.lat_force, w.compression)).collect();
            println!("slope {:.1} roll-slope {:.2} pitch {:.2} yaw {:.2} v {:.2} steer {:.2} w {}", slope, r.to_degrees() - slope, p.to_degrees(), y.to_degrees(), st.forward_speed(), steer, w.join(" "));
            if st.euler().0.to_degrees() > slope + 25.0 { break; }
        }
    }
}
