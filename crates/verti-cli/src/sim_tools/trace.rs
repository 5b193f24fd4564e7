//! Tracing a drive step by step: one line per sampled step, shared by `verti sim soak
//! --replay` and `verti sim bench --trace`.

use super::bench::{bench_controls, bench_route};
use std::sync::Arc;
use verti_sim::{Controls, Sim, SimError, SimState, StartPose, VehicleSpec};
use verti_world::World;

/// The `--world` argument that names a soak world: a built-in set's world is reported by its
/// name, `SET/NNN`, and named on the command line as `SET:N`.
pub fn world_argument(name: &str) -> String {
    match name.rsplit_once('/') {
        Some((set, index)) if index.parse::<u32>().is_ok() => {
            format!("{set}:{}", index.trim_start_matches('0'))
        }
        _ => name.to_string(),
    }
}

/// The world a trace drives: `arg` as `--world`/`--trace` take it (`SET:N`, a report's
/// `SET/NNN`, or a world directory), generated at `scale`, the vehicle's.
pub fn traced_world(arg: &str, scale: f64) -> Result<Arc<World>, verti_world::error::WorldError> {
    Ok(Arc::new(verti_world::sets::resolve_world(
        &world_argument(arg),
        scale,
    )?))
}

/// One line of a trace: time, centre of mass, roll/pitch/yaw in degrees, speed, the controls,
/// the contact counts (chassis-terrain, chassis-obstacle, wheel-obstacle, soil nodes, points of
/// a track's raised ends) and each wheel's normal force / spring compression / spin rate.
pub fn trace_line(st: &SimState, c: &Controls) -> String {
    let p = st.com_position();
    let (r, pi, y) = st.euler();
    let wheels: Vec<String> = st
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
    format!(
        "t {:6.2} p ({:7.2} {:7.2} {:6.2}) rpy ({:6.1} {:6.1} {:6.1}) |v| {:7.2} c {:.2}/{:.2}/{:.2} cont ({} {} {} {} {}) w {}",
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
        ct.track_run_points,
        wheels.join(" ")
    )
}

/// Drives the benchmark's route on `world` with the benchmark's scripted driver (the very drive
/// `verti sim bench` times, at its 50 Hz control rate) for `sim_seconds`, and hands `print` a
/// trace line every `every` control steps. Also the drive to profile (e.g. under callgrind).
pub fn bench_trace(
    world: &Arc<World>,
    spec: &VehicleSpec,
    sim_seconds: f64,
    every: u64,
    mut print: impl FnMut(&str),
) -> Result<(), SimError> {
    let control_dt = 0.02;
    let (from, to) = bench_route(world);
    let yaw0 = (to[1] - from[1]).atan2(to[0] - from[0]);
    let sim = Sim::new(world, spec)?;
    let mut state = sim.state_at(StartPose::new(from[0], from[1], yaw0))?;
    let steps = (sim_seconds / control_dt).round() as u64;
    for k in 1..=steps {
        let controls = bench_controls(&state, to, world.meta.scale);
        sim.step(&mut state, controls, control_dt)?;
        if k.is_multiple_of(every.max(1)) {
            print(&trace_line(&state, &controls));
        }
    }
    Ok(())
}
