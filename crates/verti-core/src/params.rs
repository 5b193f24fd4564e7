//! Typed, documented parameters of anything built by name (mobility systems, elevation
//! sources): a [`ParamSpec`] declares a parameter (type, default, range or choices, doc);
//! [`Params::resolve`] checks given values against the declarations and fills in defaults;
//! [`ParamSpec::parse`] reads a value from command-line text per the declared type.
//!
//! Resolved [`Params`] serialise as a JSON object in declared order (`{"speed": 3.0,
//! "samples": 800, "weights": "models/tal.bin"}`), which is what `run.json` records.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A parameter problem, worded for the user and naming the parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError(pub String);

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ParamError {}

/// The type of a parameter and what values it accepts.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum ParamKind {
    /// A finite number in `[min, max]`.
    Float {
        min: f64,
        max: f64,
    },
    /// An integer in `[min, max]`.
    Int {
        min: i64,
        max: i64,
    },
    Bool,
    /// Text; one of `choices` unless that is empty.
    #[serde(rename = "string")]
    Str {
        choices: Vec<String>,
    },
    /// A file or directory path (e.g. network weights). A non-empty value must exist.
    Path,
}

impl ParamKind {
    /// `float`, `int`, `bool`, `string` or `path`.
    pub fn type_name(&self) -> &'static str {
        match self {
            ParamKind::Float { .. } => "float",
            ParamKind::Int { .. } => "int",
            ParamKind::Bool => "bool",
            ParamKind::Str { .. } => "string",
            ParamKind::Path => "path",
        }
    }

    /// What the kind accepts, for listings: `[0.1, 30]`, `one of a, b`, `true or false`, ...
    pub fn accepted(&self) -> String {
        match self {
            ParamKind::Float { min, max } => format!("[{min}, {max}]"),
            ParamKind::Int { min, max } => format!("[{min}, {max}]"),
            ParamKind::Bool => "true or false".into(),
            ParamKind::Str { choices } if choices.is_empty() => "any text".into(),
            ParamKind::Str { choices } => format!("one of {}", choices.join(", ")),
            ParamKind::Path => "an existing path, or empty for none".into(),
        }
    }
}

/// A parameter value.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Float(f64),
    Int(i64),
    Bool(bool),
    Str(String),
    Path(PathBuf),
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Float(v) => write!(f, "{v}"),
            ParamValue::Int(v) => write!(f, "{v}"),
            ParamValue::Bool(v) => write!(f, "{v}"),
            ParamValue::Str(v) => f.write_str(v),
            ParamValue::Path(v) => write!(f, "{}", v.display()),
        }
    }
}

impl From<f64> for ParamValue {
    fn from(v: f64) -> Self {
        ParamValue::Float(v)
    }
}
impl From<i64> for ParamValue {
    fn from(v: i64) -> Self {
        ParamValue::Int(v)
    }
}
impl From<bool> for ParamValue {
    fn from(v: bool) -> Self {
        ParamValue::Bool(v)
    }
}
impl From<&str> for ParamValue {
    fn from(v: &str) -> Self {
        ParamValue::Str(v.to_string())
    }
}
impl From<String> for ParamValue {
    fn from(v: String) -> Self {
        ParamValue::Str(v)
    }
}
impl From<PathBuf> for ParamValue {
    fn from(v: PathBuf) -> Self {
        ParamValue::Path(v)
    }
}
impl From<&Path> for ParamValue {
    fn from(v: &Path) -> Self {
        ParamValue::Path(v.to_path_buf())
    }
}

/// JSON form: a number, a boolean or a string (paths as strings).
impl Serialize for ParamValue {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            ParamValue::Float(v) => s.serialize_f64(*v),
            ParamValue::Int(v) => s.serialize_i64(*v),
            ParamValue::Bool(v) => s.serialize_bool(*v),
            ParamValue::Str(v) => s.serialize_str(v),
            ParamValue::Path(v) => s.serialize_str(&v.to_string_lossy()),
        }
    }
}

/// Reads back what [`Serialize`] wrote: integers as `Int`, other numbers as `Float`, strings
/// as `Str` (resolution against the declaration turns them into paths where declared so).
/// Written as a visitor rather than an untagged enum so that a bad value is reported as what
/// it is ("expected a number, true/false or text") instead of "did not match any variant".
impl<'de> Deserialize<'de> for ParamValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = ParamValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a parameter value (a number, true/false or text)")
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<ParamValue, E> {
                Ok(ParamValue::Bool(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<ParamValue, E> {
                Ok(ParamValue::Int(v))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ParamValue, E> {
                // beyond i64 it can only be out of any declared integer range; keep the number
                Ok(i64::try_from(v).map_or(ParamValue::Float(v as f64), ParamValue::Int))
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<ParamValue, E> {
                Ok(ParamValue::Float(v))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<ParamValue, E> {
                Ok(ParamValue::Str(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// The declaration of one parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamSpec {
    pub name: String,
    #[serde(flatten)]
    pub kind: ParamKind,
    pub default: ParamValue,
    pub doc: String,
}

impl ParamSpec {
    pub fn float(name: &str, default: f64, min: f64, max: f64, doc: &str) -> Self {
        Self::new(name, ParamKind::Float { min, max }, default.into(), doc)
    }
    pub fn int(name: &str, default: i64, min: i64, max: i64, doc: &str) -> Self {
        Self::new(name, ParamKind::Int { min, max }, default.into(), doc)
    }
    pub fn bool(name: &str, default: bool, doc: &str) -> Self {
        Self::new(name, ParamKind::Bool, default.into(), doc)
    }
    /// Free text.
    pub fn string(name: &str, default: &str, doc: &str) -> Self {
        let kind = ParamKind::Str { choices: vec![] };
        Self::new(name, kind, default.into(), doc)
    }
    /// One of a fixed set of words.
    pub fn choice(name: &str, default: &str, choices: &[&str], doc: &str) -> Self {
        let choices = choices.iter().map(|c| c.to_string()).collect();
        Self::new(name, ParamKind::Str { choices }, default.into(), doc)
    }
    /// A path; the default may be empty, meaning none.
    pub fn path(name: &str, default: &str, doc: &str) -> Self {
        Self::new(name, ParamKind::Path, PathBuf::from(default).into(), doc)
    }

    fn new(name: &str, kind: ParamKind, default: ParamValue, doc: &str) -> Self {
        ParamSpec {
            name: name.to_string(),
            kind,
            default,
            doc: doc.to_string(),
        }
    }

    fn err(&self, owner: &str, what: String) -> ParamError {
        ParamError(format!("{owner} parameter {}: {what}", self.name))
    }

    /// Reads a value from text (e.g. `--param name=value`) per the declared type, and checks it
    /// with [`ParamSpec::check`], the same check Python values get, so the command line and
    /// Python accept the same values: `2.0` and `2` for an int, never `2.5`.
    pub fn parse(&self, owner: &str, text: &str) -> Result<ParamValue, ParamError> {
        let t = text.trim();
        let v = match &self.kind {
            ParamKind::Float { .. } => match t.parse() {
                Ok(x) => ParamValue::Float(x),
                Err(_) => return Err(self.err(owner, format!("{} is not a number", quote(t)))),
            },
            ParamKind::Int { min, max } => match t.parse::<i64>() {
                Ok(i) => ParamValue::Int(i),
                // digits only, yet not an i64: an integer far outside any declared range
                Err(_) if is_integer_literal(t) => {
                    return Err(self.err(owner, format!("{} is outside [{min}, {max}]", quote(t))));
                }
                // `64.0` or `1e3` is an exact integer written as a number; `check` refuses the
                // rest (2.5, NaN, 1e300)
                Err(_) => ParamValue::Float(
                    t.parse()
                        .map_err(|_| self.err(owner, format!("{} is not an integer", quote(t))))?,
                ),
            },
            ParamKind::Bool => ParamValue::Bool(match t.to_ascii_lowercase().as_str() {
                "true" | "1" | "yes" | "on" => true,
                "false" | "0" | "no" | "off" => false,
                _ => {
                    return Err(self.err(owner, format!("{} is not true or false", quote(t))));
                }
            }),
            ParamKind::Str { .. } => ParamValue::Str(t.to_string()),
            ParamKind::Path => ParamValue::Path(PathBuf::from(t)),
        };
        self.check(owner, v)
    }

    /// Checks a value against the declaration, converting where nothing is lost (an integer
    /// for a float, an integral float for an integer, text for a path and back); returns the
    /// value in the declared type. Every refusal names the parameter, the value and what the
    /// parameter accepts.
    pub fn check(&self, owner: &str, value: ParamValue) -> Result<ParamValue, ParamError> {
        match (&self.kind, value) {
            (ParamKind::Float { min, max }, v @ (ParamValue::Float(_) | ParamValue::Int(_))) => {
                let x = match v {
                    ParamValue::Int(i) => i as f64,
                    ParamValue::Float(x) => x,
                    _ => unreachable!(),
                };
                if !x.is_finite() {
                    return Err(self.err(owner, format!("`{x}` is not a finite number")));
                }
                if !(x >= *min && x <= *max) {
                    let shown = show_float(x);
                    return Err(self.err(owner, format!("{shown} is outside [{min}, {max}]")));
                }
                Ok(ParamValue::Float(x))
            }
            (ParamKind::Int { min, max }, v @ (ParamValue::Float(_) | ParamValue::Int(_))) => {
                let i = match v {
                    ParamValue::Int(i) => i,
                    ParamValue::Float(x) if x.is_finite() && x.fract() == 0.0 => {
                        // an exact integer; beyond i64 it is outside every declared range
                        if x.abs() >= 9.0e18 {
                            let shown = show_float(x);
                            return Err(
                                self.err(owner, format!("{shown} is outside [{min}, {max}]"))
                            );
                        }
                        x as i64
                    }
                    ParamValue::Float(x) => {
                        let shown = show_float(x);
                        return Err(self.err(owner, format!("`{shown}` is not an integer")));
                    }
                    _ => unreachable!(),
                };
                if i < *min || i > *max {
                    return Err(self.err(owner, format!("{i} is outside [{min}, {max}]")));
                }
                Ok(ParamValue::Int(i))
            }
            (ParamKind::Bool, ParamValue::Bool(b)) => Ok(ParamValue::Bool(b)),
            (ParamKind::Str { choices }, v @ (ParamValue::Str(_) | ParamValue::Path(_))) => {
                let s = v.to_string();
                if !choices.is_empty() && !choices.contains(&s) {
                    return Err(self.err(
                        owner,
                        format!("{} is not one of {}", quote(&s), choices.join(", ")),
                    ));
                }
                Ok(ParamValue::Str(s))
            }
            (ParamKind::Path, v @ (ParamValue::Str(_) | ParamValue::Path(_))) => {
                let p = match v {
                    ParamValue::Str(s) => PathBuf::from(s),
                    ParamValue::Path(p) => p,
                    _ => unreachable!(),
                };
                if !p.as_os_str().is_empty() && !p.exists() {
                    let shown = quote(&p.display().to_string());
                    return Err(self.err(owner, format!("{shown} does not exist")));
                }
                Ok(ParamValue::Path(p))
            }
            (_, v) => {
                let shown = match &v {
                    ParamValue::Float(x) => format!("`{}`", show_float(*x)),
                    other => quote(&other.to_string()),
                };
                Err(self.err(
                    owner,
                    format!("expected {}, got {shown}", self.kind.type_name()),
                ))
            }
        }
    }
}

/// `text` in backquotes for a message, shortened when long, so a pasted blob or a 300-digit
/// number does not drown the message.
fn quote(text: &str) -> String {
    const MAX: usize = 40;
    if text.chars().count() <= MAX {
        format!("`{text}`")
    } else {
        let head: String = text.chars().take(MAX).collect();
        format!("`{head}...` ({} characters)", text.chars().count())
    }
}

/// A float as people write it: `2.5`, `100`, and `1e300` rather than 301 digits.
fn show_float(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-6..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// An optional sign then ASCII digits: text that means an integer even where i64 cannot hold it.
fn is_integer_literal(t: &str) -> bool {
    let digits = t.strip_prefix(['+', '-']).unwrap_or(t);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

/// Finds a declaration or says which ones exist.
fn spec_named<'a>(
    owner: &str,
    specs: &'a [ParamSpec],
    name: &str,
) -> Result<&'a ParamSpec, ParamError> {
    specs.iter().find(|s| s.name == name).ok_or_else(|| {
        let known: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
        ParamError(if known.is_empty() {
            format!("{owner} has no parameter `{name}`; it takes no parameters")
        } else {
            format!(
                "{owner} has no parameter `{name}`; its parameters: {}",
                known.join(", ")
            )
        })
    })
}

/// Parses `name=value` text against declarations.
pub fn parse_assignment(
    owner: &str,
    specs: &[ParamSpec],
    text: &str,
) -> Result<(String, ParamValue), ParamError> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| ParamError(format!("parameter `{text}` must look like name=value")))?;
    let spec = spec_named(owner, specs, name.trim())?;
    Ok((spec.name.clone(), spec.parse(owner, value)?))
}

/// Every declared parameter with its value, in declared order.
///
/// Made by [`Params::resolve`], which keeps the declarations for typed access and defaults.
/// Read back from JSON (`run.json`), a `Params` holds the recorded values only; equality
/// compares values only.
#[derive(Clone, Debug, Default)]
pub struct Params {
    values: Vec<(String, ParamValue)>,
    specs: Arc<[ParamSpec]>,
}

impl PartialEq for Params {
    fn eq(&self, other: &Self) -> bool {
        self.values == other.values
    }
}

impl Params {
    /// Checks `given` (names and values) against `specs` and fills in defaults. `owner` names
    /// what the parameters belong to in errors, e.g. `system mppi`.
    pub fn resolve(
        owner: &str,
        specs: impl Into<Arc<[ParamSpec]>>,
        given: &[(String, ParamValue)],
    ) -> Result<Params, ParamError> {
        let specs: Arc<[ParamSpec]> = specs.into();
        let mut values: Vec<(String, ParamValue)> = specs
            .iter()
            .map(|s| (s.name.clone(), s.default.clone()))
            .collect();
        for (k, (name, v)) in given.iter().enumerate() {
            let spec = spec_named(owner, &specs, name)?;
            // `--param samples=10 --param samples=20` would otherwise keep one of them silently
            if given[..k].iter().any(|(n, _)| n == name) {
                return Err(ParamError(format!(
                    "{owner} parameter {name} is given twice"
                )));
            }
            let i = specs
                .iter()
                .position(|s| s.name == spec.name)
                .expect("found");
            values[i].1 = spec.check(owner, v.clone())?;
        }
        Ok(Params { values, specs })
    }

    /// Name and value pairs, in declared order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &ParamValue)> {
        self.values.iter().map(|(n, v)| (n.as_str(), v))
    }

    /// The values as `(name, value)` pairs, e.g. to resolve recorded values again.
    pub fn to_pairs(&self) -> Vec<(String, ParamValue)> {
        self.values.clone()
    }

    /// The declarations (empty when read back from JSON).
    pub fn specs(&self) -> &Arc<[ParamSpec]> {
        &self.specs
    }

    pub fn get(&self, name: &str) -> Option<&ParamValue> {
        self.values.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    fn typed<'a, T>(
        &'a self,
        name: &str,
        want: &str,
        f: impl Fn(&'a ParamValue) -> Option<T>,
    ) -> T {
        let v = self
            .get(name)
            .unwrap_or_else(|| panic!("parameter `{name}` is not declared"));
        f(v).unwrap_or_else(|| panic!("parameter `{name}` = {v:?} is not declared as {want}"))
    }

    /// A float parameter's value. Panics when `name` is not a declared float (a bug in the
    /// code that declared it).
    pub fn float(&self, name: &str) -> f64 {
        self.typed(name, "float", |v| match v {
            ParamValue::Float(x) => Some(*x),
            _ => None,
        })
    }
    /// An int parameter's value (panics like [`Params::float`]).
    pub fn int(&self, name: &str) -> i64 {
        self.typed(name, "int", |v| match v {
            ParamValue::Int(i) => Some(*i),
            _ => None,
        })
    }
    /// An int parameter declared with a non-negative range, as `usize`.
    pub fn usize(&self, name: &str) -> usize {
        usize::try_from(self.int(name)).unwrap_or_else(|_| panic!("parameter `{name}` is negative"))
    }
    pub fn bool(&self, name: &str) -> bool {
        self.typed(name, "bool", |v| match v {
            ParamValue::Bool(b) => Some(*b),
            _ => None,
        })
    }
    pub fn str(&self, name: &str) -> &str {
        self.typed(name, "string", |v| match v {
            ParamValue::Str(s) => Some(s.as_str()),
            _ => None,
        })
    }
    /// A path parameter's value; `None` when empty.
    pub fn path(&self, name: &str) -> Option<&Path> {
        self.typed(name, "path", |v| match v {
            ParamValue::Path(p) => Some((!p.as_os_str().is_empty()).then_some(p.as_path())),
            _ => None,
        })
    }

    /// Whether `recorded` (read back from a record such as `run.json`) describes the same
    /// values as these resolved ones. Recorded values are converted to the declared types; a
    /// declared parameter missing from the record counts as its default (records written
    /// before it existed, or before all parameters were recorded). Without declarations the
    /// values must be equal.
    pub fn same_as_recorded(&self, recorded: &Params) -> bool {
        if self.specs.is_empty() {
            return self == recorded;
        }
        match Params::resolve("recorded", self.specs.clone(), &recorded.values) {
            Ok(r) => r == *self,
            Err(_) => false,
        }
    }
}

/// A JSON object of name → value in declared order.
impl Serialize for Params {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.values.len()))?;
        for (k, v) in &self.values {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

/// Accepts the object [`Serialize`] writes, and a list of `[name, value]` pairs (what
/// `run.json` held before parameters were typed: only the values given, as numbers).
impl<'de> Deserialize<'de> for Params {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Vec<(String, ParamValue)>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object of parameter values or a list of [name, value] pairs")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                while let Some(e) = a.next_entry::<String, ParamValue>()? {
                    out.push(e);
                }
                Ok(out)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                while let Some(e) = a.next_element::<(String, ParamValue)>()? {
                    out.push(e);
                }
                Ok(out)
            }
        }
        Ok(Params {
            values: d.deserialize_any(V)?,
            specs: Arc::from(Vec::new()),
        })
    }
}
