//! A vehicle file with a missing field or a value of the wrong type is reported as
//! "FILE: field `a.b` ..." in words, with no serde jargon (`f64`, `struct ChassisSpec`).

use verti_sim::{VehicleSpec, vehicles};

fn error_for(edit: impl Fn(&str) -> String) -> String {
    let dir = std::env::temp_dir().join(format!("verti-spec-messages-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("v{}.yaml", rand_suffix()));
    std::fs::write(&path, edit(vehicles::builtin_yaml("hmmwv").unwrap())).unwrap();
    let msg = VehicleSpec::from_file(&path).unwrap_err().to_string();
    std::fs::remove_file(&path).ok();
    let file = path.display().to_string();
    assert!(msg.starts_with(&format!("{file}: ")), "{msg}");
    msg[file.len() + 2..].to_string()
}

/// A distinct file name per call (tests run in parallel threads of one process).
fn rand_suffix() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    N.fetch_add(1, Ordering::Relaxed)
}

#[test]
fn missing_fields_are_named_by_their_path() {
    assert_eq!(
        error_for(|t| t.replace("internal_step: 0.005\n", "")),
        "field `internal_step` is missing"
    );
    assert_eq!(
        error_for(|t| t.replace("  mass: 2086.52\n", "")),
        "field `chassis.mass` is missing"
    );
    assert_eq!(
        error_for(|t| t.replacen("bump_travel: 0.18, ", "", 1)),
        "field `axles[0].suspension.bump_travel` is missing"
    );
}

#[test]
fn wrong_types_say_what_was_expected_and_what_was_found() {
    let m = error_for(|t| t.replace("mass: 2086.52", "mass: heavy"));
    assert!(
        m.starts_with(r#"field `chassis.mass`: expected a number, found the text "heavy" (line "#),
        "{m}"
    );
    let m = error_for(|t| t.replace("mass: 2086.52", "mass:"));
    assert!(
        m.starts_with("field `chassis.mass`: expected a number, found nothing"),
        "{m}"
    );
    let m = error_for(|t| t.replacen("steered: true", "steered: 2", 1));
    assert!(
        m.starts_with("field `axles[0].steered`: expected true or false, found the integer 2"),
        "{m}"
    );
    let m = error_for(|t| t.replace("[1078.52, 2955.66, 3570.20]", "[1078.52, 2955.66]"));
    assert!(
        m.starts_with("field `chassis.inertia`: expected a list of 3 items, found 2 items"),
        "{m}"
    );
    let m = error_for(|t| t.replace("kind: ackermann", "kind: ackerman"));
    assert!(
        m.starts_with("field `steering.kind`: `ackerman` is not one of ackermann, skid"),
        "{m}"
    );
    let m = error_for(|t| t.replace("  friction: 1.0\n", "  friction: 1.0\n  frictin: 2\n"));
    assert!(
        m.starts_with("field `chassis.frictin` is not a known field; known fields: mass,"),
        "{m}"
    );
    for m in [&m, &error_for(|t| t.replace("chassis:\n", "chassis: [\n"))] {
        assert!(
            !m.contains("f64") && !m.contains("struct ") && !m.contains(" at line "),
            "{m}"
        );
    }
}

#[test]
fn an_empty_file_says_so() {
    let m = error_for(|_| "# nothing here\n".to_string());
    assert!(m.starts_with("the file is empty"), "{m}");
}

/// A differential is `locked`, `open` or `{clutch: TORQUE}` (Chrono's locked differential: a
/// clutch that slips beyond its locking torque); a bad one is named by its field, and a
/// clutch reads back as written.
#[test]
fn differentials_read_as_locked_open_or_a_clutch() {
    fn edit(axle: &'static str, central: &'static str) -> impl Fn(&str) -> String {
        move |t: &str| {
            t.replace(
                "axle_differential: locked",
                &format!("axle_differential: {axle}"),
            )
            .replace(
                "central_differential: locked",
                &format!("central_differential: {central}"),
            )
        }
    }
    let m = error_for(edit("welded", "locked"));
    assert!(
        m.contains("powertrain.axle_differential")
            && m.contains("unknown differential `welded`: use locked, open or {clutch: TORQUE}"),
        "{m}"
    );
    assert_eq!(
        error_for(edit("{clutch: -5}", "locked")),
        "field `powertrain.axle_differential.clutch`: -5 must be a finite number >= 0"
    );
    let m = error_for(edit("locked", "{clutch: 100}"));
    assert!(
        m.contains("powertrain.central_differential") && m.contains("locked axle differentials"),
        "{m}"
    );
    // Chrono's HMMWV driveline reads, and writes back the same
    let text = edit("{clutch: 100.0}", "{clutch: 100.0}")(vehicles::builtin_yaml("hmmwv").unwrap());
    let spec = VehicleSpec::from_yaml_str(&text, "clutch.yaml").unwrap();
    assert_eq!(
        spec.powertrain.axle_differential,
        verti_sim::spec::Differential::Clutch(100.0)
    );
    let again = VehicleSpec::from_yaml_str(&spec.to_yaml(), "again.yaml").unwrap();
    assert_eq!(again.powertrain, spec.powertrain);
}
