//! Vehicle files with extreme numbers (hardening issue, item 9): a vehicle YAML damaged the
//! way `verti-world/tests/fuzz.rs` damages worlds (bytes flipped, inserted, deleted, the file
//! cut short, numbers swapped for extreme ones such as 1e-30, 1e308, -1, .nan, .inf) is read
//! into a vehicle or refused with an error naming the file, never a panic; and a vehicle that
//! is read must be usable: building the simulator, seating the vehicle and stepping it a few
//! times returns `Ok` or `Err`, never a panic. (`spec_props.rs` covers the parse alone.)
//!
//! Case counts are capped so the file runs in seconds in the dev profile; `PROPTEST_CASES`
//! overrides them for a longer run (`PROPTEST_CASES=5000 cargo test --release -p verti-sim
//! --test fuzz_vehicle`). A failing case is shrunk and printed by proptest.

use proptest::prelude::*;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};
use verti_sim::{Controls, Sim, SpecError, StartPose, VehicleSpec, testing, vehicles};
use verti_testkit::config;
use verti_testkit::mutate::{self, Edit, edited, number_spans, text_edit_strategy_with};
use verti_world::World;

/// The world fuzzer's extreme numbers and the (1e-30, 1e308, -1, .nan, .inf), with
/// their negatives and tiny ones near the edge of validity.
const EXTREMES: &[&str] = &[
    "1e-30",
    "1e308",
    "-1e308",
    "-1",
    ".nan",
    ".inf",
    "-.inf",
    "0",
    "-0.0",
    "1e30",
    "-1e30",
    "1e-320",
    "1e-9",
    "0.5",
    "1",
    "4294967296",
    "99999999999999999999",
    "1e15",
];

/// Edits of YAML text that keep it ASCII; extreme numbers are the most common edit (six in
/// ten: four parts of the common text mix, half of which are swaps, and one of swaps alone),
/// since a file that still parses reaches the most checks and the simulator.
fn text_edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![4 => text_edit_strategy_with(EXTREMES), 1 => number_edit()]
}

fn number_edit() -> impl Strategy<Value = Edit> {
    mutate::number_edit(EXTREMES)
}

/// A flat world of `scale`, built once per scale (the vehicle drives a world of its own).
fn flat_world(scale: f64) -> Arc<World> {
    static WORLDS: OnceLock<Mutex<BTreeMap<u64, Arc<World>>>> = OnceLock::new();
    let worlds = WORLDS.get_or_init(|| Mutex::new(BTreeMap::new()));
    let mut w = worlds.lock().unwrap_or_else(|e| e.into_inner());
    Arc::clone(
        w.entry(scale.to_bits())
            .or_insert_with(|| Arc::new(testing::flat_world(scale, 0.8))),
    )
}

/// Simulated seconds a vehicle that was read is driven: a few steps, bounded in internal
/// steps so that a valid but tiny `internal_step` (down to 1e-5 s) stays quick.
fn drive(spec: &VehicleSpec) {
    let world = flat_world(spec.scale);
    let Ok(sim) = Sim::new(&world, spec) else {
        return;
    };
    let Ok(mut state) = sim.state_at(StartPose::new(0.0, 0.0, 0.3)) else {
        return;
    };
    let dt = (100.0 * spec.internal_step).min(0.02);
    for k in 0..3 {
        let controls = Controls::new(0.8, 0.0, if k % 2 == 0 { 0.5 } else { -1.0 });
        if sim.step(&mut state, controls, dt).is_err() {
            // a vehicle that blows up is reported as an error, which is allowed
            return;
        }
    }
    let _ = (state.euler(), state.forward_speed(), sim.energy(&state));
}

/// Reads `text` as a vehicle file and drives what is read; an error names the file.
fn read_and_drive(text: &[u8]) -> Result<(), TestCaseError> {
    let Ok(text) = std::str::from_utf8(text) else {
        return Ok(());
    };
    match VehicleSpec::from_yaml_str(text, "fuzz.yaml") {
        Ok(spec) => {
            // what was read writes and reads back as the same vehicle
            let again = VehicleSpec::from_yaml_str(&spec.to_yaml(), "again.yaml");
            prop_assert!(again.is_ok(), "{:?}", again.err());
            drive(&spec);
        }
        Err(e) => {
            let m = e.to_string();
            prop_assert!(m.starts_with("fuzz.yaml: "), "{}", m);
            if let SpecError::Invalid { field, .. } = &e {
                prop_assert!(!field.is_empty(), "{}", m);
            }
        }
    }
    Ok(())
}

fn mutated(name: &str, edits: &[Edit]) -> Vec<u8> {
    edited(vehicles::builtin_yaml(name).unwrap().as_bytes(), edits)
}

proptest! {
    #![proptest_config(config(48))]

    /// One number of a built-in vehicle swapped for an extreme value: the file parses, so the
    /// validation decides, and what it accepts is driven.
    #[test]
    fn one_extreme_number_gives_a_usable_vehicle_or_an_error(
        name in prop::sample::select(vehicles::builtin_names()),
        edit in number_edit(),
    ) {
        read_and_drive(&mutated(name, &[edit]))?;
    }

    #[test]
    fn mutated_vehicle_files_never_panic(
        name in prop::sample::select(vehicles::builtin_names()),
        edits in prop::collection::vec(text_edit_strategy(), 1..6),
    ) {
        read_and_drive(&mutated(name, &edits))?;
    }
}

/// Every number of every built-in vehicle, one at a time, set to each of the extreme
/// values: read and driven, or refused by name. Deterministic, so that every field meets
/// them in CI (the proptests draw from all of `EXTREMES`).
#[test]
fn every_number_of_every_vehicle_at_the_extremes() {
    for name in vehicles::builtin_names() {
        let count = number_spans(vehicles::builtin_yaml(name).unwrap().as_bytes()).len();
        for n in 0..count {
            for v in ["1e-30", "1e308", "-1e308", "-1", ".nan", ".inf"] {
                let text = mutated(name, &[Edit::Number(n, v)]);
                if let Err(e) = read_and_drive(&text) {
                    panic!("{name}, number {n} set to {v}: {e}");
                }
            }
        }
    }
}

/// A torque map value near `f64::MAX` passed as finite, then overflowed through the drivetrain
/// and panicked a step on a NaN clamp bound (`friction.rs`); it is refused by name.
#[test]
fn an_engine_torque_near_f64_max_is_refused_by_name() {
    let mut spec = vehicles::builtin("hmmwv").unwrap();
    for torque in [1e308, -1e308, 1.1e7] {
        spec.powertrain.full_throttle[1][1] = torque;
        let e = VehicleSpec::from_yaml_str(&spec.to_yaml(), "big.yaml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("big.yaml: ") && e.contains("powertrain.full_throttle[1][1]"),
            "{e}"
        );
    }
}
