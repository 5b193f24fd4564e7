//! Worlds: generation, loading, import, inspection and rendering.

use super::*;

/// One immutable world: terrain, semantics, obstacles, tasks and global paths.
#[pyclass(name = "World", module = "verti", frozen)]
pub struct PyWorld {
    pub inner: Arc<World>,
}

/// The elevation source a generate call names (as `verti world sources` lists them: the
/// default `procedural-rock`, the other procedural ones, the trained `swae-v1`), with its
/// parameters from a dict checked as the command line's are.
pub(super) fn elevation_source(
    name: &str,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Box<dyn ElevationSource>> {
    let registry = verti_registry::elevation_sources();
    let mut given = Vec::new();
    if let Some(d) = params {
        for (k, v) in d.iter() {
            let k: String = k.extract()?;
            let value = param_value(&k, &v)?;
            given.push((k, value));
        }
    }
    registry
        .create(name, &given)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

pub(super) fn generate_one(
    seed: u64,
    index: u32,
    count: u32,
    scale: f64,
    source: &dyn ElevationSource,
) -> Result<World, WorldError> {
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
    generate_world(&config, index, l, t, d, source)
}

pub(super) fn obstacle_dict<'py>(
    py: Python<'py>,
    o: &verti_world::Obstacle,
) -> PyResult<Bound<'py, PyDict>> {
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
    /// `verti world generate` writes. Generates only that world. `elevation` names the
    /// elevation source (`verti world sources`; default `procedural-rock`, e.g. `swae-v1`)
    /// and `elevation_params` its parameters.
    #[staticmethod]
    #[pyo3(signature = (seed = 0, index = 1, count = 100, scale = 1.0, elevation = "procedural-rock", elevation_params = None))]
    #[allow(clippy::too_many_arguments)]
    fn generate(
        py: Python<'_>,
        seed: u64,
        index: u32,
        count: u32,
        scale: f64,
        elevation: &str,
        elevation_params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyWorld> {
        let source = elevation_source(elevation, elevation_params)?;
        let w = detached(py, || {
            generate_one(seed, index, count, scale, source.as_ref())
        })?
        .map_err(world_err)?;
        Ok(PyWorld { inner: Arc::new(w) })
    }

    /// Every world of a generated set, in parallel (Ctrl-C stops it); `elevation` and
    /// `elevation_params` as for `generate`.
    #[staticmethod]
    #[pyo3(signature = (seed = 0, count = 100, scale = 1.0, elevation = "procedural-rock", elevation_params = None))]
    fn generate_set(
        py: Python<'_>,
        seed: u64,
        count: u32,
        scale: f64,
        elevation: &str,
        elevation_params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Vec<PyWorld>> {
        let source = elevation_source(elevation, elevation_params)?;
        let source = source.as_ref();
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
                    generate_world(&config, i as u32 + 1, l, t, d, source)
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
    /// `scale` (default 1) applies to generated and imported worlds; a saved world keeps its
    /// own, and another `scale` for it is an error.
    #[staticmethod]
    #[pyo3(signature = (spec, scale = None))]
    fn resolve(py: Python<'_>, spec: String, scale: Option<f64>) -> PyResult<PyWorld> {
        let cancel = AtomicBool::new(false);
        let w = interruptible(py, &cancel, || {
            let w = verti_world::sets::resolve_world(&spec, scale.unwrap_or(1.0))?;
            verti_world::scale::set_scale(&spec, [&w], scale)?;
            Ok(w)
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

    /// Writes the world as a directory in verti's format. An existing directory is replaced
    /// only with `overwrite=True` (like the CLI's `--force`); a missing parent directory is
    /// not created.
    #[pyo3(signature = (path, overwrite = false))]
    fn save(&self, py: Python<'_>, path: PathBuf, overwrite: bool) -> PyResult<()> {
        out_dir_arg("path", &path)?;
        if !overwrite && path.exists() {
            return Err(pyo3::exceptions::PyFileExistsError::new_err(format!(
                "{} already exists: pass overwrite=True to replace it",
                path.display()
            )));
        }
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
pub(super) fn scratch_dir() -> PathBuf {
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

pub(super) fn read_files(dir: &std::path::Path) -> Result<Vec<(String, Vec<u8>)>, String> {
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
pub(super) fn _world_from_files(py: Python<'_>, files: &Bound<'_, PyDict>) -> PyResult<PyWorld> {
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

pub(super) fn image_to_numpy(
    py: Python<'_>,
    img: image::RgbImage,
) -> PyResult<Bound<'_, PyArray3<u8>>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    PyArray1::from_vec(py, img.into_raw()).reshape([h, w, 3])
}

/// Every world of a set given by name (`verti-100`, `verti-20-s7`, a saved set directory, a
/// world directory or a folder of Verti-Bench worlds). Ctrl-C stops generation.
#[pyfunction]
#[pyo3(signature = (spec = "verti-100", scale = None))]
pub(super) fn load_worlds(
    py: Python<'_>,
    spec: &str,
    scale: Option<f64>,
) -> PyResult<Vec<PyWorld>> {
    let spec = spec.to_string();
    if let Some(s) = scale {
        verti_world::scale::check_scale(s).map_err(world_err)?;
    }
    let requested = scale;
    let scale = scale.unwrap_or(1.0);
    if let Some(config) = verti_world::sets::builtin_config(&spec, scale)
        && !std::path::Path::new(&spec).exists()
    {
        // generated sets: world by world, so Ctrl-C can stop between worlds
        return PyWorld::generate_set(
            py,
            config.seed,
            config.count,
            config.scale,
            verti_world::generate::sources::DEFAULT_SOURCE,
            None,
        );
    }
    let cancel = AtomicBool::new(false);
    let set = interruptible(py, &cancel, || {
        let set = verti_world::sets::resolve_set(&spec, scale, &|| {})?;
        // a saved set keeps its scale: another one asked for is an error, not ignored
        verti_world::scale::set_scale(&spec, &set.worlds, requested)?;
        Ok(set)
    })?
    .map_err(world_err)?;
    Ok(set
        .worlds
        .into_iter()
        .map(|w| PyWorld { inner: Arc::new(w) })
        .collect())
}

/// [`worlds_arg`] for a run of selected tasks: a set given by name builds only the worlds
/// `only` names where it can ([`verti_world::sets::resolve_set_worlds`]); the flag says
/// whether the worlds returned are the whole set the argument names.
pub(super) fn some_worlds_arg(
    py: Python<'_>,
    arg: &Bound<'_, PyAny>,
    scale: Option<f64>,
    only: Option<&std::collections::BTreeSet<u32>>,
) -> PyResult<(Vec<Arc<World>>, String, bool)> {
    let set_name = arg.cast::<PyString>().ok().and_then(|s| {
        let spec: String = s.extract().ok()?;
        verti_world::sets::split_world_index(&spec)
            .is_none()
            .then_some(spec)
    });
    let (Some(spec), Some(only)) = (set_name, only) else {
        let (worlds, name) = worlds_arg(py, arg, scale)?;
        return Ok((worlds, name, true));
    };
    if let Some(s) = scale {
        verti_world::scale::check_scale(s).map_err(world_err)?;
    }
    let cancel = AtomicBool::new(false);
    let set = interruptible(py, &cancel, || {
        let set = verti_world::sets::resolve_set_worlds(&spec, scale.unwrap_or(1.0), only, &|| {})?;
        verti_world::scale::set_scale(&spec, &set.worlds, scale)?;
        Ok(set)
    })?
    .map_err(world_err)?;
    let (worlds, whole) = verti_world::sets::keep_worlds(set.worlds, only);
    Ok((worlds.into_iter().map(Arc::new).collect(), spec, whole))
}

/// Worlds from a Python argument: a World, a list of Worlds or a name (see `load_worlds`;
/// `SET:INDEX` names one world).
/// `scale` (default 1) applies to generated and imported worlds; worlds already built keep
/// theirs, and another `scale` for them is an error, as is a list mixing scales.
pub(super) fn worlds_arg(
    py: Python<'_>,
    arg: &Bound<'_, PyAny>,
    scale: Option<f64>,
) -> PyResult<(Vec<Arc<World>>, String)> {
    if let Ok(s) = arg.cast::<PyString>() {
        let spec: String = s.extract()?;
        let is_world = verti_world::sets::split_world_index(&spec).is_some()
            || std::path::Path::new(&spec).join("world.yaml").is_file();
        let worlds = if is_world {
            vec![PyWorld::resolve(py, spec.clone(), scale)?]
        } else {
            load_worlds(py, &spec, scale)?
        };
        return Ok((worlds.into_iter().map(|w| w.inner).collect(), spec));
    }
    if let Ok(w) = arg.cast::<PyWorld>() {
        let name = w.get().inner.meta.name.clone();
        verti_world::scale::set_scale(&name, [&*w.get().inner], scale).map_err(world_err)?;
        return Ok((vec![w.get().inner.clone()], name));
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
    verti_world::scale::set_scale(&name, out.iter().map(|w| &**w), scale).map_err(world_err)?;
    Ok((out, name))
}
