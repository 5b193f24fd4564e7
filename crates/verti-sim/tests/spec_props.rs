//! Property test of vehicle files: randomly damaged copies of a valid vehicle YAML are read
//! into a vehicle or refused with a message naming the origin, never a panic. Cases are capped
//! so the file runs in a second or two in a debug build.

use proptest::prelude::*;
use verti_sim::{VehicleSpec, vehicles};

/// One damage to the text, at a position given as a fraction of its length.
#[derive(Clone, Debug)]
enum Edit {
    DeleteLine(f64),
    DuplicateLine(f64),
    SwapLines(f64, f64),
    /// Replaces the value after a `key:` with a hostile token.
    ReplaceValue(f64, &'static str),
    InsertChar(f64, char),
    DeleteChar(f64),
    Truncate(f64),
}

const TOKENS: &[&str] = &[
    "",
    "~",
    "nan",
    ".nan",
    "-.inf",
    "1e400",
    "-1",
    "0",
    "1e-300",
    "abc",
    "[]",
    "{}",
    "[1, 2]",
    "true",
    "'x'",
    "&a 1",
    "*a",
    "!!str 5",
    "- 1",
    "{a: [1",
    "\"",
    "18446744073709551616",
];

fn edit() -> impl Strategy<Value = Edit> {
    let at = 0.0f64..1.0;
    let chars: Vec<char> = ":-[]{}#,&*!|>'\" \t\n0123456789.e".chars().collect();
    prop_oneof![
        at.clone().prop_map(Edit::DeleteLine),
        at.clone().prop_map(Edit::DuplicateLine),
        (at.clone(), at.clone()).prop_map(|(a, b)| Edit::SwapLines(a, b)),
        (at.clone(), prop::sample::select(TOKENS)).prop_map(|(a, t)| Edit::ReplaceValue(a, t)),
        (at.clone(), prop::sample::select(chars)).prop_map(|(a, c)| Edit::InsertChar(a, c)),
        at.clone().prop_map(Edit::DeleteChar),
        at.prop_map(Edit::Truncate),
    ]
}

fn index(fraction: f64, len: usize) -> usize {
    ((fraction * len as f64) as usize).min(len.saturating_sub(1))
}

fn apply(text: &str, e: &Edit) -> String {
    if text.is_empty() {
        // truncated to nothing: there is nothing left to damage
        return String::new();
    }
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let n = lines.len();
    let mut chars: Vec<char> = text.chars().collect();
    match *e {
        Edit::DeleteLine(a) => {
            lines.remove(index(a, n));
        }
        Edit::DuplicateLine(a) => {
            let l = lines[index(a, n)].clone();
            lines.insert(index(a, n), l);
        }
        Edit::SwapLines(a, b) => lines.swap(index(a, n), index(b, n)),
        Edit::ReplaceValue(a, token) => {
            let i = index(a, n);
            if let Some((key, _)) = lines[i].split_once(": ") {
                lines[i] = format!("{key}: {token}");
            }
        }
        Edit::InsertChar(a, c) => {
            chars.insert(index(a, chars.len()), c);
            return chars.into_iter().collect();
        }
        Edit::DeleteChar(a) => {
            chars.remove(index(a, chars.len()));
            return chars.into_iter().collect();
        }
        Edit::Truncate(a) => return chars[..index(a, chars.len())].iter().collect(),
    }
    lines.join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 300,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn damaged_vehicle_files_never_panic(
        name in prop::sample::select(vehicles::builtin_names()),
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        let mut text = vehicles::builtin_yaml(name).unwrap().to_string();
        for e in &edits {
            text = apply(&text, e);
        }
        if let Err(e) = VehicleSpec::from_yaml_str(&text, "damaged.yaml") {
            let m = e.to_string();
            prop_assert!(m.starts_with("damaged.yaml: "), "{}", m);
            // serde's type names never reach the user
            prop_assert!(!m.contains("struct ") && !m.contains("expected f64"), "{}", m);
        }
    }

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        let _ = VehicleSpec::from_yaml_str(&text, "random.yaml");
    }
}
