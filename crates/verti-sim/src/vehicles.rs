//! The built-in vehicles, shipped as YAML files in `crates/verti-sim/vehicles/` and embedded in
//! the binary. Users add their own with [`crate::VehicleSpec::from_file`].

use crate::error::SpecError;
use crate::spec::{SteeringKind, TyreModel, VehicleSpec};
use std::fmt::Write as _;
use std::path::Path;

/// (name, YAML text) of every built-in vehicle, in display order.
const BUILTINS: &[(&str, &str)] = &[
    // Verti-Bench's configuration: rigid tyres
    ("hmmwv", include_str!("../vehicles/hmmwv.yaml")),
    // the same HMMWV on compliant handling tyres
    (
        "hmmwv-handling",
        include_str!("../vehicles/hmmwv-handling.yaml"),
    ),
    ("artcar", include_str!("../vehicles/artcar.yaml")),
    ("verti4", include_str!("../vehicles/verti4.yaml")),
    ("truck6", include_str!("../vehicles/truck6.yaml")),
    ("truck8", include_str!("../vehicles/truck8.yaml")),
    ("m113", include_str!("../vehicles/m113.yaml")),
    // the paper's remaining families: leaf-spring solid axles and toe-bar steering; single
    // wishbone and rack-and-pinion steering
    ("uaz", include_str!("../vehicles/uaz.yaml")),
    ("gator", include_str!("../vehicles/gator.yaml")),
    // a road car: double wishbone in front, multilink rear, rack-and-pinion steering
    ("sedan", include_str!("../vehicles/sedan.yaml")),
];

/// Names of the built-in vehicles.
/// The built-in vehicle a world of `scale` is driven by unless another is named: the artcar at
/// 1/6, the verti4 at 1/10, the HMMWV otherwise (the command line and Python agree on it).
pub fn default_for_scale(scale: f64) -> &'static str {
    if (scale - 1.0 / 6.0).abs() < 1e-3 {
        "artcar"
    } else if (scale - 0.1).abs() < 1e-3 {
        "verti4"
    } else {
        "hmmwv"
    }
}

pub fn builtin_names() -> Vec<&'static str> {
    BUILTINS.iter().map(|(n, _)| *n).collect()
}

/// A built-in vehicle by name; unknown names get an error listing the known ones.
pub fn builtin(name: &str) -> Result<VehicleSpec, SpecError> {
    let Some((_, text)) = BUILTINS.iter().find(|(n, _)| *n == name) else {
        return Err(SpecError::UnknownVehicle {
            name: name.to_string(),
            known: builtin_names().join(", "),
        });
    };
    VehicleSpec::from_yaml_str(text, &format!("built-in vehicle `{name}`"))
}

/// The YAML source of a built-in vehicle (a template for user vehicles).
pub fn builtin_yaml(name: &str) -> Option<&'static str> {
    BUILTINS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// Every built-in vehicle.
pub fn all_builtin() -> Vec<VehicleSpec> {
    builtin_names()
        .into_iter()
        .map(|n| builtin(n).expect("built-in vehicles are valid"))
        .collect()
}

/// What a built-in vehicle is, in the terms of the Verti-Bench paper's vehicle list (§III-E:
/// scale; 4-, 6-, 8-wheeled or 2-tracked chassis; suspension and steering families), how this
/// engine represents it, and where its numbers come from. Descriptive only: the physics reads
/// the vehicle file.
#[derive(Clone, Copy, Debug)]
pub struct Mechanisms {
    pub chassis: &'static str,
    /// The paper's suspension families this vehicle represents (`single wishbone`,
    /// `double wishbone`, `multilink`, `toe-bar leaf-spring`, `tensioned`).
    pub suspension_families: &'static [&'static str],
    /// The paper's steering families (`pitman arm`, `rack-and-pinion`, `toe-bar`,
    /// `bellcrank/rotary arm`, `differential`).
    pub steering_families: &'static [&'static str],
    /// The suspension and how it is modelled.
    pub suspension: &'static str,
    /// The steering and how it is modelled.
    pub steering: &'static str,
    /// Where the numbers come from (the file's comments give them number by number).
    pub source: &'static str,
}

/// The [`Mechanisms`] of a built-in vehicle, by name.
pub fn mechanisms(name: &str) -> Option<Mechanisms> {
    let hmmwv = Mechanisms {
        chassis: "4-wheeled",
        // neither linkage's geometry is simulated for it, so it claims no family of the paper
        suspension_families: &[],
        steering_families: &[],
        suspension: "double wishbone (Chrono's reduced double-A-arm), modelled as independent wheels \
                     sliding straight up and down with the linkage's roll centres (0.354 m front, \
                     0.407 m rear above the ground, from Chrono's hardpoints)",
        steering: "ideal Ackermann geometry up to 30.23°, the road-wheel angle of Chrono's JSON \
                   HMMWV (Chrono's HMMWV steers by a Pitman arm, the HMMWV_Reduced Verti-Bench \
                   drives by a rack and pinion with a 21.7° bicycle angle at full input; neither \
                   linkage is modelled for it: see the engine docs)",
        source: "Chrono 9.0.1 HMMWV_Reduced as Verti-Bench uses it (physics_spec §3.1)",
    };
    let man = |chassis, steering| Mechanisms {
        chassis,
        suspension_families: &["multilink"],
        steering_families: &["bellcrank/rotary arm"],
        suspension: "solid three-link axles after Chrono's MAN Kat1: each axle one beam (springs \
                     1.18 m apart in front, 1.31 m at the rear) whose wheels stay square to it as \
                     it rolls, roll centres at the triangle link's apex, 0.89 m above the ground",
        steering,
        source: "Chrono MAN Kat1 chassis and layout (physics_spec §3.3); springs, tyres, engine chosen",
    };
    Some(match name {
        "hmmwv" | "hmmwv-handling" => hmmwv,
        "artcar" => Mechanisms {
            chassis: "4-wheeled, 1/6 scale",
            suspension_families: &["double wishbone"],
            steering_families: &["pitman arm"],
            suspension: "double wishbone: independent wheels with the linkage's roll centre, \
                         0.029 m above the ground, and its camber change, -42.6°/m of travel",
            steering: "Pitman arm and idler: each wheel's angle from the linkage's geometry",
            source: "Chrono ARTcar (physics_spec §3.2); COM, wheel rate, motor voltage chosen",
        },
        "verti4" => Mechanisms {
            chassis: "4-wheeled, 1/10 scale",
            // no public geometry: it claims no family of the paper
            suspension_families: &[],
            steering_families: &[],
            suspension: "solid three-link (multi-link beam) axles, modelled as independent wheels \
                         (no public suspension geometry of this vehicle)",
            steering: "rotary arm / bellcrank, modelled as Ackermann geometry",
            source: "Verti-4-Wheeler C++ model in the Verti-Bench fork (verti_bench_spec §4.3); springs, motor, inertia chosen",
        },
        "truck6" => man(
            "6-wheeled",
            "rotary arm and bellcrank (Chrono's MAN 7t): each wheel's angle from the linkage's \
             geometry (left and right locks differ)",
        ),
        "truck8" => man(
            "8-wheeled",
            "a rotary arm and bellcrank on each of the two steered axles (Chrono's MAN 10t), both \
             driven by the one input: each wheel's angle from its axle's linkage's geometry",
        ),
        "m113" => Mechanisms {
            chassis: "2-tracked",
            suspension_families: &["tensioned"],
            steering_families: &["differential"],
            suspension: "torsion-arm road wheels on a tensioned track, modelled as independent road \
                         wheels tied to one spin per side; the track's raised ends (first road wheel \
                         up to the sprocket, last one up to the idler) and the spans between road \
                         wheels touch the ground and obstacles, and the moving track drives over \
                         what they touch",
            steering: "differential (skid) steering: a steer unit holds the inner track at the speed \
                       ratio that gives the path of an equivalent bicycle (the HMMWV's minimum radius \
                       at full input), corrected by the yaw rate's shortfall, with a limited \
                       steer-brake torque",
            source: "Chrono M113 (physics_spec §3.3); torsion rate, dampers, gears chosen",
        },
        "uaz" => Mechanisms {
            chassis: "4-wheeled",
            suspension_families: &["toe-bar leaf-spring"],
            steering_families: &["toe-bar", "bellcrank/rotary arm"],
            suspension: "leaf-spring solid axles (toe-bar axle in front), modelled as solid axles: \
                         wheels coupled through springs 1.028 m and dampers 0.882 m apart and square \
                         to the beam as it rolls, roll centres at the axle tube's guide, 0.372 m \
                         above the ground",
            steering: "toe-bar axle steered by a drag link from a rotary Pitman arm: each wheel's \
                       angle from the linkage's geometry (left and right locks differ)",
            source: "Chrono UAZ469 / UAZBUS (data/vehicle/uaz, src/chrono_models/vehicle/uaz)",
        },
        "gator" => Mechanisms {
            chassis: "4-wheeled",
            suspension_families: &["single wishbone"],
            steering_families: &["rack-and-pinion"],
            suspension: "single wishbone (swing arm) in front: wheel rate from the strut's motion \
                         ratio 0.62, roll centre at the arm's pivot line, 0.342 m above the ground, \
                         the wheel tilting with the 0.5-m arm (camber -114.6°/m of travel); rigid \
                         rear axle (a spring as stiff as the step allows)",
            steering: "rack and pinion: each wheel's angle from the linkage's geometry (parallel \
                       steer)",
            source: "Chrono Gator (src/chrono_models/vehicle/gator, data/vehicle/gator/json)",
        },
        "sedan" => Mechanisms {
            chassis: "4-wheeled",
            suspension_families: &["double wishbone", "multilink"],
            steering_families: &["rack-and-pinion"],
            suspension: "double wishbone in front, multilink rear (upper A-arm, lateral, trailing \
                         and toe links): independent wheels at their wheel rates (coil motion ratios \
                         0.519 front, 0.612 rear, by virtual work) with the linkages' roll centres, \
                         0.164 m front and 0.043 m rear above the ground, and their camber \
                         change, -19.3°/m front and -30.2°/m rear",
            steering: "rack and pinion: each wheel's angle from the linkage's geometry \
                       (anti-Ackermann)",
            source: "Chrono Sedan, C++ model (src/chrono_models/vehicle/sedan)",
        },
        _ => return None,
    })
}

/// The methods of [`VehicleSpec`] that look at the built-in vehicles. They live here, not in
/// `spec.rs`, so that the spec types stay below this catalogue of specs.
impl VehicleSpec {
    /// Reads a user vehicle file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<VehicleSpec, SpecError> {
        let path = path.as_ref();
        let text = verti_world::yaml::read_yaml_bounded(
            path,
            &verti_world::yaml::YamlLimits::DEFAULT,
            "a vehicle file",
        )
        .map_err(|e| match e {
            verti_world::WorldError::Io { path, source } => SpecError::Io { path, source },
            verti_world::WorldError::Invalid {
                path,
                field,
                problem,
            } => SpecError::Invalid {
                origin: path.display().to_string(),
                field,
                problem,
            },
            verti_world::WorldError::Argument(problem) => SpecError::Parse {
                origin: path.display().to_string(),
                message: problem,
            },
        })?;
        let spec = Self::from_yaml_str(&text, &path.display().to_string())?;
        // results record vehicles by name: a different vehicle under a built-in's name would be
        // taken for the built-in (an exact copy of a built-in is fine)
        if let Ok(builtin) = builtin(&spec.name)
            && builtin != spec
        {
            return Err(SpecError::Invalid {
                origin: path.display().to_string(),
                field: "name".into(),
                problem: format!(
                    "`{}` is the name of a built-in vehicle, and this one differs from it: give it a name of its own",
                    spec.name
                ),
            });
        }
        Ok(spec)
    }

    /// A human-readable description for `verti vehicle show NAME`.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{} — {}", self.name, self.description);
        let _ = writeln!(
            s,
            "  scale            {}",
            verti_world::scale::scale_label(self.scale)
        );
        let _ = writeln!(
            s,
            "  mass             {:.2} kg total ({:.2} kg sprung{}), inertia {:?} kg m²",
            self.total_mass(),
            self.chassis.mass + self.track.map_or(0.0, |t| 2.0 * t.track_mass),
            if self.is_tracked() {
                ", tracks included"
            } else {
                ""
            },
            self.chassis.inertia
        );
        let _ = writeln!(
            s,
            "  wheelbase        {:.3} m, {} axles, {} wheels{}",
            self.wheelbase(),
            self.axles.len(),
            self.wheel_count(),
            if self.is_tracked() {
                " (road wheels on tracks)"
            } else {
                ""
            }
        );
        // the origin is what systems steer and the rules judge: say where it is on the vehicle
        let first = self.axles.first().map_or(0.0, |a| a.x);
        let last = self.axles.last().map_or(0.0, |a| a.x);
        let mid = (first + last) / 2.0;
        let place = if mid.abs() < 5e-4 {
            "mid-way between the first and last axles".to_string()
        } else {
            format!(
                "{:.3} m {} mid-way between the first and last axles",
                mid.abs(),
                if mid < 0.0 { "ahead of" } else { "behind" }
            )
        };
        let _ = writeln!(
            s,
            "  position         the origin, {place}: systems steer it along the path and the goal is judged there (centre of mass at x {:+.3} m)",
            self.chassis.com[0]
        );
        for (i, a) in self.axles.iter().enumerate() {
            let _ = writeln!(
                s,
                "  axle {i}: x {:+.3} m, track {:.3} m, tyre r {:.3} w {:.3} m, spring {:.0} N/m, damper {:.0} N s/m{}{}",
                a.x,
                a.track,
                a.wheel.radius,
                a.wheel.width,
                a.suspension.stiffness,
                a.suspension.damping,
                if a.steered { ", steered" } else { "" },
                if a.driven { ", driven" } else { "" }
            );
            if let Some(sa) = &a.solid_axle {
                let _ = writeln!(
                    s,
                    "          solid axle: springs {:.3} m apart, dampers {:.3} m apart (roll rate {:.0} % of heave), wheels square to the beam",
                    sa.spring_track,
                    sa.damper_track,
                    100.0 * (sa.spring_track / a.track).powi(2)
                );
                if let Some(b) = &sa.beam {
                    let _ = writeln!(
                        s,
                        "          beam {:.1} kg, roll inertia {:.2} kg m² (its wheels' travels share one mass matrix)",
                        b.mass, b.roll_inertia
                    );
                }
            }
            if let Some(h) = a.roll_centre_height {
                let _ = writeln!(
                    s,
                    "          roll centre {h:.3} m above the ground (the links carry F_y·{h:.3} m of the roll moment of the axle's lateral force F_y)"
                );
            }
            if let Some(g) = a.camber_gain_deg_per_m {
                let _ = writeln!(
                    s,
                    "          camber change {g:.1}°/m of wheel travel from rest (a {:.2}-m swing arm in front view)",
                    1.0 / g.to_radians().abs()
                );
            }
            if let Some(bar) = &a.anti_roll_bar {
                let _ = writeln!(
                    s,
                    "          anti-roll bar {:.0} N/m per metre of travel difference (+{:.0} N m/rad of roll stiffness)",
                    bar.rate,
                    bar.rate * a.track * a.track
                );
            }
        }
        match self.steering.kind {
            SteeringKind::Ackermann => {
                let _ = writeln!(
                    s,
                    "  steering         Ackermann, max {:.1}°, {:.0}°/s",
                    self.steering.max_angle_deg, self.steering.rate_deg_per_s
                );
            }
            SteeringKind::Linkage => {
                // each steered axle's linkage, its wheels' locks against ideal Ackermann
                // geometry about the unsteered axles' mean line
                let unsteered: Vec<f64> = (self.axles.iter())
                    .filter(|a| !a.steered)
                    .map(|a| a.x)
                    .collect();
                let x_rear = unsteered.iter().sum::<f64>() / unsteered.len().max(1) as f64;
                let steered = self.axles.iter().enumerate().filter(|(_, a)| a.steered);
                for (rank, ((k, ax), l)) in steered.zip(crate::model::linkages(self)).enumerate() {
                    let mechanism = match l.kind {
                        crate::spec::LinkageKind::RackAndPinion => "rack and pinion",
                        crate::spec::LinkageKind::PitmanArm => "Pitman arm",
                        crate::spec::LinkageKind::ToeBar => "toe bar",
                        crate::spec::LinkageKind::Bellcrank => "rotary arm and bellcrank",
                    };
                    let label = if rank == 0 {
                        "  steering        ".to_string()
                    } else {
                        format!("    axle {k}        ")
                    };
                    let _ = write!(s, "{label} {mechanism} linkage; at full lock");
                    for (turn, u) in [("left", 1.0), ("right", -1.0)] {
                        let (left, right) = crate::linkage::wheel_angles(&l, u).unwrap_or_default();
                        let (inner, outer) = if u > 0.0 {
                            (left, right)
                        } else {
                            (-right, -left)
                        };
                        // the outer angle ideal Ackermann geometry gives for this inner one
                        let kingpins = 2.0 * l.kingpin[1];
                        let ideal = (1.0 / (1.0 / inner.tan() + kingpins / (ax.x - x_rear))).atan();
                        let _ = write!(
                            s,
                            " {turn}: inner {:.1}°, outer {:.1}° (ideal {:.1}°)",
                            inner.to_degrees(),
                            outer.to_degrees(),
                            ideal.to_degrees()
                        );
                    }
                    if rank == 0 {
                        let _ = writeln!(
                            s,
                            "; bicycle {:.2}°, {:.0}°/s",
                            crate::linkage::full_lock_bicycle_angle(&l).to_degrees(),
                            self.steering.rate_deg_per_s
                        );
                    } else {
                        let _ = writeln!(s, "; the same input");
                    }
                }
            }
            SteeringKind::Skid => {
                let _ = writeln!(
                    s,
                    "  steering         skid: a steer unit holds the tracks' speed ratio for the path of \
                     a bicycle of wheelbase {:.2} m at up to {:.1}° ({:.1} m minimum radius), {:.0}°/s; \
                     steer brake {:.0} N m per wheel",
                    self.wheelbase(),
                    self.steering.max_angle_deg,
                    self.wheelbase() / self.steering.max_angle_deg.to_radians().tan(),
                    self.steering.rate_deg_per_s,
                    self.steering.skid_brake_torque
                );
            }
        }
        let p = &self.powertrain;
        let peak = p
            .full_throttle
            .iter()
            .map(|pt| pt[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let drive = if self.is_tracked() {
            "tracks (one spin per side)".to_string()
        } else {
            format!(
                "differentials axle {:?} / central {:?}",
                p.axle_differential, p.central_differential
            )
        };
        let _ = writeln!(
            s,
            "  powertrain       peak {} N m, max {:.0} rpm, gears {:?}, final drive {}, {}",
            significant(peak, 4),
            p.max_speed_rpm,
            p.gears,
            p.final_drive,
            drive
        );
        let _ = writeln!(
            s,
            "  tyre             {}μ {}, Cz {:.3e} N/m, rolling resistance {}",
            match self.tyre.model {
                TyreModel::Handling => "",
                TyreModel::Rigid => "rigid cylinder, ",
            },
            self.tyre.friction,
            self.tyre.radial_stiffness,
            self.tyre.rolling_resistance
        );
        let _ = write!(s, "  internal step    {} ms", self.internal_step * 1e3);
        // a built-in (unchanged): what it stands for and where its numbers come from
        if let Some(m) = mechanisms(&self.name)
            && builtin(&self.name).is_ok_and(|b| b == *self)
        {
            let _ = write!(
                s,
                "\n  chassis          {}\n  suspension       {}\n  steering         {}\n  sources          {}; `verti vehicle show {} --yaml` cites each number",
                m.chassis, m.suspension, m.steering, m.source, self.name
            );
        }
        s
    }
}

/// `x` with about `digits` significant digits (no exponent), for summaries of vehicles from
/// 1/10 scale (0.06 N m motors) to trucks (1600 N m engines).
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}
