//! How a wheel's plane tilts with its suspension: an independent linkage's camber change, and
//! a beam axle's wheels square to the beam (`AxleSpec::camber_gain_deg_per_m`,
//! `AxleSpec::solid_axle`), against the geometry they come from.
//!
//! Tilt is measured as the rotation of the wheel's spin axis about the chassis' x axis,
//! asin(axle · up) for an unsteered wheel (positive lifts the axle's left end). A camber change
//! γ = gain·(s − s_rest) (negative: a rising wheel's top tips inwards) is a tilt of −γ on the
//! left and +γ on the right.

use verti_core::Vec3;
use verti_sim::{Controls, Sim, SimState, testing, vehicles};

mod common;
use common::run;

/// Each wheel's tilt relative to the chassis \[rad\] and its travel \[m\].
fn tilts(sim: &Sim, st: &SimState) -> Vec<(f64, f64)> {
    let up = st.orientation().rotate(Vec3::Z);
    sim.wheel_axles(st)
        .iter()
        .zip(st.wheels())
        .map(|(a, w)| (a.dot(up).asin(), w.compression))
        .collect()
}

fn parked(name: &str, cross_slope_deg: f64) -> (Sim, SimState) {
    let spec = vehicles::builtin(name).unwrap();
    let world = testing::plane_world(spec.scale, 0.0, cross_slope_deg.to_radians(), 0.9);
    let (sim, mut st) = common::sim_at(world, &spec, 0.0, 0.0, 0.0);
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 4.0);
    (sim, st)
}

#[test]
fn an_independent_wheel_cambers_at_its_linkages_gain() {
    for name in ["sedan", "artcar", "gator"] {
        let spec = vehicles::builtin(name).unwrap();
        // at rest on level ground every wheel is square to the chassis
        let (sim, st) = parked(name, 0.0);
        let rest = tilts(&sim, &st);
        for (w, (tilt, _)) in rest.iter().enumerate() {
            assert!(
                tilt.to_degrees().abs() < 0.05,
                "{name} wheel {w}: {:.3}° at rest",
                tilt.to_degrees()
            );
        }
        // across a 12° slope the downhill (right) wheels rise into the body and the uphill ones
        // drop: each tilts by its gain times its travel from rest
        let (sim, st) = parked(name, 12.0);
        let mut leaned = 0;
        for (w, &(tilt, s)) in tilts(&sim, &st).iter().enumerate() {
            let ax = &spec.axles[w / 2];
            let side = if w % 2 == 0 { 1.0 } else { -1.0 };
            let travel = s - rest[w].1;
            let camber = ax.camber_gain_deg_per_m.unwrap_or(0.0).to_radians() * travel;
            println!(
                "{name} wheel {w}: travel {:+.1} mm, tilt {:+.3}°, derived {:+.3}°",
                travel * 1e3,
                tilt.to_degrees(),
                (-side * camber).to_degrees()
            );
            // the rest compression of the model and of the settled vehicle differ by the
            // settling's residue: 0.05° at most
            assert!(
                (tilt - (-side * camber)).to_degrees().abs() < 0.05,
                "{name} wheel {w}: {:.3}° against {:.3}°",
                tilt.to_degrees(),
                (-side * camber).to_degrees()
            );
            if camber.to_degrees().abs() > 0.01 {
                leaned += 1;
                // a negative gain: the rising downhill wheel's top tips inwards, uphill, so
                // its spin axis (pointing left, uphill) turns down, and the uphill one's up
                if ax.camber_gain_deg_per_m.unwrap() < 0.0 {
                    assert_eq!(tilt.signum(), side * travel.signum(), "{name} wheel {w}");
                }
            }
        }
        assert!(leaned >= 2, "{name}: the slope hardly moved the wheels");
    }
}

#[test]
fn a_wheel_without_a_linkage_stays_square_to_the_chassis() {
    let (sim, st) = parked("hmmwv", 12.0);
    for (w, (tilt, s)) in tilts(&sim, &st).iter().enumerate() {
        assert!(
            tilt.abs() < 1e-12,
            "hmmwv wheel {w}: {tilt} rad at travel {s}"
        );
    }
}

/// A beam axle's wheels are its ends: both spin axes lie along the line between the two hubs,
/// so on twisted ground they follow the ground under the axle, not the body.
#[test]
fn a_beam_axles_wheels_stay_square_to_the_beam() {
    let spec = vehicles::builtin("uaz").unwrap();
    let deg_per_m = 2.0;
    let x_rear = 0.5;
    let world = testing::twisting_slope_world(1.0, 0.0, deg_per_m, 0.9);
    let (sim, mut st) = common::sim_at(world, &spec, x_rear - spec.axles[1].x, 0.0, 0.0);
    run(&sim, &mut st, Controls::new(0.0, 1.0, 0.0), 4.0);
    let axles = sim.wheel_axles(&st);
    let hubs = sim.wheel_centers(&st);
    let (chassis_roll, _, _) = st.euler();
    for k in 0..spec.axles.len() {
        let (l, r) = (2 * k, 2 * k + 1);
        let beam = (hubs[l] - hubs[r]).normalized();
        assert!(
            (axles[l] - axles[r]).norm() < 1e-12,
            "axle {k}: the two wheels differ"
        );
        assert!(
            axles[l].cross(beam).norm() < 1e-9,
            "axle {k}: wheel axis {:?} off the beam {beam:?}",
            axles[l]
        );
        let travel_difference = st.wheels()[l].compression - st.wheels()[r].compression;
        // the ground's cross slope under the axle, and how far the body and the wheels are
        // from it
        let ground = (deg_per_m * hubs[l].x).to_radians();
        let wheels = axles[l].z.asin();
        println!(
            "axle {k}: articulation {:+.1} mm, ground {:.2}°, wheels {:.2}°, body {:.2}°",
            travel_difference * 1e3,
            ground.to_degrees(),
            wheels.to_degrees(),
            chassis_roll.to_degrees()
        );
        assert!(
            travel_difference.abs() > 0.005,
            "axle {k} did not articulate"
        );
        assert!(
            (wheels - ground).abs() < (chassis_roll - ground).abs(),
            "axle {k}: the wheels should follow the ground more closely than the body"
        );
    }
}

#[test]
fn vehicle_files_check_the_camber_gain() {
    let check = |name: &str, edit: &dyn Fn(&mut verti_sim::spec::VehicleSpec), want: &str| {
        let mut spec = vehicles::builtin(name).unwrap();
        edit(&mut spec);
        let err = spec.validate("test.yaml").unwrap_err().to_string();
        assert!(
            err.contains("axles[0].camber_gain_deg_per_m") && err.contains(want),
            "{err}"
        );
    };
    check(
        "sedan",
        &|s| s.axles[0].camber_gain_deg_per_m = Some(f64::INFINITY),
        "finite",
    );
    // a swing arm shorter than the wheel
    check(
        "sedan",
        &|s| s.axles[0].camber_gain_deg_per_m = Some(-400.0),
        "shorter than the wheel's radius",
    );
    // a beam axle's wheels tilt with the beam
    check(
        "uaz",
        &|s| s.axles[0].camber_gain_deg_per_m = Some(-10.0),
        "solid axle",
    );
    // a wheel wider than its track (a tilted one of 1e308 m once overflowed the contact)
    let mut spec = vehicles::builtin("artcar").unwrap();
    spec.axles[1].wheel.width = 1e308;
    let err = spec.validate("test.yaml").unwrap_err().to_string();
    assert!(
        err.contains("axles[1].wheel.width") && err.contains("wider than the track"),
        "{err}"
    );
    // absent, it is not written: files of older vehicles read and write as before
    assert!(
        !vehicles::builtin("hmmwv")
            .unwrap()
            .to_yaml()
            .contains("camber")
    );
    assert!(
        vehicles::builtin("sedan")
            .unwrap()
            .to_yaml()
            .contains("camber_gain_deg_per_m: -19.3")
    );
}
