//! Model compilation: a [`VehicleSpec`] (what the vehicle file says) becomes a [`Model`] (what
//! the inner loops want): masses and inertias about the centre of mass, per-wheel constants,
//! spin groups, the chassis collision lattice and contact stiffnesses sized from the step.
//!
//! # Mass model
//! The chassis is a rigid body with 6 degrees of freedom (position, unit quaternion). Each wheel
//! has a suspension degree of freedom along the chassis z axis (spring, damper, bump and rebound
//! stops) carrying its unsprung mass, and belongs to a *spin group*: one spin degree of freedom
//! per set of wheels a locked differential (or a track) ties together. Sideways and fore-aft,
//! the wheels move with the chassis, so those forces act on the whole vehicle's mass; along the
//! suspension the unsprung mass moves on its own and only the spring-damper force reaches the
//! chassis. This is the exact mass matrix of that system when every suspension axis is the
//! chassis z axis, which is how vehicles are described here.

use crate::spec::{Differential, SolidAxleSpec, VehicleSpec};
use crate::state::WheelState;
use crate::track_runs::TrackRuns;
use verti_core::Vec3;

/// Standard gravity \[m/s²\] (Chrono: 9.81 along −Z).
pub(crate) const GRAVITY: f64 = 9.81;

/// Constants of one wheel, derived from the spec once.
#[derive(Clone, Debug)]
pub(crate) struct WheelModel {
    /// Wheel centre at spring free length, body frame, relative to the centre of mass.
    pub attach: Vec3,
    /// Lateral position in the reference frame (for Ackermann).
    pub y: f64,
    /// x relative to the mean of the unsteered axles (for Ackermann).
    pub ackermann_dx: f64,
    pub steered: bool,
    /// A steered wheel's linkage: its axle's rank among the steered axles.
    pub linkage: usize,
    pub driven: bool,
    pub radius: f64,
    pub half_width: f64,
    pub rim_depth: f64,
    pub unsprung_mass: f64,
    pub spring: f64,
    pub damper: f64,
    pub bump: f64,
    pub rebound: f64,
    pub stop: f64,
    pub stop_damping: f64,
    pub brake_torque: f64,
    pub group: usize,
    /// Low-speed damping of the transient slip \[N s/m\] (bristle damping).
    pub slip_damping_long: f64,
    pub slip_damping_lat: f64,
    /// Nominal static load \[N\]: sets the fixed stiffness of the tyre at standstill.
    pub nominal_load: f64,
    /// Static compression of the spring with the vehicle at rest (see [`static_compressions`]).
    pub static_compression: f64,
    /// On a solid axle or with an anti-roll bar: the wheel at the axle's other end and how its
    /// travel loads this one. `spring` and `damper` above are then the self terms (see
    /// [`crate::spec::SolidAxleSpec`] and [`crate::spec::AntiRollBarSpec`]).
    pub coupling: Option<AxleCoupling>,
    /// Beam axles: roll-centre height over track, h/t (left wheels only; 0 for none): the
    /// locating links carry this share of the axle's lateral ground force as a vertical pair on
    /// its two wheels (`suspension::roll_centre_links`).
    pub link_share: f64,
    /// Independent wheels: the contact patch's outward travel per unit of wheel travel, 2h/t
    /// (signed: times +1 on the left, −1 on the right; 0 for none): the wheel's lateral ground
    /// force jacks its travel by this share.
    pub jacking: f64,
    /// A road wheel inside a track whose belt is modelled (`track_runs`): where a rigid patch
    /// borders soil, the belt spanning the road wheels meets the patch's edge, not the wheel
    /// (`soil_edges`).
    pub belted: bool,
    /// A belted road wheel on soil: how far ahead of and behind its centre the belt's lower
    /// run, flat between this road wheel and its neighbours, presses the soil as a plate
    /// (half the spacing to the next road wheel each way; zero at the run's ends, where the
    /// belt rises to the sprocket or idler) \[m\]. (0, 0): the wheel's own cylinder only.
    pub belt_plate: (f64, f64),
    /// How the wheel's plane tilts with its travel (camber, or a beam axle's roll).
    pub tilt: WheelTilt,
}

/// The coupling of a wheel to the other end of its axle (a beam, an anti-roll bar): the
/// suspension force on this wheel gains `spring_cross`·s_other + `damper_cross`·ṡ_other.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxleCoupling {
    pub partner: usize,
    pub spring_cross: f64,
    pub damper_cross: f64,
    /// A beam with its own roll inertia: the (diagonal, off-diagonal) terms of the two travels'
    /// mass matrix ([`crate::spec::BeamSpec::mass_matrix`]); the pair is then updated together.
    pub beam: Option<(f64, f64)>,
}

/// How a wheel's spin axis tilts away from square to the chassis, as a rotation about the
/// chassis' x axis (positive lifts the axle's left end). The hub still moves straight along the
/// chassis' up axis; only the wheel's plane turns, so a rigid tyre bears on the edge its
/// suspension tips down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum WheelTilt {
    /// Always square (a wheel sliding straight up and down).
    Square,
    /// An independent linkage's camber change: tilt `per_metre`·(s − `rest`) for travel s
    /// (`per_metre` signed by side, so that both wheels' tops lean the same way relative to the
    /// chassis' centre line at equal travel).
    Camber { per_metre: f64, rest: f64 },
    /// One end of a beam axle: square to the beam, which rolls by atan((s_l − s_r)/t) relative
    /// to the chassis; `side_over_track` is ±1/t (+ on the left).
    Beam {
        partner: usize,
        side_over_track: f64,
    },
}

impl WheelTilt {
    /// The tilt \[rad\] with the wheels' travels of `wheels`; `None` when square.
    #[inline]
    pub(crate) fn angle(&self, own: f64, wheels: &[WheelState]) -> Option<f64> {
        match *self {
            WheelTilt::Square => None,
            WheelTilt::Camber { per_metre, rest } => Some(per_metre * (own - rest)),
            WheelTilt::Beam {
                partner,
                side_over_track,
            } => Some(libm::atan(
                side_over_track * (own - wheels[partner].compression),
            )),
        }
    }
}

/// Wheels that share one spin degree of freedom (a track's side, or a locked differential).
#[derive(Clone, Debug)]
pub(crate) struct SpinGroup {
    pub wheels: Vec<usize>,
    pub inertia: f64,
    /// Share of the engine torque.
    pub drive_share: f64,
    /// Side, for the skid-steer unit (+1 left, −1 right, 0 mixed).
    pub side: f64,
    pub driven: bool,
}

/// A differential's clutch between two sets of wheels (`Differential::Clutch`): it holds the
/// mean spins of the two sets equal while that takes at most `capacity` and slips beyond it.
/// Its torque goes in equal parts to the wheels of one set and out of the other's.
#[derive(Clone, Debug)]
pub(crate) struct Coupling {
    /// Each side's spin groups. A clutch differential leaves every wheel its own group (a
    /// central clutch is refused with locked axle differentials), so a group is one wheel.
    pub a: Vec<usize>,
    pub b: Vec<usize>,
    /// The clutch's largest torque, at the wheels (over one side's wheels) \[N m\].
    pub capacity: f64,
}

/// The compiled vehicle: everything the internal step needs that does not change.
#[derive(Clone, Debug)]
pub(crate) struct Model {
    /// The fixed internal step \[s\].
    pub step: f64,
    pub wheels: Vec<WheelModel>,
    pub groups: Vec<SpinGroup>,
    /// Differential clutches between spin groups (empty unless a differential is `clutch`).
    pub couplings: Vec<Coupling>,
    pub sprung_mass: f64,
    pub total_mass: f64,
    /// Chassis-only principal inertia and the composite (with unsprung masses) one.
    pub chassis_inertia: Vec3,
    pub inertia: Vec3,
    /// Centre of mass in the reference frame.
    pub com: Vec3,
    /// Chassis collision points (body frame, about the centre of mass) and the collision box.
    pub body_points: Vec<Vec3>,
    pub box_center: Vec3,
    pub box_half: Vec3,
    pub body_stiffness: f64,
    pub body_damping: f64,
    /// Sliding speed below which body friction is regularised (viscous) \[m/s\].
    pub friction_speed: f64,
    /// Bounding radius of the vehicle around its centre of mass, plus a margin \[m\].
    pub reach: f64,
    /// How far below a soil surface the chassis meets a floor: one (largest) wheel diameter
    /// (soil itself does not hold the chassis, see `contact::body`) \[m\].
    pub soil_floor: f64,
    pub driven_wheels: usize,
    /// Distance from the first steered axle to the mean of the unsteered ones (Ackermann).
    pub wheelbase: f64,
    /// Each steering linkage's (sin δ, cos δ) of the left and right steered wheels at
    /// [`LINKAGE_SAMPLES`] + 1 evenly spaced inputs from −1 to 1 (the closed form costs a
    /// dozen trigonometric calls, too many for every internal step), one per steered axle
    /// in axle order; empty unless the steering is `kind: linkage`.
    pub linkage_tables: Vec<Vec<[(f64, f64); 2]>>,
    /// Whether any axle has a roll centre above (or below) the ground.
    pub roll_centres: bool,
    /// Whether any solid axle's beam has its own roll inertia (its wheels update as a pair).
    pub beams: bool,
    /// A tracked vehicle's raised track ends, when its file gives them.
    pub track_runs: Option<TrackRuns>,
}

/// Intervals of [`Model::linkage_tables`]: between samples the wheel angle changes by at most
/// ~0.005 rad, so interpolating sine and cosine and normalising is within ~1e-6 rad of the
/// closed form.
pub(crate) const LINKAGE_SAMPLES: usize = 400;

impl Model {
    /// Compiles a validated `spec` for a world of the given scale.
    pub fn compile(spec: &VehicleSpec, scale: f64) -> Model {
        let com = Vec3::new(
            spec.chassis.com[0],
            spec.chassis.com[1],
            spec.chassis.com[2],
        );
        let track_mass = spec.track.map_or(0.0, |t| 2.0 * t.track_mass);
        let sprung_mass = spec.chassis.mass + track_mass;
        let total_mass = sprung_mass
            + spec
                .axles
                .iter()
                .map(|a| 2.0 * a.wheel.unsprung_mass)
                .sum::<f64>();
        let comp = static_compressions(spec);
        let steered_x: Vec<f64> = spec
            .axles
            .iter()
            .filter(|a| !a.steered)
            .map(|a| a.x)
            .collect();
        let x_rear = if steered_x.is_empty() {
            0.0
        } else {
            steered_x.iter().sum::<f64>() / steered_x.len() as f64
        };
        let h = spec.internal_step;

        let (groups, group_of) = spin_groups(spec);
        let couplings = couplings(spec, &group_of);
        let driven_wheels = spec.axles.iter().filter(|a| a.driven).count() * 2;

        let mut wheels = Vec::with_capacity(spec.wheel_count());
        let mut inertia = Vec3::new(
            spec.chassis.inertia[0],
            spec.chassis.inertia[1],
            spec.chassis.inertia[2],
        );
        let mut reach: f64 = 0.0;
        let per_wheel_load = total_mass * GRAVITY / spec.wheel_count() as f64;
        for (k, ax) in spec.axles.iter().enumerate() {
            for side in [1.0f64, -1.0] {
                let w = wheels.len();
                let attach = Vec3::new(ax.x, side * 0.5 * ax.track, ax.z) - com;
                let mu = ax.wheel.unsprung_mass;
                inertia += Vec3::new(
                    mu * (attach.y.powi(2) + attach.z.powi(2)),
                    mu * (attach.x.powi(2) + attach.z.powi(2)),
                    mu * (attach.x.powi(2) + attach.y.powi(2)),
                );
                reach = reach.max(attach.norm() + ax.wheel.radius + 0.5 * ax.wheel.width);
                let t = &spec.tyre;
                // Bristle damping at critical-ish ratio 0.3 of the slip-spring against the
                // wheel's spin inertia (longitudinal) and its share of the mass (lateral).
                let k_long = t.dfx0 * per_wheel_load / t.relaxation_length;
                let k_lat = t.dfy0 * per_wheel_load / t.relaxation_length;
                let g = group_of[w];
                let spin_mass =
                    groups[g].inertia / groups[g].wheels.len() as f64 / ax.wheel.radius.powi(2);
                let lat_mass = total_mass / spec.wheel_count() as f64;
                let stop_damping = 2.0 * 0.5 * (ax.suspension.stop_stiffness * mu).sqrt();
                let (rate_k, rate_c) = (ax.suspension.stiffness, ax.suspension.damping);
                // an axle's wheels are numbered left (even), right (odd)
                let (mut spring, damper, mut coupling) = match &ax.solid_axle {
                    None => (rate_k, rate_c, None),
                    Some(sa) => {
                        let (ks, kx) = SolidAxleSpec::coefficients(sa.spring_track, ax.track);
                        let (cs, cx) = SolidAxleSpec::coefficients(sa.damper_track, ax.track);
                        let coupling = AxleCoupling {
                            partner: w ^ 1,
                            spring_cross: rate_k * kx,
                            damper_cross: rate_c * cx,
                            beam: sa.beam.map(|b| b.mass_matrix(mu, ax.track)),
                        };
                        if let (Some(b), true) = (&sa.beam, side > 0.0) {
                            // the beam rolls and yaws with the body as one bar, not as two
                            // points at its ends
                            let extra = b.roll_inertia - 0.25 * b.mass * ax.track * ax.track;
                            inertia += Vec3::new(extra, 0.0, extra);
                        }
                        (rate_k * ks, rate_c * cs, Some(coupling))
                    }
                };
                if let Some(bar) = &ax.anti_roll_bar {
                    // rate·(s_own − s_other): a self term and a cross term of opposite sign
                    spring += bar.rate;
                    let c = coupling.get_or_insert(AxleCoupling {
                        partner: w ^ 1,
                        spring_cross: 0.0,
                        damper_cross: 0.0,
                        beam: None,
                    });
                    c.spring_cross -= bar.rate;
                }
                let (link_share, jacking) = match (ax.roll_centre_height, &ax.solid_axle) {
                    (Some(h), Some(_)) if side > 0.0 => (h / ax.track, 0.0),
                    (Some(h), None) => (0.0, side * 2.0 * h / ax.track),
                    _ => (0.0, 0.0),
                };
                wheels.push(WheelModel {
                    attach,
                    y: side * 0.5 * ax.track,
                    ackermann_dx: ax.x - x_rear,
                    steered: ax.steered,
                    linkage: spec.axles[..k].iter().filter(|a| a.steered).count(),
                    driven: ax.driven,
                    radius: ax.wheel.radius,
                    half_width: 0.5 * ax.wheel.width,
                    rim_depth: ax.wheel.radius - ax.wheel.rim_radius,
                    unsprung_mass: mu,
                    spring,
                    damper,
                    bump: ax.suspension.bump_travel,
                    rebound: ax.suspension.rebound_travel,
                    stop: ax.suspension.stop_stiffness,
                    stop_damping,
                    brake_torque: ax.brake_torque,
                    group: g,
                    slip_damping_long: 0.6 * (k_long * spin_mass).sqrt(),
                    slip_damping_lat: 0.6 * (k_lat * lat_mass).sqrt(),
                    nominal_load: per_wheel_load,
                    static_compression: comp[k],
                    coupling,
                    link_share,
                    jacking,
                    belted: false,
                    belt_plate: (0.0, 0.0),
                    tilt: match (&ax.solid_axle, ax.camber_gain_deg_per_m) {
                        (Some(_), _) => WheelTilt::Beam {
                            partner: w ^ 1,
                            side_over_track: side / ax.track,
                        },
                        // a rising left wheel whose top tips inwards turns about +x
                        (None, Some(g)) => WheelTilt::Camber {
                            per_metre: -side * g.to_radians(),
                            rest: comp[k],
                        },
                        (None, None) => WheelTilt::Square,
                    },
                });
            }
        }
        // Chassis collision points: the 18 points of a 3x3x2 lattice on the collision box,
        // bottom face first; within a face x from rear to front, y from right to left within
        // each x (`contact::belly` reads the bottom nine in this order).
        let bx = &spec.chassis.collision_box;
        let box_center = Vec3::new(bx.center[0], bx.center[1], bx.center[2]) - com;
        let box_half = Vec3::new(bx.size[0], bx.size[1], bx.size[2]) * 0.5;
        let mut body_points = Vec::with_capacity(18);
        for iz in [-1.0, 1.0] {
            for ix in [-1.0, 0.0, 1.0] {
                for iy in [-1.0, 0.0, 1.0] {
                    let p =
                        box_center + Vec3::new(ix * box_half.x, iy * box_half.y, iz * box_half.z);
                    reach = reach.max(p.norm());
                    body_points.push(p);
                }
            }
        }
        // Body contact stiffness: chassis contact mode at ω·h = 0.15 when a quarter of the mass
        // rests on one point; damping ratio 0.5. Against obstacles it is 4x stiffer
        // (ω·h = 0.3, see `contact::body`); against terrain many points rest at once (a
        // rolled vehicle on its roof) and the softer value keeps that stable.
        let omega_body = 0.15 / h;
        let body_stiffness = 0.25 * total_mass * omega_body * omega_body;
        let body_damping = 2.0 * 0.5 * (body_stiffness * 0.25 * total_mass).sqrt();
        if let Some(runs) = spec.track.and_then(|t| t.runs) {
            // the rollers the track wraps reach beyond the hull's box
            let ax = &spec.axles[0];
            let y = 0.5 * ax.track + 0.5 * ax.wheel.width;
            for r in [runs.sprocket, runs.idler] {
                reach = reach.max((Vec3::new(r.x, y, r.z) - com).norm() + r.radius);
            }
        }
        let reach = reach * 1.1 + 0.2 * scale;
        let roll_centres = wheels
            .iter()
            .any(|w| w.link_share != 0.0 || w.jacking != 0.0);
        let beams = wheels
            .iter()
            .any(|w| w.coupling.is_some_and(|c| c.beam.is_some()));
        let soil_floor = spec.largest_wheel_diameter();
        // each wheel's (x, y) in the reference frame
        let wheel_xy: Vec<(f64, f64)> = wheels.iter().map(|m| (m.attach.x + com.x, m.y)).collect();
        let track_runs = TrackRuns::compile(
            spec,
            com,
            &group_of,
            &wheel_xy,
            body_stiffness,
            body_damping,
        );
        if let Some(runs) = &track_runs {
            for side in &runs.sides {
                for &w in &side.wheels {
                    wheels[w].belted = true;
                    wheels[w].belt_plate = spec.belt_plate(w / 2);
                }
            }
        }
        let wheelbase = wheels
            .iter()
            .find(|w| w.steered)
            .map_or(1.0, |w| w.ackermann_dx);
        Model {
            step: h,
            wheels,
            groups,
            couplings,
            sprung_mass,
            total_mass,
            chassis_inertia: Vec3::new(
                spec.chassis.inertia[0],
                spec.chassis.inertia[1],
                spec.chassis.inertia[2],
            ),
            inertia,
            com,
            body_points,
            box_center,
            box_half,
            body_stiffness,
            body_damping,
            friction_speed: 0.05 * scale.sqrt(),
            reach,
            soil_floor,
            driven_wheels,
            wheelbase,
            linkage_tables: linkages(spec)
                .iter()
                .map(|l| {
                    (0..=LINKAGE_SAMPLES)
                        .map(|k| {
                            let u = -1.0 + 2.0 * k as f64 / LINKAGE_SAMPLES as f64;
                            // validation checked that the linkage closes over the whole range
                            let (left, right) =
                                crate::linkage::wheel_angles(l, u).unwrap_or((0.0, 0.0));
                            [
                                (libm::sin(left), libm::cos(left)),
                                (libm::sin(right), libm::cos(right)),
                            ]
                        })
                        .collect()
                })
                .collect(),
            roll_centres,
            beams,
            track_runs,
        }
    }
}

/// The steering linkages of a `kind: linkage` vehicle, one per steered axle in axle order:
/// the first steered axle's is `steering.linkage`, each further one's its own (empty for the
/// other kinds).
pub(crate) fn linkages(spec: &VehicleSpec) -> Vec<crate::spec::LinkageSpec> {
    let Some(first) = spec.steering.linkage else {
        return Vec::new();
    };
    let further = spec.axles.iter().filter(|a| a.steered).skip(1);
    std::iter::once(first)
        .chain(further.filter_map(|a| a.linkage))
        .collect()
}

/// Static spring compression per axle: a rigid chassis on the axle springs (heave and pitch),
/// which is exact for two axles and the stiffness-weighted split for more.
pub(crate) fn static_compressions(spec: &VehicleSpec) -> Vec<f64> {
    let w = spec.chassis.mass * GRAVITY;
    let xc = spec.chassis.com[0];
    let (mut k0, mut k1, mut k2) = (0.0, 0.0, 0.0);
    for ax in &spec.axles {
        let k = 2.0 * ax.suspension.stiffness;
        let dx = ax.x - xc;
        k0 += k;
        k1 += k * dx;
        k2 += k * dx * dx;
    }
    // Solve [k0 k1; k1 k2] [z; θ] = [W; 0] with compression_i = z + θ·dx_i.
    let det = k0 * k2 - k1 * k1;
    let (z, th) = if det.abs() > 1e-12 * k0 * k2.max(1e-12) {
        (w * k2 / det, -w * k1 / det)
    } else {
        (w / k0, 0.0)
    };
    spec.axles.iter().map(|ax| z + th * (ax.x - xc)).collect()
}

/// Spin groups (tracks tie a side; locked differentials tie axles and sides) and each wheel's
/// group. Wheels are numbered axle by axle, left then right.
fn spin_groups(spec: &VehicleSpec) -> (Vec<SpinGroup>, Vec<usize>) {
    let mut group_of = vec![usize::MAX; spec.wheel_count()];
    let mut groups: Vec<SpinGroup> = Vec::new();
    let tracked = spec.is_tracked();
    for (k, ax) in spec.axles.iter().enumerate() {
        for (j, side) in [1.0f64, -1.0].into_iter().enumerate() {
            let w = 2 * k + j;
            let key = group_key(spec, tracked, w);
            let existing = key.and_then(|key| {
                groups
                    .iter()
                    .position(|g| group_key(spec, tracked, g.wheels[0]) == Some(key))
            });
            let g = match existing {
                Some(g) => g,
                None => {
                    groups.push(SpinGroup {
                        wheels: Vec::new(),
                        inertia: 0.0,
                        drive_share: 0.0,
                        side,
                        driven: false,
                    });
                    groups.len() - 1
                }
            };
            let grp = &mut groups[g];
            grp.wheels.push(w);
            grp.inertia += ax.wheel.spin_inertia;
            grp.driven |= ax.driven;
            if grp.side != side {
                grp.side = 0.0;
            }
            group_of[w] = g;
        }
    }
    if let Some(tr) = &spec.track {
        for g in &mut groups {
            // the track's mass spins with its side at the road-wheel radius
            let r = g
                .wheels
                .iter()
                .map(|&w| spec.axles[w / 2].wheel.radius)
                .sum::<f64>()
                / g.wheels.len() as f64;
            g.inertia += tr.track_mass * r * r;
        }
    }
    let driven_wheels = spec.axles.iter().filter(|a| a.driven).count() * 2;
    for g in &mut groups {
        let driven_members = g
            .wheels
            .iter()
            .filter(|&&w| spec.axles[w / 2].driven)
            .count();
        g.drive_share = driven_members as f64 / driven_wheels as f64;
        g.driven = driven_members > 0;
    }
    (groups, group_of)
}

/// The differential clutches: one between the two wheels of each driven axle with a clutch
/// axle differential (its shafts turn with the wheels), and with a clutch central differential
/// one between the two driven axles (its shafts turn `1 / final_drive` times faster than the
/// wheels, so it passes `1 / final_drive` times its torque at the wheels). Validation allows a
/// clutch central differential only with two driven axles whose differentials are not locked.
fn couplings(spec: &VehicleSpec, group_of: &[usize]) -> Vec<Coupling> {
    let p = &spec.powertrain;
    let mut out = Vec::new();
    if spec.is_tracked() {
        return out; // a track's side is its spin group; the differentials play no part
    }
    let driven: Vec<usize> = (0..spec.axles.len())
        .filter(|&k| spec.axles[k].driven)
        .collect();
    if let Differential::Clutch(torque) = p.axle_differential {
        for &k in &driven {
            out.push(Coupling {
                a: vec![group_of[2 * k]],
                b: vec![group_of[2 * k + 1]],
                capacity: torque,
            });
        }
    }
    if let (Differential::Clutch(torque), [front, rear]) = (p.central_differential, &driven[..]) {
        let side = |k: usize| vec![group_of[2 * k], group_of[2 * k + 1]];
        out.push(Coupling {
            a: side(*front),
            b: side(*rear),
            capacity: torque / p.final_drive,
        });
    }
    out
}

/// Key identifying which spin group a wheel joins (None = its own group).
fn group_key(spec: &VehicleSpec, tracked: bool, w: usize) -> Option<usize> {
    let ax = &spec.axles[w / 2];
    let j = w % 2;
    if tracked {
        return Some(j);
    }
    if !ax.driven {
        return None;
    }
    match (
        spec.powertrain.axle_differential,
        spec.powertrain.central_differential,
    ) {
        (Differential::Locked, Differential::Locked) => Some(100),
        (Differential::Locked, Differential::Open) => Some(200 + w / 2),
        _ => None,
    }
}
