//! verti's registries, assembled once for every front end: the `verti` command line and the
//! Python module `verti._verti` both call [`systems`] and [`elevation_sources`], so a system
//! or source registered here is known to both, and listed in the same order by
//! `verti systems list` / `verti.systems()` and `verti world sources`.
//!
//! A crate that provides mobility systems or elevation sources adds its `register` call to
//! [`systems`] or [`elevation_sources`], after the ones already there: registration order is
//! listing order. Built-in vehicles live in `verti_sim::vehicles`; [`vehicle`] is the rule
//! that reads a `--vehicle` / `vehicle=` argument as a built-in name or a vehicle file.
//!
//! [`ReadySystem`] is a system whose parameters were resolved against its factory's
//! declarations ([`SystemRegistry::resolve`]) and whose first instance was built, which is the
//! only way to run the checks a factory makes when it builds (a model card that must load, a
//! plan that must fit in memory, the oracle's whole control periods). That first instance is
//! not thrown away: it drives the run's first trial.

use std::path::Path;
use std::sync::Mutex;
use verti_bench::{MobilitySystem, Params, SystemRegistry};
use verti_core::ParamError;
use verti_sim::{SpecError, VehicleSpec};
use verti_world::generate::sources::ElevationRegistry;

/// Every mobility system verti can run, in listing order: the built-in ones (PID, EH, MPPI,
/// the oracle), then those of the crates above verti-systems, all evaluated without a learning
/// framework.
pub fn systems() -> SystemRegistry {
    let mut r = SystemRegistry::new();
    verti_systems::register(&mut r);
    // the learned planners: MPPI over the shipped kinodynamic models (mppi6, wmvct, tal, tnt)
    verti_kino::systems::register(&mut r, verti_kino::shipped::systems())
        .expect("the shipped learned systems have distinct names and valid parameters");
    // the driving policies trained with PPO (rl, mcl, acl)
    verti_policy::system::register(&mut r, verti_policy::shipped::systems())
        .expect("the shipped policies have distinct names and valid parameters");
    // PIETRA's risk-aware planner over the shipped traversability model
    verti_pietra::system::register(&mut r, verti_pietra::shipped::pietra_v1)
        .expect("pietra has a distinct name and valid parameters");
    // VertiAdaptor: MPPI over the shipped function encoder with online least squares
    verti_va::system::register(&mut r, verti_va::shipped::va_small_v1)
        .expect("va has a distinct name and valid parameters");
    r
}

/// Every elevation source worlds can be generated from, in listing order: the procedural ones,
/// then the trained SWAE (`swae-v1`).
pub fn elevation_sources() -> ElevationRegistry {
    let mut r = ElevationRegistry::new();
    verti_world::generate::sources::register(&mut r);
    verti_nn::shipped::register_sources(&mut r);
    r
}

/// A vehicle by built-in name (`verti_sim::vehicles::builtin_names`) or a vehicle YAML file.
/// Anything that looks like a file (a `.yaml`/`.yml` extension, a path separator) or exists is
/// read as one, so a missing file is reported as such rather than as an unknown vehicle name;
/// any other name is a built-in one (an unknown name gets the list of known ones).
pub fn vehicle(name: &str) -> Result<VehicleSpec, SpecError> {
    use verti_sim::vehicles;
    if vehicles::builtin_names().contains(&name) {
        return vehicles::builtin(name);
    }
    let path = Path::new(name);
    let looks_like_file = path.extension().is_some_and(|e| e == "yaml" || e == "yml")
        || name.contains(std::path::MAIN_SEPARATOR)
        || path.exists();
    if looks_like_file {
        return VehicleSpec::from_file(path);
    }
    vehicles::builtin(name)
}

/// One system of a registry ready to run: its parameters resolved against its declarations,
/// and built once, so what only building can check has been checked. [`ReadySystem::make`]
/// hands out instances for trials, the one built here first.
pub struct ReadySystem<'a> {
    registry: &'a SystemRegistry,
    name: String,
    params: Params,
    first: Mutex<Option<Box<dyn MobilitySystem>>>,
}

impl<'a> ReadySystem<'a> {
    /// Builds system `name` of `registry` with `params` (resolved by
    /// [`SystemRegistry::resolve`]); the error is the registry's (`cannot build system ...`).
    pub fn new(
        registry: &'a SystemRegistry,
        name: &str,
        params: Params,
    ) -> Result<Self, ParamError> {
        let first = registry.build(name, &params)?;
        Ok(ReadySystem {
            registry,
            name: name.to_string(),
            params,
            first: Mutex::new(Some(first)),
        })
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// The resolved parameters (every declared one, defaults filled in).
    pub fn params(&self) -> &Params {
        &self.params
    }

    pub fn registry(&self) -> &'a SystemRegistry {
        self.registry
    }

    /// A fresh instance for one trial: the one [`ReadySystem::new`] built, then new ones.
    pub fn make(&self) -> Box<dyn MobilitySystem> {
        let first = self.first.lock().unwrap_or_else(|p| p.into_inner()).take();
        first.unwrap_or_else(|| {
            self.registry
                .build(&self.name, &self.params)
                .expect("the system was built once already")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_bench::ParamValue;

    #[test]
    fn listing_order_is_registration_order() {
        assert_eq!(
            systems().names(),
            [
                "pid", "eh", "mppi", "oracle", "mppi6", "wmvct", "tal", "tnt", "rl", "mcl", "acl",
                "pietra", "va"
            ]
        );
        assert_eq!(elevation_sources().names(), ["procedural-rock", "swae-v1"]);
    }

    #[test]
    fn a_ready_system_hands_out_its_first_instance_then_new_ones() {
        let registry = systems();
        let params = registry
            .resolve("mppi", &[("samples".into(), ParamValue::Int(16))])
            .unwrap();
        let ready = ReadySystem::new(&registry, "mppi", params).unwrap();
        assert_eq!(ready.name(), "mppi");
        assert_eq!(ready.params().int("samples"), 16);
        assert!(ready.first.lock().unwrap().is_some());
        assert_eq!(ready.make().name(), "mppi");
        assert!(ready.first.lock().unwrap().is_none());
        assert_eq!(ready.make().name(), "mppi");
    }

    #[test]
    fn what_only_building_checks_fails_with_the_registry_error() {
        let registry = systems();
        // within its declared range, but not a whole number of control periods
        let params = registry
            .resolve("oracle", &[("horizon".into(), ParamValue::Float(1.25))])
            .unwrap();
        let e = ReadySystem::new(&registry, "oracle", params)
            .err()
            .expect("refused")
            .to_string();
        assert!(e.starts_with("cannot build system oracle: "), "{e}");
        assert!(e.contains("horizon"), "{e}");
    }

    #[test]
    fn a_vehicle_is_a_built_in_name_or_a_file() {
        assert_eq!(vehicle("hmmwv").unwrap().name, "hmmwv");
        let unknown = vehicle("hovercraft").unwrap_err().to_string();
        assert!(
            unknown.contains("hovercraft") && unknown.contains("hmmwv"),
            "{unknown}"
        );
        // a path that is not there is a missing file, not an unknown vehicle
        for missing in ["/nonexistent/rover.yaml", "/nonexistent/rover"] {
            let e = vehicle(missing).unwrap_err();
            assert!(matches!(e, SpecError::Io { .. }), "{missing}: {e}");
        }
    }
}
