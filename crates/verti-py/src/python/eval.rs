//! Evaluation: built-in systems run in parallel in Rust, results as dicts.

use super::*;
use verti_registry::ReadySystem;

/// Wraps a system so an interrupted evaluation ends its running trials at their next control
/// step: once `cancel` is raised the system returns an invalid action, which `run_episode`
/// ends at once (that trial is then discarded, never reported or recorded).
pub(super) struct Cancellable {
    inner: Box<dyn MobilitySystem>,
    cancel: Arc<AtomicBool>,
}

impl MobilitySystem for Cancellable {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn control_rate(&self) -> f64 {
        self.inner.control_rate()
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.inner.reset(task)
    }
    fn act(&mut self, obs: &Observation) -> Action {
        if self.cancel.load(Ordering::Relaxed) {
            return Action::HighLevel {
                speed: f64::NAN,
                steering: 0.0,
            };
        }
        self.inner.act(obs)
    }
    fn failure(&self) -> Option<String> {
        self.inner.failure()
    }
}

pub(super) fn parse_rules(s: &str) -> PyResult<Rules> {
    match s {
        "paper" => Ok(Rules::Paper),
        "verti-bench" | "vertibench" | "reference" => Ok(Rules::VertiBench),
        _ => Err(value_err(format!(
            "unknown rules `{s}`: use 'paper' or 'verti-bench'"
        ))),
    }
}

pub(super) fn tasks_arg(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<u32>> {
    let Some(arg) = arg else {
        return Ok(Vec::new());
    };
    if arg.is_none() {
        return Ok(Vec::new());
    }
    if let Ok(s) = arg.cast::<PyString>() {
        return parse_tasks(&s.extract::<String>()?).map_err(eval_err);
    }
    if let Ok(n) = arg.extract::<i64>() {
        return u32::try_from(n)
            .ok()
            .filter(|n| *n >= 1)
            .map(|n| vec![n])
            .ok_or_else(|| value_err(format!("task number {n} must be at least 1")));
    }
    let list: Vec<i64> = arg.extract().map_err(|_| PyTypeError::new_err("tasks must be None (all), a task number, a list of task numbers or a range string like '1-10,15'"))?;
    if list.is_empty() {
        // an empty list would select nothing; "all" is spelled None
        return Err(value_err(
            "tasks=[] selects no task; pass None for all tasks".into(),
        ));
    }
    let mut out = Vec::with_capacity(list.len());
    for n in list {
        out.push(
            u32::try_from(n)
                .ok()
                .filter(|n| *n >= 1)
                .ok_or_else(|| value_err(format!("task number {n} must be at least 1")))?,
        );
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

pub(super) fn results_to_py(py: Python<'_>, results: &[TrialResult]) -> PyResult<Vec<Py<PyAny>>> {
    // serde is the single definition of the result fields (the same JSON as results.jsonl)
    let loads = py.import("json")?.getattr("loads")?;
    results
        .iter()
        .map(|r| {
            let text =
                serde_json::to_string(r).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            Ok(loads.call1((text,))?.unbind())
        })
        .collect()
}

/// One parameter value: bool, int, float, str or a path (`pathlib.Path`), as the same
/// `ParamValue` the command line's text becomes, so both are checked by the same
/// `ParamSpec::check` (an int parameter takes 2 and 2.0, never 2.5). `name` names the parameter
/// in the error for a value of another type or an int beyond 64 bits.
pub(super) fn param_value(name: &str, v: &Bound<'_, PyAny>) -> PyResult<ParamValue> {
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Ok(ParamValue::Bool(v.extract::<bool>()?));
    }
    if v.is_instance_of::<pyo3::types::PyInt>() {
        if let Ok(i) = v.extract::<i64>() {
            return Ok(ParamValue::Int(i));
        }
        // beyond 64 bits it is outside every declared range; as a float the check says which
        // range (`1e30 is outside [1, 65536]`), unless even a float cannot hold it
        return v.extract::<f64>().map(ParamValue::Float).map_err(|_| {
            let digits = v.str().map(|s| s.to_string()).unwrap_or_default();
            value_err(format!(
                "parameter {name}: the integer {} ({} digits) is outside the 64-bit range",
                &digits[..digits.len().min(20)],
                digits.trim_start_matches('-').len()
            ))
        });
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(ParamValue::Int(i));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(ParamValue::Float(x));
    }
    if let Ok(t) = v.extract::<String>() {
        return Ok(ParamValue::Str(t));
    }
    v.extract::<PathBuf>().map(ParamValue::Path).map_err(|_| {
        let kind = v
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        PyTypeError::new_err(format!(
            "parameter {name}: a value of type {kind} is not a parameter value; give a number, bool, str or path"
        ))
    })
}

/// System parameters: None, a dict name -> value, or a list of (name, value) pairs.
pub(super) fn params_arg(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<(String, ParamValue)>> {
    let Some(arg) = arg.filter(|a| !a.is_none()) else {
        return Ok(Vec::new());
    };
    let bad = || {
        PyTypeError::new_err(
            "params must be a dict of parameter name -> value (number, bool, str or path), e.g. {'speed': 4.0}",
        )
    };
    let pair = |k: &Bound<'_, PyAny>, v: &Bound<'_, PyAny>| {
        let name = k.extract::<String>().map_err(|_| bad())?;
        let value = param_value(&name, v)?;
        Ok((name, value))
    };
    if let Ok(d) = arg.cast::<PyDict>() {
        return d.iter().map(|(k, v)| pair(&k, &v)).collect();
    }
    arg.try_iter()
        .map_err(|_| bad())?
        .map(|item| {
            let (k, v) = item?
                .extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>()
                .map_err(|_| bad())?;
            pair(&k, &v)
        })
        .collect()
}

/// Runs `system` on the selected tasks, `jobs` trials at a time, and returns one dict per
/// trial (the fields of `results.jsonl`), sorted by task. With `out`, results are also written
/// there, resumable like `verti eval`. Ctrl-C stops it.
///
/// Arguments:
///
/// - system: a built-in system's name (default "pid"; `verti.systems()` lists them), or a
///   Python object with `reset(task)` and `act(obs)`, run one trial at a time through the same
///   trial code. `act` returns (target speed m/s, steering in [-1, 1]), or with
///   `action_mode = "low"` (throttle, brake, steering). Optional attributes: `name`,
///   `control_rate` (Hz), `action_mode`, `state_features`, `lookahead`, `elevation`,
///   `semantic`, `occupancy` (the observation the object asks for).
/// - worlds: a set by name ("verti-100", the default; "verti-N-sSEED"; a saved set, a world
///   directory or a folder of Verti-Bench worlds), "SET:INDEX" for one world, a World or a
///   list of Worlds. A set by name builds only the worlds of the selected tasks.
/// - tasks: task numbers, as "1-10,15", an int, a sequence or an array of ints; None for all.
/// - jobs: trials run at once (default: one per core; a Python system runs one at a time).
/// - vehicle: a built-in vehicle's name or a vehicle YAML file (default: the vehicle for the
///   worlds' scale).
/// - params: a built-in system's parameters, as {name: value} or (name, value) pairs; each is
///   checked against its declared type and range (`verti.systems()`).
/// - rules: "paper" (default) or "verti-bench" (the reference code's success and failure rules).
/// - max_time: seconds per trial before a timeout (default 60).
/// - seed: the seed of every random draw (default 0): same seed, same results.
/// - scale: the scale to build named worlds at (1, 1/6, 1/10, ...; default 1).
/// - start: "settled" (default: the vehicle starts at rest on the ground) or "drop"
///   (Verti-Bench's spawn above the ground).
/// - out: a folder for `results.jsonl` and `run.json`, created if missing (its parent must
///   exist).
/// - resume: continue the run in `out`, skipping finished tasks.
/// - force: discard the run in `out` and start over.
/// - perception: "none" (default), a preset ("low", "medium", "high") or a perception YAML
///   file: noise on what the system observes.
#[pyfunction]
#[pyo3(signature = (system = None, worlds = None, tasks = None, jobs = None, *, vehicle = None, params = None, rules = "paper", max_time = 60.0, seed = 0, scale = None, start = "settled", out = None, resume = false, force = false, perception = "none"))]
#[allow(clippy::too_many_arguments)]
pub(super) fn evaluate(
    py: Python<'_>,
    system: Option<&Bound<'_, PyAny>>,
    worlds: Option<&Bound<'_, PyAny>>,
    tasks: Option<&Bound<'_, PyAny>>,
    jobs: Option<usize>,
    vehicle: Option<&str>,
    params: Option<&Bound<'_, PyAny>>,
    rules: &str,
    max_time: f64,
    seed: u64,
    scale: Option<f64>,
    start: &str,
    out: Option<PathBuf>,
    resume: bool,
    force: bool,
    perception: &str,
) -> PyResult<Vec<Py<PyAny>>> {
    let default = PyString::new(py, "pid");
    let system = match system {
        Some(s) if !s.is_none() => s,
        _ => default.as_any(),
    };
    if resume && force {
        return Err(value_err(
            "resume=True continues the run in `out` and force=True discards it: pass one of them"
                .into(),
        ));
    }
    if let Some(out) = &out {
        out_dir_arg("out", out)?;
    }
    let setup = EvalArgs {
        worlds,
        tasks,
        jobs,
        vehicle,
        rules,
        max_time,
        seed,
        scale,
        start,
        out,
        resume,
        force,
        perception,
    };
    if !system.is_instance_of::<PyString>() {
        return evaluate_object(py, system, params, setup);
    }
    let system: String = system.extract()?;
    let system = system.as_str();
    let registry = system_registry();
    // unknown names and bad parameters fail here, against the declarations, before any work
    let params = registry
        .resolve(system, &params_arg(params)?)
        .map_err(|e| value_err(e.to_string()))?;
    // what only building checks (a model card that must load, a plan that must fit in
    // memory): the instance built for it drives the first trial
    let ready =
        ReadySystem::new(&registry, system, params).map_err(|e| value_err(e.to_string()))?;
    let params = ready.params();
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    verti_bench::eval::check_jobs(jobs, "jobs").map_err(value_err)?;
    let Prepared {
        spec,
        worlds,
        whole_set,
        worlds_name,
        selected,
        episode,
    } = prepare(py, &setup)?;
    let out = setup.out;
    let cancel = Arc::new(AtomicBool::new(false));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| value_err(format!("cannot start {jobs} worker threads: {e}")))?;

    let Some(out) = out else {
        let results: Vec<Option<TrialResult>> = interruptible(py, &cancel, || {
            pool.install(|| {
                selected
                    .par_iter()
                    .map(|&(wi, pair)| {
                        if cancel.load(Ordering::Relaxed) {
                            return None;
                        }
                        let inner = ready.make();
                        let mut sys = Cancellable {
                            inner,
                            cancel: cancel.clone(),
                        };
                        let r = run_episode(&worlds[wi], &spec, pair, &mut sys, &episode, None);
                        (!cancel.load(Ordering::Relaxed)).then_some(r)
                    })
                    .collect()
            })
        })?;
        let results: Vec<TrialResult> = results.into_iter().flatten().collect();
        return results_to_py(py, &results);
    };

    // With a results folder: verti_bench::eval::evaluate (the CLI's resumable runner) in one
    // call. Ctrl-C raises `cancel` while it runs (see `interruptible`), so it needs no chunks
    // (which digested the worlds and re-read the results file once per chunk).
    let numbers: Vec<u32> = selected
        .iter()
        .map(|&(wi, pair)| {
            TaskId {
                world: worlds[wi].meta.index,
                pair,
            }
            .number()
        })
        .collect();
    let run = RunInfo {
        system: system.to_string(),
        params: params.clone(),
        vehicle: spec.name.clone(),
        worlds: worlds_name,
        scale: worlds[0].meta.scale,
        rules: episode.rules,
        seed,
        max_time,
    };
    let notes = std::sync::Mutex::new(Vec::new());
    let note = |m: &str| {
        notes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .push(m.to_string())
    };
    // `evaluate` reads an empty selection as "all tasks"; nothing selected runs nothing
    let mut all = Vec::new();
    let inputs = |tasks: &[(usize, u32)]| {
        verti_bench::identity::system_inputs(&registry, system, params, &worlds, tasks)
    };
    if !numbers.is_empty() {
        let setup = EvalSetup {
            worlds: &worlds,
            whole_set,
            vehicle: &spec,
            episode: episode.clone(),
            jobs,
            out: out.clone(),
            resume,
            force,
            run,
            inputs: Some(&inputs),
            shard: None,
            step_log: None,
            cancel: Some(&cancel),
            warn: Some(&note),
        };
        // trials in flight stop at their next control step on Ctrl-C, and are not recorded
        let make = || -> Box<dyn MobilitySystem> {
            Box::new(Cancellable {
                inner: ready.make(),
                cancel: cancel.clone(),
            })
        };
        all = interruptible(py, &cancel, || {
            verti_bench::eval::evaluate(&setup, &numbers, &make, &|_| {})
        })?
        .map_err(eval_err)?;
    }
    warn_all(py, &notes)?;
    let wanted: std::collections::BTreeSet<u32> = numbers.into_iter().collect();
    all.retain(|r| wanted.contains(&r.task));
    results_to_py(py, &all)
}

/// The systems that `evaluate` knows, with their parameters (name, type, default, min and
/// max or choices, doc).
#[pyfunction]
pub(super) fn systems(py: Python<'_>) -> PyResult<Py<PyAny>> {
    let list: Vec<verti_bench::SystemInfo> = system_registry().list().cloned().collect();
    let text = serde_json::to_string(&list).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(py
        .import("json")?
        .getattr("loads")?
        .call1((text,))?
        .unbind())
}

/// The settings of `evaluate` that do not depend on the kind of system.
pub(super) struct EvalArgs<'a, 'py> {
    worlds: Option<&'a Bound<'py, PyAny>>,
    tasks: Option<&'a Bound<'py, PyAny>>,
    jobs: Option<usize>,
    vehicle: Option<&'a str>,
    rules: &'a str,
    max_time: f64,
    seed: u64,
    scale: Option<f64>,
    start: &'a str,
    out: Option<PathBuf>,
    resume: bool,
    force: bool,
    /// A perception preset or YAML file (`none`: ground truth).
    perception: &'a str,
}

/// What every evaluation resolves first: the vehicle, the worlds, the selected tasks and the
/// rules, each checked with a clear error.
struct Prepared {
    spec: VehicleSpec,
    worlds: Vec<Arc<World>>,
    /// Whether `worlds` are the whole set (else only the selected tasks' worlds).
    whole_set: bool,
    worlds_name: String,
    selected: Vec<(usize, u32)>,
    episode: EpisodeConfig,
}

/// A perception preset or YAML file; None for ground truth.
pub(super) fn perception_arg(
    spec: &str,
) -> PyResult<Option<Arc<verti_bench::perception::PerceptionModel>>> {
    let m = verti_bench::perception::PerceptionModel::load(spec)
        .map_err(|e| value_err(format!("perception: {e}")))?;
    Ok((!m.is_none()).then(|| Arc::new(m)))
}

fn prepare(py: Python<'_>, a: &EvalArgs<'_, '_>) -> PyResult<Prepared> {
    // a selection of tasks needs only the worlds they are on, and a resume those of the
    // recorded run too (`worlds_to_load`)
    let selection = tasks_arg(a.tasks)?;
    let only = match &a.out {
        Some(out) => verti_bench::run::worlds_to_load(out, a.resume, a.force, &selection),
        None => (!selection.is_empty()).then(|| verti_bench::run::task_worlds(&selection)),
    };
    let default = PyString::new(py, "verti-100");
    let arg = match a.worlds {
        Some(w) if !w.is_none() => w,
        _ => default.as_any(),
    };
    let (worlds, worlds_name, whole_set) = some_worlds_arg(py, arg, a.scale, only.as_ref())?;
    if worlds.is_empty() {
        return Err(value_err(format!("`{worlds_name}` holds no worlds")));
    }
    // as on the command line: the worlds' scale picks the default vehicle, and a vehicle
    // built for another scale runs with a warning
    let scale = worlds[0].meta.scale;
    let spec = vehicle_spec(
        a.vehicle
            .unwrap_or_else(|| verti_sim::vehicles::default_for_scale(scale)),
    )?;
    if let Some(m) = verti_bench::identity::scale_mismatch(&spec, scale) {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        let text = std::ffi::CString::new(m.replace('\0', " ")).expect("no NUL left");
        PyErr::warn(py, &category, &text, 1)?;
    }
    let start = verti_bench::StartMode::from_name(a.start).ok_or_else(|| {
        value_err(format!(
            "unknown start {:?}: use 'settled' or 'drop'",
            a.start
        ))
    })?;
    let episode = EpisodeConfig {
        rules: parse_rules(a.rules)?,
        max_time: a.max_time,
        seed: a.seed,
        start,
        perception: perception_arg(a.perception)?,
        ..Default::default()
    };
    episode.validate().map_err(value_err)?;
    let selected = select_tasks(&worlds, &selection).map_err(eval_err)?;
    Ok(Prepared {
        spec,
        worlds,
        whole_set,
        worlds_name,
        selected,
        episode,
    })
}

/// `evaluate` with a Python object as the system: one trial at a time (the object is not
/// shared between threads), through `run_episode` and, with `out`, the resumable runner.
fn evaluate_object(
    py: Python<'_>,
    object: &Bound<'_, PyAny>,
    params: Option<&Bound<'_, PyAny>>,
    a: EvalArgs<'_, '_>,
) -> PyResult<Vec<Py<PyAny>>> {
    if params.is_some_and(|p| !p.is_none()) {
        return Err(value_err(
            "params apply to built-in systems; a Python system takes its settings itself".into(),
        ));
    }
    if a.jobs.is_some_and(|j| j != 1) {
        return Err(value_err(
            "a Python system runs one trial at a time: leave jobs unset or pass jobs=1".into(),
        ));
    }
    let sys_spec = PySystemSpec::of(object)?;
    let Prepared {
        spec,
        worlds,
        whole_set,
        worlds_name,
        selected,
        episode,
    } = prepare(py, &a)?;
    let raised: RaisedError = Arc::new(std::sync::Mutex::new(None));
    let cancel = Arc::new(AtomicBool::new(false));
    let object: Py<PyAny> = object.clone().unbind();
    let make = || -> Box<dyn MobilitySystem> {
        let obj = Python::attach(|py| object.clone_ref(py));
        Box::new(PySystem::new(
            obj,
            sys_spec.clone(),
            raised.clone(),
            cancel.clone(),
        ))
    };
    let take_raised = || raised.lock().unwrap_or_else(|p| p.into_inner()).take();

    let Some(out) = a.out else {
        let results: Vec<TrialResult> = interruptible(py, &cancel, || {
            let mut done = Vec::new();
            for &(wi, pair) in &selected {
                let mut system = make();
                let r = run_episode(&worlds[wi], &spec, pair, system.as_mut(), &episode, None);
                if cancel.load(Ordering::SeqCst) {
                    break;
                }
                done.push(r);
            }
            done
        })?;
        if let Some(e) = take_raised() {
            return Err(e);
        }
        return results_to_py(py, &results);
    };
    let run = RunInfo {
        system: sys_spec.name.clone(),
        params: Default::default(),
        vehicle: spec.name.clone(),
        worlds: worlds_name,
        scale: worlds[0].meta.scale,
        rules: episode.rules,
        seed: a.seed,
        max_time: a.max_time,
    };
    let notes = std::sync::Mutex::new(Vec::new());
    let note = |m: &str| {
        notes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .push(m.to_string())
    };
    let setup = EvalSetup {
        worlds: &worlds,
        whole_set,
        vehicle: &spec,
        episode,
        jobs: 1,
        out,
        resume: a.resume,
        force: a.force,
        run,
        // a Python object: no files known to the registry
        inputs: None,
        shard: None,
        step_log: None,
        cancel: Some(&cancel),
        warn: Some(&note),
    };
    let numbers: Vec<u32> = selected
        .iter()
        .map(|&(wi, pair)| worlds[wi].task_id(pair).number())
        .collect();
    let result = interruptible(py, &cancel, || {
        verti_bench::eval::evaluate(&setup, &numbers, &make, &|_| {})
    })?;
    if let Some(e) = take_raised() {
        return Err(e);
    }
    let mut all = result.map_err(eval_err)?;
    warn_all(py, &notes)?;
    let wanted: std::collections::BTreeSet<u32> = numbers.into_iter().collect();
    all.retain(|r| wanted.contains(&r.task));
    results_to_py(py, &all)
}

/// Passes the notes of a run (repairs made on the way) to Python's `warnings`.
fn warn_all(py: Python<'_>, notes: &std::sync::Mutex<Vec<String>>) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for m in notes.lock().unwrap_or_else(|p| p.into_inner()).drain(..) {
        let text = std::ffi::CString::new(m.replace('\0', " ")).expect("no NUL left");
        PyErr::warn(py, &category, &text, 1)?;
    }
    Ok(())
}
