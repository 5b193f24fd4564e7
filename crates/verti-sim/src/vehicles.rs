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
