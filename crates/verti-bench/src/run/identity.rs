//! What a run is, by content: the record `verti eval` keeps in `OUT/run.json`, compared on
//! resume, by `verti report` (to keep runs of different settings apart) and by `verti replay`
//! (to re-run a trial on the worlds the run used).
//!
//! Names alone are not enough: `--worlds w` may name another set when resumed from another
//! directory, and a vehicle file may be edited between two calls. So the record holds a digest
//! of the world set's contents and of the vehicle spec next to the names, and a resume that
//! differs is refused with the settings that differ, one by one.

use super::error::EvalError;
use crate::episode::StartMode;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use verti_core::digest::Digest;
use verti_sim::VehicleSpec;
use verti_world::World;

/// Digest of everything a trial reads from one world: its description, elevation, surface
/// patches, obstacles, tasks and global paths.
pub fn world_digest(world: &World) -> String {
    let mut d = Digest::new();
    let t = &world.terrain;
    d.debug(&world.meta)
        .u64(t.size() as u64)
        .f64(t.cell())
        .f64s(t.heights())
        .debug(&world.patches)
        .debug(&world.obstacles)
        .debug(&world.tasks)
        .debug(&world.paths)
        .f64(world.path_clearance);
    d.hex()
}

/// Digest of a world set: its worlds' digests in index order (the order worlds were listed in
/// does not change what a run covers).
pub fn set_digest(worlds: &[Arc<World>]) -> String {
    let each = world_digests(worlds);
    let mut d = Digest::new();
    d.u64(each.len() as u64);
    for (index, digest) in &each {
        d.u64(u64::from(*index)).str(digest);
    }
    d.hex()
}

/// [`world_digest`] of each world, by index: what a run of selected tasks records when it
/// loaded only the worlds they are on (and what [`set_digest`] folds into one).
pub fn world_digests(worlds: &[Arc<World>]) -> BTreeMap<u32, String> {
    use rayon::prelude::*;
    worlds
        .par_iter()
        .map(|w| (w.meta.index, world_digest(w)))
        .collect::<Vec<_>>()
        .into_iter()
        .collect()
}

/// Digest of a vehicle spec (every field of it, the name included).
pub fn vehicle_digest(vehicle: &VehicleSpec) -> String {
    let text = serde_json::to_string(vehicle).expect("vehicle specs serialise");
    Digest::new().str(&text).hex()
}

/// How a step-log setting is recorded: `None` for no logs, `all`, or `last10` for the last
/// 10 s of each trial.
pub fn step_log_label(seconds: Option<f64>) -> Option<String> {
    seconds.map(|s| {
        if s.is_finite() {
            format!("last{s}")
        } else {
            "all".to_string()
        }
    })
}

/// A file the system loads (a model card, its weights), by content: [`input_files`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputFile {
    /// The path as the system was given it.
    pub path: String,
    /// [`Digest::of_file`] of its bytes.
    pub digest: String,
}

/// The files `paths` by content, sorted by path, each once; an unreadable file is an error
/// naming it.
pub fn input_files(paths: &[std::path::PathBuf]) -> Result<Vec<InputFile>, EvalError> {
    let mut out: Vec<InputFile> = Vec::with_capacity(paths.len());
    for p in paths {
        let digest = Digest::of_file(p).map_err(|source| EvalError::Io {
            path: p.clone(),
            source,
        })?;
        out.push(InputFile {
            path: p.display().to_string(),
            digest,
        });
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    out.dedup_by(|a, b| a.path == b.path);
    Ok(out)
}

/// The files system `name` of `registry` loads with `params` when it drives `tasks` (world
/// position, pair) of `worlds`, by content: what [`crate::eval::EvalSetup::inputs`] takes.
pub fn system_inputs(
    registry: &crate::system::SystemRegistry,
    name: &str,
    params: &verti_core::params::Params,
    worlds: &[Arc<World>],
    tasks: &[(usize, u32)],
) -> Result<Vec<InputFile>, EvalError> {
    let mut indices: Vec<u32> = tasks.iter().map(|&(wi, _)| worlds[wi].meta.index).collect();
    indices.sort_unstable();
    indices.dedup();
    let paths = registry
        .inputs(name, params, &indices)
        .map_err(|e| EvalError::Argument(e.to_string()))?;
    input_files(&paths)
}

/// The split a run is one part of (`verti eval --shard INDEX/COUNT`): the shard and the whole
/// selection it was cut from, so that `verti merge` can tell whether its shards cover it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SplitRecord {
    pub index: usize,
    pub count: usize,
    /// The selection the split divides, as task ranges (`1-1000`).
    pub of: String,
}

impl SplitRecord {
    /// What `split` says a run is: `shard i/N of tasks ...`, or `a whole run`.
    pub fn describe(split: Option<&SplitRecord>) -> String {
        split.map_or("a whole run".into(), |s| s.to_string())
    }
}

impl std::fmt::Display for SplitRecord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "shard {}/{} of tasks {}",
            self.index, self.count, self.of
        )
    }
}

/// What a run is, as its caller describes it; `run.json` holds it with the content digests
/// of the worlds and vehicle ([`RunRecord`]) and is compared on resume.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    pub system: String,
    /// Every parameter of the system (defaults included), resolved by its registry. Older
    /// `run.json` files hold only the parameters given, as `[name, number]` pairs; they still
    /// resume (see [`RunRecord::differences`]).
    pub params: verti_core::params::Params,
    pub vehicle: String,
    pub worlds: String,
    /// World scale the set was generated or imported at.
    pub scale: f64,
    pub rules: crate::episode::Rules,
    pub seed: u64,
    pub max_time: f64,
}

/// `OUT/run.json`: the run's settings as given, what they resolved to by content, and the
/// tasks the run covers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    #[serde(flatten)]
    pub run: RunInfo,
    /// [`set_digest`] of the whole world set (absent in runs recorded before digests, and in
    /// runs that loaded only their tasks' worlds: those record `world_digests`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub worlds_digest: Option<String>,
    /// [`world_digest`] of each world the run's tasks are on, by index, for a run of selected
    /// tasks that loaded only those worlds (`verti eval --tasks 1-5` builds one world, not
    /// the set's hundred). Runs compare on the worlds both hold.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub world_digests: BTreeMap<u32, String>,
    /// [`vehicle_digest`] of the vehicle driven (absent in runs recorded before digests).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle_digest: Option<String>,
    /// The vehicle itself, so that `verti replay` drives the same vehicle even when its file
    /// has moved or changed (absent in runs recorded before digests).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle_spec: Option<VehicleSpec>,
    /// How each trial's vehicle starts (runs recorded before the option started settled).
    #[serde(default)]
    pub start: StartMode,
    /// Per-step logs kept ([`step_log_label`]); `None` when the run keeps none.
    #[serde(default)]
    pub step_log: Option<String>,
    /// The tasks the run covers (`all`, or ranges like `1-60`): not part of the identity, a
    /// resume may extend them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tasks: Option<String>,
    /// Perception noise on what the system observed (absent: ground truth).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub perception: Option<crate::perception::PerceptionModel>,
    /// Every file the system loads, by content (absent in runs recorded before, and in runs
    /// of systems that load none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<InputFile>,
    /// The split this run is one shard of (absent: a whole run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<SplitRecord>,
    /// Tasks of the selection with no result: a merge of shards that did not cover it, made
    /// with `--allow-partial` (`verti eval --resume` on the merged directory runs them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub missing: Option<String>,
}

impl RunRecord {
    /// The record of `run` over `worlds` with `vehicle` (digests computed here): `whole_set`
    /// when `worlds` are the whole set `run.worlds` names, else only some of its worlds (then
    /// each world's digest is recorded instead of the set's).
    pub fn new(
        run: &RunInfo,
        worlds: &[Arc<World>],
        whole_set: bool,
        vehicle: &VehicleSpec,
        start: StartMode,
        step_log: Option<f64>,
    ) -> Self {
        let (worlds_digest, world_digests) = if whole_set {
            (Some(set_digest(worlds)), BTreeMap::new())
        } else {
            (None, self::world_digests(worlds))
        };
        RunRecord {
            run: run.clone(),
            worlds_digest,
            world_digests,
            vehicle_digest: Some(vehicle_digest(vehicle)),
            vehicle_spec: Some(vehicle.clone()),
            start,
            step_log: step_log_label(step_log),
            tasks: None,
            perception: None,
            inputs: Vec::new(),
            shard: None,
            missing: None,
        }
    }

    /// Reads `run.json`; errors name the file and what is wrong with it.
    pub fn read(path: &Path) -> Result<Self, EvalError> {
        let text = std::fs::read_to_string(path).map_err(|source| EvalError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| EvalError::Corrupt {
            path: path.to_path_buf(),
            line: e.line(),
            problem: verti_core::messages::explain_serde_error(&e.to_string()),
        })
    }

    /// Whether this record predates content digests (then worlds and vehicle can only be
    /// compared by name).
    pub fn by_name_only(&self) -> bool {
        (self.worlds_digest.is_none() && self.world_digests.is_empty())
            || self.vehicle_digest.is_none()
    }

    /// The worlds both runs recorded one by one whose digests differ, by index (runs of selected
    /// tasks compare on the worlds both hold).
    pub fn worlds_differing_from(&self, other: &RunRecord) -> Vec<u32> {
        self.world_digests
            .iter()
            .filter(|(i, d)| other.world_digests.get(i).is_some_and(|e| e != *d))
            .map(|(i, _)| *i)
            .collect()
    }

    /// Whether the run recorded only its tasks' worlds ([`RunRecord::world_digests`]), not the
    /// whole set's digest.
    pub fn some_worlds(&self) -> bool {
        self.worlds_digest.is_none() && !self.world_digests.is_empty()
    }

    /// The settings in which `recorded` (read from `run.json`) differs from this run, each as
    /// `setting: recorded value, now value`; empty when it is the same run. Worlds and vehicle
    /// compare by content when both records have digests, else by name; parameters compare
    /// by value after resolution (missing ones at their defaults); `tasks` is not compared.
    pub fn differences(&self, recorded: &RunRecord) -> Vec<String> {
        let mut out = Vec::new();
        let (a, b) = (&recorded.run, &self.run);
        differ(&mut out, "system", a.system.clone(), b.system.clone());
        match (&recorded.worlds_digest, &self.worlds_digest) {
            (Some(x), Some(y)) if x != y => out.push(format!(
                "world set: its contents differ (`{}` recorded, `{}` now; world-set digest {} recorded, {} now)",
                a.worlds,
                b.worlds,
                short(x),
                short(y)
            )),
            (Some(_), Some(_)) => {}
            _ if recorded.some_worlds() && self.some_worlds() => {
                let differing: Vec<String> = recorded
                    .worlds_differing_from(self)
                    .iter()
                    .map(u32::to_string)
                    .collect();
                if !differing.is_empty() {
                    out.push(format!(
                        "world set: its contents differ (world(s) {} of `{}` recorded, `{}` now)",
                        differing.join(", "),
                        a.worlds,
                        b.worlds
                    ));
                }
            }
            _ if recorded.some_worlds() || self.some_worlds() => {
                let kind = |r: &RunRecord| {
                    if r.some_worlds() {
                        "only its tasks' worlds"
                    } else {
                        "the whole set"
                    }
                };
                out.push(format!(
                    "world set: `{}` recorded by {}, `{}` now by {}, so their contents cannot be compared",
                    a.worlds,
                    kind(recorded),
                    b.worlds,
                    kind(self)
                ));
            }
            _ => differ(&mut out, "world set", a.worlds.clone(), b.worlds.clone()),
        }
        match (&recorded.vehicle_digest, &self.vehicle_digest) {
            (Some(x), Some(y)) if x != y => differ(
                &mut out,
                "vehicle",
                format!("`{}` (digest {})", a.vehicle, short(x)),
                format!("`{}` (digest {})", b.vehicle, short(y)),
            ),
            (Some(_), Some(_)) => {}
            _ => differ(&mut out, "vehicle", a.vehicle.clone(), b.vehicle.clone()),
        }
        differ(&mut out, "scale", a.scale.to_string(), b.scale.to_string());
        differ(&mut out, "rules", json(&a.rules), json(&b.rules));
        differ(&mut out, "seed", a.seed.to_string(), b.seed.to_string());
        differ(
            &mut out,
            "max_time",
            a.max_time.to_string(),
            b.max_time.to_string(),
        );
        differ(
            &mut out,
            "start",
            recorded.start.name().to_string(),
            self.start.name().to_string(),
        );
        differ(
            &mut out,
            "step logs",
            recorded.step_log.clone().unwrap_or("none".into()),
            self.step_log.clone().unwrap_or("none".into()),
        );
        if recorded.perception != self.perception {
            let name = |p: &Option<crate::perception::PerceptionModel>| {
                p.as_ref()
                    .map_or("none".to_string(), |m| format!("`{}`", m.name))
            };
            out.push(format!(
                "perception: {} recorded, {} now{}",
                name(&recorded.perception),
                name(&self.perception),
                if name(&recorded.perception) == name(&self.perception) {
                    " (same name, different parameters)"
                } else {
                    ""
                }
            ));
        }
        if a.system == b.system {
            out.extend(param_differences(&b.params, &a.params));
        }
        out.extend(input_differences(&recorded.inputs, &self.inputs));
        differ(
            &mut out,
            "split",
            SplitRecord::describe(recorded.shard.as_ref()),
            SplitRecord::describe(self.shard.as_ref()),
        );
        out
    }
}

/// Files loaded now and by the recorded run that differ by content, or that only one of them
/// loads. A record from before inputs were recorded (none) is compared by parameters only.
fn input_differences(recorded: &[InputFile], now: &[InputFile]) -> Vec<String> {
    if recorded.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for f in now {
        match recorded.iter().find(|r| r.path == f.path) {
            Some(r) if r.digest != f.digest => out.push(format!(
                "file `{}`: its contents changed (digest {} recorded, {} now)",
                f.path,
                short(&r.digest),
                short(&f.digest)
            )),
            Some(_) => {}
            None => out.push(format!(
                "file `{}`: loaded now, not by the recorded run",
                f.path
            )),
        }
    }
    for r in recorded {
        if !now.iter().any(|f| f.path == r.path) {
            out.push(format!(
                "file `{}`: loaded by the recorded run, not now",
                r.path
            ));
        }
    }
    out
}

/// Notes `what` in `out` when its recorded and current values differ.
fn differ(out: &mut Vec<String>, what: &str, was: String, now: String) {
    if was != now {
        out.push(format!("{what}: {was} recorded, {now} now"));
    }
}

/// Parameters of `now` whose value differs from `recorded` (taken at `now`'s declared types,
/// missing ones at their defaults).
fn param_differences(
    now: &verti_core::params::Params,
    recorded: &verti_core::params::Params,
) -> Vec<String> {
    if now.same_as_recorded(recorded) {
        return Vec::new();
    }
    let pairs = recorded.to_pairs();
    let resolved = verti_core::params::Params::resolve("run.json", now.specs().clone(), &pairs);
    let Ok(resolved) = resolved else {
        return vec![format!(
            "parameters: {} recorded, {} now",
            json(recorded),
            json(now)
        )];
    };
    let mut out = Vec::new();
    for (name, value) in now.iter() {
        let was = resolved.get(name);
        if was != Some(value) {
            out.push(format!(
                "parameter `{name}`: {} recorded, {value} now",
                was.map_or("none".to_string(), |v| v.to_string())
            ));
        }
    }
    if out.is_empty() {
        // same values, different sets of names (an unknown recorded name)
        out.push(format!(
            "parameters: {} recorded, {} now",
            json(recorded),
            json(now)
        ));
    }
    out
}

fn json<T: Serialize>(x: &T) -> String {
    serde_json::to_string(x).expect("settings serialise")
}

fn short(digest: &str) -> &str {
    &digest[..digest.len().min(12)]
}

/// A warning when a vehicle built for one scale drives worlds of another (a 1/10-scale car on
/// full-scale rocks is legal, and sometimes the point, but rarely what was meant).
pub fn scale_mismatch(vehicle: &VehicleSpec, world_scale: f64) -> Option<String> {
    let label = verti_world::scale::scale_label;
    ((vehicle.scale - world_scale).abs() > 1e-9 * world_scale.abs().max(vehicle.scale.abs()))
        .then(|| {
            format!(
                "vehicle {} is built for scale {} but the worlds are at scale {}: obstacles, slopes and speeds will be out of proportion",
                vehicle.name,
                label(vehicle.scale),
                label(world_scale)
            )
        })
}
