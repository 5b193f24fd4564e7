//! The tracked M113 turns by skid steering: a steer unit holds the inner track's speed at the
//! ratio ρ that gives the path curvature of an equivalent bicycle (`skid_speed_ratio`), so
//! every system's steering input means the same path on it as on a wheeled vehicle. Expected
//! numbers are derived on paper from the vehicle file; tolerances are stated in each test.

use verti_core::Vec3;
use verti_sim::spec::VehicleSpec;
use verti_sim::{Controls, SimState, skid_speed_ratio, testing, vehicles};

mod common;
use common::fit_circle;

fn m113() -> VehicleSpec {
    vehicles::builtin("m113").unwrap()
}

/// Track speed ratio against the closed form: with gauge B = 2.159 m and the equivalent
/// bicycle (L = 2.667 m, 25.2° at full input), κ = tan δ / L and ρ = (1 − κB/2) / (1 + κB/2):
/// at full input R = L / tan 25.2° = 5.67 m, ρ = (5.67 − 1.0795) / (5.67 + 1.0795) = 0.680.
#[test]
fn speed_ratio_is_the_kinematic_one() {
    let spec = m113();
    let rho = skid_speed_ratio(&spec, 25.2f64.to_radians());
    let r = 2.667 / 25.2f64.to_radians().tan();
    let expected = (r - 1.0795) / (r + 1.0795);
    assert!((rho - expected).abs() < 1e-12, "{rho} vs {expected}");
    assert!((expected - 0.680).abs() < 1e-3, "{expected}");
    assert_eq!(skid_speed_ratio(&spec, 0.0), 1.0);
    // symmetric in the turn's direction; the inner side is chosen by the sign
    assert_eq!(skid_speed_ratio(&spec, 0.3), skid_speed_ratio(&spec, -0.3));
}

/// Drives at about `speed` with a fixed steering input for `seconds` and returns the state
/// and the vehicle centre's positions (the middle of the road-wheel span) after `settle` s.
fn drive(steering: f64, speed: f64, seconds: f64, settle: f64) -> (SimState, Vec<(f64, f64)>) {
    let spec = m113();
    let world = testing::flat_world(1.0, 0.8);
    let (sim, mut st) = common::sim_at(world, &spec, 0.0, 0.0, 0.0);
    let mid = 0.5 * (spec.axles[0].x + spec.axles[4].x);
    let mut points = Vec::new();
    let steps = (seconds / 0.01) as usize;
    for k in 0..steps {
        let u = (0.3 * (speed - st.forward_speed())).clamp(0.0, 1.0);
        sim.step(&mut st, Controls::new(u, 0.0, steering), 0.01)
            .unwrap();
        if k as f64 * 0.01 >= settle && k % 10 == 0 {
            let c = sim.point_world(&st, Vec3::new(mid, 0.0, 0.0));
            points.push((c.x, c.y));
        }
    }
    (st, points)
}

/// With no steering input the unit holds both tracks at one speed: over 30 m on flat ground
/// the heading stays within 0.5° and the path within 0.2 m of the straight line.
#[test]
fn straight_with_no_input() {
    let (st, points) = drive(0.0, 2.0, 25.0, 0.0);
    let (_, _, yaw) = st.euler();
    let (x, y) = *points.last().unwrap();
    println!(
        "straight: {x:.1} m forward, {y:.3} m aside, yaw {:.3}°",
        yaw.to_degrees()
    );
    assert!(x > 30.0, "drove only {x:.1} m");
    assert!(yaw.to_degrees().abs() < 0.5, "heading drifted {yaw}");
    assert!(y.abs() < 0.2, "drifted {y} m sideways");
}

/// Steady turns on flat ground (μ 0.8) at 1.5 m/s. Tracks held at ρ would turn on the
/// kinematic radius R = L / tan(s·25.2°) without slip, but a skid-steered vehicle must slip to
/// turn: the outer track drives and the inner brakes against the ground's lateral resistance
/// moment, and the tracks sliding sideways at both ends widen the turn (Wong, Theory of Ground
/// Vehicles, ch. 7: R' > R; held at ρ alone, this M113 turned 32–41 % wider). The steer unit
/// therefore corrects the ratio by the yaw rate's shortfall (gain 3 on the curvature's
/// error). Checked:
/// - the road wheels' spin ratio is the one the unit's law gives for the final state,
///   ρ(κ + 3 (κ − r/v)), to 1e-3 (the law reads the state at the last internal step's start)
///   at input 0.25; at 0.5 and 1 the correction asks more than the steering brake's capacity
///   (15 kN m a side) and the unit slips a little: the ratio may only be larger;
/// - at full input the road wheels slide sideways, and the lateral resistance moment about
///   the track centre is Wong's Coulomb one for firm ground, μ_t Σ N_i |x_i| (μ_t = the track's
///   lateral friction 0.55, N_i the road-wheel loads at distances x_i), within 15 %; the
///   longitudinal forces' moment balances it within 1 %;
/// - the radius is at least the kinematic one, at most 15 % wider (a proportional correction
///   of gain 3 leaves about a quarter of the open loop's 35 % widening; measured +10.1 /
///   +9.6 / +13.9 %, the last with the unit at its capacity), and shrinks with the input.
#[test]
fn turning_radius_against_the_track_speed_ratio() {
    let spec = m113();
    let mid = 0.5 * (spec.axles[0].x + spec.axles[4].x);
    let half_gauge = 0.5 * spec.axles[0].track;
    let mut last = f64::INFINITY;
    for s in [0.25, 0.5, 1.0] {
        let (st, points) = drive(s, 1.5, 40.0, 15.0);
        let delta = s * spec.steering.max_angle_deg.to_radians();
        let kinematic = spec.wheelbase() / delta.tan();
        let radius = fit_circle(&points);
        // left (inner) wheels are even-numbered
        let ratio = st.wheels()[0].spin_rate / st.wheels()[1].spin_rate;
        let kappa = delta.tan() / spec.wheelbase();
        let measured = st.angular_velocity_body().z / st.velocity_body().x;
        let corrected = kappa + 3.0 * (kappa - measured);
        let rho = {
            let kb = corrected * half_gauge;
            (1.0 - kb) / (1.0 + kb)
        };
        let (mut m_lat, mut m_long, mut m_wong) = (0.0, 0.0, 0.0);
        for (w, ws) in st.wheels().iter().enumerate() {
            let x = spec.axles[w / 2].x - mid;
            let y = if w % 2 == 0 { half_gauge } else { -half_gauge };
            m_lat -= ws.lat_force * x;
            m_long -= ws.long_force * y;
            m_wong += spec.tyre.fys * ws.normal_force * x.abs();
        }
        println!(
            "input {s}: radius {radius:.2} m, kinematic {kinematic:.2} m ({:+.1} %), spin ratio \
             {ratio:.4}, ρ {rho:.4}; resistance moment {m_lat:.0} N m (Wong's Coulomb {m_wong:.0}), \
             driving moment {m_long:.0} N m",
            100.0 * (radius / kinematic - 1.0)
        );
        // the unit holds the law's ratio, or falls short of it (a wider turn) at its brake's
        // capacity
        assert!(ratio >= rho - 1e-3, "spin ratio {ratio} vs ρ {rho}");
        if s == 0.25 {
            assert!((ratio - rho).abs() < 1e-3, "spin ratio {ratio} vs ρ {rho}");
        }
        assert!(
            (m_long - m_lat).abs() < 0.01 * m_lat.abs(),
            "moments {m_long} vs {m_lat}"
        );
        if s == 1.0 {
            assert!(
                (m_lat / m_wong - 1.0).abs() < 0.15,
                "resistance moment {m_lat:.0} N m against Wong's {m_wong:.0} N m"
            );
        }
        assert!(
            radius >= kinematic * 0.99 && radius <= kinematic * 1.15,
            "input {s}: radius {radius:.2} m against kinematic {kinematic:.2} m"
        );
        assert!(radius < last, "input {s} turned wider than a smaller one");
        last = radius;
    }
}

/// Drives the M113 (or, with `runs` false, the same vehicle with only its road wheels
/// touching anything) at 2 m/s towards a 3-m-long box rock of height `height` across its
/// path, for 25 s; returns how far the centre of mass got and the largest |pitch| \[°\].
fn drive_at_step(height: f64, runs: bool) -> (f64, f64) {
    let mut spec = m113();
    if !runs {
        spec.track.as_mut().unwrap().runs = None;
    }
    let world = testing::rock_world(1.0, 0.8, 6.0, Vec3::new(3.0, 4.0, height));
    let (sim, mut st) = common::sim_at(world, &spec, 0.0, 0.0, 0.0);
    let mut pitch: f64 = 0.0;
    for _ in 0..2500 {
        let u = (0.5 * (2.0 - st.forward_speed())).clamp(0.0, 1.0);
        sim.step(&mut st, Controls::new(u, 0.0, 0.0), 0.01).unwrap();
        pitch = pitch.max(st.euler().1.abs().to_degrees());
    }
    (st.com_position().x, pitch)
}

/// A road wheel alone climbs a step only up to about its radius (0.305 m): the edge then meets
/// it at its axle's height and pushes straight back. A track climbs higher: the run from the
/// first road wheel up to the sprocket meets the edge first, the moving track slides down
/// along it, and its friction lifts the hull and pushes it on (Wong, Theory of Ground
/// Vehicles, ch. 7: a tracked vehicle's vertical-obstacle limit is about its sprocket's
/// height). The M113's sprocket centre is 0.575 m above level ground (road wheels at
/// z −0.266 with radius 0.305; sprocket at the origin), its track's lowest point there
/// 0.254 m (radius 0.317). Checked on a 3-m-long box rock:
/// - 0.30 m (about a road wheel's radius): both versions drive over it;
/// - 0.45 m (1.5 radii): the raised ends climb it, the road wheels alone stop at its face;
/// - 0.70 m (above the sprocket's centre): neither climbs it.
///
/// (Measured limit with the raised ends: between 0.45 and 0.48 m; at 0.48 m the edge meets the
/// sprocket's arc 17° below its centre, where the rock's friction, 0.6, lifts less than the
/// hull's front weighs against what the road wheels behind can push. The real M113 is rated
/// for a 0.61-m wall.)
#[test]
fn the_raised_track_ends_climb_a_step_the_road_wheels_cannot() {
    let past = 6.0 + 3.0 + 2.0; // the rock's far face, plus the hull's centre behind its front
    for (height, with_runs, without) in [
        (0.30, true, true),
        (0.45, true, false),
        (0.70, false, false),
    ] {
        let (x_runs, pitch_runs) = drive_at_step(height, true);
        let (x_wheels, _) = drive_at_step(height, false);
        println!(
            "step {height} m: with the raised ends x {x_runs:.2} m (max pitch {pitch_runs:.1}°), \
             road wheels alone x {x_wheels:.2} m"
        );
        assert_eq!(
            x_runs > past,
            with_runs,
            "step {height} m with the raised ends: x {x_runs}"
        );
        assert_eq!(
            x_wheels > past,
            without,
            "step {height} m, road wheels alone: x {x_wheels}"
        );
    }
}

/// At rest on level ground the road wheels carry the whole vehicle: the raised ends stand
/// clear (the sprocket's track 0.25 m up, the idler's 0.14 m) and the spans between road
/// wheels lie 2 cm inside the wheels' common tangent, more than the wheels' static tyre
/// deflection (~5 mm), so no point of them touches, and the road wheels' normal forces sum
/// to the vehicle's weight within 0.1 %.
#[test]
fn at_rest_the_road_wheels_carry_the_vehicle() {
    let spec = m113();
    let world = testing::flat_world(1.0, 0.8);
    let (sim, mut st) = common::sim_at(world, &spec, 0.0, 0.0, 0.0);
    common::run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 3.0);
    let load: f64 = st.wheels().iter().map(|w| w.normal_force).sum();
    let weight = spec.total_mass() * 9.81;
    println!(
        "at rest: {} points of the raised ends touch; wheel loads {load:.0} N, weight {weight:.0} N",
        st.contacts().track_run_points
    );
    assert_eq!(st.contacts().track_run_points, 0);
    assert!((load / weight - 1.0).abs() < 1e-3, "{load} vs {weight}");
}

/// A vehicle file's rollers are checked against its road wheels, and the error names the field.
#[test]
fn bad_rollers_are_refused_by_name() {
    let text = m113().to_yaml();
    for (from, to, field) in [
        ("x: -1.9615", "x: -1.0", "track.runs.idler.x"),
        ("radius: 0.317", "radius: 0.0", "track.runs.sprocket.radius"),
        ("radius: 0.317", "radius: 2.0", "track.runs.sprocket.radius"),
    ] {
        assert!(text.contains(from), "{from} not in the M113's YAML");
        let bad = text.replacen(from, to, 1);
        let msg = VehicleSpec::from_yaml_str(&bad, "m113-edit")
            .unwrap_err()
            .to_string();
        println!("{msg}");
        assert!(msg.contains(field), "{msg}");
    }
}

/// At rest on snow the belt between the road wheels bears on it as a plate (the road wheels'
/// plates; `contact::soil` tests one plate against the closed form quasi-statically), so the
/// track sinks as Bekker's plate under the vehicle's weight: z = (p / (k_c/b + k_φ))^(1/n)
/// with p = W / (2 b L), b the track's width (0.413 m) and L the road wheels' span (2.667 m):
/// 0.274 m. The ends of the run (the outer halves of the first and last road wheels) add a
/// little area, so the track sinks a little less; within 10 %. The sinkage is the hull's drop
/// below its rest height on rigid ground plus the road wheels' tyre deflection there (the
/// deepest node under a wheel reads the heaped rim too). Before the plate the road wheels sank
/// as wheels, 0.33 m. In mud and sand (printed) the settling from the start pose leaves the
/// plates deeper than the closed form (0.042 against 0.034 m, 5 against 2.5 mm): a stiffer
/// soil's plastic memory keeps the first bounce.
#[test]
fn at_rest_the_track_sinks_as_bekkers_plate() {
    use verti_world::SoilParams;
    let spec = m113();
    let weight = spec.total_mass() * 9.81;
    let (b, span) = (spec.axles[0].wheel.width, spec.axles[0].x - spec.axles[4].x);
    let p = weight / (2.0 * b * span);
    let rest = |world| {
        let (sim, mut st) = common::sim_at(world, &spec, 0.0, 0.0, 0.0);
        common::run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 3.0);
        let deflection =
            st.wheels().iter().map(|w| w.tyre_deflection).sum::<f64>() / st.wheels().len() as f64;
        (st.com_position().z, deflection)
    };
    let (rigid_z, deflection) = rest(testing::flat_world(1.0, 0.8));
    for (name, soil) in [
        ("snow", SoilParams::SOFT),
        ("mud", SoilParams::MID),
        ("sand", SoilParams::HARD),
    ] {
        let (z, _) = rest(testing::soil_world(1.0, soil, 0.0));
        let sinkage = rigid_z - z + deflection;
        let closed = (p / (soil.bekker_kc / b + soil.bekker_kphi)).powf(1.0 / soil.bekker_n);
        println!("{name}: the track sinks {sinkage:.4} m, Bekker's plate {closed:.4} m");
        if name == "snow" {
            assert!(
                (sinkage / closed - 1.0).abs() < 0.1,
                "{name}: {sinkage} vs {closed}"
            );
        }
    }
}
