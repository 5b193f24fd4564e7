//! The registries of the command line: every crate that provides mobility systems or
//! elevation sources registers them here (a crate above verti-systems adds its `register`
//! call next to the built-in ones).

use verti_bench::SystemRegistry;
use verti_world::generate::sources::ElevationRegistry;

/// Every mobility system `verti` can run.
pub fn systems() -> SystemRegistry {
    let mut r = SystemRegistry::new();
    verti_systems::register(&mut r);
    // the learned planners (MPPI over shipped kinodynamic models), evaluated without burn
    verti_kino::systems::register(&mut r, verti_kino::shipped::systems())
        .expect("learned system names are unique");
    // the driving policies trained with PPO (rl, mcl, acl), evaluated without burn
    verti_policy::system::register(&mut r, verti_policy::shipped::systems())
        .expect("policy system names are unique");
    // PIETRA's risk-aware planner over the shipped traversability model, evaluated without burn
    verti_pietra::system::register(&mut r, verti_pietra::shipped::pietra_v1)
        .expect("system names are unique");
    // VertiAdaptor: MPPI over the shipped function encoder with online least squares
    verti_va::system::register(&mut r, verti_va::shipped::va_small_v1)
        .expect("system names are unique");
    r
}

/// Every elevation source `verti world generate` can use.
pub fn elevation_sources() -> ElevationRegistry {
    let mut r = ElevationRegistry::new();
    verti_world::generate::sources::register(&mut r);
    // the trained SWAE (`swae-v1`), evaluated without burn
    verti_nn::shipped::register_sources(&mut r);
    r
}

/// Prints each entry of a registry with its parameters: name, type, default, accepted values
/// and doc.
pub fn print_list<'a>(entries: impl Iterator<Item = &'a verti_core::FactoryInfo>) {
    for s in entries {
        println!("{}  {}", s.name, s.summary);
        for p in &s.params {
            let default = match p.default.to_string() {
                d if d.is_empty() => "\"\"".to_string(),
                d => d,
            };
            println!(
                "    {:<15} {:<6} {:>9}   {:<16}  {}",
                p.name,
                p.kind.type_name(),
                default,
                p.kind.accepted(),
                p.doc
            );
        }
    }
}
