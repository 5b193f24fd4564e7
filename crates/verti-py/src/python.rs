//! The extension module `verti._verti`: worlds, the simulator, evaluation and the environment
//! cores, for the Python package in `python/verti`.
//!
//! Conventions, so Python users get what Rust users get:
//! * every Rust error becomes a Python exception carrying the Rust message unchanged
//!   (`ValueError` for bad input, `FileNotFoundError`/`OSError` for files, `SimulationError` for
//!   a blown-up simulation); a panic becomes `RuntimeError` instead of crossing the boundary;
//! * calls that can take long run with the GIL released, on a helper thread, while the calling
//!   thread polls for signals, so Ctrl-C interrupts them with `KeyboardInterrupt`.

use crate::env::{
    ActionMode, EnvConfig, EnvCore, ObsBuf, RewardConfig, STATE_DIM, STATE_FIELDS, StepReport,
    TaskFilter, VecCore, outcome_code,
};
use numpy::ndarray::{Array2, ArrayView2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use rayon::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;
use verti_bench::episode::{EpisodeConfig, Outcome, Rules, TrialResult, pose6, run_episode};
use verti_bench::eval::{EvalError, EvalSetup, RunInfo, parse_tasks, select_tasks};
use verti_bench::observation::CropSpec;
use verti_bench::{Action, MobilitySystem, Observation, ParamValue, TaskInfo};
use verti_sim::{Controls, SimError, SpecError, VehicleSpec};
use verti_world::generate::{SetConfig, composition, elevation::ProceduralRock, generate_world};
use verti_world::{ElevationLevel, ObstacleDensity, TaskId, TerrainType, World, WorldError};

pyo3::create_exception!(
    _verti,
    SimulationError,
    PyRuntimeError,
    "The simulation blew up: the vehicle state stopped being finite or physical."
);

// ------------------------------------------------------------------------------------------
// errors

fn io_error(message: String, source: &std::io::Error) -> PyErr {
    if source.kind() == std::io::ErrorKind::NotFound {
        PyFileNotFoundError::new_err(message)
    } else {
        PyOSError::new_err(message)
    }
}

fn world_err(e: WorldError) -> PyErr {
    match &e {
        WorldError::Io { source, .. } => io_error(e.to_string(), source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

fn spec_err(e: SpecError) -> PyErr {
    match &e {
        SpecError::Io { source, .. } => io_error(e.to_string(), source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

fn sim_err(e: SimError) -> PyErr {
    match e {
        SimError::NonFinite { .. } | SimError::BlowUp { .. } => {
            SimulationError::new_err(e.to_string())
        }
        _ => PyValueError::new_err(e.to_string()),
    }
}

fn eval_err(e: EvalError) -> PyErr {
    match &e {
        EvalError::Io { source, .. } => io_error(e.to_string(), source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

fn value_err(e: String) -> PyErr {
    PyValueError::new_err(e)
}

fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

fn internal(p: Box<dyn std::any::Any + Send>) -> PyErr {
    PyRuntimeError::new_err(format!(
        "internal error in verti (please report it): {}",
        panic_message(p)
    ))
}

/// Runs short work with the GIL released; a panic becomes `RuntimeError`.
fn detached<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(work)))
        .map_err(internal)
}

/// Runs long work on a helper thread with the GIL released while this thread checks for
/// signals every 50 ms. On a signal (Ctrl-C) `cancel` is raised, the work (which polls it) is
/// waited for, and the signal's exception (`KeyboardInterrupt`) is returned.
fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let (outcome, interrupted) = py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = std::sync::mpsc::channel::<()>();
            let handle = s.spawn(move || {
                let r = catch_unwind(AssertUnwindSafe(work));
                let _ = tx.send(());
                r
            });
            let mut interrupted: Option<PyErr> = None;
            // until the worker reports (or is gone), poll for signals between waits
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
                rx.recv_timeout(Duration::from_millis(50))
            {
                if interrupted.is_none()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    cancel.store(true, Ordering::SeqCst);
                    interrupted = Some(e);
                }
            }
            let outcome = handle.join().unwrap_or_else(Err);
            (outcome, interrupted)
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    outcome.map_err(internal)
}

// ------------------------------------------------------------------------------------------
// worlds

/// One immutable world: terrain, semantics, obstacles, tasks and global paths.
#[pyclass(name = "World", module = "verti", frozen)]
pub struct PyWorld {
    pub inner: Arc<World>,
}

fn generate_one(seed: u64, index: u32, count: u32, scale: f64) -> Result<World, WorldError> {
    let config = SetConfig {
        seed,
        count,
        scale,
        ..Default::default()
    };
    config.validate()?;
    if index == 0 || index > count {
        return Err(WorldError::Argument(format!(
            "a set of {count} worlds has indices 1..={count}, not {index}"
        )));
    }
    let (l, t, d) = composition(&config)[index as usize - 1];
    generate_world(&config, index, l, t, d, &ProceduralRock::default())
}

fn obstacle_dict<'py>(py: Python<'py>, o: &verti_world::Obstacle) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let p = o.position();
    d.set_item("kind", if o.is_rock() { "rock" } else { "tree" })?;
    d.set_item("position", (p.x, p.y, p.z))?;
    d.set_item("yaw", o.yaw())?;
    d.set_item("radius", o.radius_xy())?;
    d.set_item("z_range", o.z_range())?;
    let fp: Vec<f64> = o.footprint().iter().flatten().copied().collect();
    let n = fp.len() / 2;
    d.set_item("footprint", PyArray1::from_vec(py, fp).reshape([n, 2])?)?;
    Ok(d)
}

#[pymethods]
impl PyWorld {
    /// World `index` (1-based) of the generated set (seed, count, scale); the same world as
    /// `verti world generate` writes. Generates only that world.
    #[staticmethod]
    #[pyo3(signature = (seed = 0, index = 1, count = 100, scale = 1.0))]
    fn generate(
        py: Python<'_>,
        seed: u64,
        index: u32,
        count: u32,
        scale: f64,
    ) -> PyResult<PyWorld> {
        let w = detached(py, || generate_one(seed, index, count, scale))?.map_err(world_err)?;
        Ok(PyWorld { inner: Arc::new(w) })
    }

    /// Every world of a generated set, in parallel (Ctrl-C stops it).
    #[staticmethod]
    #[pyo3(signature = (seed = 0, count = 100, scale = 1.0))]
    fn generate_set(py: Python<'_>, seed: u64, count: u32, scale: f64) -> PyResult<Vec<PyWorld>> {
        let config = SetConfig {
            seed,
            count,
            scale,
            ..Default::default()
        };
        config.validate().map_err(world_err)?;
        let cancel = AtomicBool::new(false);
        let comp = composition(&config);
        let worlds: Result<Vec<World>, WorldError> = interruptible(py, &cancel, || {
            comp.par_iter()
                .enumerate()
                .map(|(i, &(l, t, d))| {
                    if cancel.load(Ordering::Relaxed) {
                        return Err(WorldError::Argument("interrupted".into()));
                    }
                    generate_world(&config, i as u32 + 1, l, t, d, &ProceduralRock::default())
                })
                .collect()
        })?;
        Ok(worlds
            .map_err(world_err)?
            .into_iter()
            .map(|w| PyWorld { inner: Arc::new(w) })
            .collect())
    }

    /// Loads a world directory (with world.yaml) written by `verti world generate` or `save`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyWorld> {
        let w = detached(py, || verti_world::format::load_world(&path))?.map_err(world_err)?;
        Ok(PyWorld { inner: Arc::new(w) })
    }

    /// A world by the command line's names: `verti-100:42`, `verti-20-s7:3`, a world directory,
    /// or `DIR:INDEX` of a saved set or a Verti-Bench folder.
    #[staticmethod]
    #[pyo3(signature = (spec, scale = 1.0))]
    fn resolve(py: Python<'_>, spec: String, scale: f64) -> PyResult<PyWorld> {
        let cancel = AtomicBool::new(false);
        let w = interruptible(py, &cancel, || {
            verti_world::sets::resolve_world(&spec, scale)
        })?
        .map_err(world_err)?;
        Ok(PyWorld { inner: Arc::new(w) })
    }

    /// Imports an original Verti-Bench world from its config YAML, grey heightmap BMP and
    /// optional label npy.
    #[staticmethod]
    #[pyo3(signature = (config, heightmap, labels = None, scale = 1.0, index = None, clearance = None))]
    fn import_verti_bench(
        py: Python<'_>,
        config: PathBuf,
        heightmap: PathBuf,
        labels: Option<PathBuf>,
        scale: f64,
        index: Option<u32>,
        clearance: Option<f64>,
    ) -> PyResult<PyWorld> {
        let mut opts = verti_world::import_vb::ImportOptions {
            scale,
            index,
            ..Default::default()
        };
        if let Some(c) = clearance {
            opts.clearance = c;
        }
        let w = detached(py, || {
            verti_world::import_vb::import_vb(&config, &heightmap, labels.as_deref(), &opts)
        })?
        .map_err(world_err)?;
        Ok(PyWorld { inner: Arc::new(w) })
    }

    /// Writes the world as a directory in verti's format.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let w = self.inner.clone();
        detached(py, move || verti_world::format::save_world(&w, &path))?.map_err(world_err)
    }

    /// Vertex heights (m), `size × size`, row 0 north, column 0 west: a read-only view of the
    /// world's own memory (no copy).
    #[getter]
    fn heights<'py>(slf: Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = slf.get().inner.terrain.size();
        let view = ArrayView2::from_shape((n, n), slf.get().inner.terrain.heights())
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        // SAFETY: the array's base object is this World, which keeps the Arc<World> (and so the
        // heights, never reallocated: a World is immutable) alive as long as the array lives.
        let array = unsafe { PyArray2::borrow_from_array(&view, slf.clone().into_any()) };
        // Worlds are shared between simulators and threads: writes must not be possible.
        let _ = array.readwrite().make_nonwriteable();
        Ok(array)
    }

    /// Terrain class label (Verti-Bench ids 0..9) at every vertex, `size × size`, uint8.
    #[getter]
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u8>>> {
        let n = self.inner.terrain.size();
        let a = Array2::from_shape_vec((n, n), self.inner.labels())
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.meta.name.clone()
    }
    /// 1-based index in its set (the Verti-Bench world id for imports).
    #[getter]
    fn index(&self) -> u32 {
        self.inner.meta.index
    }
    /// Vertices per side.
    #[getter]
    fn size(&self) -> usize {
        self.inner.terrain.size()
    }
    /// Metres between vertices.
    #[getter]
    fn cell(&self) -> f64 {
        self.inner.terrain.cell()
    }
    /// The map spans [-half_extent, half_extent] metres in x and y.
    #[getter]
    fn half_extent(&self) -> f64 {
        self.inner.terrain.half_extent()
    }
    #[getter]
    fn scale(&self) -> f64 {
        self.inner.meta.scale
    }
    #[getter]
    fn level(&self) -> &'static str {
        self.inner.meta.level.name()
    }
    #[getter]
    fn terrain_type(&self) -> &'static str {
        self.inner.meta.terrain_type.name()
    }
    #[getter]
    fn density(&self) -> &'static str {
        self.inner.meta.density.name()
    }
    #[getter]
    fn max_height(&self) -> f64 {
        self.inner.meta.max_height
    }

    /// Terrain height (m) at world (x, y) on the triangulated surface.
    fn height_at(&self, x: f64, y: f64) -> f64 {
        self.inner.terrain.height_at(x, y)
    }

    /// The start/goal pairs: dicts with `pair`, `task` (global number), `start`, `goal`,
    /// `distance` and `path_length`.
    #[getter]
    fn tasks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for (i, t) in self.inner.tasks.iter().enumerate() {
            let d = PyDict::new(py);
            d.set_item("pair", t.pair)?;
            d.set_item("task", self.inner.task_id(t.pair).number())?;
            d.set_item("start", (t.start[0], t.start[1]))?;
            d.set_item("goal", (t.goal[0], t.goal[1]))?;
            d.set_item("distance", t.distance())?;
            d.set_item(
                "path_length",
                self.inner.paths.get(i).map_or(0.0, |p| p.length()),
            )?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The global path of a pair, `k × 2` world (x, y); empty when no path exists.
    fn path<'py>(&self, py: Python<'py>, pair: u32) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let i = self
            .inner
            .tasks
            .iter()
            .position(|t| t.pair == pair)
            .ok_or_else(|| {
                value_err(format!(
                    "world {} has no pair {pair} (pairs 0..{})",
                    self.inner.meta.name,
                    self.inner.tasks.len()
                ))
            })?;
        let pts: Vec<f64> = self
            .inner
            .paths
            .get(i)
            .map(|p| p.points.iter().flatten().copied().collect())
            .unwrap_or_default();
        let n = pts.len() / 2;
        PyArray1::from_vec(py, pts).reshape([n, 2])
    }

    /// Rocks and trees: dicts with `kind`, `position`, `yaw`, `radius` (horizontal bounding
    /// radius), `z_range` and `footprint` (convex polygon, `k × 2`).
    #[getter]
    fn obstacles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for o in &self.inner.obstacles {
            out.append(obstacle_dict(py, o)?)?;
        }
        Ok(out)
    }

    /// A top view (`H × W × 3` uint8) like `verti world render`.
    #[pyo3(signature = (pixels_per_cell = 4, legend = true, title = true))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        pixels_per_cell: u32,
        legend: bool,
        title: bool,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let w = self.inner.clone();
        let opts = verti_render::RenderOptions {
            pixels_per_cell,
            show_legend: legend,
            show_title: title,
            ..Default::default()
        };
        let img = detached(py, move || verti_render::render_world(&w, &opts))?
            .map_err(|e| value_err(e.to_string()))?;
        image_to_numpy(py, img.image)
    }

    fn __repr__(&self) -> String {
        let m = &self.inner.meta;
        format!(
            "World('{}', index={}, level={}, terrain={}, density={}, scale={}, size={})",
            m.name,
            m.index,
            m.level.name(),
            m.terrain_type.name(),
            m.density.name(),
            m.scale,
            self.inner.terrain.size()
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyWorld>().is_ok_and(|o| {
            Arc::ptr_eq(&o.get().inner, &self.inner) || *o.get().inner == *self.inner
        })
    }

    /// Pickling (multiprocessing, SubprocVecEnv): the world travels as the bytes of its files
    /// in verti's format, which round-trips a world exactly.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyDict>,))> {
        let py = slf.py();
        let w = slf.get().inner.clone();
        let files = detached(py, move || -> Result<Vec<(String, Vec<u8>)>, String> {
            let dir = scratch_dir();
            let out = verti_world::format::save_world(&w, &dir)
                .map_err(|e| e.to_string())
                .and_then(|_| read_files(&dir));
            let _ = std::fs::remove_dir_all(&dir);
            out
        })?
        .map_err(|e| PyOSError::new_err(format!("cannot pickle the world: {e}")))?;
        let d = PyDict::new(py);
        for (name, bytes) in files {
            d.set_item(name, pyo3::types::PyBytes::new(py, &bytes))?;
        }
        let make = py.import("verti._verti")?.getattr("_world_from_files")?;
        Ok((make, (d,)))
    }

    /// Worlds are immutable: a copy is the same world (gymnasium deep-copies make() kwargs).
    fn __copy__(slf: Bound<'_, Self>) -> Bound<'_, Self> {
        slf
    }
    fn __deepcopy__<'py>(slf: Bound<'py, Self>, _memo: &Bound<'py, PyAny>) -> Bound<'py, Self> {
        slf
    }

    /// Consistent with `==`: equal worlds have equal metadata.
    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let m = &self.inner.meta;
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (
            m.name.as_str(),
            m.index,
            m.scale.to_bits(),
            self.inner.terrain.size(),
        )
            .hash(&mut h);
        h.finish()
    }
}

/// A fresh scratch directory for pickling worlds.
fn scratch_dir() -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    std::env::temp_dir().join(format!(
        "verti-world-{}-{}-{nanos}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ))
}

fn read_files(dir: &std::path::Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or("odd file name")?
            .to_string();
        out.push((
            name,
            std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?,
        ));
    }
    Ok(out)
}

/// Rebuilds a pickled world from the bytes of its files.
#[pyfunction]
fn _world_from_files(py: Python<'_>, files: &Bound<'_, PyDict>) -> PyResult<PyWorld> {
    let files: Vec<(String, Vec<u8>)> = files
        .iter()
        .map(|(k, v)| {
            Ok((
                k.extract::<String>()?,
                v.cast::<pyo3::types::PyBytes>()?.as_bytes().to_vec(),
            ))
        })
        .collect::<PyResult<_>>()?;
    let w = detached(py, move || -> Result<World, String> {
        let dir = scratch_dir();
        let write = || -> Result<World, String> {
            std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
            for (name, bytes) in &files {
                if name.contains('/') || name.contains('\\') || name.starts_with('.') {
                    return Err(format!("bad file name `{name}` in a pickled world"));
                }
                std::fs::write(dir.join(name), bytes).map_err(|e| e.to_string())?;
            }
            verti_world::format::load_world(&dir).map_err(|e| e.to_string())
        };
        let out = write();
        let _ = std::fs::remove_dir_all(&dir);
        out
    })?
    .map_err(|e| value_err(format!("cannot unpickle the world: {e}")))?;
    Ok(PyWorld { inner: Arc::new(w) })
}

fn image_to_numpy(py: Python<'_>, img: image::RgbImage) -> PyResult<Bound<'_, PyArray3<u8>>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    PyArray1::from_vec(py, img.into_raw()).reshape([h, w, 3])
}

/// Every world of a set given by name (`verti-100`, `verti-20-s7`, a saved set directory, a
/// world directory or a folder of Verti-Bench worlds). Ctrl-C stops generation.
#[pyfunction]
#[pyo3(signature = (spec = "verti-100".to_string(), scale = 1.0))]
fn load_worlds(py: Python<'_>, spec: String, scale: f64) -> PyResult<Vec<PyWorld>> {
    if let Some(config) = verti_world::sets::builtin_config(&spec, scale)
        && !std::path::Path::new(&spec).exists()
    {
        // generated sets: world by world, so Ctrl-C can stop between worlds
        return PyWorld::generate_set(py, config.seed, config.count, config.scale);
    }
    let cancel = AtomicBool::new(false);
    let set = interruptible(py, &cancel, || {
        verti_world::sets::resolve_set(&spec, scale, &|| {})
    })?
    .map_err(world_err)?;
    Ok(set
        .worlds
        .into_iter()
        .map(|w| PyWorld { inner: Arc::new(w) })
        .collect())
}

/// Worlds from a Python argument: a World, a list of Worlds or a name (see `load_worlds`;
/// `SET:INDEX` names one world).
fn worlds_arg(
    py: Python<'_>,
    arg: &Bound<'_, PyAny>,
    scale: f64,
) -> PyResult<(Vec<Arc<World>>, String)> {
    if let Ok(s) = arg.cast::<PyString>() {
        let spec: String = s.extract()?;
        let is_world = spec
            .rsplit_once(':')
            .is_some_and(|(_, i)| i.parse::<u32>().is_ok())
            || std::path::Path::new(&spec).join("world.yaml").is_file();
        let worlds = if is_world {
            vec![PyWorld::resolve(py, spec.clone(), scale)?]
        } else {
            load_worlds(py, spec.clone(), scale)?
        };
        return Ok((worlds.into_iter().map(|w| w.inner).collect(), spec));
    }
    if let Ok(w) = arg.cast::<PyWorld>() {
        return Ok((vec![w.get().inner.clone()], w.get().inner.meta.name.clone()));
    }
    let mut out = Vec::new();
    let iter = arg.try_iter().map_err(|_| {
        PyTypeError::new_err(
            "worlds must be a World, a list of Worlds or a world-set name such as 'verti-100'",
        )
    })?;
    for item in iter {
        let item = item?;
        let w = item.cast::<PyWorld>().map_err(|_| {
            PyTypeError::new_err(format!(
                "expected World objects in the list, got {}",
                item.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        out.push(w.get().inner.clone());
    }
    if out.is_empty() {
        return Err(value_err("the list of worlds is empty".into()));
    }
    let name = if out.len() == 1 {
        out[0].meta.name.clone()
    } else {
        format!("{} worlds", out.len())
    };
    Ok((out, name))
}

// ------------------------------------------------------------------------------------------
// vehicles and the simulator

/// A vehicle by built-in name (`hmmwv`, `artcar`, ...) or path to a vehicle YAML file.
fn vehicle_spec(name: &str) -> PyResult<VehicleSpec> {
    if verti_sim::vehicles::builtin_names().contains(&name) {
        return verti_sim::vehicles::builtin(name).map_err(spec_err);
    }
    let path = std::path::Path::new(name);
    if path.extension().is_some_and(|e| e == "yaml" || e == "yml") || path.exists() {
        return VehicleSpec::from_file(path).map_err(spec_err);
    }
    verti_sim::vehicles::builtin(name).map_err(spec_err)
}

/// Names of the built-in vehicles.
#[pyfunction]
fn vehicles() -> Vec<&'static str> {
    verti_sim::vehicles::builtin_names()
}

/// A snapshot of a vehicle's state (immutable; restore it with `Sim.state = snapshot`).
#[pyclass(name = "SimState", module = "verti", frozen)]
pub struct PySimState {
    sim: Arc<verti_sim::Sim>,
    state: verti_sim::SimState,
}

fn state_vector(sim: &verti_sim::Sim, s: &verti_sim::SimState) -> [f64; 16] {
    let p = pose6(sim, s);
    let v = s.velocity_body();
    let w = s.angular_velocity_body();
    [
        s.time(),
        p.x,
        p.y,
        p.z,
        p.roll,
        p.pitch,
        p.yaw,
        v.x,
        v.y,
        v.z,
        w.x,
        w.y,
        w.z,
        s.forward_speed(),
        s.steer_angle(),
        f64::from(u8::from(s.is_rolled_over())),
    ]
}

/// Names of the entries of `SimState.vector` and of the rows of `Sim.rollout`.
const SIM_STATE_FIELDS: [&str; 16] = [
    "time",
    "x",
    "y",
    "z",
    "roll",
    "pitch",
    "yaw",
    "vx",
    "vy",
    "vz",
    "wx",
    "wy",
    "wz",
    "forward_speed",
    "steer_angle",
    "rolled_over",
];

#[pymethods]
impl PySimState {
    /// Simulated time, s.
    #[getter]
    fn time(&self) -> f64 {
        self.state.time()
    }
    /// Reference-frame pose (x, y, z, roll, pitch, yaw): metres and radians, Z-Y-X Euler angles.
    #[getter]
    fn pose(&self) -> (f64, f64, f64, f64, f64, f64) {
        let p = pose6(&self.sim, &self.state);
        (p.x, p.y, p.z, p.roll, p.pitch, p.yaw)
    }
    /// Centre-of-mass position (world), m.
    #[getter]
    fn com_position(&self) -> (f64, f64, f64) {
        let p = self.state.com_position();
        (p.x, p.y, p.z)
    }
    /// (roll, pitch, yaw), rad.
    #[getter]
    fn euler(&self) -> (f64, f64, f64) {
        self.state.euler()
    }
    /// Linear velocity in the body frame (x forward, y left, z up), m/s.
    #[getter]
    fn velocity_body(&self) -> (f64, f64, f64) {
        let v = self.state.velocity_body();
        (v.x, v.y, v.z)
    }
    /// Angular velocity in the body frame, rad/s.
    #[getter]
    fn angular_velocity_body(&self) -> (f64, f64, f64) {
        let v = self.state.angular_velocity_body();
        (v.x, v.y, v.z)
    }
    /// Speed along the chassis x axis, m/s.
    #[getter]
    fn forward_speed(&self) -> f64 {
        self.state.forward_speed()
    }
    /// True when the chassis is upside down or on its side.
    #[getter]
    fn rolled_over(&self) -> bool {
        self.state.is_rolled_over()
    }
    /// The state as a float64 vector with the entries named by `verti.SIM_STATE_FIELDS`.
    #[getter]
    fn vector<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &state_vector(&self.sim, &self.state))
    }
    /// The state as a dict of the named entries.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in SIM_STATE_FIELDS
            .iter()
            .zip(state_vector(&self.sim, &self.state))
        {
            d.set_item(k, v)?;
        }
        Ok(d)
    }
    fn __repr__(&self) -> String {
        let p = pose6(&self.sim, &self.state);
        format!(
            "SimState(t={:.3}, x={:.3}, y={:.3}, z={:.3}, roll={:.2}°, pitch={:.2}°, yaw={:.2}°, speed={:.3})",
            self.state.time(),
            p.x,
            p.y,
            p.z,
            p.roll.to_degrees(),
            p.pitch.to_degrees(),
            p.yaw.to_degrees(),
            self.state.forward_speed()
        )
    }
}

/// One vehicle on one world. `step` advances it; `state` reads (or restores) a snapshot;
/// `clone` gives an independent copy sharing the immutable model (cheap).
#[pyclass(name = "Sim", module = "verti")]
pub struct PySim {
    sim: Arc<verti_sim::Sim>,
    state: verti_sim::SimState,
}

#[pymethods]
impl PySim {
    /// `start`: None for the world's pair 0, an int for that pair's start (facing its goal),
    /// or (x, y, yaw) in metres and radians.
    #[new]
    #[pyo3(signature = (world, vehicle = "hmmwv", start = None))]
    fn new(
        py: Python<'_>,
        world: &Bound<'_, PyWorld>,
        vehicle: &str,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PySim> {
        let w = world.get().inner.clone();
        let spec = vehicle_spec(vehicle)?;
        let (x, y, yaw) = match start {
            None => start_of_pair(&w, 0)?,
            Some(s) => {
                if let Ok(pair) = s.extract::<u32>() {
                    start_of_pair(&w, pair)?
                } else {
                    s.extract::<(f64, f64, f64)>().map_err(|_| {
                        PyTypeError::new_err(
                            "start must be None, a pair number or an (x, y, yaw) tuple",
                        )
                    })?
                }
            }
        };
        let sim = detached(py, || {
            verti_sim::start_pose(&w, &spec, x, y, yaw)
                .and_then(|p| verti_sim::Sim::new(&w, &spec, p))
        })?
        .map_err(sim_err)?;
        let state = sim.initial_state();
        Ok(PySim {
            sim: Arc::new(sim),
            state,
        })
    }

    /// Advances by `dt` seconds (default 0.01, the benchmark's inner step) with the driver
    /// inputs held: throttle and brake in [0, 1], steering in [-1, 1] (positive = left).
    #[pyo3(signature = (throttle, brake, steering, dt = 0.01))]
    fn step(
        &mut self,
        py: Python<'_>,
        throttle: f64,
        brake: f64,
        steering: f64,
        dt: f64,
    ) -> PyResult<()> {
        let controls = Controls::new(throttle, brake, steering);
        controls.validate().map_err(sim_err)?;
        let sim = &self.sim;
        let state = &mut self.state;
        // Sim::step leaves the state untouched on bad input; on a blow-up it is not finite
        // and every later step reports the blow-up again.
        if dt > 0.05 {
            detached(py, || sim.step(state, controls, dt))?.map_err(sim_err)
        } else {
            catch_unwind(AssertUnwindSafe(|| sim.step(state, controls, dt)))
                .map_err(internal)?
                .map_err(sim_err)
        }
    }

    /// Applies each row (throttle, brake, steering) of `controls` for `dt` seconds and returns
    /// the state after each row, `T × 16` (columns `verti.SIM_STATE_FIELDS`). The GIL is
    /// released; a planner can roll out clones from several threads.
    #[pyo3(signature = (controls, dt = 0.01))]
    fn rollout<'py>(
        &mut self,
        py: Python<'py>,
        controls: PyReadonlyArray2<'py, f64>,
        dt: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let c = controls.as_array();
        if c.ncols() != 3 {
            return Err(value_err(format!(
                "controls must have 3 columns (throttle, brake, steering), got shape {:?}",
                c.shape()
            )));
        }
        let rows: Vec<Controls> = c
            .rows()
            .into_iter()
            .map(|r| Controls::new(r[0], r[1], r[2]))
            .collect();
        for (i, r) in rows.iter().enumerate() {
            r.validate()
                .map_err(|e| value_err(format!("controls row {i}: {e}")))?;
        }
        let sim = &self.sim;
        let state = &mut self.state;
        let out: Result<Vec<f64>, SimError> = detached(py, || {
            let mut out = Vec::with_capacity(rows.len() * 16);
            for r in &rows {
                sim.step(state, *r, dt)?;
                out.extend(state_vector(sim, state));
            }
            Ok(out)
        })?;
        let out = out.map_err(sim_err)?;
        let n = out.len() / 16;
        PyArray1::from_vec(py, out).reshape([n, 16])
    }

    /// Back to the start, at rest.
    fn reset(&mut self) {
        self.state = self.sim.initial_state();
    }

    /// A snapshot of the current state; assigning one (from this Sim or a clone) restores it.
    #[getter]
    fn get_state(&self) -> PySimState {
        PySimState {
            sim: self.sim.clone(),
            state: self.state.clone(),
        }
    }
    #[setter]
    fn set_state(&mut self, s: &Bound<'_, PySimState>) -> PyResult<()> {
        let s = s.get();
        if !Arc::ptr_eq(&s.sim, &self.sim) {
            return Err(value_err("this SimState belongs to another simulation (another world, vehicle or start); take it from this Sim or its clones".into()));
        }
        self.state = s.state.clone();
        Ok(())
    }

    /// An independent copy at the same state (shares the immutable model).
    fn clone(&self) -> PySim {
        PySim {
            sim: self.sim.clone(),
            state: self.state.clone(),
        }
    }
    fn __copy__(&self) -> PySim {
        self.clone()
    }
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PySim {
        self.clone()
    }

    #[getter]
    fn time(&self) -> f64 {
        self.state.time()
    }
    #[getter]
    fn vehicle(&self) -> String {
        self.sim.spec().name.clone()
    }
    #[getter]
    fn world(&self) -> PyWorld {
        PyWorld {
            inner: self.sim.world().clone(),
        }
    }
    /// The fixed internal physics step, s.
    #[getter]
    fn internal_step(&self) -> f64 {
        self.sim.internal_step()
    }
    fn __repr__(&self) -> String {
        format!(
            "Sim(world='{}', vehicle='{}', t={:.3})",
            self.sim.world().meta.name,
            self.sim.spec().name,
            self.state.time()
        )
    }
}

fn start_of_pair(w: &World, pair: u32) -> PyResult<(f64, f64, f64)> {
    let t = w.tasks.iter().find(|t| t.pair == pair).ok_or_else(|| {
        value_err(format!(
            "world {} has no pair {pair} (pairs 0..{})",
            w.meta.name,
            w.tasks.len()
        ))
    })?;
    Ok((t.start[0], t.start[1], t.start_yaw()))
}

// ------------------------------------------------------------------------------------------
// evaluation

/// Wraps a system so an interrupted evaluation ends its running trials at their next control
/// step: once `cancel` is raised the system returns an invalid action, which `run_episode`
/// ends at once (that trial is then discarded, never reported).
struct Cancellable<'a> {
    inner: Box<dyn MobilitySystem>,
    cancel: &'a AtomicBool,
}

impl MobilitySystem for Cancellable<'_> {
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
}

fn parse_rules(s: &str) -> PyResult<Rules> {
    match s {
        "paper" => Ok(Rules::Paper),
        "verti-bench" | "vertibench" | "reference" => Ok(Rules::VertiBench),
        _ => Err(value_err(format!(
            "unknown rules `{s}`: use 'paper' or 'verti-bench'"
        ))),
    }
}

fn tasks_arg(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<u32>> {
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

fn results_to_py(py: Python<'_>, results: &[TrialResult]) -> PyResult<Vec<Py<PyAny>>> {
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

/// The systems Python can run: the built-in ones and those of crates above verti-systems.
fn system_registry() -> verti_bench::SystemRegistry {
    let mut r = verti_bench::SystemRegistry::new();
    verti_systems::register(&mut r);
    r
}

/// One parameter value: bool, int, float, str or a path (`pathlib.Path`); checked against
/// the declared type when resolved.
fn param_value(v: &Bound<'_, PyAny>) -> Option<ParamValue> {
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return v.extract::<bool>().ok().map(ParamValue::Bool);
    }
    if let Ok(i) = v.extract::<i64>() {
        return Some(ParamValue::Int(i));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Some(ParamValue::Float(x));
    }
    if let Ok(t) = v.extract::<String>() {
        return Some(ParamValue::Str(t));
    }
    v.extract::<PathBuf>().ok().map(ParamValue::Path)
}

/// System parameters: None, a dict name -> value, or a list of (name, value) pairs.
fn params_arg(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<(String, ParamValue)>> {
    let Some(arg) = arg.filter(|a| !a.is_none()) else {
        return Ok(Vec::new());
    };
    let bad = || {
        PyTypeError::new_err(
            "params must be a dict of parameter name -> value (number, bool, str or path), e.g. {'speed': 4.0}",
        )
    };
    let pair = |k: &Bound<'_, PyAny>, v: &Bound<'_, PyAny>| {
        Ok((
            k.extract::<String>().map_err(|_| bad())?,
            param_value(v).ok_or_else(bad)?,
        ))
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
#[pyfunction]
#[pyo3(signature = (system = "pid", worlds = None, tasks = None, jobs = None, *, vehicle = "hmmwv", params = None, rules = "paper", max_time = 60.0, seed = 0, scale = 1.0, out = None, resume = false, force = false))]
#[allow(clippy::too_many_arguments)]
fn evaluate(
    py: Python<'_>,
    system: &str,
    worlds: Option<&Bound<'_, PyAny>>,
    tasks: Option<&Bound<'_, PyAny>>,
    jobs: Option<usize>,
    vehicle: &str,
    params: Option<&Bound<'_, PyAny>>,
    rules: &str,
    max_time: f64,
    seed: u64,
    scale: f64,
    out: Option<PathBuf>,
    resume: bool,
    force: bool,
) -> PyResult<Vec<Py<PyAny>>> {
    let registry = system_registry();
    let params = registry
        .resolve(system, &params_arg(params)?)
        .map_err(|e| value_err(e.to_string()))?;
    // build one system up front so unknown names and bad parameters fail before any work
    registry
        .build(system, &params)
        .map_err(|e| value_err(e.to_string()))?;
    let spec = vehicle_spec(vehicle)?;
    let (worlds, worlds_name) = match worlds {
        Some(w) if !w.is_none() => worlds_arg(py, w, scale)?,
        _ => worlds_arg(py, PyString::new(py, "verti-100").as_any(), scale)?,
    };
    let selection = tasks_arg(tasks)?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    if jobs == 0 {
        return Err(value_err("jobs must be at least 1".into()));
    }
    let episode = EpisodeConfig {
        rules: parse_rules(rules)?,
        max_time,
        seed,
        ..Default::default()
    };
    episode.validate().map_err(value_err)?;
    let selected = select_tasks(&worlds, &selection).map_err(eval_err)?;
    let cancel = AtomicBool::new(false);
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
                        let inner = registry.build(system, &params).expect("checked above");
                        let mut sys = Cancellable {
                            inner,
                            cancel: &cancel,
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

    // With a results folder: verti_bench::eval::evaluate (the CLI's resumable runner), in
    // chunks so Ctrl-C can stop between them; every chunk resumes the same run.
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
    let mut all = Vec::new();
    for (k, chunk) in numbers.chunks((4 * jobs).max(16)).enumerate() {
        let setup = EvalSetup {
            worlds: &worlds,
            vehicle: &spec,
            episode: episode.clone(),
            jobs,
            out: out.clone(),
            resume: resume || k > 0,
            force: force && k == 0,
            run: run.clone(),
            step_log: None,
        };
        let make = || registry.build(system, &params).expect("checked above");
        all = interruptible(py, &cancel, || {
            verti_bench::eval::evaluate(&setup, chunk, &make, &|_| {})
        })?
        .map_err(eval_err)?;
    }
    let wanted: std::collections::BTreeSet<u32> = numbers.into_iter().collect();
    all.retain(|r| wanted.contains(&r.task));
    results_to_py(py, &all)
}

/// The systems that `evaluate` knows, with their parameters (name, type, default, min and
/// max or choices, doc).
#[pyfunction]
fn systems(py: Python<'_>) -> PyResult<Py<PyAny>> {
    let list: Vec<verti_bench::SystemInfo> = system_registry().list().cloned().collect();
    let text = serde_json::to_string(&list).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(py
        .import("json")?
        .getattr("loads")?
        .call1((text,))?
        .unbind())
}

// ------------------------------------------------------------------------------------------
// environments

fn crop_arg(v: &Bound<'_, PyAny>, name: &str) -> PyResult<Option<CropSpec>> {
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

fn names_arg<T>(
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
    names
        .iter()
        .map(|n| parse(n).ok_or_else(|| value_err(format!("unknown {what} `{n}`; known: {known}"))))
        .collect()
}

fn reward_arg(v: &Bound<'_, PyAny>) -> PyResult<RewardConfig> {
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
fn env_core(
    py: Python<'_>,
    worlds: &Bound<'_, PyAny>,
    vehicle: &str,
    settings: &Bound<'_, PyDict>,
) -> PyResult<EnvCore> {
    const KNOWN: [&str; 17] = [
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
    let scale = f("scale", 1.0)?;
    let (worlds, _) = worlds_arg(py, worlds, scale)?;
    let spec = vehicle_spec(vehicle)?;
    let mut cfg = EnvConfig::default();
    cfg.control_rate = f("control_rate", cfg.control_rate)?;
    cfg.max_speed = f("max_speed", cfg.max_speed)?;
    cfg.lookahead = f("lookahead", cfg.lookahead)?;
    cfg.episode.max_time = f("max_time", cfg.episode.max_time)?;
    cfg.episode.inner_dt = f("inner_dt", cfg.episode.inner_dt)?;
    if let Some(r) = get("rules")? {
        cfg.episode.rules = parse_rules(&r.extract::<String>()?)?;
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
    EnvCore::new(worlds, spec, cfg, &filter, seed).map_err(value_err)
}

fn obs_dict<'py>(py: Python<'py>, cfg: &EnvConfig, o: &ObsBuf) -> PyResult<Bound<'py, PyDict>> {
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

fn info_dict<'py>(
    py: Python<'py>,
    core: &EnvCore,
    report: Option<&StepReport>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let Some(ep) = core.episode() else {
        return Ok(d);
    };
    let world = &core.worlds()[ep.world];
    let m = &ep.metrics;
    d.set_item("task", ep.id.number())?;
    d.set_item("world", ep.id.world)?;
    d.set_item("pair", ep.id.pair)?;
    d.set_item("world_name", world.meta.name.as_str())?;
    d.set_item("level", world.meta.level.name())?;
    d.set_item("density", world.meta.density.name())?;
    d.set_item("terrain_type", world.meta.terrain_type.name())?;
    d.set_item("time", m.time)?;
    d.set_item("distance_to_goal", m.distance_to_goal)?;
    let p = ep.pose();
    d.set_item("pose", (p.x, p.y, p.z, p.roll, p.pitch, p.yaw))?;
    d.set_item("local_goal_xy", (ep.local_goal()[0], ep.local_goal()[1]))?;
    d.set_item("outcome", ep.outcome.map(|o| o.name()))?;
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
    if ep.outcome.is_some() {
        // the benchmark's per-trial metrics (degrees, metres, seconds)
        let mt = PyDict::new(py);
        mt.set_item("outcome", ep.outcome.map(|o| o.name()))?;
        mt.set_item("time", m.time)?;
        mt.set_item("traversal_time", m.traversal_time)?;
        mt.set_item("path_length", m.path_length)?;
        mt.set_item("final_distance", m.distance_to_goal)?;
        mt.set_item("final_roll", m.final_roll_deg)?;
        mt.set_item("roll_mean_abs", m.roll.abs.mean)?;
        mt.set_item("roll_max_abs", m.roll.abs.max)?;
        mt.set_item("pitch_mean_abs", m.pitch.abs.mean)?;
        mt.set_item("pitch_max_abs", m.pitch.abs.max)?;
        mt.set_item("error", m.error.as_deref())?;
        d.set_item("metrics", mt)?;
    }
    Ok(d)
}

/// (observation, reward, terminated, truncated, info) of one step.
type StepTuple<'py> = (Bound<'py, PyDict>, f64, bool, bool, Bound<'py, PyDict>);

/// The Rust side of `verti.envs.NavigateEnv`: one environment, stepped one control period per
/// call. Use the gymnasium wrapper rather than this class directly.
#[pyclass(name = "EnvCore", module = "verti")]
pub struct PyEnvCore {
    core: EnvCore,
    obs: ObsBuf,
}

#[pymethods]
impl PyEnvCore {
    #[new]
    #[pyo3(signature = (worlds, vehicle = "hmmwv", **settings))]
    fn new(
        py: Python<'_>,
        worlds: &Bound<'_, PyAny>,
        vehicle: &str,
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
        .map_err(value_err)?;
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
        let action = self.core.action_from_normalized(&a).map_err(value_err)?;
        let (core, obs) = (&mut self.core, &mut self.obs);
        let report = detached(py, || {
            core.step(action).and_then(|r| core.observe(obs).map(|_| r))
        })?
        .map_err(value_err)?;
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
        let img = detached(py, || core.render(pixels_per_cell))?.map_err(value_err)?;
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
        Ok(PySim {
            sim: ep.sim_arc(),
            state: ep.state().clone(),
        })
    }
}

fn layout<'py>(py: Python<'py>, cfg: &EnvConfig) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("state", ((STATE_DIM,), "float32"))?;
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
    v: VecCore,
}

/// Stacks per-environment rows into one (n, *shape) numpy array.
fn batch<'a, 'py, T: numpy::Element + Copy + 'a>(
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
            batch(py, o.iter().map(|b| &b.state[..]), n, &[STATE_DIM])?,
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
        let eps: Vec<&crate::env::Episode> = self
            .v
            .envs
            .iter()
            .map(|e| e.episode().expect("reset before use"))
            .collect();
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
                .map(|e| e.metrics.distance_to_goal)
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
            eps.iter()
                .map(|e| e.metrics.path_length)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item("_path_length", ended.clone().into_pyarray(py))?;
        d.set_item(
            "roll_mean_abs",
            eps.iter()
                .map(|e| e.metrics.roll.abs.mean)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )?;
        d.set_item("_roll_mean_abs", ended.clone().into_pyarray(py))?;
        d.set_item(
            "pitch_mean_abs",
            eps.iter()
                .map(|e| e.metrics.pitch.abs.mean)
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
    #[pyo3(signature = (num_envs, worlds, vehicle = "hmmwv", num_threads = None, **settings))]
    fn new(
        py: Python<'_>,
        num_envs: usize,
        worlds: &Bound<'_, PyAny>,
        vehicle: &str,
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
            v: VecCore::new(core, num_envs, threads).map_err(value_err)?,
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
        detached(py, || v.reset(seeds.as_deref()))?.map_err(value_err)?;
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
        detached(py, || v.step(&flat))?.map_err(value_err)?;
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
        let img = detached(py, || core.render(pixels_per_cell))?.map_err(value_err)?;
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

// ------------------------------------------------------------------------------------------

#[pymodule]
#[pyo3(name = "_verti")]
fn verti_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<PyWorld>()?;
    m.add_class::<PySim>()?;
    m.add_class::<PySimState>()?;
    m.add_class::<PyEnvCore>()?;
    m.add_class::<PyVecEnvCore>()?;
    m.add_function(wrap_pyfunction!(load_worlds, m)?)?;
    m.add_function(wrap_pyfunction!(_world_from_files, m)?)?;
    m.add_function(wrap_pyfunction!(vehicles, m)?)?;
    m.add_function(wrap_pyfunction!(systems, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("STATE_FIELDS", STATE_FIELDS.to_vec())?;
    m.add("SIM_STATE_FIELDS", SIM_STATE_FIELDS.to_vec())?;
    m.add(
        "OUTCOMES",
        Outcome::ALL.iter().map(|o| o.name()).collect::<Vec<_>>(),
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
