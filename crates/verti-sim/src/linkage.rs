//! Steering linkages: the two road-wheel angles a rack and pinion, a Pitman arm, a toe bar or a
//! bellcrank gives for a steering input, from the linkage's points in the ground plane.
//!
//! Each side is a four-bar "crank": the knuckle turns about its kingpin K, its steering arm
//! ends at T (the tie rod's outer joint), and a tie rod of fixed length joins T to a point C on
//! the rack or the centre link. The driver moves C (a rack translates across the vehicle; a
//! Pitman arm and its idler swing the centre link on a parallelogram), and the knuckle's
//! rotation follows in closed form: with D = C − K, ρ = |D|, arm length r and rod length l,
//! the arm's new direction is atan2(D) ± acos((r² + ρ² − l²) / (2 r ρ)), the branch the one
//! the linkage is assembled in. A toe bar chains two cranks: the drag link turns the left
//! knuckle, and the toe bar between the steering arms turns the right one. A bellcrank chains
//! three: the rotary arm moves the drag link, which turns the bellcrank (a crank about its
//! pivot), which moves both tie rods' inner joints. Left and right
//! sides are mirror images (a toe bar's drive is not, so its locks differ), and the two wheels turn by
//! different angles: the linkage's Ackermann error, which ideal Ackermann geometry
//! (cot δ_o − cot δ_i = d / L) would not have. Kingpin inclination, caster and the suspension's
//! travel are neglected (within 0.1–0.3° of Chrono's full three-dimensional joints for the
//! Gator and the Sedan, 0.7° for the ARTcar, up to 2° for the HMMWV's tilted steering box).

use serde::{Deserialize, Serialize};

/// The mechanism that moves the tie rods' inner joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LinkageKind {
    /// A rack across the vehicle, moved by `rack_travel` at full input (to the right for a
    /// left turn, the tie rods behind the kingpins).
    RackAndPinion,
    /// A Pitman arm of `arm_length` along +x, turned by `arm_max_angle_deg` at full input, and
    /// an idler arm like it: the centre link they carry keeps its direction (a parallelogram).
    PitmanArm,
    /// A solid axle's knuckles tied by a toe bar between their steering arms, the left knuckle
    /// turned by a drag link from a rotary arm: the arm hangs `arm_length` down from a pivot
    /// across the vehicle and turns by `arm_max_angle_deg` at full input, moving the drag
    /// link's end forward for a left turn. Left and right locks differ.
    ToeBar,
    /// A rotary arm turning about a vertical axis at `arm_pivot` by `arm_max_angle_deg` at
    /// full input (clockwise seen from above for a left turn) pulls a drag link that turns a
    /// bellcrank about `drag_kingpin` on the axle; the bellcrank carries both tie rods' inner
    /// joints. Left and right locks differ (the drag link's angle changes as it swings).
    Bellcrank,
}

/// A steering linkage in the ground plane, by its points on the left side (the right side is
/// its mirror image), in the vehicle's reference frame \[m\]: x forward, y left.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkageSpec {
    pub kind: LinkageKind,
    /// Where the kingpin (steering axis) meets the plane of the tie rods.
    pub kingpin: [f64; 2],
    /// The steering arm's end on the knuckle (the tie rod's or toe bar's joint), wheels
    /// straight.
    pub steering_arm: [f64; 2],
    /// Rack and pinion, Pitman arm: the tie rod's inner joint on the rack or centre link,
    /// wheels straight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tie_rod_inner: Option<[f64; 2]>,
    /// Toe bar: the drag link's joint on the left knuckle, its other end on the rotary arm
    /// (wheels straight), and the kingpin at the drag link's height. Bellcrank: the drag
    /// link's joint on the bellcrank, its other end on the rotary arm, and the bellcrank's
    /// pivot (these two may lie anywhere, not only on the left).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag_arm: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag_link_end: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag_kingpin: Option<[f64; 2]>,
    /// Rack and pinion: the rack's travel at full input \[m\].
    #[serde(default)]
    pub rack_travel: f64,
    /// Pitman arm: its length \[m\] and its rotation at full input \[deg\].
    #[serde(default)]
    pub arm_length: f64,
    #[serde(default)]
    pub arm_max_angle_deg: f64,
    /// Bellcrank: the rotary arm's pivot (its vertical axis); its length is the distance to
    /// `drag_link_end`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_pivot: Option<[f64; 2]>,
}

/// Planar point \[m\]: x forward, y left.
type P2 = [f64; 2];

/// The knuckle's rotation \[rad, positive = toward the left\] when the tie rod's inner joint
/// moves from `inner0` to `inner`, the arm ending at `arm0` when the knuckle is straight; `None`
/// where the linkage cannot close (the rod is too short or too long to reach).
fn knuckle_rotation(kingpin: P2, arm0: P2, inner0: P2, inner: P2) -> Option<f64> {
    let a0 = [arm0[0] - kingpin[0], arm0[1] - kingpin[1]];
    let d0 = [inner0[0] - kingpin[0], inner0[1] - kingpin[1]];
    let d = [inner[0] - kingpin[0], inner[1] - kingpin[1]];
    let r = a0[0].hypot(a0[1]);
    let rod = (arm0[0] - inner0[0]).hypot(arm0[1] - inner0[1]);
    let rho = d[0].hypot(d[1]);
    // the branch the linkage is assembled in: which side of K→C the arm lies on
    let branch = if d0[0] * a0[1] - d0[1] * a0[0] >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let cos_gamma = (r * r + rho * rho - rod * rod) / (2.0 * r * rho);
    if cos_gamma.is_nan() || cos_gamma.abs() > 1.0 {
        return None;
    }
    let phi = libm::atan2(d[1], d[0]) + branch * libm::acos(cos_gamma) - libm::atan2(a0[1], a0[0]);
    Some(libm::atan2(libm::sin(phi), libm::cos(phi)))
}

/// How far the tie rods' inner joints move \[m\] (x, y) for input `u` in \[−1, 1\] (positive =
/// left turn): a rack moves to the right by `u` times its travel; a Pitman arm of length a
/// along +x, turned by −u·θ_max, carries the centre link by (a(cos θ − 1), −a sin θ).
fn inner_joint_shift(l: &LinkageSpec, u: f64) -> P2 {
    match l.kind {
        LinkageKind::RackAndPinion => [0.0, -u * l.rack_travel],
        LinkageKind::PitmanArm => {
            let theta = u * l.arm_max_angle_deg.to_radians();
            [
                l.arm_length * (libm::cos(theta) - 1.0),
                -l.arm_length * libm::sin(theta),
            ]
        }
        LinkageKind::ToeBar | LinkageKind::Bellcrank => [0.0, 0.0],
    }
}

/// `p` turned by `angle` about `centre`.
fn rotate(p: P2, centre: P2, angle: f64) -> P2 {
    let (s, c) = (libm::sin(angle), libm::cos(angle));
    let (x, y) = (p[0] - centre[0], p[1] - centre[1]);
    [centre[0] + c * x - s * y, centre[1] + s * x + c * y]
}

/// The left and right road-wheel angles \[rad, positive = toward the left\] for input `u` in
/// \[−1, 1\]; `None` where the linkage cannot close.
pub fn wheel_angles(l: &LinkageSpec, u: f64) -> Option<(f64, f64)> {
    let mirror = |p: P2| [p[0], -p[1]];
    if l.kind == LinkageKind::ToeBar {
        // the rotary arm hangs down: its end, and the drag link's, moves forward by a·sin θ;
        // the drag link turns the left knuckle, whose toe-bar arm then turns the right one
        let (drag_arm, drag_end, drag_kingpin) = (l.drag_arm?, l.drag_link_end?, l.drag_kingpin?);
        let theta = u * l.arm_max_angle_deg.to_radians();
        let moved = [drag_end[0] + l.arm_length * libm::sin(theta), drag_end[1]];
        let left = knuckle_rotation(drag_kingpin, drag_arm, drag_end, moved)?;
        let toe_left = rotate(l.steering_arm, l.kingpin, left);
        let right = knuckle_rotation(
            mirror(l.kingpin),
            mirror(l.steering_arm),
            l.steering_arm,
            toe_left,
        )?;
        return Some((left, right));
    }
    if l.kind == LinkageKind::Bellcrank {
        // the rotary arm turns its end about its vertical axis; the drag link, a crank of its
        // own, turns the bellcrank; the bellcrank carries both tie rods' inner joints
        let (crank_arm, drag_end, pivot) = (l.drag_arm?, l.drag_link_end?, l.drag_kingpin?);
        let arm_end = rotate(
            drag_end,
            l.arm_pivot?,
            -u * l.arm_max_angle_deg.to_radians(),
        );
        let crank = knuckle_rotation(pivot, crank_arm, drag_end, arm_end)?;
        let inner_left = l.tie_rod_inner?;
        let inner_right = mirror(inner_left);
        let left = knuckle_rotation(
            l.kingpin,
            l.steering_arm,
            inner_left,
            rotate(inner_left, pivot, crank),
        )?;
        let right = knuckle_rotation(
            mirror(l.kingpin),
            mirror(l.steering_arm),
            inner_right,
            rotate(inner_right, pivot, crank),
        )?;
        return Some((left, right));
    }
    let tie_rod_inner = l.tie_rod_inner?;
    let shift = inner_joint_shift(l, u);
    let left = knuckle_rotation(
        l.kingpin,
        l.steering_arm,
        tie_rod_inner,
        [tie_rod_inner[0] + shift[0], tie_rod_inner[1] + shift[1]],
    )?;
    let inner_right = mirror(tie_rod_inner);
    let right = knuckle_rotation(
        mirror(l.kingpin),
        mirror(l.steering_arm),
        inner_right,
        [inner_right[0] + shift[0], inner_right[1] + shift[1]],
    )?;
    Some((left, right))
}

/// The linkage's bicycle angle at full input \[rad\]: the mean of a full left and a full
/// right turn's (they differ where the linkage is not symmetric, as a toe bar's drag link is).
pub fn full_lock_bicycle_angle(l: &LinkageSpec) -> f64 {
    let (l1, r1) = wheel_angles(l, 1.0).unwrap_or_default();
    let (l2, r2) = wheel_angles(l, -1.0).unwrap_or_default();
    0.5 * (bicycle_angle(l1, r1) - bicycle_angle(l2, r2))
}

/// The bicycle angle \[rad\] equivalent to two road-wheel angles: the mean of their
/// cotangents, cot δ_c = (cot δ_l + cot δ_r) / 2 (the centre of the two wheels' turn circles;
/// exact for ideal Ackermann geometry).
pub fn bicycle_angle(left: f64, right: f64) -> f64 {
    if left == 0.0 || right == 0.0 {
        return 0.0;
    }
    let (tl, tr) = (libm::tan(left), libm::tan(right));
    libm::atan(2.0 * tl * tr / (tl + tr))
}

/// Why a linkage cannot serve as steering, if it cannot: it must close over the whole input
/// range and turn both wheels one way, further the more the input.
pub(crate) fn check(l: &LinkageSpec) -> Result<(), String> {
    let mut last = (-f64::INFINITY, -f64::INFINITY);
    for k in -100..=100 {
        let u = f64::from(k) / 100.0;
        let Some((left, right)) = wheel_angles(l, u) else {
            return Err(format!(
                "the linkage cannot close at steering input {u:.2} (a tie rod is too short or too \
                 long for the arm to reach)"
            ));
        };
        if left <= last.0 || right <= last.1 {
            return Err(format!(
                "the road-wheel angles do not grow with the input at {u:.2}: check the points' \
                 sides (left side, y > 0) and the sign of the travel"
            ));
        }
        last = (left, right);
    }
    Ok(())
}

/// Checks one linkage block of a vehicle file, named `field` in errors (`steering.linkage`,
/// `axles[1].linkage`): the points its kind needs are given and finite, the mirrored ones on
/// the left, none it does not use; its travel or arm is positive; it closes over the whole
/// input range. Returns the bad field and why.
pub(crate) fn validate(l: &LinkageSpec, field: &str) -> Result<(), (String, String)> {
    let needed: &[&str] = match l.kind {
        LinkageKind::RackAndPinion | LinkageKind::PitmanArm => &["tie_rod_inner"],
        LinkageKind::ToeBar => &["drag_arm", "drag_link_end", "drag_kingpin"],
        LinkageKind::Bellcrank => &[
            "tie_rod_inner",
            "drag_arm",
            "drag_link_end",
            "drag_kingpin",
            "arm_pivot",
        ],
    };
    // points a mirror image is taken of lie on the left; a bellcrank's drive may not
    let anywhere: &[&str] = match l.kind {
        LinkageKind::Bellcrank => &["drag_link_end", "drag_kingpin", "arm_pivot"],
        _ => &[],
    };
    let points = [
        ("kingpin", Some(l.kingpin)),
        ("steering_arm", Some(l.steering_arm)),
        ("tie_rod_inner", l.tie_rod_inner),
        ("drag_arm", l.drag_arm),
        ("drag_link_end", l.drag_link_end),
        ("drag_kingpin", l.drag_kingpin),
        ("arm_pivot", l.arm_pivot),
    ];
    let bad = |name: &str, problem: String| Err((format!("{field}.{name}"), problem));
    for (name, p) in points {
        match p {
            None if needed.contains(&name) => {
                return bad(name, format!("missing: a {:?} linkage needs it", l.kind));
            }
            Some(_) if !needed.contains(&name) && !matches!(name, "kingpin" | "steering_arm") => {
                return bad(name, format!("not used by a {:?} linkage", l.kind));
            }
            Some(p) if !(p[0].is_finite() && p[1].is_finite()) => {
                return bad(name, format!("{p:?} must be a finite point"));
            }
            Some(p) if p[1] <= 0.0 && !anywhere.contains(&name) => {
                return bad(
                    name,
                    format!("{p:?} must be a finite point on the left side (y > 0)"),
                );
            }
            _ => {}
        }
    }
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            bad(name, format!("{v} must be a positive finite number"))
        }
    };
    match l.kind {
        LinkageKind::RackAndPinion => positive("rack_travel", l.rack_travel)?,
        LinkageKind::PitmanArm | LinkageKind::ToeBar => positive("arm_length", l.arm_length)?,
        // its arm's length is the distance from `arm_pivot` to `drag_link_end`
        LinkageKind::Bellcrank => {}
    }
    // every kind but the rack turns an arm
    if l.kind != LinkageKind::RackAndPinion
        && !(l.arm_max_angle_deg > 0.0 && l.arm_max_angle_deg < 90.0)
    {
        return bad(
            "arm_max_angle_deg",
            format!("{} must be in (0, 90)", l.arm_max_angle_deg),
        );
    }
    check(l).map_err(|e| (field.to_string(), e))
}
