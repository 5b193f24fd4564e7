//! Development probe: the HMMWV driven straight along +x with the Chrono reference's driver law
//! (throttle = clamp(3 − v), steering = heading error to a point 10 m ahead on y = 0, rate-limited
//! 0.05 per 5 ms step) on a test world, printing a 10 Hz trace `t,x,y,z,roll,pitch,yaw,v,throttle`
//! and per-wheel sinkage. Worlds: `ramp SOIL` (flat to x = −35, then a slope growing 0.8/90 per
//! metre; heights quantised to 16 bits of 45 m as in the PNG the Chrono run reads), `side SOIL DEG`
//! (a constant side slope, ground falling towards −y), `edge SOIL` (flat: soil for x < 0, rigid
//! ground of friction 0.8 for x > 0, the step out of the soil onto a rigid patch; the Chrono side
//! is an SCM patch over x < 0 beside a rigid box patch over x > 0).
//! `cargo run -p verti-sim --release --example soil_probe -- ramp mud > trace.csv`
use std::sync::Arc;
use verti_sim::{Controls, Sim, StartPose, testing, vehicles};
use verti_world::SoilParams;

fn soil(name: &str) -> Option<SoilParams> {
    match name {
        "snow" => Some(SoilParams::SOFT),
        "mud" => Some(SoilParams::MID),
        "sand" => Some(SoilParams::HARD),
        _ => None,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map_or("ramp", |s| s.as_str());
    let soil_name = args.get(2).map_or("mud", |s| s.as_str());
    let deg: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(15.0);
    let duration: f64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let patch = match soil(soil_name) {
        Some(p) => testing::soil_patch(p),
        None => testing::rigid_patch(0.8),
    };
    let patches = vec![
        patch;
        verti_world::surface::PATCHES_PER_SIDE
            * verti_world::surface::PATCHES_PER_SIDE
    ];
    let world = match kind {
        "edge" => {
            let soil = soil(soil_name).unwrap_or(SoilParams::SOFT);
            testing::half_soil_world(1.0, soil, 0.8)
        }
        "side" => {
            let t = deg.to_radians().tan();
            testing::world_from_fn("side", 1.0, move |_, y| t * (y + 64.0), patches, Vec::new())
        }
        _ => {
            let c = 0.8 / 90.0;
            let top = 45.0;
            testing::world_from_fn(
                "ramp",
                1.0,
                move |x, _| {
                    let h = if x < -35.0 {
                        0.0
                    } else {
                        0.5 * c * (x + 35.0).powi(2)
                    };
                    (h / top * 65535.0).round() / 65535.0 * top
                },
                patches,
                Vec::new(),
            )
        }
    };
    let world = Arc::new(world);
    // VERTI_PROBE_VEHICLE=NAME: another built-in vehicle (the per-wheel columns are its first four)
    let vehicle = std::env::var("VERTI_PROBE_VEHICLE").unwrap_or_else(|_| "hmmwv".into());
    let spec = vehicles::builtin(&vehicle).unwrap();
    let sim = Sim::new(&world, &spec).unwrap();
    // VERTI_PROBE_DROP=1: the reference's start, 1 m above the ground (throttle from t = 0)
    let start = StartPose::new(-55.0, 0.0, 0.0);
    // (the start faces +x; a heading is reached within the first metres)
    let mut st = if std::env::var_os("VERTI_PROBE_DROP").is_some() {
        sim.state_dropped(start, 1.0).unwrap()
    } else {
        sim.state_at(start).unwrap()
    };
    let heading = std::env::var("VERTI_PROBE_HEADING")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or(0.0)
        .to_radians();
    // VERTI_PROBE_SPEED=M/S: the driver's target speed (default the reference's 3 m/s)
    let speed: f64 = std::env::var("VERTI_PROBE_SPEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3.0);
    let dt = 0.005;
    let mut steer = 0.0f64;
    println!(
        "t,x,y,z,roll,pitch,yaw,v,throttle,sinkage_fl,sinkage_fr,sinkage_rl,sinkage_rr,fz_fl,fz_fr,fz_rl,fz_rr,gear,engine_torque,wheel_torque,omega_fl,omega_fr,omega_rl,omega_rr,fx_fl,fx_fr,fx_rl,fx_rr"
    );
    let steps = (duration / dt).round() as usize;
    for k in 0..steps {
        let p = st.com_position();
        let (_, _, yaw) = st.euler();
        // VERTI_PROBE_HEADING=DEG: follow the line through the start at that angle to +x
        let target = (
            p.x + 10.0 * heading.cos(),
            (p.x + 10.0 * heading.cos() + 55.0) * heading.tan(),
        );
        let want = (target.1 - p.y).atan2(target.0 - p.x);
        let err = (want - yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        steer = (steer + (err - steer).clamp(-0.05, 0.05)).clamp(-1.0, 1.0);
        let u = (speed - st.forward_speed()).clamp(-1.0, 1.0);
        let c = Controls::new(u.max(0.0), (-u).max(0.0), steer);
        if let Err(e) = sim.step(&mut st, c, dt) {
            eprintln!("error {e}");
            break;
        }
        if (k + 1)
            % std::env::var("VERTI_PROBE_EVERY")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(20)
            == 0
        {
            let p = st.com_position();
            let (r, pi, y) = st.euler();
            let w = st.wheels();
            let (_, engine_torque) = st.engine();
            let ratio = spec.powertrain.gears[st.gear()] * spec.powertrain.final_drive;
            println!(
                "{:.2},{:.3},{:.3},{:.3},{:.2},{:.2},{:.2},{:.3},{:.3},{:.4},{:.4},{:.4},{:.4},{:.0},{:.0},{:.0},{:.0},{},{:.1},{:.0},{:.3},{:.3},{:.3},{:.3},{:.0},{:.0},{:.0},{:.0}",
                st.time(),
                p.x,
                p.y,
                p.z,
                r.to_degrees(),
                pi.to_degrees(),
                y.to_degrees(),
                st.forward_speed(),
                u.max(0.0),
                w[0].sinkage,
                w[1].sinkage,
                w[2].sinkage,
                w[3].sinkage,
                w[0].normal_force,
                w[1].normal_force,
                w[2].normal_force,
                w[3].normal_force,
                st.gear(),
                engine_torque,
                engine_torque / ratio,
                w[0].spin_rate,
                w[1].spin_rate,
                w[2].spin_rate,
                w[3].spin_rate,
                w[0].long_force,
                w[1].long_force,
                w[2].long_force,
                w[3].long_force,
            );
        }
    }
}
