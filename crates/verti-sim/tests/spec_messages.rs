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
