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
use verti_world::World;

/// `default` cases, or `PROPTEST_CASES` when set (a longer run than CI's).
fn config(default: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    ProptestConfig {
        cases,
        // a failure is printed shrunk; no regression file is written into the source tree
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// One edit of a byte string; positions are taken modulo the current length.
#[derive(Clone, Debug)]
enum Edit {
    Flip(usize, u8),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
    Truncate(usize),
    /// Replace the n-th number in the text by an extreme one.
    Number(usize, &'static str),
}

/// The world fuzzer's extreme numbers and the (1e-30, 1e308, -1, .nan, .inf), with
/// their negatives and tiny ones near the edge of validity.
const EXTREMES: [&str; 18] = [
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

/// Edits of YAML text that keep it ASCII; extreme numbers are the most common edit, since a
/// file that still parses reaches the most checks and the simulator.
fn text_edit_strategy() -> impl Strategy<Value = Edit> {
    let yaml_bytes = prop::sample::select(b"[]{},:-#&*!|>'\" 0123456789.eE+abc\n\t".to_vec());
    prop_oneof![
        1 => (any::<usize>(), 1u8..=127).prop_map(|(p, x)| Edit::Flip(p, x)),
        1 => (any::<usize>(), prop::collection::vec(yaml_bytes, 1..16))
            .prop_map(|(p, b)| Edit::Insert(p, b)),
        1 => (any::<usize>(), 1usize..64).prop_map(|(p, n)| Edit::Delete(p, n)),
        1 => any::<usize>().prop_map(Edit::Truncate),
        6 => number_edit(),
    ]
}

fn number_edit() -> impl Strategy<Value = Edit> {
    (any::<usize>(), prop::sample::select(EXTREMES.to_vec())).prop_map(|(n, v)| Edit::Number(n, v))
}

/// Start and end of every number-looking token (after a space, `[`, `,` or `:`).
fn number_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = (b[i].is_ascii_digit() || b[i] == b'-')
            && i > 0
            && matches!(b[i - 1], b' ' | b'[' | b',' | b':');
        if starts {
            let j = i + b[i..]
                .iter()
                .take_while(|c| c.is_ascii_digit() || matches!(c, b'.' | b'e' | b'-' | b'+'))
                .count();
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    let at = |p: usize, len: usize| if len == 0 { 0 } else { p % len };
    match edit {
        Edit::Flip(p, x) => {
            if !bytes.is_empty() {
                let i = at(*p, bytes.len());
                bytes[i] ^= x;
            }
        }
        Edit::Insert(p, b) => {
            let i = at(*p, bytes.len() + 1);
            bytes.splice(i..i, b.iter().copied());
        }
        Edit::Delete(p, n) => {
            let i = at(*p, bytes.len());
            let j = (i + n).min(bytes.len());
            bytes.drain(i..j);
        }
        Edit::Truncate(p) => bytes.truncate(at(*p, bytes.len() + 1)),
        Edit::Number(n, v) => {
            let spans = number_spans(bytes);
            if !spans.is_empty() {
                let (i, j) = spans[n % spans.len()];
                bytes.splice(i..j, v.bytes());
            }
        }
    }
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
    let mut b = vehicles::builtin_yaml(name).unwrap().as_bytes().to_vec();
    for e in edits {
        apply(&mut b, e);
    }
    b
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
