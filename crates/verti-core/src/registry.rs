//! Open registries: things built by name from typed parameters.
//!
//! A [`Factory<T>`] describes one kind of `T` ([`FactoryInfo`]: name, summary, parameter
//! declarations) and builds it from resolved [`Params`]. A [`Registry<T>`] holds factories;
//! the crates at the top of the workspace (the command line, the Python module) compose one
//! from the `register` functions of every crate that provides factories, so a crate can add
//! its own without the crates below it knowing. verti uses `Registry<dyn MobilitySystem>`
//! (verti-bench, `SystemRegistry`) and `Registry<dyn ElevationSource>` (verti-world).

use crate::params::{ParamError, ParamSpec, ParamValue, Params, parse_assignment};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// Something built by a registry; `WHAT` names it in messages (`system`).
pub trait Registrable {
    const WHAT: &'static str;
}

/// What a factory builds: its name, a one-line summary and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FactoryInfo {
    pub name: String,
    pub summary: String,
    pub params: Vec<ParamSpec>,
}

/// Builds one kind of `T` by name.
pub trait Factory<T: ?Sized + Registrable>: Send + Sync {
    fn info(&self) -> FactoryInfo;
    /// Builds from parameters resolved against `info().params` (every declared parameter is
    /// present, in its declared type). Called once per use (e.g. once per trial), so a factory
    /// that loads something expensive (network weights) should load it once and share it.
    fn build(&self, params: &Params) -> Result<Box<T>, String>;
    /// The files that what `build` makes reads when used with `params` on the worlds whose
    /// indices are `worlds` (model cards, their weights): a run records them by content, so a
    /// resume or merge with a changed file is refused. By default every non-empty path
    /// parameter; a factory whose files name other files (a card and its weights) or whose
    /// paths are templates lists them all.
    fn inputs(&self, params: &Params, worlds: &[u32]) -> Result<Vec<PathBuf>, String> {
        let _ = worlds;
        Ok(path_params(params))
    }
}

/// The non-empty path parameters of `params`, in declaration order.
pub fn path_params(params: &Params) -> Vec<PathBuf> {
    params
        .iter()
        .filter_map(|(_, v)| match v {
            ParamValue::Path(p) if !p.as_os_str().is_empty() => Some(p.clone()),
            _ => None,
        })
        .collect()
}

struct Entry<T: ?Sized + Registrable> {
    info: FactoryInfo,
    specs: Arc<[ParamSpec]>,
    factory: Arc<dyn Factory<T>>,
}

impl<T: ?Sized + Registrable> Clone for Entry<T> {
    fn clone(&self) -> Self {
        Entry {
            info: self.info.clone(),
            specs: self.specs.clone(),
            factory: self.factory.clone(),
        }
    }
}

/// Factories by name, in registration order.
pub struct Registry<T: ?Sized + Registrable> {
    entries: Vec<Entry<T>>,
}

impl<T: ?Sized + Registrable> Clone for Registry<T> {
    fn clone(&self) -> Self {
        Registry {
            entries: self.entries.clone(),
        }
    }
}

impl<T: ?Sized + Registrable> Default for Registry<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: ?Sized + Registrable> Registry<T> {
    /// An empty registry.
    pub fn new() -> Self {
        Registry {
            entries: Vec::new(),
        }
    }

    /// Adds a factory. A name can be registered once; the declared defaults must pass their
    /// own checks (paths excepted), so a bad declaration fails here rather than in use.
    pub fn register(&mut self, factory: impl Factory<T> + 'static) -> Result<(), ParamError> {
        let info = factory.info();
        if self.entries.iter().any(|e| e.info.name == info.name) {
            return Err(ParamError(format!(
                "{} `{}` is registered twice",
                T::WHAT,
                info.name
            )));
        }
        let owner = format!("{} {}", T::WHAT, info.name);
        for (i, p) in info.params.iter().enumerate() {
            if info.params[..i].iter().any(|q| q.name == p.name) {
                return Err(ParamError(format!(
                    "{owner} declares parameter {} twice",
                    p.name
                )));
            }
            if !matches!(p.kind, crate::params::ParamKind::Path) {
                p.check(&owner, p.default.clone())
                    .map_err(|e| ParamError(format!("default of {e}")))?;
            }
        }
        self.entries.push(Entry {
            specs: info.params.clone().into(),
            info,
            factory: Arc::new(factory),
        });
        Ok(())
    }

    /// Every factory's description, in registration order.
    pub fn list(&self) -> impl Iterator<Item = &FactoryInfo> {
        self.entries.iter().map(|e| &e.info)
    }

    pub fn names(&self) -> Vec<&str> {
        self.entries.iter().map(|e| e.info.name.as_str()).collect()
    }

    fn entry(&self, name: &str) -> Result<&Entry<T>, ParamError> {
        self.entries
            .iter()
            .find(|e| e.info.name == name)
            .ok_or_else(|| {
                ParamError(format!(
                    "unknown {} `{name}`; known: {}",
                    T::WHAT,
                    self.names().join(", ")
                ))
            })
    }

    pub fn info(&self, name: &str) -> Result<&FactoryInfo, ParamError> {
        Ok(&self.entry(name)?.info)
    }

    fn owner(&self, name: &str) -> String {
        format!("{} {name}", T::WHAT)
    }

    /// Parses `param=value` text for the factory `name`, per the parameter's declared type.
    pub fn parse_param(&self, name: &str, text: &str) -> Result<(String, ParamValue), ParamError> {
        let e = self.entry(name)?;
        parse_assignment(&self.owner(name), &e.specs, text)
    }

    /// Checks given parameters and fills in defaults.
    pub fn resolve(
        &self,
        name: &str,
        given: &[(String, ParamValue)],
    ) -> Result<Params, ParamError> {
        let e = self.entry(name)?;
        Params::resolve(&self.owner(name), e.specs.clone(), given)
    }

    /// Builds from resolved parameters (re-resolving them when they were resolved elsewhere,
    /// e.g. read back from `run.json`).
    pub fn build(&self, name: &str, params: &Params) -> Result<Box<T>, ParamError> {
        let e = self.entry(name)?;
        let resolved;
        let params = if Arc::ptr_eq(params.specs(), &e.specs) {
            params
        } else {
            resolved = Params::resolve(&self.owner(name), e.specs.clone(), &params.to_pairs())?;
            &resolved
        };
        e.factory
            .build(params)
            .map_err(|why| ParamError(format!("cannot build {}: {why}", self.owner(name))))
    }

    /// The files the factory `name` reads with `params` on the worlds `worlds`
    /// ([`Factory::inputs`]).
    pub fn inputs(
        &self,
        name: &str,
        params: &Params,
        worlds: &[u32],
    ) -> Result<Vec<PathBuf>, ParamError> {
        let e = self.entry(name)?;
        e.factory
            .inputs(params, worlds)
            .map_err(|why| ParamError(format!("{}: {why}", self.owner(name))))
    }

    /// [`Registry::resolve`] then [`Registry::build`].
    pub fn create(&self, name: &str, given: &[(String, ParamValue)]) -> Result<Box<T>, ParamError> {
        let p = self.resolve(name, given)?;
        self.build(name, &p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamKind;

    trait Greeter {
        fn greet(&self) -> String;
    }
    impl Registrable for dyn Greeter {
        const WHAT: &'static str = "greeter";
    }
    struct Hello(String, i64);
    impl Greeter for Hello {
        fn greet(&self) -> String {
            format!("{} x{}", self.0, self.1)
        }
    }
    struct HelloFactory;
    impl Factory<dyn Greeter> for HelloFactory {
        fn info(&self) -> FactoryInfo {
            FactoryInfo {
                name: "hello".into(),
                summary: "says hello".into(),
                params: vec![
                    ParamSpec::choice("word", "hi", &["hi", "hey"], "greeting"),
                    ParamSpec::int("times", 1, 1, 3, "repeats"),
                    ParamSpec::float("volume", 0.5, 0.0, 1.0, "loudness"),
                    ParamSpec::bool("shout", false, "upper case"),
                    ParamSpec::path("voice", "", "a voice file"),
                ],
            }
        }
        fn build(&self, p: &Params) -> Result<Box<dyn Greeter>, String> {
            assert!(p.path("voice").is_none() && !p.bool("shout") && p.float("volume") >= 0.0);
            Ok(Box::new(Hello(p.str("word").to_string(), p.int("times"))))
        }
    }

    #[test]
    fn builds_by_name_with_typed_parameters_and_clear_errors() {
        let mut r: Registry<dyn Greeter> = Registry::new();
        r.register(HelloFactory).unwrap();
        let e = r.register(HelloFactory).unwrap_err().to_string();
        assert!(e.contains("registered twice"), "{e}");
        assert_eq!(r.create("hello", &[]).unwrap().greet(), "hi x1");
        let given = vec![
            r.parse_param("hello", "word=hey").unwrap(),
            r.parse_param("hello", "times = 3").unwrap(),
            r.parse_param("hello", "volume=1").unwrap(),
        ];
        assert_eq!(r.create("hello", &given).unwrap().greet(), "hey x3");
        // an integral float is an integer, an integer a float
        let g = vec![("times".to_string(), ParamValue::Float(2.0))];
        assert_eq!(r.create("hello", &g).unwrap().greet(), "hi x2");
        let bad = |text: &str| r.parse_param("hello", text).unwrap_err().to_string();
        assert!(bad("times=4").contains("times: 4 is outside [1, 3]"));
        assert!(bad("times=1.5").contains("times"));
        assert!(bad("word=yo").contains("`yo` is not one of hi, hey"));
        assert!(bad("volume=loud").contains("volume: `loud` is not a number"));
        assert!(bad("shout=maybe").contains("shout"));
        assert!(bad("voice=/no/such/file").contains("voice: `/no/such/file` does not exist"));
        assert!(
            bad("nope=1").contains("greeter hello has no parameter `nope`; its parameters: word")
        );
        assert!(bad("times").contains("name=value"));
        let e = r.create("bye", &[]).err().unwrap().to_string();
        assert!(e.contains("unknown greeter `bye`; known: hello"), "{e}");
        let e = r
            .create("hello", &[("shout".into(), ParamValue::Int(1))])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("shout: expected bool"), "{e}");
        assert!(matches!(
            r.info("hello").unwrap().params[1].kind,
            ParamKind::Int { min: 1, max: 3 }
        ));
    }

    #[test]
    fn params_round_trip_through_json_and_match_legacy_records() {
        let mut r: Registry<dyn Greeter> = Registry::new();
        r.register(HelloFactory).unwrap();
        let p = r
            .resolve("hello", &[("times".into(), ParamValue::Int(2))])
            .unwrap();
        let json = serde_json::to_string(&p).unwrap();
        assert_eq!(
            json,
            r#"{"word":"hi","times":2,"volume":0.5,"shout":false,"voice":""}"#
        );
        let back: Params = serde_json::from_str(&json).unwrap();
        assert!(p.same_as_recorded(&back));
        // a record of the given values only, as numbers (before parameters were typed)
        let legacy: Params = serde_json::from_str(r#"[["times", 2.0]]"#).unwrap();
        assert!(p.same_as_recorded(&legacy));
        let other: Params = serde_json::from_str(r#"[["times", 3.0]]"#).unwrap();
        assert!(!p.same_as_recorded(&other));
        let unknown: Params = serde_json::from_str(r#"{"nope": 1}"#).unwrap();
        assert!(!p.same_as_recorded(&unknown));
        // values read back rebuild the same thing
        assert_eq!(r.build("hello", &back).unwrap().greet(), "hi x2");
    }
}
