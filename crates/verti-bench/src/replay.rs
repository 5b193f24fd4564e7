//! Replaying one evaluated trial: everything a replay needs, resolved from a run directory
//! and checked to be what the run used (trials are deterministic, so re-running the task with
//! the recorded settings is the trial).

use crate::episode::{EpisodeConfig, TrialResult};
use crate::run::identity::RunRecord;
use crate::run::{RESULTS_FILE, RUN_FILE, read_results};
use crate::system::{MobilitySystem, SystemRegistry};
use std::path::Path;
use std::sync::Arc;
use verti_sim::VehicleSpec;
use verti_world::{TaskId, World};

/// One trial of a run, ready to be driven again.
pub struct ReplaySetup {
    pub world: Arc<World>,
    pub vehicle: VehicleSpec,
    pub pair: u32,
    pub system: Box<dyn MobilitySystem>,
    /// The run's settings (rules, limit, seed, start, perception), no step log.
    pub cfg: EpisodeConfig,
    /// The trial as the run recorded it.
    pub recorded: TrialResult,
}

impl ReplaySetup {
    /// A warning when `replayed` ended otherwise than the recorded trial (a changed system or
    /// engine since the run).
    pub fn mismatch(&self, replayed: &TrialResult) -> Option<String> {
        let r = &self.recorded;
        (replayed.outcome != r.outcome || (replayed.time - r.time).abs() > 1e-9).then(|| {
            format!(
                "the replay ended differently ({:?} at {:.2} s) from the recorded trial ({:?} at {:.2} s)",
                replayed.outcome, replayed.time, r.outcome, r.time
            )
        })
    }
}

/// Where a replay finds the run's worlds. Every choice is checked by content against the run's
/// record. A run made on worlds held in memory (`verti.evaluate` on a list of `World`s)
/// records only a label such as `100 worlds`, which no name resolves: it needs one of the
/// other two.
pub enum ReplayWorlds {
    /// The set the run names, at its recorded scale.
    Recorded,
    /// Another set name or path (as `verti eval --worlds`), or one world as `SET:INDEX`, at the
    /// run's recorded scale.
    Named(String),
    /// The worlds themselves.
    Given(Vec<Arc<World>>),
}

/// Reads `dir/run.json` and the result of `task`, and rebuilds its world (from the run's set,
/// checked by content), vehicle (the recorded spec, checked by digest) and system (from
/// `registry` with the recorded parameters). `vehicle_by_name` loads a vehicle for runs
/// recorded before specs were kept. `worlds` says where the worlds come from.
pub fn prepare(
    dir: &Path,
    task: u32,
    registry: &SystemRegistry,
    vehicle_by_name: &dyn Fn(&str) -> Result<VehicleSpec, String>,
    worlds: ReplayWorlds,
) -> Result<ReplaySetup, String> {
    let run_path = dir.join(RUN_FILE);
    let record = RunRecord::read(&run_path).map_err(|e| e.to_string())?;
    let run = &record.run;
    let (results, _) = read_results(&dir.join(RESULTS_FILE)).map_err(|e| e.to_string())?;
    let recorded = results
        .iter()
        .find(|r| r.task == task)
        .cloned()
        .ok_or_else(|| {
            format!(
                "task {task} is not in {} ({} results)",
                dir.display(),
                results.len()
            )
        })?;
    let vehicle = match &record.vehicle_spec {
        Some(spec) => spec.clone(),
        None => vehicle_by_name(&run.vehicle)?,
    };
    if let Some(d) = &record.vehicle_digest
        && *d != crate::run::identity::vehicle_digest(&vehicle)
    {
        return Err(format!(
            "{}: vehicle `{}` is not the one the run drove (its contents changed since)",
            run_path.display(),
            run.vehicle
        ));
    }
    let id = TaskId::from_number(task).ok_or("task numbers start at 1")?;
    // the whole set, to check by content that it is still the set the run used (or, for a run
    // that recorded only its tasks' worlds, the task's world alone)
    let given = !matches!(worlds, ReplayWorlds::Recorded);
    let as_set = |worlds: Vec<World>| worlds.into_iter().map(Arc::new).collect::<Vec<_>>();
    let set: Vec<Arc<World>> = match worlds {
        ReplayWorlds::Given(set) => set,
        ReplayWorlds::Named(spec) => {
            let resolved = if verti_world::sets::split_world_index(&spec).is_some() {
                verti_world::sets::resolve_world(&spec, run.scale).map(|w| vec![w])
            } else {
                verti_world::sets::resolve_set(&spec, run.scale, &|| {}).map(|s| s.worlds)
            };
            as_set(resolved.map_err(|e| format!("the worlds `{spec}`: {e}"))?)
        }
        ReplayWorlds::Recorded => as_set(
            if record.some_worlds() {
                let one = std::collections::BTreeSet::from([id.world]);
                verti_world::sets::resolve_set_worlds(&run.worlds, run.scale, &one, &|| {})
            } else {
                verti_world::sets::resolve_set(&run.worlds, run.scale, &|| {})
            }
            .map_err(|e| {
                    format!(
                        "the run's world set `{}`: {e}; a run made on worlds held in memory is replayed by passing the same worlds (verti.replay(..., worlds=...), verti replay --worlds SET)",
                        run.worlds
                    )
                })?
                .worlds,
        ),
    };
    let world = set
        .iter()
        .find(|w| w.meta.index == id.world)
        .cloned()
        .ok_or_else(|| format!("`{}` has no world {}", run.worlds, id.world))?;
    let same = match &record.worlds_digest {
        Some(d) => *d == crate::run::identity::set_digest(&set),
        None if record.some_worlds() => record
            .world_digests
            .get(&id.world)
            .is_some_and(|d| *d == crate::run::identity::world_digest(&world)),
        None => true,
    };
    if !same {
        return Err(if given {
            format!(
                "the worlds given are not those the run in {} used (`{}`: their contents differ)",
                dir.display(),
                run.worlds
            )
        } else {
            format!(
                "`{}` no longer holds the worlds the run in {} used (their contents differ); replay where the run was made, or restore the set",
                run.worlds,
                dir.display()
            )
        });
    }
    let system = registry
        .build(&run.system, &run.params)
        .map_err(|e| e.to_string())?;
    let cfg = EpisodeConfig {
        rules: run.rules,
        max_time: run.max_time,
        seed: run.seed,
        start: record.start,
        perception: record.perception.clone().map(Arc::new),
        ..Default::default()
    };
    Ok(ReplaySetup {
        world,
        vehicle,
        pair: id.pair,
        system,
        cfg,
        recorded,
    })
}
