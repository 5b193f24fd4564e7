//! Keeping runs apart in a report: results files that belong to one run (the same settings by
//! content, e.g. a run split over two machines) merge into one column; runs of one system with
//! different settings become separate columns labelled by what differs (`pid [speed=6]`); and
//! a file given twice, or two copies of one run covering the same tasks, are refused instead
//! of being counted twice.

use super::loaded::{LoadedFile, ReportError};
use crate::episode::TrialResult;
use crate::run::identity::RunRecord;
use std::collections::{BTreeMap, HashMap};

/// The settings of a run that its results depend on, as `name → value` text (parameters as
/// `name`, the rest by their `run.json` names). Step logs are left out: they change what is
/// kept, not what happens.
fn settings(r: &RunRecord) -> BTreeMap<String, String> {
    let run = &r.run;
    let mut out = BTreeMap::new();
    let mut put = |k: &str, v: String| {
        out.insert(k.to_string(), v);
    };
    put("system", run.system.clone());
    put(
        "worlds",
        // a run of selected tasks recorded only its worlds' digests: it goes by the set's
        // name (`separate_runs` tells apart two that disagree on a world)
        match &r.worlds_digest {
            Some(d) => format!("{}#{}", run.worlds, &d[..8.min(d.len())]),
            None => run.worlds.clone(),
        },
    );
    put(
        "vehicle",
        match &r.vehicle_digest {
            Some(d) => format!("{}#{}", run.vehicle, &d[..8.min(d.len())]),
            None => run.vehicle.clone(),
        },
    );
    put("scale", run.scale.to_string());
    put(
        "rules",
        serde_json::to_value(run.rules)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default(),
    );
    put("seed", run.seed.to_string());
    put("max_time", run.max_time.to_string());
    put("start", r.start.name().to_string());
    // a run without perception noise has no entry, so older runs group as before
    if let Some(p) = &r.perception {
        // a preset by its name; a custom model by name and content (two files of one name
        // with different noise are two runs)
        let value = if crate::perception::PerceptionModel::preset(&p.name).as_ref() == Some(p) {
            p.name.clone()
        } else {
            let hex = verti_core::digest::Digest::new().debug(p).hex();
            format!("{}#{}", p.name, &hex[..8.min(hex.len())])
        };
        put("perception", value);
    }
    for (k, v) in run.params.iter() {
        put(k, v.to_string());
    }
    out
}

/// Checks the files for duplicates and relabels each result's `system` so that runs of one
/// system with different settings stay apart. `results[i]` holds the trials of `files[i]`; a
/// file without `run.json` is grouped by its system name alone.
pub(super) fn separate_runs(
    files: &[LoadedFile],
    results: &mut [Vec<TrialResult>],
) -> Result<(), ReportError> {
    let dup = |m: String| ReportError::Duplicate(m);
    // the same file twice (however its path was written)
    let mut seen: HashMap<std::path::PathBuf, usize> = HashMap::new();
    for (i, f) in files.iter().enumerate() {
        let key = std::fs::canonicalize(&f.path).unwrap_or_else(|_| f.path.clone());
        if let Some(&j) = seen.get(&key) {
            return Err(dup(format!(
                "{} was given twice (as {} and {}): its trials would count twice",
                key.display(),
                files[j].path.display(),
                f.path.display()
            )));
        }
        seen.insert(key, i);
    }
    // one identity per file: its settings, or nothing for a file without run.json (its trials
    // are then told apart by their system and vehicle alone, as they were before run.json)
    let mut identity: Vec<BTreeMap<String, String>> = files
        .iter()
        .zip(results.iter())
        .map(|(f, rs)| match &f.run {
            Some(r) => settings(r),
            None => BTreeMap::from([(
                "system".to_string(),
                rs.first().map(|r| r.system.clone()).unwrap_or_default(),
            )]),
        })
        .collect();
    // runs of selected tasks with the same settings are one run unless they disagree on the
    // contents of a world both ran on: then each is labelled by its worlds' digest
    for i in 0..files.len() {
        for j in 0..i {
            let (Some(a), Some(b)) = (&files[i].run, &files[j].run) else {
                continue;
            };
            let clash = a.some_worlds()
                && b.some_worlds()
                && identity[i] == identity[j]
                && !a.worlds_differing_from(b).is_empty();
            if clash {
                for (k, r) in [(i, a), (j, b)] {
                    let hex = verti_core::digest::Digest::new()
                        .debug(&r.world_digests)
                        .hex();
                    identity[k].insert(
                        "worlds".into(),
                        format!("{}#{}", r.run.worlds, &hex[..8.min(hex.len())]),
                    );
                }
            }
        }
    }
    // files of one identity merge, but may not share a task
    type Key<'a> = (Option<&'a BTreeMap<String, String>>, &'a str, &'a str, u32);
    let mut owner: HashMap<Key, usize> = HashMap::new();
    for (i, rs) in results.iter().enumerate() {
        let id = files[i].run.as_ref().map(|_| &identity[i]);
        for r in rs {
            let key = (id, r.system.as_str(), r.vehicle.as_str(), r.task);
            if let Some(&j) = owner.get(&key) {
                let what = if i == j {
                    format!("{} holds task {} twice", files[i].path.display(), r.task)
                } else {
                    format!(
                        "{} and {} both hold task {} of {} with the same settings (a copy of one run?)",
                        files[j].path.display(),
                        files[i].path.display(),
                        r.task,
                        r.system
                    )
                };
                return Err(dup(format!("{what}: its trials would count twice")));
            }
            owner.insert(key, i);
        }
    }
    // label identities that share a system name by the settings in which they differ
    let mut by_system: BTreeMap<&str, Vec<&BTreeMap<String, String>>> = BTreeMap::new();
    for id in &identity {
        let list = by_system.entry(id["system"].as_str()).or_default();
        if !list.contains(&id) {
            list.push(id);
        }
    }
    let labels: Vec<Option<String>> = identity
        .iter()
        .map(|id| {
            let others = &by_system[id["system"].as_str()];
            if others.len() < 2 {
                return None;
            }
            let differing: Vec<String> = id
                .iter()
                .filter(|(k, _)| k.as_str() != "system")
                .filter(|(k, v)| others.iter().any(|o| o.get(*k) != Some(*v)))
                // several vehicles of one system are told apart by the aggregation already;
                // only one vehicle name with different contents needs a label here
                .filter(|(k, v)| {
                    k.as_str() != "vehicle"
                        || others.iter().any(|o| {
                            o.get(*k)
                                .is_some_and(|w| w != *v && name_of(w) == name_of(v))
                        })
                })
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            (!differing.is_empty()).then(|| format!("{} [{}]", id["system"], differing.join(", ")))
        })
        .collect();
    for (rs, label) in results.iter_mut().zip(labels) {
        if let Some(label) = label {
            for r in rs {
                r.system = label.clone();
            }
        }
    }
    Ok(())
}

/// The vehicle name of a `name#digest` setting.
fn name_of(v: &str) -> &str {
    v.split('#').next().unwrap_or(v)
}
