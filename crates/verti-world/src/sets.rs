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
use crate::import_vb::{
    ImportOptions, VbWorldFiles, import_vb, index_from_config_name, scan_vb_dir,
};
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

/// True when something (a file, a directory, a broken link) is at `path`.
fn present(path: &Path) -> bool {
    path.symlink_metadata().is_ok()
}

/// True when `dir` holds any `configN_LEVEL.yaml` (an original Verti-Bench folder).
fn has_vb_configs(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries.flatten().any(|e| {
            let p = e.path();
            p.extension().is_some_and(|x| x == "yaml") && index_from_config_name(&p).is_some()
        })
    })
}

/// True when `path` is something a set spec can name: a saved set, a world directory or a
/// Verti-Bench folder (or a manifest that is there but unreadable, which should be reported).
fn is_world_source(path: &Path) -> bool {
    present(&path.join(SET_MANIFEST))
        || present(&path.join(MANIFEST))
        || (path.is_dir() && has_vb_configs(path))
}

/// When `spec` names a built-in set (`verti-100`) and something of that name in the current
/// directory is not a world set (an empty folder, say), the built-in set is used; this is the
/// note to show the user. Without it an empty `./verti-100` silently turned `verti-100` into
/// an error about Verti-Bench configs.
pub fn builtin_shadow_note(spec: &str) -> Option<String> {
    let set = split_world_index(spec).map_or(spec, |(set, _)| set);
    let path = Path::new(set);
    (builtin_config(set, 1.0).is_some() && present(path) && !is_world_source(path)).then(|| {
        format!(
            "`{set}` here is not a world set (no set.yaml, world.yaml or Verti-Bench configs): using the built-in set `{set}`; to use the directory, make it a set or name it as ./{set}"
        )
    })
}

/// Resolves a set spec. `scale` applies to built-in and imported sets; saved sets carry theirs.
pub fn resolve_set(spec: &str, scale: f64, progress: &(dyn Fn() + Sync)) -> Result<WorldSet> {
    let path = Path::new(spec);
    // a manifest that is there in any form is loaded, so a directory or a link loop in its
    // place is reported as what it is
    if present(&path.join(SET_MANIFEST)) {
        let (m, worlds) = load_set(path)?;
        return Ok(WorldSet {
            name: m.name,
            worlds,
        });
    }
    if present(&path.join(MANIFEST))
        || (path.is_file() && path.extension().is_some_and(|e| e == "yaml"))
    {
        let w = load_world(path)?;
        return Ok(WorldSet {
            name: w.meta.name.clone(),
            worlds: vec![w],
        });
    }
    if path.is_dir() && has_vb_configs(path) {
        let files = scan_vb_dir(path)?;
        return import_vb_set(path, &files.iter().collect::<Vec<_>>(), scale, progress);
    }
    // a built-in name wins over a directory of that name that holds no set (see
    // builtin_shadow_note); `./verti-100` always means the directory
    if let Some(config) = builtin_config(spec, scale) {
        let worlds = generate_set(&config, progress)?;
        return Ok(WorldSet {
            name: set_name(&config),
            worlds,
        });
    }
    if let Some(e) = crate::input::unreadable_reason(path, "a world set")
        && present(path)
        && e.kind() != std::io::ErrorKind::IsADirectory
    {
        return Err(WorldError::io(path, e));
    }
    if path.is_dir() {
        return Err(WorldError::Argument(format!(
            "{spec} is a directory but not a world set: it has no set.yaml (a saved set), no world.yaml (a world) and no configN_LEVEL.yaml (Verti-Bench worlds)"
        )));
    }
    Err(WorldError::Argument(format!(
        "unknown world set `{spec}`: expected `verti-100` (built-in), a set directory (with set.yaml), a world directory (with world.yaml) or a folder of Verti-Bench configs"
    )))
}

/// `SET:INDEX` as the set and the world's 1-based index, when `spec` names one world of a set
/// that way; `None` for anything else (a set, a world directory).
pub fn split_world_index(spec: &str) -> Option<(&str, u32)> {
    let (set, index) = spec.rsplit_once(':')?;
    index.parse().ok().map(|index| (set, index))
}

/// The worlds a run of selected tasks keeps of those [`resolve_set_worlds`] returned, and
/// whether they are the whole set: the worlds in `indices` when all of them are there, else
/// everything (a saved set is read whole; one lacking a world asked for is kept whole so that
/// the run's task check names the set's real range).
pub fn keep_worlds(
    worlds: Vec<World>,
    indices: &std::collections::BTreeSet<u32>,
) -> (Vec<World>, bool) {
    let has_all = indices
        .iter()
        .all(|i| worlds.iter().any(|w| w.meta.index == *i));
    if !has_all {
        return (worlds, true);
    }
    let kept = worlds
        .into_iter()
        .filter(|w| indices.contains(&w.meta.index))
        .collect();
    (kept, false)
}

/// The worlds of set `spec` with the given indices, for a run of selected tasks (a task's world
/// is its number's: see [`crate::TaskId`]): a built-in set generates only those worlds and a
/// Verti-Bench folder imports only those, each exactly as the whole set would hold it. A saved
/// set or world is read whole, as is a set lacking one of the indices (so that the run's task
/// check names the set's real range). The worlds come in the set's order.
pub fn resolve_set_worlds(
    spec: &str,
    scale: f64,
    indices: &std::collections::BTreeSet<u32>,
    progress: &(dyn Fn() + Sync),
) -> Result<WorldSet> {
    let path = Path::new(spec);
    let saved = present(&path.join(SET_MANIFEST))
        || present(&path.join(MANIFEST))
        || (path.is_file() && path.extension().is_some_and(|e| e == "yaml"));
    if saved || indices.is_empty() {
        return resolve_set(spec, scale, progress);
    }
    if path.is_dir() && has_vb_configs(path) {
        let files = scan_vb_dir(path)?;
        let chosen: Vec<_> = files
            .iter()
            .filter(|f| indices.contains(&f.index))
            .collect();
        if chosen.len() != indices.len() {
            return resolve_set(spec, scale, progress);
        }
        return import_vb_set(path, &chosen, scale, progress);
    }
    if let Some(config) = builtin_config(spec, scale) {
        config.validate()?;
        if indices.iter().any(|&i| i == 0 || i > config.count) {
            return resolve_set(spec, scale, progress);
        }
        let comp = crate::generate::composition(&config);
        let source = crate::generate::elevation::ProceduralRock::default();
        let wanted: Vec<u32> = indices.iter().copied().collect();
        let worlds = wanted
            .par_iter()
            .map(|&i| {
                let (level, ty, density) = comp[i as usize - 1];
                let w = crate::generate::generate_world(&config, i, level, ty, density, &source);
                progress();
                w
            })
            .collect::<Result<Vec<_>>>()?;
        return Ok(WorldSet {
            name: set_name(&config),
            worlds,
        });
    }
    resolve_set(spec, scale, progress)
}

/// The set `vb-DIR` of the Verti-Bench worlds `files` of folder `dir`, imported in parallel at
/// `scale`.
fn import_vb_set(
    dir: &Path,
    files: &[&VbWorldFiles],
    scale: f64,
    progress: &(dyn Fn() + Sync),
) -> Result<WorldSet> {
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
    let name = dir
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("verti-bench");
    Ok(WorldSet {
        name: format!("vb-{name}"),
        worlds,
    })
}

/// Resolves a single world: a world directory or `SET:INDEX` (1-based index).
pub fn resolve_world(spec: &str, scale: f64) -> Result<World> {
    let path = Path::new(spec);
    if present(&path.join(MANIFEST))
        || (path.is_file() && path.extension().is_some_and(|e| e == "yaml"))
    {
        return load_world(path);
    }
    let Some((set, index)) = spec.rsplit_once(':') else {
        if present(&path.join(SET_MANIFEST)) || (path.is_dir() && has_vb_configs(path)) {
            return Err(WorldError::Argument(format!(
                "{spec} is a world set, not a world: name one of its worlds as {spec}:INDEX"
            )));
        }
        if present(path) {
            // the loader says what is wrong: no world.yaml, a link loop, permission denied...
            return load_world(path);
        }
        return Err(WorldError::Argument(format!(
            "`{spec}` is not a world directory; name a world of a set as SET:INDEX, e.g. verti-100:42"
        )));
    };
    let index: u32 = index.parse().map_err(|_| {
        WorldError::Argument(format!(
            "`{index}` in `{spec}` is not a world index (1-based integer)"
        ))
    })?;
    // Generate only the requested world of a built-in set (unless a set of that name is here).
    if !is_world_source(Path::new(set))
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
    fn selected_worlds_equal_the_set_members() {
        let set = resolve_set("verti-6", 1.0, &|| {}).unwrap();
        let pick = std::collections::BTreeSet::from([2, 5]);
        let some = resolve_set_worlds("verti-6", 1.0, &pick, &|| {}).unwrap();
        assert_eq!(some.name, set.name);
        assert_eq!(
            some.worlds,
            vec![set.worlds[1].clone(), set.worlds[4].clone()]
        );
        // an index the set lacks: the whole set, for the caller's range check to report
        let beyond = std::collections::BTreeSet::from([2, 7]);
        let all = resolve_set_worlds("verti-6", 1.0, &beyond, &|| {}).unwrap();
        assert_eq!(all.worlds.len(), 6);
        // what a run keeps: the two asked for out of a whole set, or all six when one is missing
        let (kept, whole) = keep_worlds(set.worlds.clone(), &pick);
        assert_eq!((kept, whole), (some.worlds, false));
        let (kept, whole) = keep_worlds(set.worlds, &beyond);
        assert_eq!((kept.len(), whole), (6, true));
    }

    #[test]
    fn set_index_names_one_world() {
        assert_eq!(split_world_index("verti-100:42"), Some(("verti-100", 42)));
        assert_eq!(split_world_index("runs/w:3"), Some(("runs/w", 3)));
        for not_one in ["verti-100", "verti-100:x", "verti-100:-1", "dir/world"] {
            assert_eq!(split_world_index(not_one), None, "{not_one}");
        }
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
