//! The registries of the command line: assembled once, in `verti-registry`, for the command
//! line and the Python module alike (a crate that provides systems or elevation sources
//! registers them there).

pub use verti_registry::{elevation_sources, systems};

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
