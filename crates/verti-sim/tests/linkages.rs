//! Steering linkages (rack and pinion, Pitman arm, toe bar, bellcrank) against their
//! derivation: the road-wheel angles of the Gator's and the Sedan's racks, the ARTcar's Pitman
//! arm, the UAZ's toe bar and the truck6's and truck8's rotary arms and bellcranks, from Chrono's
//! hardpoints projected on the ground plane, worked out independently of this code (a Python
//! derivation of the same four-bar closed form from the hardpoints: left and right angles for
//! inputs 0.25 to 1, to 0.01°), and the limits that follow from the geometry by hand.

use verti_sim::linkage::{bicycle_angle, wheel_angles};
use verti_sim::spec::{LinkageKind, LinkageSpec};
use verti_sim::vehicles;

fn linkage(name: &str) -> LinkageSpec {
    vehicles::builtin(name).unwrap().steering.linkage.unwrap()
}

/// (input, left °, right °) from the derivation. A `mirrored` linkage's right turn is its left
/// turn's mirror image (a toe bar's drag link drives one side only, so its locks differ).
fn check(name: &str, expected: &[(f64, f64, f64)], mirrored: bool) {
    let l = linkage(name);
    for &(u, left, right) in expected {
        let (l_deg, r_deg) = wheel_angles(&l, u)
            .map(|(a, b)| (a.to_degrees(), b.to_degrees()))
            .unwrap();
        println!("{name} input {u}: left {l_deg:.3}°, right {r_deg:.3}° (derived {left}, {right})");
        assert!(
            (l_deg - left).abs() < 0.006,
            "{name} {u}: left {l_deg} vs {left}"
        );
        assert!(
            (r_deg - right).abs() < 0.006,
            "{name} {u}: right {r_deg} vs {right}"
        );
        if mirrored {
            let (ml, mr) = wheel_angles(&l, -u).unwrap();
            assert!(
                (ml.to_degrees() + r_deg).abs() < 1e-9 && (mr.to_degrees() + l_deg).abs() < 1e-9
            );
        }
    }
}

#[test]
fn gator_rack_and_pinion() {
    check(
        "gator",
        &[
            (0.25, 10.08, 10.08),
            (0.5, 20.51, 20.46),
            (0.75, 31.81, 31.53),
            (1.0, 45.07, 43.85),
        ],
        true,
    );
    // by hand: the 0.05-m arm points straight back and the 0.27-m tie rod runs across, so
    // without the rod's angularity sin δ = travel / arm: asin(0.035 / 0.05) = 44.4° at full lock
    let (left, right) = wheel_angles(&linkage("gator"), 1.0).unwrap();
    let hand = (0.035f64 / 0.05).asin();
    assert!((left - hand).abs() < 1f64.to_radians() && (right - hand).abs() < 1f64.to_radians());
}

#[test]
fn sedan_rack_and_pinion_is_anti_ackermann() {
    check(
        "sedan",
        &[
            (0.25, 8.38, 8.49),
            (0.5, 16.78, 17.23),
            (0.75, 25.39, 26.35),
            (1.0, 34.48, 35.98),
        ],
        true,
    );
    // its arm points back and outboard of the kingpin: the outer wheel turns more than the inner
    let (inner, outer) = wheel_angles(&linkage("sedan"), 1.0).unwrap();
    assert!(outer > inner);
}

/// The UAZ's toe bar, driven on the left by a drag link: a left and a right turn differ.
#[test]
fn uaz_toe_bar() {
    check(
        "uaz",
        &[
            (0.25, 5.67, 5.51),
            (0.5, 11.38, 10.75),
            (0.75, 17.18, 15.75),
            (1.0, 23.12, 20.53),
            (-0.25, -5.67, -5.84),
            (-0.5, -11.37, -12.08),
            (-0.75, -17.15, -18.88),
            (-1.0, -23.05, -26.47),
        ],
        false,
    );
}

#[test]
fn artcar_pitman_arm() {
    check(
        "artcar",
        &[
            (0.25, 6.21, 5.93),
            (0.5, 12.77, 11.60),
            (0.75, 19.86, 16.99),
            (1.0, 27.89, 22.05),
        ],
        true,
    );
}

// The truck6's rotary arm and bellcrank (Chrono's MAN 7t): the derivation's angles, and the
// same chain solved another way, as three sets of distance constraints by bisection (the drag
// link's, then each tie rod's length kept), to 1e-9 rad.
#[test]
fn truck6_rotary_arm_and_bellcrank() {
    check(
        "truck6",
        &[
            (0.25, 9.65, 9.15),
            (0.5, 20.41, 18.20),
            (0.75, 32.42, 26.79),
            (1.0, 46.34, 34.38),
            (-0.25, -8.62, -9.07),
            (-0.5, -16.30, -18.03),
            (-0.75, -23.10, -26.97),
            (-1.0, -29.10, -36.16),
        ],
        false,
    );
    let l = linkage("truck6");
    bellcrank_by_bisection(&l);
    // the locks differ: the bicycle angle is 39.6° turning left, 32.3° turning right, and the
    // vehicle file's 35.96° is their mean
    let (l1, r1) = wheel_angles(&l, 1.0).unwrap();
    let (l2, r2) = wheel_angles(&l, -1.0).unwrap();
    assert!((bicycle_angle(l1, r1).to_degrees() - 39.62).abs() < 0.01);
    assert!((-bicycle_angle(l2, r2).to_degrees() - 32.29).abs() < 0.01);
}

/// A bellcrank linkage's wheel angles against the geometry solved numerically: at inputs −1 to
/// 1, the rotary arm's end turned about its pivot, the bellcrank's angle that keeps the drag
/// link's length and each knuckle's angle that keeps its tie rod's, found by bisection,
/// within 1e-9 rad of the closed form.
fn bellcrank_by_bisection(l: &LinkageSpec) {
    let rot = |p: [f64; 2], c: [f64; 2], a: f64| {
        let (s, co) = a.sin_cos();
        let (x, y) = (p[0] - c[0], p[1] - c[1]);
        [c[0] + co * x - s * y, c[1] + s * x + co * y]
    };
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    // the angle in [-1.2, 1.2] rad at which `gap` (a length minus its rest value, monotonic
    // over the linkage's range) vanishes
    let solve = |gap: &dyn Fn(f64) -> f64| {
        let (mut lo, mut hi) = (-1.2, 1.2);
        let rising = gap(hi) > gap(lo);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (gap(mid) > 0.0) == rising {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let (pivot, crank0, end0) = (
        l.drag_kingpin.unwrap(),
        l.drag_arm.unwrap(),
        l.drag_link_end.unwrap(),
    );
    let inner0 = l.tie_rod_inner.unwrap();
    let mirror = |p: [f64; 2]| [p[0], -p[1]];
    for k in -4..=4 {
        let u = f64::from(k) / 4.0;
        let end = rot(
            end0,
            l.arm_pivot.unwrap(),
            -u * l.arm_max_angle_deg.to_radians(),
        );
        let drag = dist(end0, crank0);
        let crank = solve(&|phi| dist(end, rot(crank0, pivot, phi)) - drag);
        let side = |kingpin: [f64; 2], arm: [f64; 2], inner: [f64; 2]| {
            let moved = rot(inner, pivot, crank);
            let rod = dist(arm, inner);
            solve(&|delta| dist(rot(arm, kingpin, delta), moved) - rod)
        };
        let left = side(l.kingpin, l.steering_arm, inner0);
        let right = side(mirror(l.kingpin), mirror(l.steering_arm), mirror(inner0));
        let (wl, wr) = wheel_angles(l, u).unwrap();
        assert!(
            (wl - left).abs() < 1e-9 && (wr - right).abs() < 1e-9,
            "input {u}: {wl} {wr} vs {left} {right}"
        );
    }
}

// The truck8's two rotary arms and bellcranks (Chrono's MAN 10t: the MAN 7t's mechanism on
// each steered axle, the second arm turning 28.37° where the first turns 39°, and each axle's
// own knuckle joint): each against its geometry solved numerically, and the two axles' turn
// centres at full lock against ideal Ackermann geometry about the rear bogie's centre line.
#[test]
fn truck8_two_rotary_arms_and_bellcranks() {
    let spec = vehicles::builtin("truck8").unwrap();
    let first = spec.steering.linkage.unwrap();
    let second = spec.axles[1].linkage.unwrap();
    bellcrank_by_bisection(&first);
    bellcrank_by_bisection(&second);
    // ideal: both axles' centre lines point at one turn centre on the rear bogie's line,
    // tan δ2 / tan δ1 = (x2 − x_rear) / (x1 − x_rear)
    let x_rear = 0.5 * (spec.axles[2].x + spec.axles[3].x);
    let ideal = (spec.axles[1].x - x_rear) / (spec.axles[0].x - x_rear);
    let mut mean = 0.0;
    for u in [1.0, -1.0] {
        let (l1, r1) = wheel_angles(&first, u).unwrap();
        let (l2, r2) = wheel_angles(&second, u).unwrap();
        let (b1, b2) = (bicycle_angle(l1, r1), bicycle_angle(l2, r2));
        let ratio = b2.tan() / b1.tan();
        println!(
            "truck8 input {u}: first axle {:.2}° / {:.2}° (bicycle {:.2}°), second {:.2}° / \
             {:.2}° (bicycle {:.2}°); tan ratio {ratio:.4} against Ackermann's {ideal:.4}",
            l1.to_degrees(),
            r1.to_degrees(),
            b1.to_degrees(),
            l2.to_degrees(),
            r2.to_degrees(),
            b2.to_degrees()
        );
        assert!((ratio / ideal - 1.0).abs() < 0.06, "{ratio} vs {ideal}");
        mean += 0.5 * ratio;
    }
    // turning left the second axle turns 2 % short of Ackermann's, turning right 5 % past:
    // on average within 1.5 %
    assert!((mean / ideal - 1.0).abs() < 0.02, "{mean} vs {ideal}");
}

/// With the arms straight back and the tie rods across (parallel steer) both wheels turn alike
/// while the rods' angularity is small, as sin δ = travel / arm by hand; and the bicycle angle
/// of two different wheel angles lies between them.
#[test]
fn parallel_steer_by_hand() {
    let arm = 0.15f64;
    let l = LinkageSpec {
        kind: LinkageKind::RackAndPinion,
        kingpin: [0.0, 0.75],
        steering_arm: [-arm, 0.75],
        tie_rod_inner: Some([-arm, 0.3]),
        drag_arm: None,
        drag_link_end: None,
        drag_kingpin: None,
        rack_travel: 0.05,
        arm_length: 0.0,
        arm_max_angle_deg: 0.0,
        arm_pivot: None,
    };
    let (a, b) = wheel_angles(&l, 0.2).unwrap();
    let hand = (0.2f64 * 0.05 / arm).asin();
    println!(
        "parallel steer at 0.2: {:.3}° and {:.3}°, by hand {:.3}°",
        a.to_degrees(),
        b.to_degrees(),
        hand.to_degrees()
    );
    assert!((a - b).abs() < 0.02 * a, "parallel steer: {a} vs {b}");
    assert!((a - hand).abs() < 0.02 * hand && (b - hand).abs() < 0.02 * hand);
    let (inner, outer) = wheel_angles(&linkage("artcar"), 1.0).unwrap();
    let c = bicycle_angle(inner, outer);
    assert!(c < inner && c > outer);
}

/// The engine turns the wheels by the linkage's angles: after the steering has slewed to an
/// input, each steered wheel's angle is the closed form's within 1e-5 rad (the engine
/// interpolates a table of 400 intervals, see `Model::linkage_tables`).
#[test]
fn the_engine_steers_by_the_linkage() {
    for name in ["gator", "sedan", "uaz", "artcar", "truck8"] {
        let spec = vehicles::builtin(name).unwrap();
        let l = spec.steering.linkage.unwrap();
        let world = verti_sim::testing::flat_world(spec.scale, 0.8);
        let world = std::sync::Arc::new(world);
        let sim = verti_sim::Sim::new(&world, &spec).unwrap();
        for u in [-0.83, -0.3, 0.123, 0.6, 1.0] {
            let mut st = sim
                .state_at(verti_sim::StartPose::new(0.0, 0.0, 0.0))
                .unwrap();
            for _ in 0..200 {
                sim.step(&mut st, verti_sim::Controls::new(0.0, 1.0, u), 0.01)
                    .unwrap();
            }
            // each steered axle by its own linkage (the truck8's second axle: wheels 2, 3)
            let mut axles = vec![(0, l)];
            if let Some(second) = spec.axles[1].linkage {
                axles.push((2, second));
            }
            for (w, l) in axles {
                let (left, right) = wheel_angles(&l, u).unwrap();
                let (a, b) = (st.wheels()[w].steer_angle, st.wheels()[w + 1].steer_angle);
                assert!(
                    (a - left).abs() < 1e-5 && (b - right).abs() < 1e-5,
                    "{name} at {u}, wheels {w}, {}: engine {a} / {b}, linkage {left} / {right}",
                    w + 1
                );
            }
        }
    }
}

/// With linkage steering every steered axle after the first gives its own linkage, and no other
/// axle does; the error names the axle's field.
#[test]
fn per_axle_linkages_are_checked_by_name() {
    let spec = vehicles::builtin("truck8").unwrap();
    let mut missing = spec.clone();
    missing.axles[1].linkage = None;
    let mut extra = spec.clone();
    extra.axles[2].linkage = spec.axles[1].linkage;
    let mut bad_point = spec.clone();
    bad_point.axles[1].linkage.as_mut().unwrap().steering_arm = [-0.2, -0.8];
    for (edited, field) in [
        (missing, "axles[1].linkage"),
        (extra, "axles[2].linkage"),
        (bad_point, "axles[1].linkage.steering_arm"),
    ] {
        let text = edited.to_yaml();
        let msg = verti_sim::VehicleSpec::from_yaml_str(&text, "truck8-edit")
            .unwrap_err()
            .to_string();
        println!("{msg}");
        assert!(msg.contains(&format!("field `{field}`")), "{msg}");
    }
}
