//! Elevation sources by name, with typed parameters (`verti world sources`,
//! `verti world generate --elevation NAME --elevation-param name=value`).
//!
//! [`register`] adds the built-in procedural generator; a crate above verti-world (the SWAE
//! terrain model of a future learning crate) registers its own source with the registry that
//! the command line composes.

use super::elevation::{ElevationSource, ProceduralRock};
use verti_core::params::{ParamSpec, Params};
use verti_core::registry::{Factory, FactoryInfo, Registrable, Registry};

impl Registrable for dyn ElevationSource {
    const WHAT: &'static str = "elevation source";
}

/// Elevation sources by name.
pub type ElevationRegistry = Registry<dyn ElevationSource>;

/// The name of the default source (what `verti-100` is generated with).
pub const DEFAULT_SOURCE: &str = "procedural-rock";

/// [`ProceduralRock`], its shape parameters adjustable.
pub struct ProceduralRockFactory;

impl Factory<dyn ElevationSource> for ProceduralRockFactory {
    fn info(&self) -> FactoryInfo {
        let d = ProceduralRock::default();
        FactoryInfo {
            name: DEFAULT_SOURCE.into(),
            summary: "procedural rock terrain (rubble, ridges, boulders, pits) calibrated on the Verti-Bench maps".into(),
            params: vec![
                ParamSpec::float(
                    "rock_size_min",
                    d.rock_size.0,
                    0.5,
                    20.0,
                    "smallest mean rock semi-axis, cells",
                ),
                ParamSpec::float(
                    "rock_size_max",
                    d.rock_size.1,
                    0.5,
                    20.0,
                    "largest mean rock semi-axis, cells",
                ),
                ParamSpec::float(
                    "coverage",
                    d.coverage,
                    0.0,
                    10.0,
                    "rubble rock area as a multiple of the map area",
                ),
                ParamSpec::float(
                    "rock_height_spread",
                    d.rock_height_spread,
                    0.0,
                    2.0,
                    "relative spread of rock heights",
                ),
                ParamSpec::int("pits_min", d.pits.0, 0, 1000, "fewest pits cut into the rubble"),
                ParamSpec::int("pits_max", d.pits.1, 0, 1000, "most pits cut into the rubble"),
                ParamSpec::float(
                    "undulation",
                    d.undulation,
                    0.0,
                    10.0,
                    "weight of the low-frequency undulation, rock heights",
                ),
            ],
        }
    }

    fn build(&self, p: &Params) -> Result<Box<dyn ElevationSource>, String> {
        let rock_size = (p.float("rock_size_min"), p.float("rock_size_max"));
        let pits = (p.int("pits_min"), p.int("pits_max"));
        if rock_size.0 > rock_size.1 {
            return Err(format!(
                "rock_size_min {} is larger than rock_size_max {}",
                rock_size.0, rock_size.1
            ));
        }
        if pits.0 > pits.1 {
            return Err(format!(
                "pits_min {} is larger than pits_max {}",
                pits.0, pits.1
            ));
        }
        let source = ProceduralRock {
            rock_size,
            coverage: p.float("coverage"),
            rock_height_spread: p.float("rock_height_spread"),
            pits,
            undulation: p.float("undulation"),
            ..Default::default()
        };
        let defaults = ProceduralRock::default();
        // worlds record their generator by name: name non-default settings too
        let changed: Vec<String> = self
            .info()
            .params
            .iter()
            .filter_map(|s| {
                let v = p.get(&s.name)?;
                (*v != s.default).then(|| format!("{}={v}", s.name))
            })
            .collect();
        Ok(if changed.is_empty() {
            Box::new(source)
        } else {
            Box::new(Renamed {
                name: format!("{}({})", defaults.name(), changed.join(",")),
                source,
            })
        })
    }
}

/// A source under another name.
struct Renamed<S> {
    name: String,
    source: S,
}

impl<S: ElevationSource> ElevationSource for Renamed<S> {
    fn name(&self) -> &str {
        &self.name
    }
    fn generate(&self, rng: &mut verti_core::Rng, n: usize) -> Vec<f64> {
        self.source.generate(rng, n)
    }
}

/// Adds the built-in elevation sources to a registry.
pub fn register(registry: &mut ElevationRegistry) {
    registry
        .register(ProceduralRockFactory)
        .expect("the built-in elevation sources are declared correctly and registered once");
}

/// A registry of the built-in elevation sources only.
pub fn builtin() -> ElevationRegistry {
    let mut r = ElevationRegistry::new();
    register(&mut r);
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_core::Rng;

    #[test]
    fn the_default_source_by_name_is_the_procedural_generator() {
        let r = builtin();
        let by_name = r.create(DEFAULT_SOURCE, &[]).unwrap();
        assert_eq!(by_name.name(), "procedural-rock-v1");
        let direct = ProceduralRock::default();
        assert_eq!(
            by_name.generate(&mut Rng::new(3), 33),
            direct.generate(&mut Rng::new(3), 33)
        );
        let p = r.parse_param(DEFAULT_SOURCE, "coverage=1.2").unwrap();
        let custom = r.create(DEFAULT_SOURCE, &[p]).unwrap();
        assert_eq!(custom.name(), "procedural-rock-v1(coverage=1.2)");
        let bad = r
            .create(
                DEFAULT_SOURCE,
                &[r.parse_param(DEFAULT_SOURCE, "pits_min=40").unwrap()],
            )
            .err()
            .unwrap()
            .to_string();
        assert!(
            bad.contains("pits_min 40 is larger than pits_max 30"),
            "{bad}"
        );
        let e = r.parse_param(DEFAULT_SOURCE, "pits_max=x").unwrap_err();
        assert!(
            e.to_string()
                .contains("elevation source procedural-rock parameter pits_max")
        );
    }
}
