//! Plain wording for errors of the file readers (serde with YAML or JSON).
//!
//! serde's messages are written for programmers and come in several shapes: `chassis: missing
//! field `mass` at line 10 column 3`, `chassis.mass: invalid type: string "heavy", expected f64
//! at line 10 column 9`, `missing field `name``. [`explain_serde_error`] rewrites them into one
//! shape that names the field by its full path and says what was expected and what was found:
//!
//! * ``field `chassis.mass` is missing``
//! * ``field `chassis.mass`: expected a number, found the text "heavy" (line 10, column 9)``
//! * ``field `steering.kind`: `ackerman` is not one of ackermann, skid (line 53, column 19)``
//!
//! The caller puts the file name in front (`FILE: field ...`). Messages of another shape (YAML
//! syntax errors, I/O) keep their words and get the same location suffix.

/// The wording of a serde error message (its `Display` text) for a user; see the module docs.
pub fn explain_serde_error(message: &str) -> String {
    let (text, location) = split_location(message);
    let (path, rest) = split_path(&text);
    let field = |name: &str| match path {
        Some(p) if name.is_empty() => format!("field `{p}`"),
        Some(p) => format!("field `{p}.{name}`"),
        None if name.is_empty() => "the file".to_string(),
        None => format!("field `{name}`"),
    };
    // missing fields are reported where their parent mapping starts, which only misleads
    if let Some(name) = backquoted_after(rest, "missing field ") {
        return format!("{} is missing", field(name));
    }
    let explained = if let Some(name) = backquoted_after(rest, "duplicate field ") {
        format!("{} is given twice", field(name))
    } else if let Some(name) = backquoted_after(rest, "unknown field ") {
        match rest.split_once(", expected one of ") {
            Some((_, known)) => format!(
                "{} is not a known field; known fields: {}",
                field(name),
                unquote_list(known)
            ),
            None => format!("{} is not a known field", field(name)),
        }
    } else if let Some(name) = backquoted_after(rest, "unknown variant ") {
        let choices = rest
            .split_once(", expected ")
            .map(|(_, c)| unquote_list(c.trim_start_matches("one of ")))
            .unwrap_or_default();
        format!("{}: `{name}` is not one of {choices}", field(""))
    } else if let Some(body) = rest
        .strip_prefix("invalid type: ")
        .or_else(|| rest.strip_prefix("invalid value: "))
    {
        match body.rsplit_once(", expected ") {
            Some((found, expected)) => format!(
                "{}: expected {}, found {}",
                field(""),
                expected_words(expected),
                found_words(found)
            ),
            None => format!("{}: {body}", field("")),
        }
    } else if let Some(body) = rest.strip_prefix("invalid length ") {
        match body.split_once(", expected ") {
            Some((n, expected)) => format!(
                "{}: expected {}, found {} {}",
                field(""),
                expected_words(expected),
                n,
                if n == "1" { "item" } else { "items" }
            ),
            None => format!("{}: invalid length {body}", field("")),
        }
    } else if rest.starts_with("data did not match any variant") {
        format!("{}: the value has none of the accepted forms", field(""))
    } else if path.is_some() {
        format!("{}: {rest}", field(""))
    } else {
        rest.to_string()
    };
    match location {
        Some((line, column)) => format!("{explained} (line {line}, column {column})"),
        None => explained,
    }
}

/// Takes ` at line L column C` out of a message (serde_json and serde_norway both append it;
/// YAML scanner errors continue after it with `, while scanning ...`).
fn split_location(message: &str) -> (String, Option<(u64, u64)>) {
    if let Some(at) = message.rfind(" at line ") {
        let tail = &message[at + " at line ".len()..];
        let mut words = tail.splitn(3, ' ');
        let line = words.next().and_then(|w| w.parse::<u64>().ok());
        let column_word = words.next();
        let rest = words.next().unwrap_or("");
        let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
        if let (Some(line), Some("column"), Ok(column)) = (line, column_word, digits.parse()) {
            let after = &rest[digits.len()..];
            return (format!("{}{after}", &message[..at]), Some((line, column)));
        }
    }
    (message.to_string(), None)
}

/// Splits a leading field path (`axles[0].suspension: ...`) from the message.
fn split_path(text: &str) -> (Option<&str>, &str) {
    if let Some((head, rest)) = text.split_once(": ") {
        let is_path = !head.is_empty()
            && head
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_.[]-?".contains(c));
        if is_path {
            return (Some(head), rest);
        }
    }
    (None, text)
}

/// The backquoted word after `prefix` at the start of `text`.
fn backquoted_after<'a>(text: &'a str, prefix: &str) -> Option<&'a str> {
    let rest = text.strip_prefix(prefix)?.strip_prefix('`')?;
    rest.split_once('`').map(|(name, _)| name)
}

/// `` `a`, `b` or `c` `` as `a, b, c`.
fn unquote_list(text: &str) -> String {
    text.replace(" or ", ", ").replace('`', "")
}

/// What serde says it expected, in words: `f64` is a number, `struct X` a mapping.
fn expected_words(expected: &str) -> String {
    let e = expected.trim();
    match e {
        "f64" | "f32" => "a number".into(),
        "u8" | "u16" | "u32" | "u64" | "u128" | "usize" => "a whole number >= 0".into(),
        "i8" | "i16" | "i32" | "i64" | "i128" | "isize" => "a whole number".into(),
        "a boolean" => "true or false".into(),
        "a string" => "text".into(),
        "a sequence" => "a list".into(),
        _ if e.starts_with("struct ") || e.starts_with("a map") => "a mapping of fields".into(),
        _ => {
            if let Some(n) = e
                .strip_prefix("an array of length ")
                .or_else(|| e.strip_prefix("a tuple of size "))
            {
                format!("a list of {n} items")
            } else {
                e.to_string()
            }
        }
    }
}

/// What serde says it found, in words: `string "x"` is the text "x", `unit value` nothing.
fn found_words(found: &str) -> String {
    let f = found.trim();
    let inner = |s: &str| s.trim_matches('`').to_string();
    if let Some(s) = f.strip_prefix("string ") {
        format!("the text {s}")
    } else if let Some(s) = f.strip_prefix("integer ") {
        format!("the integer {}", inner(s))
    } else if let Some(s) = f.strip_prefix("floating point ") {
        format!("the number {}", inner(s))
    } else if let Some(s) = f.strip_prefix("boolean ") {
        inner(s)
    } else {
        match f {
            "unit value" => "nothing (an empty value)".into(),
            "map" => "a mapping".into(),
            "sequence" => "a list".into(),
            _ => f.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::explain_serde_error as explain;

    #[test]
    fn missing_fields_are_named_by_their_full_path() {
        assert_eq!(
            explain("missing field `internal_step` at line 5 column 1"),
            "field `internal_step` is missing"
        );
        assert_eq!(
            explain("axles[0].suspension: missing field `bump_travel` at line 25 column 17"),
            "field `axles[0].suspension.bump_travel` is missing"
        );
        assert_eq!(explain("missing field `name`"), "field `name` is missing");
    }

    #[test]
    fn wrong_types_say_what_was_expected_and_found() {
        assert_eq!(
            explain(
                r#"chassis.mass: invalid type: string "heavy", expected f64 at line 10 column 9"#
            ),
            r#"field `chassis.mass`: expected a number, found the text "heavy" (line 10, column 9)"#
        );
        assert_eq!(
            explain(
                "axles[0].steered: invalid type: integer `2`, expected a boolean at line 22 column 14"
            ),
            "field `axles[0].steered`: expected true or false, found the integer 2 (line 22, column 14)"
        );
        assert_eq!(
            explain("chassis.mass: invalid type: unit value, expected f64 at line 10 column 8"),
            "field `chassis.mass`: expected a number, found nothing (an empty value) (line 10, column 8)"
        );
        assert_eq!(
            explain(
                "chassis: invalid type: sequence, expected struct ChassisSpec at line 9 column 10"
            ),
            "field `chassis`: expected a mapping of fields, found a list (line 9, column 10)"
        );
        assert_eq!(
            explain(
                "chassis.inertia: invalid length 2, expected an array of length 3 at line 11 column 12"
            ),
            "field `chassis.inertia`: expected a list of 3 items, found 2 items (line 11, column 12)"
        );
        assert_eq!(
            explain(r#"invalid type: string "hello", expected struct VehicleSpec"#),
            r#"the file: expected a mapping of fields, found the text "hello""#
        );
    }

    #[test]
    fn unknown_names_list_the_known_ones() {
        assert_eq!(
            explain(
                "chassis: unknown field `frictin`, expected one of `mass`, `friction` at line 18 column 3"
            ),
            "field `chassis.frictin` is not a known field; known fields: mass, friction (line 18, column 3)"
        );
        assert_eq!(
            explain(
                "steering.kind: unknown variant `ackerman`, expected `ackermann` or `skid` at line 53 column 19"
            ),
            "field `steering.kind`: `ackerman` is not one of ackermann, skid (line 53, column 19)"
        );
        assert_eq!(
            explain("chassis: duplicate field `friction` at line 10 column 3"),
            "field `chassis.friction` is given twice (line 10, column 3)"
        );
    }

    #[test]
    fn other_messages_keep_their_words_with_the_location_in_words() {
        assert_eq!(
            explain(
                "found character that cannot start any token at line 10 column 1, while scanning for the next token"
            ),
            "found character that cannot start any token, while scanning for the next token (line 10, column 1)"
        );
        assert_eq!(
            explain("expected value at line 1 column 1"),
            "expected value (line 1, column 1)"
        );
        assert_eq!(explain(""), "");
    }
}
