//! The HMMWV on slopes of soil, against what statics and Mohr–Coulomb allow: no soil lets it
//! climb steeper than its friction angle (plus the little its cohesion adds), it climbs well
//! below it, and parked across a slope its downhill wheels carry the load the moment balance
//! gives and sink as Bekker's law says they must under it.

mod common;

use common::{G, run, sim_at};
use verti_sim::testing::{soil_patch, world_from_fn};
use verti_sim::{Controls, vehicles};
use verti_world::SoilParams;

const SOILS: [(&str, SoilParams); 3] = [
    ("snow", SoilParams::SOFT),
    ("mud", SoilParams::MID),
    ("sand", SoilParams::HARD),
];

/// Metres gained along +x (uphill) in `seconds` at full throttle, starting at rest on a plane
/// of `soil` rising at `deg` degrees.
fn climb(soil: SoilParams, deg: f64, seconds: f64) -> f64 {
    let spec = vehicles::builtin("hmmwv").unwrap();
    let world = verti_sim::testing::soil_world(1.0, soil, deg.to_radians());
    let (sim, mut st) = sim_at(world, &spec, -20.0, 0.0, 0.0);
    let x0 = st.com_position().x;
    run(&sim, &mut st, Controls::new(1.0, 0.0, 0.0), seconds);
    st.com_position().x - x0
}

/// The steepest slope Mohr–Coulomb lets a vehicle of weight W hold with all four wheels
/// pulling: W·sin θ = W·cos θ·tan φ + c·A, with A about 0.35 m² under the HMMWV's four
/// tyres (each 0.254 m wide, a patch under 0.4 m long at these sinkages).
fn mohr_coulomb_limit_deg(soil: &SoilParams, weight: f64) -> f64 {
    let tan_phi = soil.friction_angle_deg.to_radians().tan();
    let cohesion_share = soil.cohesion * 0.35 / weight;
    // sin θ − tan φ·cos θ = c·A/W; with θ = φ + ε this is sin ε / cos φ = c·A/W
    let phi = tan_phi.atan();
    (phi + (cohesion_share * phi.cos()).asin()).to_degrees()
}

#[test]
fn no_soil_lets_the_hmmwv_climb_past_its_friction_angle() {
    let weight = vehicles::builtin("hmmwv").unwrap().total_mass() * G;
    for (name, soil) in SOILS {
        let limit = mohr_coulomb_limit_deg(&soil, weight);
        let gained = climb(soil, limit + 3.0, 12.0);
        println!(
            "{name}: limit {limit:.1} deg, {:.1} deg: {gained:.2} m",
            limit + 3.0
        );
        assert!(
            gained < 1.0,
            "{name}: {gained:.2} m gained on a slope 3 deg past its Mohr–Coulomb limit {limit:.1} deg"
        );
    }
}

#[test]
fn the_hmmwv_climbs_soil_well_below_its_friction_angle() {
    let weight = vehicles::builtin("hmmwv").unwrap().total_mass() * G;
    for (name, soil) in SOILS {
        let limit = mohr_coulomb_limit_deg(&soil, weight);
        let gained = climb(soil, limit - 8.0, 12.0);
        println!("{name}: {:.1} deg: {gained:.2} m", limit - 8.0);
        assert!(
            gained > 10.0,
            "{name}: only {gained:.2} m up {:.1} deg",
            limit - 8.0
        );
    }
}

/// What a braked HMMWV heading +x across `soil` whose ground falls at `deg` towards −y (its
/// right side) settles to in 6 s: normal forces of the downhill and uphill pairs, the mean
/// sinkage of each pair, and how far the chassis moved.
struct Parked {
    loads: [f64; 2],
    sinkage: [f64; 2],
    moved: f64,
}

fn parked_across(soil: SoilParams, deg: f64) -> Parked {
    let spec = vehicles::builtin("hmmwv").unwrap();
    let t = deg.to_radians().tan();
    let world = world_from_fn(
        "side",
        1.0,
        move |_, y| t * y,
        vec![soil_patch(soil); 256],
        Vec::new(),
    );
    let (sim, mut st) = sim_at(world, &spec, 0.0, 0.0, 0.0);
    // settle first (the start seats the vehicle on the undeformed surface), then watch it
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 3.0);
    let p0 = st.com_position();
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 6.0);
    let w = st.wheels();
    // wheel order: front left, front right, rear left, rear right
    Parked {
        loads: [
            w[1].normal_force + w[3].normal_force,
            w[0].normal_force + w[2].normal_force,
        ],
        sinkage: [
            0.5 * (w[1].sinkage + w[3].sinkage),
            0.5 * (w[0].sinkage + w[2].sinkage),
        ],
        moved: (st.com_position() - p0).norm(),
    }
}

#[test]
fn parked_across_a_soil_slope_the_downhill_wheels_carry_and_sink_more() {
    let spec = vehicles::builtin("hmmwv").unwrap();
    let weight = spec.total_mass() * G;
    let track = spec.axles[0].track;
    let half_tread = 0.5 * spec.axles[0].wheel.width;
    // the total COM's height above the ground: the chassis' (at rest on rigid flat ground) and
    // the unsprung masses' at the hubs, a rigid tyre's radius up
    let (sim, mut st) = sim_at(
        verti_sim::testing::flat_world(1.0, 0.8),
        &spec,
        0.0,
        0.0,
        0.0,
    );
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 3.0);
    let unsprung: f64 = spec.axles.iter().map(|a| 2.0 * a.wheel.unsprung_mass).sum();
    let radius = spec.axles[0].wheel.radius;
    let h = (spec.chassis.mass * st.com_position().z + unsprung * radius) / spec.total_mass();
    for (name, soil) in SOILS {
        let deg: f64 = 15.0;
        let (s, c) = deg.to_radians().sin_cos();
        let p = parked_across(soil, deg);
        let [down, up] = p.loads;
        println!(
            "{name}: loads {down:.0} / {up:.0}, sinkage {:.3} / {:.3}, moved {:.3} m",
            p.sinkage[0], p.sinkage[1], p.moved
        );
        // statics across the slope: the loads carry the weight's normal component ...
        assert!(
            ((down + up) / (weight * c) - 1.0).abs() < 0.015,
            "{name}: {:.0} N against W cos θ = {:.0} N",
            down + up,
            weight * c
        );
        // ... and their difference balances the downhill pull's moment about the COM, with
        // each wheel's contact somewhere across its tread (soil spreads it; the pull acts at
        // the sunken contact, up to the deeper sinkage further below the COM)
        let depth = p.sinkage[0].max(p.sinkage[1]);
        let lo = 2.0 * weight * (h * s - half_tread * c) / track;
        let hi = 2.0 * weight * ((h + depth) * s + half_tread * c) / track;
        assert!(
            (lo..=hi).contains(&(down - up)),
            "{name}: downhill pair carries {:.0} N more, statics allow {lo:.0}..{hi:.0}",
            down - up
        );
        // Bekker: a more loaded wheel sinks deeper; parked, nothing slides at 15° of 30°
        assert!(p.sinkage[0] > p.sinkage[1], "{name}: {:?}", p.sinkage);
        assert!(
            p.moved < 0.05,
            "{name}: the parked vehicle moved {:.3} m",
            p.moved
        );
    }
}
