//! The environment cores behind `verti.envs` (bindings of the verti-env crate).

use super::*;

pub(super) fn crop_arg(v: &Bound<'_, PyAny>, name: &str) -> PyResult<Option<CropSpec>> {
    if v.is_none() {
        return Ok(None);
    }
    if let Ok(size) = v.extract::<usize>() {
        return Ok(Some(CropSpec {
            size,
            resolution: 0.1,
        }));
    }
    let (size, resolution) = v.extract::<(usize, f64)>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name} must be None, a size in cells (0.1 m each) or a (size, resolution_m) pair"
        ))
    })?;
    Ok(Some(CropSpec { size, resolution }))
}

pub(super) fn names_arg<T>(
    v: &Bound<'_, PyAny>,
    what: &str,
    parse: impl Fn(&str) -> Option<T>,
    known: &str,
) -> PyResult<Vec<T>> {
    if v.is_none() {
        return Ok(Vec::new());
    }
    let names: Vec<String> = if let Ok(s) = v.extract::<String>() {
        vec![s]
    } else {
        v.extract().map_err(|_| {
            PyTypeError::new_err(format!("{what} must be a name or a list of names"))
        })?
    };
    if names.is_empty() {
        // an empty list would select nothing; "all" is spelled None
        return Err(value_err(format!(
            "an empty list of {what}s selects nothing; pass None for all (known: {known})"
        )));
    }
    names
        .iter()
        .map(|n| parse(n).ok_or_else(|| value_err(format!("unknown {what} `{n}`; known: {known}"))))
        .collect()
}

pub(super) fn reward_arg(v: &Bound<'_, PyAny>) -> PyResult<RewardConfig> {
    let mut r = RewardConfig::default();
    if v.is_none() {
        return Ok(r);
    }
    let d = v
        .cast::<PyDict>()
        .map_err(|_| PyTypeError::new_err("reward weights must be a dict"))?;
    for (k, val) in d.iter() {
        let key: String = k.extract()?;
        let x: f64 = val
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("reward weight {key} must be a number")))?;
        let slot = match key.as_str() {
            "progress" => &mut r.progress,
            "no_progress_penalty" => &mut r.no_progress_penalty,
            "no_progress_speed" => &mut r.no_progress_speed,
            "roll_weight" => &mut r.roll_weight,
            "pitch_weight" => &mut r.pitch_weight,
            "tilt_threshold_deg" => &mut r.tilt_threshold_deg,
            "success" => &mut r.success,
            "timeout" => &mut r.timeout,
            "timeout_per_metre" => &mut r.timeout_per_metre,
            "stuck" => &mut r.stuck,
            "rollover" => &mut r.rollover,
            "error" => &mut r.error,
            _ => {
                return Err(value_err(format!(
                    "unknown reward weight `{key}`; known: progress, no_progress_penalty, no_progress_speed, roll_weight, pitch_weight, tilt_threshold_deg, success, timeout, timeout_per_metre, stuck, rollover, error"
                )));
            }
        };
        *slot = x;
    }
    Ok(r)
}

/// Builds an environment core from the keyword settings the Python wrappers pass through.
pub(super) fn env_core(
    py: Python<'_>,
    worlds: &Bound<'_, PyAny>,
    vehicle: Option<&str>,
    settings: &Bound<'_, PyDict>,
) -> PyResult<EnvCore> {
    const KNOWN: [&str; 19] = [
        "perception",
        "scale",
        "control_rate",
        "action_mode",
        "max_speed",
        "max_time",
        "rules",
        "lookahead",
        "elevation",
        "semantic",
        "occupancy",
        "reward_weights",
        "tasks",
        "levels",
        "densities",
        "terrain_types",
        "seed",
        "inner_dt",
        "state_features",
    ];
    for k in settings.keys() {
        let k: String = k.extract()?;
        if !KNOWN.contains(&k.as_str()) {
            return Err(value_err(format!(
                "unknown environment setting `{k}`; known: {}",
                KNOWN.join(", ")
            )));
        }
    }
    let get = |k: &str| -> PyResult<Option<Bound<'_, PyAny>>> {
        Ok(settings.get_item(k)?.filter(|v| !v.is_none()))
    };
    let f = |k: &str, default: f64| -> PyResult<f64> {
        get(k)?.map_or(Ok(default), |v| {
            v.extract::<f64>()
                .map_err(|_| PyTypeError::new_err(format!("{k} must be a number")))
        })
    };
    let scale = get("scale")?
        .map(|v| {
            v.extract::<f64>()
                .map_err(|_| PyTypeError::new_err("scale must be a number"))
        })
        .transpose()?;
    let (worlds, _) = worlds_arg(py, worlds, scale)?;
    // the worlds' scale picks the default vehicle; another scale's vehicle gets a warning
    let scale = worlds[0].meta.scale;
    let spec =
        vehicle_spec(vehicle.unwrap_or_else(|| verti_sim::vehicles::default_for_scale(scale)))?;
    if let Some(m) = verti_bench::identity::scale_mismatch(&spec, scale) {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        let text = std::ffi::CString::new(m.replace('\0', " ")).expect("no NUL left");
        PyErr::warn(py, &category, &text, 1)?;
    }
    let mut cfg = EnvConfig::default();
    cfg.control_rate = f("control_rate", cfg.control_rate)?;
    cfg.max_speed = f("max_speed", cfg.max_speed)?;
    cfg.lookahead = f("lookahead", cfg.lookahead)?;
    cfg.episode.max_time = f("max_time", cfg.episode.max_time)?;
    cfg.episode.inner_dt = f("inner_dt", cfg.episode.inner_dt)?;
    if let Some(r) = get("rules")? {
        cfg.episode.rules = parse_rules(&r.extract::<String>()?)?;
    }
    if let Some(p) = get("perception")? {
        let spec: String = p
            .extract()
            .map_err(|_| PyTypeError::new_err("perception must be a preset name or a YAML path"))?;
        cfg.episode.perception = super::eval::perception_arg(&spec)?;
    }
    if let Some(a) = get("action_mode")? {
        cfg.action = match a.extract::<String>()?.as_str() {
            "high" | "high-level" | "speed" => ActionMode::HighLevel,
            "low" | "low-level" | "drive" => ActionMode::LowLevel,
            other => {
                return Err(value_err(format!(
                    "unknown action_mode `{other}`: use 'high' (target speed, steering) or 'low' (throttle, brake, steering)"
                )));
            }
        };
    }
    let none = py.None().into_bound(py);
    cfg.elevation = crop_arg(
        &get("elevation")?.unwrap_or_else(|| none.clone()),
        "elevation",
    )?;
    cfg.semantic = crop_arg(
        &get("semantic")?.unwrap_or_else(|| none.clone()),
        "semantic",
    )?;
    cfg.occupancy = crop_arg(
        &get("occupancy")?.unwrap_or_else(|| none.clone()),
        "occupancy",
    )?;
    if let Some(names) = get("state_features")? {
        let names: Vec<String> = names.extract().map_err(|_| {
            PyTypeError::new_err("state_features must be a list of feature names (verti.FEATURES)")
        })?;
        cfg.state_features = Feature::parse_list(&names).map_err(value_err)?;
    }
    cfg.reward = reward_arg(&get("reward_weights")?.unwrap_or_else(|| none.clone()))?;
    let filter = TaskFilter {
        tasks: tasks_arg(get("tasks")?.as_ref())?,
        levels: names_arg(
            &get("levels")?.unwrap_or_else(|| none.clone()),
            "level",
            ElevationLevel::from_name,
            "low, mid, high",
        )?,
        densities: names_arg(
            &get("densities")?.unwrap_or_else(|| none.clone()),
            "density",
            ObstacleDensity::from_name,
            "sparse, medium, dense",
        )?,
        terrain_types: names_arg(
            &get("terrain_types")?.unwrap_or_else(|| none.clone()),
            "terrain type",
            TerrainType::from_name,
            "rigid, deformable, mixed",
        )?,
    };
    let seed: u64 = get("seed")?.map_or(Ok(0), |v| v.extract())?;
    EnvCore::new(worlds, spec, cfg, &filter, seed).map_err(env_err)
}

pub(super) fn obs_dict<'py>(
    py: Python<'py>,
    cfg: &EnvConfig,
    o: &ObsBuf,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("state", PyArray1::from_slice(py, &o.state))?;
    d.set_item("goal", PyArray1::from_slice(py, &o.goal))?;
    d.set_item("local_goal", PyArray1::from_slice(py, &o.local_goal))?;
    if let Some(c) = cfg.elevation {
        d.set_item(
            "elevation",
            PyArray1::from_slice(py, &o.elevation).reshape([c.size, c.size])?,
        )?;
    }
    if let Some(c) = cfg.semantic {
        d.set_item(
            "semantic",
            PyArray1::from_slice(py, &o.semantic).reshape([c.size, c.size])?,
        )?;
    }
    if let Some(c) = cfg.occupancy {
        d.set_item(
            "occupancy",
            PyArray1::from_slice(py, &o.occupancy).reshape([c.size, c.size])?,
        )?;
    }
    Ok(d)
}

pub(super) fn info_dict<'py>(
    py: Python<'py>,
    core: &EnvCore,
    report: Option<&StepReport>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let Some(ep) = core.episode() else {
        return Ok(d);
    };
    let world = &core.worlds()[ep.world];
    d.set_item("task", ep.id.number())?;
    d.set_item("world", ep.id.world)?;
    d.set_item("pair", ep.id.pair)?;
    d.set_item("world_name", world.meta.name.as_str())?;
    d.set_item("level", world.meta.level.name())?;
    d.set_item("density", world.meta.density.name())?;
    d.set_item("terrain_type", world.meta.terrain_type.name())?;
    d.set_item("time", ep.time())?;
    d.set_item("distance_to_goal", ep.goal_distance())?;
    let p = ep.pose();
    d.set_item("pose", (p.x, p.y, p.z, p.roll, p.pitch, p.yaw))?;
    d.set_item("local_goal_xy", (ep.local_goal()[0], ep.local_goal()[1]))?;
    d.set_item("outcome", ep.outcome().map(|o| o.name()))?;
    if let Some(r) = report {
        let t = PyDict::new(py);
        t.set_item("progress", r.terms.progress)?;
        t.set_item("no_progress", r.terms.no_progress)?;
        t.set_item("roll", r.terms.roll)?;
        t.set_item("pitch", r.terms.pitch)?;
        t.set_item("terminal", r.terms.terminal)?;
        d.set_item("reward_terms", t)?;
        d.set_item("default_reward", r.reward)?;
    }
    if ep.outcome().is_some() {
        // the benchmark's trial record, as in results.jsonl (degrees, metres, seconds)
        let metrics = results_to_py(py, &[ep.metrics()])?;
        d.set_item("metrics", &metrics[0])?;
    }
    Ok(d)
}

/// (observation, reward, terminated, truncated, info) of one step.
pub(super) type StepTuple<'py> = (Bound<'py, PyDict>, f64, bool, bool, Bound<'py, PyDict>);

/// The Rust side of `verti.envs.NavigateEnv`: one environment, stepped one control period per
/// call. Use the gymnasium wrapper rather than this class directly.
#[pyclass(name = "EnvCore", module = "verti")]
pub struct PyEnvCore {
    pub(super) core: EnvCore,
    pub(super) obs: ObsBuf,
}

#[pymethods]
impl PyEnvCore {
    #[new]
    #[pyo3(signature = (worlds, vehicle = None, **settings))]
    fn new(
        py: Python<'_>,
        worlds: &Bound<'_, PyAny>,
        vehicle: Option<&str>,
        settings: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyEnvCore> {
        let empty = PyDict::new(py);
        let core = env_core(py, worlds, vehicle, settings.unwrap_or(&empty))?;
        Ok(PyEnvCore {
            core,
            obs: ObsBuf::default(),
        })
    }

    /// Starts an episode: returns (observation dict, info dict).
    #[pyo3(signature = (seed = None, task = None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: Option<u64>,
        task: Option<u32>,
    ) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
        let (core, obs) = (&mut self.core, &mut self.obs);
        detached(py, || {
            core.reset(seed, task).and_then(|_| core.observe(obs))
        })?
        .map_err(env_err)?;
        Ok((
            obs_dict(py, self.core.config(), &self.obs)?,
            info_dict(py, &self.core, None)?,
        ))
    }

    /// One control period: returns (observation, default reward, terminated, truncated, info).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<StepTuple<'py>> {
        let a = action
            .as_slice()
            .map_err(|e| value_err(e.to_string()))?
            .to_vec();
        let action = self.core.action_from_normalized(&a).map_err(env_err)?;
        let (core, obs) = (&mut self.core, &mut self.obs);
        let report = detached(py, || {
            core.step(action).and_then(|r| core.observe(obs).map(|_| r))
        })?
        .map_err(env_err)?;
        Ok((
            obs_dict(py, self.core.config(), &self.obs)?,
            report.reward,
            report.terminated,
            report.truncated,
            info_dict(py, &self.core, Some(&report))?,
        ))
    }

    /// Top view with the task, the trail and the vehicle, `H × W × 3` uint8.
    #[pyo3(signature = (pixels_per_cell = 4))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        pixels_per_cell: u32,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let core = &mut self.core;
        let img = detached(py, || core.render(pixels_per_cell))?.map_err(env_err)?;
        image_to_numpy(py, img)
    }

    /// Observation layout: dict of name -> (shape, dtype name).
    #[getter]
    fn observation_layout<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        layout(py, self.core.config())
    }
    #[getter]
    fn action_dim(&self) -> usize {
        self.core.config().action.dim()
    }
    #[getter]
    fn action_mode(&self) -> &'static str {
        match self.core.config().action {
            ActionMode::HighLevel => "high",
            ActionMode::LowLevel => "low",
        }
    }
    #[getter]
    fn control_rate(&self) -> f64 {
        self.core.config().control_rate
    }
    /// Number of tasks the sampler draws from.
    #[getter]
    fn task_count(&self) -> usize {
        self.core.pool().len()
    }
    /// Global task numbers the sampler draws from.
    #[getter]
    fn task_numbers(&self) -> Vec<u32> {
        self.core
            .pool()
            .iter()
            .map(|&(wi, pair)| self.core.worlds()[wi].task_id(pair).number())
            .collect()
    }
    #[getter]
    fn worlds(&self) -> Vec<PyWorld> {
        self.core
            .worlds()
            .iter()
            .map(|w| PyWorld { inner: w.clone() })
            .collect()
    }
    /// A simulator at the current state of the episode (for planning from Python).
    fn sim(&self) -> PyResult<PySim> {
        let ep = self
            .core
            .episode()
            .ok_or_else(|| value_err("call reset() first".into()))?;
        let t = ep.task();
        Ok(PySim {
            sim: ep.sim_arc(),
            state: ep.state().clone(),
            start: verti_sim::StartPose::new(t.start[0], t.start[1], t.start_yaw()),
        })
    }
}

pub(super) fn layout<'py>(py: Python<'py>, cfg: &EnvConfig) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("state", ((cfg.state_features.len(),), "float32"))?;
    d.set_item("goal", ((2,), "float32"))?;
    d.set_item("local_goal", ((2,), "float32"))?;
    if let Some(c) = cfg.elevation {
        d.set_item("elevation", ((c.size, c.size), "float32"))?;
    }
    if let Some(c) = cfg.semantic {
        d.set_item("semantic", ((c.size, c.size), "uint8"))?;
    }
    if let Some(c) = cfg.occupancy {
        d.set_item("occupancy", ((c.size, c.size), "uint8"))?;
    }
    Ok(d)
}

/// The Rust side of `verti.envs.NavigateVectorEnv`: N environments stepped in parallel, one
/// call per batch, with next-step autoreset.
#[pyclass(name = "VecEnvCore", module = "verti")]
pub struct PyVecEnvCore {
    pub(super) v: VecCore,
}

/// Stacks per-environment rows into one (n, *shape) numpy array.
pub(super) fn batch<'a, 'py, T: numpy::Element + Copy + 'a>(
    py: Python<'py>,
    rows: impl Iterator<Item = &'a [T]>,
    n: usize,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let mut flat = Vec::with_capacity(n * shape.iter().product::<usize>());
    for r in rows {
        flat.extend_from_slice(r);
    }
    let mut dims = vec![n];
    dims.extend_from_slice(shape);
    Ok(PyArray1::from_vec(py, flat).reshape(dims)?.into_any())
}

impl PyVecEnvCore {
    fn batch_obs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let cfg = self.v.envs[0].config();
        let n = self.v.len();
        let o = &self.v.obs;
        let d = PyDict::new(py);
        d.set_item(
            "state",
            batch(
                py,
                o.iter().map(|b| &b.state[..]),
                n,
                &[cfg.state_features.len()],
            )?,
        )?;
        d.set_item("goal", batch(py, o.iter().map(|b| &b.goal[..]), n, &[2])?)?;
        d.set_item(
            "local_goal",
            batch(py, o.iter().map(|b| &b.local_goal[..]), n, &[2])?,
        )?;
        if let Some(c) = cfg.elevation {
            d.set_item(
                "elevation",
                batch(py, o.iter().map(|b| &b.elevation[..]), n, &[c.size, c.size])?,
            )?;
        }
        if let Some(c) = cfg.semantic {
            d.set_item(
                "semantic",
                batch(py, o.iter().map(|b| &b.semantic[..]), n, &[c.size, c.size])?,
            )?;
        }
        if let Some(c) = cfg.occupancy {
            d.set_item(
                "occupancy",
                batch(py, o.iter().map(|b| &b.occupancy[..]), n, &[c.size, c.size])?,
            )?;
        }
        Ok(d)
    }

    /// Vectorised info: arrays over environments (gymnasium's convention, with `_key` masks
    /// where an entry applies to some environments only).
    fn batch_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let eps: Vec<&Episode> = self
            .v
            .envs
            .iter()
            .map(|e| e.episode().expect("reset before use"))
            .collect();
        // running statistics only: no copy of each record per batch
        let metrics: Vec<&TrialResult> = eps.iter().map(|e| e.trial().running_result()).collect();
        let codes: Vec<i8> = self
            .v
            .reports
            .iter()
            .map(|r| outcome_code(r.outcome))
            .collect();
        let ended: Vec<bool> = codes.iter().map(|c| *c >= 0).collect();
        d.set_item(
            "task",
            eps.iter()
                .map(|e| e.id.number())
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "time",
            eps.iter()
                .map(|e| e.time())
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "distance_to_goal",
            eps.iter()
                .map(|e| e.goal_distance())
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item(
            "default_reward",
            self.v
                .reports
                .iter()
                .map(|r| r.reward)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item("outcome", codes.into_pyarray(py))?;
        d.set_item("_outcome", ended.clone().into_pyarray(py))?;
        d.set_item(
            "path_length",
            metrics
                .iter()
                .map(|m| m.path_length)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item("_path_length", ended.clone().into_pyarray(py))?;
        d.set_item(
            "roll_mean_abs",
            metrics
                .iter()
                .map(|m| m.roll.abs.mean)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item("_roll_mean_abs", ended.clone().into_pyarray(py))?;
        d.set_item(
            "pitch_mean_abs",
            metrics
                .iter()
                .map(|m| m.pitch.abs.mean)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item("_pitch_mean_abs", ended.into_pyarray(py))?;
        Ok(d)
    }
}

#[pymethods]
impl PyVecEnvCore {
    #[new]
    #[pyo3(signature = (num_envs, worlds, vehicle = None, num_threads = None, **settings))]
    fn new(
        py: Python<'_>,
        num_envs: usize,
        worlds: &Bound<'_, PyAny>,
        vehicle: Option<&str>,
        num_threads: Option<usize>,
        settings: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyVecEnvCore> {
        let empty = PyDict::new(py);
        let core = env_core(py, worlds, vehicle, settings.unwrap_or(&empty))?;
        let threads = num_threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
        if threads == 0 {
            return Err(value_err("num_threads must be at least 1".into()));
        }
        Ok(PyVecEnvCore {
            v: VecCore::new(core, num_envs, threads).map_err(env_err)?,
        })
    }

    /// Resets every environment: `seed` None (continue each sampler), an int (environment i
    /// gets seed + i, gymnasium's convention) or one seed per environment. Returns
    /// (observations, infos).
    #[pyo3(signature = (seed = None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>)> {
        let n = self.v.len() as u64;
        let seeds: Option<Vec<u64>> = match seed {
            None => None,
            Some(s) if s.is_none() => None,
            Some(s) => match s.extract::<u64>() {
                Ok(base) => Some((0..n).map(|i| base.wrapping_add(i)).collect()),
                Err(_) => Some(s.extract::<Vec<u64>>().map_err(|_| PyTypeError::new_err("seed must be None, a non-negative int or a list of them, one per environment"))?),
            },
        };
        let v = &mut self.v;
        detached(py, || v.reset(seeds.as_deref()))?.map_err(env_err)?;
        Ok((self.batch_obs(py)?, self.batch_info(py)?))
    }

    /// Steps all environments with `actions` (`num_envs × action_dim`, normalised) in parallel
    /// with the GIL released; returns (observations, rewards, terminated, truncated, infos).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyDict>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyDict>,
    )> {
        let a = actions.as_array();
        let flat: Vec<f64> = a.iter().copied().collect();
        if a.nrows() != self.v.len() {
            return Err(value_err(format!(
                "expected actions for {} environments, got {} rows",
                self.v.len(),
                a.nrows()
            )));
        }
        let v = &mut self.v;
        detached(py, || v.step(&flat))?.map_err(env_err)?;
        let r = &self.v.reports;
        Ok((
            self.batch_obs(py)?,
            r.iter()
                .map(|r| r.reward)
                .collect::<Vec<_>>()
                .into_pyarray(py),
            r.iter()
                .map(|r| r.terminated)
                .collect::<Vec<_>>()
                .into_pyarray(py),
            r.iter()
                .map(|r| r.truncated)
                .collect::<Vec<_>>()
                .into_pyarray(py),
            self.batch_info(py)?,
        ))
    }

    /// The info dict of one environment (as the single environment reports it).
    fn env_info<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyDict>> {
        let core = self
            .v
            .envs
            .get(i)
            .ok_or_else(|| value_err(format!("no environment {i} of {}", self.v.len())))?;
        info_dict(py, core, Some(&self.v.reports[i]))
    }

    /// Renders environment `i`.
    #[pyo3(signature = (i = 0, pixels_per_cell = 4))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        i: usize,
        pixels_per_cell: u32,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let n = self.v.len();
        let core = self
            .v
            .envs
            .get_mut(i)
            .ok_or_else(|| value_err(format!("no environment {i} of {n}")))?;
        let img = detached(py, || core.render(pixels_per_cell))?.map_err(env_err)?;
        image_to_numpy(py, img)
    }

    #[getter]
    fn num_envs(&self) -> usize {
        self.v.len()
    }
    #[getter]
    fn observation_layout<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        layout(py, self.v.envs[0].config())
    }
    #[getter]
    fn action_dim(&self) -> usize {
        self.v.envs[0].config().action.dim()
    }
    #[getter]
    fn action_mode(&self) -> &'static str {
        match self.v.envs[0].config().action {
            ActionMode::HighLevel => "high",
            ActionMode::LowLevel => "low",
        }
    }
    #[getter]
    fn control_rate(&self) -> f64 {
        self.v.envs[0].config().control_rate
    }
    #[getter]
    fn task_count(&self) -> usize {
        self.v.envs[0].pool().len()
    }
}
