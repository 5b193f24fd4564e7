//! What the commands share: their result type, the `--scale` and `name=value` arguments, and
//! loading world sets and vehicles. It sits below every `*_cmd` module so that commands never
//! import each other for these helpers (see `scripts/check_layers.py`).

use crate::progress::counter;
use clap::Args;
use verti_sim::VehicleSpec;
use verti_world::WorldError;
use verti_world::scale::parse_scale;
use verti_world::sets::resolve_set;

pub type CmdResult = Result<(), Box<dyn std::error::Error>>;

#[derive(Args)]
pub struct ScaleArg {
    /// World scale: 1, 1/6, 1/10 or any decimal in [1/1000, 10]. Every length is multiplied by it.
    /// Default 1 for generated and imported worlds; saved worlds keep the scale they were saved
    /// at, and asking for another is an error.
    #[arg(long, value_parser = scale_parser)]
    pub scale: Option<f64>,
}

impl ScaleArg {
    /// The scale to generate or import at.
    pub fn value(&self) -> f64 {
        self.scale.unwrap_or(1.0)
    }
}

fn scale_parser(s: &str) -> Result<f64, String> {
    parse_scale(s).map_err(|e| e.to_string())
}

/// `name=value`; the value is read per the parameter's declared type once the system is known.
pub fn assignment(s: &str) -> Result<String, String> {
    if s.contains('=') {
        Ok(s.to_string())
    } else {
        Err(format!("parameter `{s}` must look like name=value"))
    }
}

/// A built-in vehicle by name, or a vehicle YAML file: `verti_registry::vehicle`, the rule the
/// Python bindings use too.
pub fn load_vehicle(name: &str) -> Result<VehicleSpec, Box<dyn std::error::Error>> {
    Ok(verti_registry::vehicle(name)?)
}

/// Tells the user when a built-in set name is used although something of that name is here.
pub fn note_shadowed(spec: &str) {
    if let Some(note) = verti_world::sets::builtin_shadow_note(spec) {
        eprintln!("note: {note}");
    }
}

/// A world set at the requested scale, with a progress bar, and its scale: an explicit
/// `--scale` that a saved set cannot honour is an error rather than ignored. With `only`, the
/// worlds of those indices where the set can build them alone
/// ([`verti_world::sets::resolve_set_worlds`]).
pub fn load_set_checked(
    spec: &str,
    scale: &ScaleArg,
    only: Option<&std::collections::BTreeSet<u32>>,
) -> Result<(verti_world::sets::WorldSet, f64), WorldError> {
    let set = match only {
        None => load_set_with_progress(spec, scale.value())?,
        Some(indices) => {
            note_shadowed(spec);
            let pb = counter("loading", "worlds");
            let set =
                verti_world::sets::resolve_set_worlds(spec, scale.value(), indices, &|| pb.inc(1));
            pb.finish_and_clear();
            set?
        }
    };
    let actual = verti_world::scale::set_scale(spec, &set.worlds, scale.scale)?;
    Ok((set, actual))
}

pub fn load_set_with_progress(
    spec: &str,
    scale: f64,
) -> Result<verti_world::sets::WorldSet, WorldError> {
    note_shadowed(spec);
    let pb = counter("loading", "worlds");
    let set = resolve_set(spec, scale, &|| pb.inc(1));
    pb.finish_and_clear();
    set
}

/// `1 task`, `2 tasks`: a count with its noun, singular for one.
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}
