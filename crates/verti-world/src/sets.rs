//! Resolving what a user means by a world set or a world on the command line.
//!
//! * `verti-100` — the built-in default set (seed 0, 100 worlds), generated in memory in a
//!   second or two; `verti-N` and `verti-N-sSEED` work the same way.
//! * a directory with `set.yaml` — a saved set; with `world.yaml` — a single world.
//! * a directory of original Verti-Bench worlds (`configN_LEVEL.yaml` + heightmaps) — imported
//!   on the fly.
//!
//! A single world is `SET:INDEX` (e.g. `verti-100:42`) or a world directory.

use crate::error::{Result, WorldError};
use crate::format::{MANIFEST, SET_MANIFEST, load_set, load_world};
use crate::generate::{SetConfig, generate_set, set_name};
use crate::import_vb::{ImportOptions, import_vb, scan_vb_dir};
use crate::world::World;
use rayon::prelude::*;
use std::path::Path;

/// A named collection of worlds.
#[derive(Clone, Debug)]
pub struct WorldSet {
    pub name: String,
    pub worlds: Vec<World>,
}

/// Parses `verti-N` or `verti-N-sSEED` into a generator config.
pub fn builtin_config(spec: &str, scale: f64) -> Option<SetConfig> {
    let rest = spec.strip_prefix("verti-")?;
    let (count, seed) = match rest.split_once("-s") {
        Some((c, s)) => (c.parse().ok()?, s.parse().ok()?),
        None => (rest.parse().ok()?, 0),
    };
    Some(SetConfig {
        seed,
        count,
        scale,
        ..Default::default()
    })
}

/// Resolves a set spec. `scale` applies to built-in and imported sets; saved sets carry theirs.
pub fn resolve_set(spec: &str, scale: f64, progress: &(dyn Fn() + Sync)) -> Result<WorldSet> {
    let path = Path::new(spec);
    if path.join(SET_MANIFEST).is_file() {
        let (m, worlds) = load_set(path)?;
        return Ok(WorldSet {
            name: m.name,
            worlds,
        });
    }
    if path.join(MANIFEST).is_file() {
        let w = load_world(path)?;
        return Ok(WorldSet {
            name: w.meta.name.clone(),
            worlds: vec![w],
        });
    }
    if path.is_dir() {
        let files = scan_vb_dir(path)?;
        let opts = ImportOptions {
            scale,
            ..Default::default()
        };
        let worlds = files
            .par_iter()
            .map(|f| {
                let w = import_vb(&f.config, &f.heightmap, f.labels.as_deref(), &opts);
                progress();
                w
            })
            .collect::<Result<Vec<_>>>()?;
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("verti-bench")
            .to_string();
        return Ok(WorldSet {
            name: format!("vb-{name}"),
            worlds,
        });
    }
    if let Some(config) = builtin_config(spec, scale) {
        let worlds = generate_set(&config, progress)?;
        return Ok(WorldSet {
            name: set_name(&config),
            worlds,
        });
    }
    Err(WorldError::Argument(format!(
        "unknown world set `{spec}`: expected `verti-100` (built-in), a set directory (with set.yaml), a world directory (with world.yaml) or a folder of Verti-Bench configs"
    )))
}

/// Resolves a single world: a world directory or `SET:INDEX` (1-based index).
pub fn resolve_world(spec: &str, scale: f64) -> Result<World> {
    let path = Path::new(spec);
    if path.join(MANIFEST).is_file()
        || (path.is_file() && path.extension().is_some_and(|e| e == "yaml"))
    {
        return load_world(path);
    }
    let (set, index) = spec.rsplit_once(':').ok_or_else(|| {
        WorldError::Argument(format!("`{spec}` is not a world directory; name a world of a set as SET:INDEX, e.g. verti-100:42"))
    })?;
    let index: u32 = index.parse().map_err(|_| {
        WorldError::Argument(format!(
            "`{index}` in `{spec}` is not a world index (1-based integer)"
        ))
    })?;
    // Generate only the requested world of a built-in set.
    if !Path::new(set).exists()
        && let Some(config) = builtin_config(set, scale)
    {
        config.validate()?;
        if index == 0 || index > config.count {
            return Err(WorldError::Argument(format!(
                "{set} has worlds 1..={}, not {index}",
                config.count
            )));
        }
        let comp = crate::generate::composition(&config)[index as usize - 1];
        return crate::generate::generate_world(
            &config,
            index,
            comp.0,
            comp.1,
            comp.2,
            &crate::generate::elevation::ProceduralRock::default(),
        );
    }
    let s = resolve_set(set, scale, &|| {})?;
    let n = s.worlds.len();
    s.worlds
        .into_iter()
        .find(|w| w.meta.index == index)
        .ok_or_else(|| {
            WorldError::Argument(format!(
                "set `{set}` has no world with index {index} ({n} worlds)"
            ))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_names() {
        assert_eq!(builtin_config("verti-100", 1.0).unwrap().count, 100);
        let c = builtin_config("verti-20-s7", 0.1).unwrap();
        assert_eq!((c.count, c.seed, c.scale), (20, 7, 0.1));
        assert!(builtin_config("vertix", 1.0).is_none());
    }

    #[test]
    fn single_world_of_builtin_set_equals_set_member() {
        let w = resolve_world("verti-5:3", 1.0).unwrap();
        let set = resolve_set("verti-5", 1.0, &|| {}).unwrap();
        assert_eq!(w, set.worlds[2]);
        assert!(
            resolve_world("verti-5:9", 1.0)
                .unwrap_err()
                .to_string()
                .contains("1..=5")
        );
        assert!(
            resolve_set("no-such-set", 1.0, &|| {})
                .unwrap_err()
                .to_string()
                .contains("unknown world set")
        );
    }
}
