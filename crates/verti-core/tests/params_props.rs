//! Property tests of `name=value` parameter text (`--param`, `--elevation-param`): any text is
//! answered with a value or an error naming the parameter, never a panic; integers and floats
//! round-trip; a number is accepted for an int parameter exactly when it is an integer in range.
//! Cases are capped so the file runs in well under a second in a debug build.

use proptest::prelude::*;
use verti_core::params::{ParamSpec, ParamValue, parse_assignment};

fn specs() -> Vec<ParamSpec> {
    vec![
        ParamSpec::int("samples", 800, -5, 65536, "rollouts"),
        ParamSpec::float("lambda", 0.1, -2.5, 100.0, "temperature"),
        ParamSpec::bool("shout", false, "upper case"),
        ParamSpec::choice("word", "hi", &["hi", "hey"], "greeting"),
        ParamSpec::string("note", "", "free text"),
        ParamSpec::path("voice", "", "a voice file"),
    ]
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 512,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// `name=value` text: a declared or made-up name, then value characters that numbers, bools
/// and words are made of.
fn assignment_text() -> impl Strategy<Value = String> {
    let names = prop::sample::select(vec![
        "samples", "lambda", "shout", "word", "note", "nope", "",
    ]);
    let alphabet: Vec<char> = "0123456789.-+eEinfaNtrusyo= x_".chars().collect();
    let value = prop::collection::vec(prop::sample::select(alphabet), 0..24);
    (names, value).prop_map(|(n, v)| format!("{n}={}", v.into_iter().collect::<String>()))
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        let _ = parse_assignment("system s", &specs(), &text);
    }

    #[test]
    fn assignments_are_accepted_or_refused_by_name(text in assignment_text()) {
        let name = text.split_once('=').map(|(n, _)| n).unwrap_or_default();
        match parse_assignment("system s", &specs(), &text) {
            Ok((n, _)) => prop_assert_eq!(n, name),
            Err(e) => {
                let e = e.to_string();
                prop_assert!(e.starts_with("system s "), "{}", e);
                prop_assert!(e.contains(name), "{}", e);
                prop_assert!(e.len() < 300, "{}", e);
            }
        }
    }

    #[test]
    fn integers_in_range_round_trip(i in -5i64..=65536) {
        let (_, v) = parse_assignment("s", &specs(), &format!("samples={i}")).unwrap();
        prop_assert_eq!(v, ParamValue::Int(i));
    }

    #[test]
    fn integers_out_of_range_are_refused(i in any::<i64>()) {
        prop_assume!(!(-5..=65536).contains(&i));
        let e = parse_assignment("s", &specs(), &format!("samples={i}")).unwrap_err();
        prop_assert!(e.to_string().contains(&format!("{i} is outside [-5, 65536]")), "{}", e);
    }

    #[test]
    fn a_number_is_an_int_exactly_when_it_is_an_integer_in_range(x in any::<f64>()) {
        let accepted = parse_assignment("s", &specs(), &format!("samples={x}"));
        let integral = x.is_finite() && x.fract() == 0.0 && (-5.0..=65536.0).contains(&x);
        prop_assert_eq!(accepted.is_ok(), integral, "{} -> {:?}", x, accepted);
        if let Ok((_, v)) = accepted {
            prop_assert_eq!(v, ParamValue::Int(x as i64));
        }
    }

    #[test]
    fn floats_in_range_round_trip(x in -2.5f64..=100.0) {
        let (_, v) = parse_assignment("s", &specs(), &format!("lambda={x}")).unwrap();
        prop_assert_eq!(v, ParamValue::Float(x));
    }
}
