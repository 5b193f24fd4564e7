//! Typed parameters at the boundary: what text (`--param`) and typed values (Python) are
//! accepted, and that every refusal names the parameter, the value and what is accepted.

use verti_core::params::{ParamSpec, ParamValue, Params, parse_assignment};

fn specs() -> Vec<ParamSpec> {
    vec![
        ParamSpec::int("samples", 800, 1, 65536, "rollouts"),
        ParamSpec::float("lambda", 0.1, 1e-4, 100.0, "temperature"),
        ParamSpec::bool("shout", false, "upper case"),
        ParamSpec::choice("word", "hi", &["hi", "hey"], "greeting"),
    ]
}

fn text_err(text: &str) -> String {
    parse_assignment("system mppi", &specs(), text)
        .unwrap_err()
        .to_string()
}

fn value_err(name: &str, v: ParamValue) -> String {
    Params::resolve("system mppi", specs(), &[(name.to_string(), v)])
        .unwrap_err()
        .to_string()
}

#[test]
fn int_parameters_refuse_non_integers_by_name_value_and_type() {
    for (text, want) in [
        ("samples=2.5", "parameter samples: `2.5` is not an integer"),
        ("samples=NaN", "parameter samples: `NaN` is not an integer"),
        ("samples=inf", "parameter samples: `inf` is not an integer"),
        ("samples=abc", "parameter samples: `abc` is not an integer"),
        ("samples=", "parameter samples: `` is not an integer"),
        // exact integers too large for any range say so, briefly
        (
            "samples=1e300",
            "parameter samples: 1e300 is outside [1, 65536]",
        ),
        (
            "samples=99999999999999999999",
            "parameter samples: `99999999999999999999` is outside [1, 65536]",
        ),
        ("samples=-1", "parameter samples: -1 is outside [1, 65536]"),
    ] {
        let e = text_err(text);
        assert!(e.contains(want), "{text}: {e}");
        assert!(e.len() < 120, "{text}: message too long: {e}");
    }
    // the same values from Python, as numbers, get the same answers
    for (v, want) in [
        (ParamValue::Float(2.5), "samples: `2.5` is not an integer"),
        (
            ParamValue::Float(f64::NAN),
            "samples: `NaN` is not an integer",
        ),
        (
            ParamValue::Float(1e300),
            "samples: 1e300 is outside [1, 65536]",
        ),
        (
            ParamValue::Float(-1e19),
            "samples: -1e19 is outside [1, 65536]",
        ),
        (
            ParamValue::Str("abc".into()),
            "samples: expected int, got `abc`",
        ),
        (ParamValue::Bool(true), "samples: expected int, got `true`"),
    ] {
        let e = value_err("samples", v.clone());
        assert!(e.contains(want), "{v:?}: {e}");
    }
}

#[test]
fn exact_integers_are_accepted_the_same_way_from_text_and_from_numbers() {
    for text in [
        "samples=64",
        "samples=64.0",
        "samples=6.4e1",
        "samples= +64 ",
    ] {
        let (_, v) = parse_assignment("o", &specs(), text).unwrap();
        assert_eq!(v, ParamValue::Int(64), "{text}");
    }
    let p = Params::resolve("o", specs(), &[("samples".into(), ParamValue::Float(64.0))]).unwrap();
    assert_eq!(p.int("samples"), 64);
}

#[test]
fn float_bool_and_choice_parameters_refuse_what_they_do_not_accept() {
    for (text, want) in [
        (
            "lambda=nan",
            "parameter lambda: `NaN` is not a finite number",
        ),
        (
            "lambda=inf",
            "parameter lambda: `inf` is not a finite number",
        ),
        (
            "lambda=1e400",
            "parameter lambda: `inf` is not a finite number",
        ),
        (
            "lambda=1e300",
            "parameter lambda: 1e300 is outside [0.0001, 100]",
        ),
        ("lambda=fast", "parameter lambda: `fast` is not a number"),
        ("shout=2", "parameter shout: `2` is not true or false"),
        ("word=yo", "parameter word: `yo` is not one of hi, hey"),
    ] {
        let e = text_err(text);
        assert!(e.contains(want), "{text}: {e}");
    }
    let long = format!("word={}", "x".repeat(500));
    let e = text_err(&long);
    assert!(
        e.contains("(500 characters) is not one of hi, hey") && e.len() < 150,
        "{e}"
    );
    let e = value_err("lambda", ParamValue::Float(f64::NAN));
    assert!(e.contains("lambda: `NaN` is not a finite number"), "{e}");
    let e = value_err("shout", ParamValue::Int(2));
    assert!(e.contains("shout: expected bool, got `2`"), "{e}");
}

#[test]
fn a_parameter_given_twice_is_refused() {
    let given = vec![
        ("samples".to_string(), ParamValue::Int(10)),
        ("samples".to_string(), ParamValue::Int(20)),
    ];
    let e = Params::resolve("system mppi", specs(), &given)
        .unwrap_err()
        .to_string();
    assert_eq!(e, "system mppi parameter samples is given twice");
}

#[test]
fn a_recorded_value_of_the_wrong_shape_is_reported_as_such() {
    let e = serde_json::from_str::<Params>(r#"{"samples": [1, 2]}"#)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("expected a parameter value (a number, true/false or text)"),
        "{e}"
    );
    let p: Params = serde_json::from_str(r#"{"samples": 18446744073709551615}"#).unwrap();
    assert_eq!(p.get("samples"), Some(&ParamValue::Float(u64::MAX as f64)));
}
