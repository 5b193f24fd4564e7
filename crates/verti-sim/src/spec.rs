//! The immutable description of a vehicle ([`VehicleSpec`]), read from YAML.
//!
//! Frames: the chassis *reference frame* is ISO (x forward, y left, z up). Its origin is on the
//! centre line, at wheel-centre height, at the front axle for the HMMWV-style files (any choice
//! works: every position in the file is relative to it). Suspension travel is along the chassis
//! z axis; `s` is the spring compression measured from the spring's free length.

use crate::error::SpecError;
pub use crate::linkage::{LinkageKind, LinkageSpec};
pub use axle::{AntiRollBarSpec, BeamSpec, SolidAxleSpec};
pub use differential::Differential;
use serde::{Deserialize, Serialize};
pub use track::{RollerSpec, TrackRunsSpec, TrackSpec};

mod axle;
mod differential;
mod track;

/// Most wheels (or road wheels) a vehicle may have; keeps per-step work bounded.
pub const MAX_WHEELS: usize = 16;
/// Most steered axles a vehicle with `steering.kind: linkage` may have (one linkage each).
pub const MAX_LINKAGES: usize = 4;

/// Largest torque \[N m\] a powertrain map may give: the built-in vehicles stay below 2000,
/// the largest mining trucks below 1e5.
pub const MAX_ENGINE_TORQUE: f64 = 1e7;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleSpec {
    /// Short identifier, e.g. `hmmwv`.
    pub name: String,
    /// One line for humans.
    pub description: String,
    /// World scale the vehicle is built for (1 = full scale, 1/6, 1/10).
    pub scale: f64,
    /// Fixed internal integration step in seconds. Every shipped vehicle is stable at its value
    /// (see `tests/validation.rs`); user vehicles choose their own.
    pub internal_step: f64,
    pub chassis: ChassisSpec,
    /// Axles from front to rear. Each carries a left and a right wheel.
    pub axles: Vec<AxleSpec>,
    pub tyre: TyreSpec,
    pub steering: SteeringSpec,
    pub powertrain: PowertrainSpec,
    /// Present for tracked vehicles: the wheels of each side are road wheels linked by a track.
    #[serde(default)]
    pub track: Option<TrackSpec>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChassisSpec {
    /// Sprung mass \[kg\] (everything but the unsprung wheel assemblies).
    pub mass: f64,
    /// Principal moments of inertia about the centre of mass, body axes \[kg m²\].
    pub inertia: [f64; 3],
    /// Centre of mass in the reference frame \[m\].
    pub com: [f64; 3],
    /// Collision box (centre and full size, reference frame) used for body contacts.
    pub collision_box: BoxSpec,
    /// Coulomb friction of the body against terrain and obstacles.
    pub friction: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    pub center: [f64; 3],
    pub size: [f64; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxleSpec {
    /// Longitudinal position of the wheel centres \[m\].
    pub x: f64,
    /// Distance between the left and right wheel centres \[m\].
    pub track: f64,
    /// Height of the wheel centres when the spring is at its free length \[m\].
    pub z: f64,
    #[serde(default)]
    pub steered: bool,
    #[serde(default)]
    pub driven: bool,
    /// Maximum brake torque per wheel \[N m\].
    pub brake_torque: f64,
    pub suspension: SuspensionSpec,
    pub wheel: WheelSpec,
    /// Present when the two wheels are the ends of one rigid beam axle (leaf-spring or
    /// link-located solid axles) instead of sprung independently.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solid_axle: Option<SolidAxleSpec>,
    /// Height of the axle's geometric roll centre above the ground at the design position \[m\]
    /// (from the linkage: where the line from a contact patch through its wheel's instant
    /// centre crosses the centre line; for a beam axle, the height of its lateral location).
    /// The links then carry the share F_y·h/t of the axle's lateral ground force F_y as a
    /// vertical force pair on the two wheels, and the springs only the rest of the body's roll
    /// moment. Absent: 0, the roll centre of a wheel sliding straight up and down (the ground).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_centre_height: Option<f64>,
    /// Camber change of an independent linkage \[degrees per metre of wheel travel, bump
    /// positive\]: from its front-view instant centre at distance l from the contact patch,
    /// −1/l rad/m (a swing arm, or a double wishbone's virtual one); negative tips a rising
    /// wheel's top inwards. The wheel is square to the chassis at rest on level ground and
    /// tilts by this much per metre of travel from there. Absent: it stays square (a wheel
    /// sliding straight up and down). A solid axle's wheels tilt with their beam instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camber_gain_deg_per_m: Option<f64>,
    /// An anti-roll (stabiliser) bar between the two wheels of the axle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anti_roll_bar: Option<AntiRollBarSpec>,
    /// A steered axle after the first of a `steering.kind: linkage` vehicle: its own linkage
    /// (points relative to the axle's x), driven by the same steering input.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linkage: Option<LinkageSpec>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuspensionSpec {
    /// Linear spring rate at the wheel \[N/m\].
    pub stiffness: f64,
    /// Linear damping at the wheel \[N s/m\].
    pub damping: f64,
    /// Compression from free length at which the bump stop engages \[m\].
    pub bump_travel: f64,
    /// Extension beyond free length at which the rebound stop engages \[m\].
    pub rebound_travel: f64,
    /// Stiffness of both stops \[N/m\] (they also carry the damping of a stiff rubber stop).
    pub stop_stiffness: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelSpec {
    /// Unloaded tyre radius \[m\].
    pub radius: f64,
    /// Tyre width \[m\].
    pub width: f64,
    /// Rim radius \[m\]: below it the tyre is bottomed out and contact gets much stiffer.
    pub rim_radius: f64,
    /// Mass that moves with the suspension (wheel, tyre, upright, spindle) \[kg\].
    pub unsprung_mass: f64,
    /// Spin inertia of wheel and tyre \[kg m²\].
    pub spin_inertia: f64,
}

/// Which force law the tyres follow (vehicle-wide, `tyre.model` in the file; `handling` when
/// absent, so every file written before the choice existed keeps its meaning and its bits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TyreModel {
    /// A compliant tyre with a TMeasy-style combined-slip curve (the fields below).
    #[default]
    Handling,
    /// A rigid cylinder (radius and width of the wheel) with Coulomb friction, like Chrono's
    /// `ChRigidTire` under NSC contact: `radial_stiffness` and `radial_damping` are the stiff
    /// penalty contact standing in for the complementarity constraint, `friction` the Coulomb
    /// coefficient; the slip-curve fields are not used (`relaxation_length` still drives the
    /// soil shear on deformable ground).
    Rigid,
}

impl TyreModel {
    /// True for the default (used to leave the field out of written files, so the YAML and the
    /// digests of every handling-tyre vehicle are what they were before the field existed).
    pub fn is_handling(&self) -> bool {
        *self == TyreModel::Handling
    }
}

/// Tyre force model: radial spring-damper plus a TMeasy-style combined-slip curve. Force values
/// are per unit normal load at the tyre's own friction `friction`; on ground of lower friction
/// the peak and sliding values scale down with the patch friction (Chrono combines by `min`).
/// With `model: rigid` the tyre is a rigid cylinder instead (see [`TyreModel::Rigid`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TyreSpec {
    /// The force law: `handling` (default) or `rigid`.
    #[serde(default, skip_serializing_if = "TyreModel::is_handling")]
    pub model: TyreModel,
    /// Radial stiffness \[N/m\].
    pub radial_stiffness: f64,
    /// Radial damping \[N s/m\].
    pub radial_damping: f64,
    /// Friction coefficient of the tyre material.
    pub friction: f64,
    /// Rolling resistance coefficient (torque = c_rr · Fz · R).
    pub rolling_resistance: f64,
    /// Relaxation length of the transient slip \[m\] (about the radius).
    pub relaxation_length: f64,
    /// Longitudinal curve: initial slope, peak (value, slip), sliding (value, slip).
    pub dfx0: f64,
    pub fxm: f64,
    pub sxm: f64,
    pub fxs: f64,
    pub sxs: f64,
    /// Lateral curve (slip = tan of the slip angle).
    pub dfy0: f64,
    pub fym: f64,
    pub sym: f64,
    pub fys: f64,
    pub sys: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SteeringKind {
    /// Steered wheels turn with Ackermann geometry about the rear (unsteered) axles.
    Ackermann,
    /// Skid (differential) steering: no wheel turns; a steer unit holds the inner side's speed
    /// at a ratio of the outer side's so that the vehicle follows the path curvature of an
    /// equivalent bicycle (wheelbase [`VehicleSpec::wheelbase`], steer angle up to
    /// `max_angle_deg`): the same steering input means the same path for every vehicle
    /// (tracked vehicles; see `drivetrain::skid_speed_ratio`).
    Skid,
    /// The steered axles' wheels turn through steering linkages: a rack and pinion, a Pitman
    /// arm, a toe bar or a bellcrank, each wheel by the angle its axle's linkage gives it
    /// (`linkage` for the first steered axle, `axles[i].linkage` for each further one).
    Linkage,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteeringSpec {
    pub kind: SteeringKind,
    /// Bicycle-model angle at full input \[deg\]: Ackermann, the road wheels' centre angle;
    /// skid, the equivalent bicycle's.
    #[serde(default)]
    pub max_angle_deg: f64,
    /// Slew-rate limit of that angle \[deg/s\].
    #[serde(default)]
    pub rate_deg_per_s: f64,
    /// Skid: torque capacity of the steer unit's brake, per wheel of the inner side \[N m\];
    /// beyond it the unit slips and the vehicle turns wider than asked.
    #[serde(default)]
    pub skid_brake_torque: f64,
    /// Linkage: the first steered axle's linkage (absent for the other kinds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linkage: Option<LinkageSpec>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowertrainSpec {
    /// Engine or motor speed cap \[rpm\]; the maps are clamped to \[0, max\].
    pub max_speed_rpm: f64,
    /// Full-throttle torque map: (speed rad/s, torque N m), increasing speed.
    pub full_throttle: Vec<[f64; 2]>,
    /// Closed-throttle (engine braking) map, same form.
    pub zero_throttle: Vec<[f64; 2]>,
    /// Forward gear ratios (output speed / engine speed), increasing.
    pub gears: Vec<f64>,
    /// Upshift above this engine speed \[rpm\] (ignored with one gear).
    pub upshift_rpm: f64,
    /// Downshift below this engine speed \[rpm\].
    pub downshift_rpm: f64,
    /// Final drive ratio (wheel speed / driveshaft speed).
    pub final_drive: f64,
    pub axle_differential: Differential,
    pub central_differential: Differential,
}

// `VehicleSpec::from_file` and `VehicleSpec::summary` are in `vehicles.rs`: both compare the
// vehicle with the built-ins (a user file may not reuse a built-in's name; a summary of a
// built-in tells what it stands for), and the built-ins are specs, so `spec` stays below them.
impl VehicleSpec {
    /// Parses and validates a vehicle from YAML text. `origin` names the source in errors,
    /// which name the field by its path (``ORIGIN: field `chassis.mass` is missing``).
    pub fn from_yaml_str(text: &str, origin: &str) -> Result<VehicleSpec, SpecError> {
        // text from any source (a file, Python) gets the size and nesting limits every verti
        // YAML input has, before the parser sees it
        verti_world::yaml::check_yaml_text(text, &verti_world::yaml::YamlLimits::DEFAULT).map_err(
            |r| SpecError::Invalid {
                origin: origin.to_string(),
                field: r.field.to_string(),
                problem: r.problem,
            },
        )?;
        let parse_error = |message: String| SpecError::Parse {
            origin: origin.to_string(),
            message,
        };
        // an empty file (or one of comments only) would otherwise report its first field missing
        if text.lines().all(|l| {
            let l = l.trim();
            l.is_empty() || l.starts_with('#') || l == "---"
        }) {
            return Err(parse_error(
                "the file is empty; a vehicle file is a mapping of fields (see `verti vehicle show hmmwv --yaml`)".into(),
            ));
        }
        let spec: VehicleSpec = serde_norway::from_str(text)
            .map_err(|e| parse_error(verti_core::messages::explain_serde_error(&e.to_string())))?;
        spec.validate(origin)?;
        Ok(spec)
    }

    /// YAML text of this vehicle (round-trips through [`VehicleSpec::from_yaml_str`]).
    pub fn to_yaml(&self) -> String {
        serde_norway::to_string(self).unwrap_or_default()
    }

    /// Number of wheels (two per axle).
    pub fn wheel_count(&self) -> usize {
        2 * self.axles.len()
    }

    pub fn is_tracked(&self) -> bool {
        self.track.is_some()
    }

    /// Diameter of the largest wheel \[m\]: how far below a soil surface the chassis meets a
    /// floor, and below which a reference chassis has fallen through the soil.
    pub fn largest_wheel_diameter(&self) -> f64 {
        2.0 * self
            .axles
            .iter()
            .map(|a| a.wheel.radius)
            .fold(0.0, f64::max)
    }

    /// Total mass: sprung + unsprung (+ tracks, which are part of the sprung mass).
    pub fn total_mass(&self) -> f64 {
        self.chassis.mass
            + self.track.map_or(0.0, |t| 2.0 * t.track_mass)
            + self
                .axles
                .iter()
                .map(|a| 2.0 * a.wheel.unsprung_mass)
                .sum::<f64>()
    }

    /// Distance from the first to the last axle.
    pub fn wheelbase(&self) -> f64 {
        let first = self.axles.first().map_or(0.0, |a| a.x);
        let last = self.axles.last().map_or(0.0, |a| a.x);
        first - last
    }

    /// Checks every field; the error names the first bad field.
    pub fn validate(&self, origin: &str) -> Result<(), SpecError> {
        let bad = |field: String, problem: String| SpecError::Invalid {
            origin: origin.to_string(),
            field,
            problem,
        };
        let pos = |field: &str, v: f64| -> Result<(), SpecError> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(bad(
                    field.to_string(),
                    format!("{v} must be a positive finite number"),
                ))
            }
        };
        let nonneg = |field: &str, v: f64| -> Result<(), SpecError> {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(bad(
                    field.to_string(),
                    format!("{v} must be a finite number >= 0"),
                ))
            }
        };
        let finite = |field: &str, v: f64| -> Result<(), SpecError> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(bad(field.to_string(), format!("{v} must be finite")))
            }
        };
        if self.name.trim().is_empty() {
            return Err(bad("name".into(), "must not be empty".into()));
        }
        // the same range as world scales: a vehicle drives a world of its own scale
        verti_world::scale::check_scale(self.scale)
            .map_err(|e| bad("scale".into(), e.to_string()))?;
        pos("internal_step", self.internal_step)?;
        if !(1e-5..=0.01).contains(&self.internal_step) {
            return Err(bad(
                "internal_step".into(),
                format!("{} s is outside [1e-5, 0.01] s", self.internal_step),
            ));
        }
        let c = &self.chassis;
        pos("chassis.mass", c.mass)?;
        for (i, v) in c.inertia.iter().enumerate() {
            pos(&format!("chassis.inertia[{i}]"), *v)?;
        }
        let [a, b, cc] = c.inertia;
        if a + b < cc || a + cc < b || b + cc < a {
            return Err(bad(
                "chassis.inertia".into(),
                "violates the triangle inequality of a rigid body".into(),
            ));
        }
        for (i, v) in c.com.iter().enumerate() {
            finite(&format!("chassis.com[{i}]"), *v)?;
        }
        for i in 0..3 {
            finite(
                &format!("chassis.collision_box.center[{i}]"),
                c.collision_box.center[i],
            )?;
            pos(
                &format!("chassis.collision_box.size[{i}]"),
                c.collision_box.size[i],
            )?;
        }
        nonneg("chassis.friction", c.friction)?;
        if self.axles.is_empty() {
            return Err(bad(
                "axles".into(),
                "a vehicle needs at least one axle".into(),
            ));
        }
        if self.wheel_count() > MAX_WHEELS {
            return Err(bad(
                "axles".into(),
                format!(
                    "{} wheels; at most {MAX_WHEELS} are supported",
                    self.wheel_count()
                ),
            ));
        }
        for (i, ax) in self.axles.iter().enumerate() {
            let f = |name: &str| format!("axles[{i}].{name}");
            finite(&f("x"), ax.x)?;
            finite(&f("z"), ax.z)?;
            pos(&f("track"), ax.track)?;
            nonneg(&f("brake_torque"), ax.brake_torque)?;
            let s = &ax.suspension;
            pos(&f("suspension.stiffness"), s.stiffness)?;
            nonneg(&f("suspension.damping"), s.damping)?;
            pos(&f("suspension.bump_travel"), s.bump_travel)?;
            nonneg(&f("suspension.rebound_travel"), s.rebound_travel)?;
            pos(&f("suspension.stop_stiffness"), s.stop_stiffness)?;
            let w = &ax.wheel;
            pos(&f("wheel.radius"), w.radius)?;
            pos(&f("wheel.width"), w.width)?;
            if w.width > ax.track {
                return Err(bad(
                    f("wheel.width"),
                    format!(
                        "{} is wider than the track {}: the axle's two wheels would overlap",
                        w.width, ax.track
                    ),
                ));
            }
            pos(&f("wheel.rim_radius"), w.rim_radius)?;
            if w.rim_radius >= w.radius {
                return Err(bad(
                    f("wheel.rim_radius"),
                    format!(
                        "{} must be smaller than the radius {}",
                        w.rim_radius, w.radius
                    ),
                ));
            }
            pos(&f("wheel.unsprung_mass"), w.unsprung_mass)?;
            pos(&f("wheel.spin_inertia"), w.spin_inertia)?;
            if let Some(sa) = &ax.solid_axle {
                for (name, d) in [
                    ("spring_track", sa.spring_track),
                    ("damper_track", sa.damper_track),
                ] {
                    pos(&f(&format!("solid_axle.{name}")), d)?;
                    if d > ax.track {
                        return Err(bad(
                            f(&format!("solid_axle.{name}")),
                            format!("{d} must not exceed the track {}", ax.track),
                        ));
                    }
                }
                if let Some(beam) = &sa.beam {
                    pos(&f("solid_axle.beam.mass"), beam.mass)?;
                    pos(&f("solid_axle.beam.roll_inertia"), beam.roll_inertia)?;
                    let ends = 2.0 * ax.wheel.unsprung_mass;
                    if beam.mass > ends {
                        return Err(bad(
                            f("solid_axle.beam.mass"),
                            format!(
                                "{} is more than the two wheels' unsprung mass {ends}, which \
                                 includes the beam",
                                beam.mass
                            ),
                        ));
                    }
                }
            }
            if let Some(h) = ax.roll_centre_height {
                finite(&f("roll_centre_height"), h)?;
                if h.abs() > ax.track {
                    return Err(bad(
                        f("roll_centre_height"),
                        format!(
                            "{h} is further from the ground than the track {} (a roll centre \
                             sits within a wheel diameter or so of the ground)",
                            ax.track
                        ),
                    ));
                }
            }
            if let Some(g) = ax.camber_gain_deg_per_m {
                finite(&f("camber_gain_deg_per_m"), g)?;
                if ax.solid_axle.is_some() {
                    return Err(bad(
                        f("camber_gain_deg_per_m"),
                        "a solid axle's wheels tilt with its beam; camber gain is for \
                         independent wheels"
                            .into(),
                    ));
                }
                // a swing arm shorter than the wheel's radius is no suspension
                let per_m = g.to_radians().abs();
                if per_m * ax.wheel.radius > 1.0 {
                    return Err(bad(
                        f("camber_gain_deg_per_m"),
                        format!(
                            "{g}: a swing arm of {:.3} m, shorter than the wheel's radius {}",
                            1.0 / per_m,
                            ax.wheel.radius
                        ),
                    ));
                }
            }
            if let Some(bar) = &ax.anti_roll_bar {
                nonneg(&f("anti_roll_bar.rate"), bar.rate)?;
            }
            if i > 0 && ax.x >= self.axles[i - 1].x {
                return Err(bad(
                    f("x"),
                    "axles must be listed from front to rear (decreasing x)".into(),
                ));
            }
        }
        if !self.axles.iter().any(|a| a.driven) {
            return Err(bad("axles".into(), "no axle is driven".into()));
        }
        let t = &self.tyre;
        pos("tyre.radial_stiffness", t.radial_stiffness)?;
        nonneg("tyre.radial_damping", t.radial_damping)?;
        pos("tyre.friction", t.friction)?;
        nonneg("tyre.rolling_resistance", t.rolling_resistance)?;
        pos("tyre.relaxation_length", t.relaxation_length)?;
        for (name, df0, fm, sm, fs, ss) in [
            ("x", t.dfx0, t.fxm, t.sxm, t.fxs, t.sxs),
            ("y", t.dfy0, t.fym, t.sym, t.fys, t.sys),
        ] {
            pos(&format!("tyre.df{name}0"), df0)?;
            pos(&format!("tyre.f{name}m"), fm)?;
            pos(&format!("tyre.s{name}m"), sm)?;
            pos(&format!("tyre.f{name}s"), fs)?;
            pos(&format!("tyre.s{name}s"), ss)?;
            if df0 * sm <= fm {
                return Err(bad(
                    format!("tyre.df{name}0"),
                    format!(
                        "initial slope {df0} must exceed f{name}m / s{name}m = {}",
                        fm / sm
                    ),
                ));
            }
            if ss <= sm || fs > fm {
                return Err(bad(format!("tyre.s{name}s"), "sliding slip must exceed the peak slip and sliding force must not exceed the peak".into()));
            }
        }
        let st = &self.steering;
        if !(st.max_angle_deg.is_finite() && st.max_angle_deg > 0.0 && st.max_angle_deg < 80.0) {
            return Err(bad(
                "steering.max_angle_deg".into(),
                format!("{} must be in (0, 80)", st.max_angle_deg),
            ));
        }
        pos("steering.rate_deg_per_s", st.rate_deg_per_s)?;
        if st.linkage.is_some() != (st.kind == SteeringKind::Linkage) {
            return Err(bad(
                "steering.linkage".into(),
                "a linkage is given with `kind: linkage`, and only then".into(),
            ));
        }
        if let Some(l) = &st.linkage {
            crate::linkage::validate(l, "steering.linkage")
                .map_err(|(field, problem)| bad(field, problem))?;
            // the systems plan with a bicycle of `max_angle_deg`: it must be the linkage's
            // (the mean of the two directions' where left and right locks differ)
            let full = crate::linkage::full_lock_bicycle_angle(l).to_degrees();
            if (full - st.max_angle_deg).abs() > 0.05 {
                return Err(bad(
                    "steering.max_angle_deg".into(),
                    format!(
                        "{} is not the linkage's bicycle angle at full input, {full:.2}°",
                        st.max_angle_deg
                    ),
                ));
            }
        }
        // with `kind: linkage` the first steered axle takes `steering.linkage`, every further
        // steered axle its own `linkage`; no other axle has one
        let first_steered = self.axles.iter().position(|a| a.steered);
        for (k, ax) in self.axles.iter().enumerate() {
            let field = format!("axles[{k}].linkage");
            let wanted = st.kind == SteeringKind::Linkage && ax.steered && Some(k) != first_steered;
            match (&ax.linkage, wanted) {
                (Some(l), true) => crate::linkage::validate(l, &field)
                    .map_err(|(field, problem)| bad(field, problem))?,
                (None, true) => {
                    return Err(bad(
                        field,
                        "missing: with `steering.kind: linkage`, a steered axle after the first \
                         gives its own linkage"
                            .into(),
                    ));
                }
                (Some(_), false) => {
                    return Err(bad(
                        field,
                        "only a steered axle after the first, with `steering.kind: linkage`, \
                         has its own linkage (the first steered axle's is `steering.linkage`)"
                            .into(),
                    ));
                }
                (None, false) => {}
            }
        }
        let steered = self.axles.iter().filter(|a| a.steered).count();
        if st.kind == SteeringKind::Linkage && steered > MAX_LINKAGES {
            return Err(bad(
                "axles".into(),
                format!("{steered} steered axles: linkage steering takes at most {MAX_LINKAGES}"),
            ));
        }
        match st.kind {
            SteeringKind::Ackermann | SteeringKind::Linkage => {
                if !self.axles.iter().any(|a| a.steered) {
                    return Err(bad(
                        "axles".into(),
                        "Ackermann steering needs a steered axle".into(),
                    ));
                }
                if self.axles.iter().all(|a| a.steered) {
                    return Err(bad(
                        "axles".into(),
                        "Ackermann steering needs at least one unsteered axle".into(),
                    ));
                }
            }
            SteeringKind::Skid => {
                pos("steering.skid_brake_torque", st.skid_brake_torque)?;
                if self.wheelbase() <= 0.0 {
                    return Err(bad(
                        "axles".into(),
                        "skid steering needs axles at more than one x (the equivalent bicycle's \
                         wheelbase is the first axle's x minus the last's)"
                            .into(),
                    ));
                }
                if self.axles.iter().any(|a| a.steered) {
                    return Err(bad(
                        "axles".into(),
                        "skid-steered vehicles have no steered axles".into(),
                    ));
                }
            }
        }
        let p = &self.powertrain;
        pos("powertrain.max_speed_rpm", p.max_speed_rpm)?;
        for (name, map) in [
            ("full_throttle", &p.full_throttle),
            ("zero_throttle", &p.zero_throttle),
        ] {
            if map.len() < 2 {
                return Err(bad(
                    format!("powertrain.{name}"),
                    "a map needs at least two points".into(),
                ));
            }
            for (k, pt) in map.iter().enumerate() {
                finite(&format!("powertrain.{name}[{k}][0]"), pt[0])?;
                finite(&format!("powertrain.{name}[{k}][1]"), pt[1])?;
                // finite is not enough: a torque near f64::MAX overflows to infinity once
                // multiplied through the drivetrain, and the simulator meets inf - inf = NaN
                // inside a step (found by tests/fuzz_vehicle.rs with 1e308)
                if pt[1].abs() > MAX_ENGINE_TORQUE {
                    return Err(bad(
                        format!("powertrain.{name}[{k}][1]"),
                        format!(
                            "torque {} N m is beyond ±{MAX_ENGINE_TORQUE:e} N m, far more than any engine",
                            pt[1]
                        ),
                    ));
                }
                if k > 0 && pt[0] <= map[k - 1][0] {
                    return Err(bad(
                        format!("powertrain.{name}[{k}]"),
                        "speeds must increase".into(),
                    ));
                }
            }
        }
        if p.gears.is_empty() {
            return Err(bad(
                "powertrain.gears".into(),
                "needs at least one gear".into(),
            ));
        }
        for (k, g) in p.gears.iter().enumerate() {
            pos(&format!("powertrain.gears[{k}]"), *g)?;
            if k > 0 && *g <= p.gears[k - 1] {
                return Err(bad(
                    format!("powertrain.gears[{k}]"),
                    "gear ratios must increase".into(),
                ));
            }
        }
        pos("powertrain.upshift_rpm", p.upshift_rpm)?;
        nonneg("powertrain.downshift_rpm", p.downshift_rpm)?;
        if p.gears.len() > 1 && p.downshift_rpm * p.gears[1] / p.gears[0] >= p.upshift_rpm {
            return Err(bad(
                "powertrain.downshift_rpm".into(),
                "shift bands overlap: an upshift would immediately downshift".into(),
            ));
        }
        pos("powertrain.final_drive", p.final_drive)?;
        for (field, d) in [
            ("powertrain.axle_differential", p.axle_differential),
            ("powertrain.central_differential", p.central_differential),
        ] {
            if let Differential::Clutch(t) = d {
                nonneg(&format!("{field}.clutch"), t)?;
            }
        }
        if let Differential::Clutch(_) = p.central_differential {
            let driven = self.axles.iter().filter(|a| a.driven).count();
            if driven != 2 || self.is_tracked() || p.axle_differential == Differential::Locked {
                return Err(bad(
                    "powertrain.central_differential".into(),
                    format!(
                        "a clutch central differential joins two driven axles with open or clutch axle differentials; this vehicle has {driven} driven axles{}",
                        if p.axle_differential == Differential::Locked {
                            " and locked axle differentials"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        }
        if let Some(tr) = &self.track {
            nonneg("track.track_mass", tr.track_mass)?;
            if let Some(runs) = &tr.runs {
                let (first, last) = (&self.axles[0], &self.axles[self.axles.len() - 1]);
                runs.check((first.x, first.z), (last.x, last.z), first.wheel.radius)
                    .map_err(|(field, problem)| bad(field, problem))?;
            }
            if st.kind != SteeringKind::Skid {
                return Err(bad(
                    "steering.kind".into(),
                    "a tracked vehicle must use skid steering".into(),
                ));
            }
        }
        Ok(())
    }
}
