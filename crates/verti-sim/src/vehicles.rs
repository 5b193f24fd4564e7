//! The built-in vehicles, shipped as YAML files in `crates/verti-sim/vehicles/` and embedded in
//! the binary. Users add their own with [`crate::VehicleSpec::from_file`].

use crate::error::SpecError;
use crate::spec::VehicleSpec;

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
        suspension_families: &["double wishbone"],
        steering_families: &["pitman arm"],
        suspension: "double wishbone (Chrono's reduced double-A-arm), modelled as independent wheels",
        steering: "Pitman arm, modelled as Ackermann geometry up to the 30.23° road-wheel angle",
        source: "Chrono 9.0.1 HMMWV_Reduced as Verti-Bench uses it (physics_spec §3.1)",
    };
    let man = |chassis| Mechanisms {
        chassis,
        suspension_families: &["multilink"],
        steering_families: &["bellcrank/rotary arm"],
        suspension: "solid three-link (multi-link beam) axles after Chrono's MAN Kat1, modelled as independent wheels",
        steering: "rotary arm (bellcrank), modelled as Ackermann geometry",
        source: "Chrono MAN Kat1 chassis and layout (physics_spec §3.3); springs, tyres, engine chosen",
    };
    Some(match name {
        "hmmwv" | "hmmwv-handling" => hmmwv,
        "artcar" => Mechanisms {
            chassis: "4-wheeled, 1/6 scale",
            suspension_families: &["double wishbone"],
            steering_families: &["pitman arm"],
            suspension: "double wishbone, modelled as independent wheels",
            steering: "Pitman arm, modelled as Ackermann geometry",
            source: "Chrono ARTcar (physics_spec §3.2); COM, wheel rate, motor voltage chosen",
        },
        "verti4" => Mechanisms {
            chassis: "4-wheeled, 1/10 scale",
            suspension_families: &["multilink"],
            steering_families: &["bellcrank/rotary arm"],
            suspension: "solid three-link (multi-link beam) axles, modelled as independent wheels",
            steering: "rotary arm / bellcrank, modelled as Ackermann geometry",
            source: "Verti-4-Wheeler C++ model in the Verti-Bench fork (verti_bench_spec §4.3); springs, motor, inertia chosen",
        },
        "truck6" => man("6-wheeled"),
        "truck8" => man("8-wheeled"),
        "m113" => Mechanisms {
            chassis: "2-tracked",
            suspension_families: &["tensioned"],
            steering_families: &["differential"],
            suspension: "torsion-arm road wheels on a tensioned track, modelled as independent road wheels tied to one spin per side",
            steering: "differential (skid) steering: torque bias and inner-side braking",
            source: "Chrono M113 (physics_spec §3.3); torsion rate, dampers, gears chosen",
        },
        "uaz" => Mechanisms {
            chassis: "4-wheeled",
            suspension_families: &["toe-bar leaf-spring"],
            steering_families: &["toe-bar", "bellcrank/rotary arm"],
            suspension: "leaf-spring solid axles (toe-bar axle in front), modelled as solid axles: \
                         wheels coupled through springs 1.028 m and dampers 0.882 m apart",
            steering: "toe-bar axle steered by a drag link from a rotary Pitman arm, modelled as \
                       Ackermann geometry up to the 27° road-wheel angle",
            source: "Chrono UAZ469 / UAZBUS (data/vehicle/uaz, src/chrono_models/vehicle/uaz)",
        },
        "gator" => Mechanisms {
            chassis: "4-wheeled",
            suspension_families: &["single wishbone"],
            steering_families: &["rack-and-pinion"],
            suspension: "single wishbone in front (wheel rate from the strut's motion ratio 0.62), \
                         rigid rear axle (a spring as stiff as the step allows)",
            steering: "rack and pinion, modelled as Ackermann geometry up to the 25° road-wheel angle",
            source: "Chrono Gator (src/chrono_models/vehicle/gator, data/vehicle/gator/json)",
        },
        "sedan" => Mechanisms {
            chassis: "4-wheeled",
            suspension_families: &["double wishbone", "multilink"],
            steering_families: &["rack-and-pinion"],
            suspension: "double wishbone in front, multilink rear (upper A-arm, lateral, trailing \
                         and toe links), modelled as independent wheels at their wheel rates (coil \
                         motion ratios 0.519 front, 0.612 rear, by virtual work)",
            steering: "rack and pinion, modelled as Ackermann geometry up to the 25° road-wheel angle",
            source: "Chrono Sedan, C++ model (src/chrono_models/vehicle/sedan)",
        },
        _ => return None,
    })
}
