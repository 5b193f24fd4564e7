//! `verti.data`: loading a dataset written by `verti data generate` (through the Rust reader,
//! so no pyarrow is needed). Python's `verti/data.py` turns the columns into a DataFrame.

use super::interruptible;
use numpy::IntoPyArray;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use verti_data::Dataset;
use verti_data::table::Column;

/// Loads the dataset in `path`: (dict of column name -> numpy array, in schema order; the
/// `outcome` column is a list of str or None) and the manifest as JSON text.
#[pyfunction]
pub(super) fn _load_dataset(py: Python<'_>, path: PathBuf) -> PyResult<(Py<PyDict>, String)> {
    if !path.is_dir() {
        return Err(PyFileNotFoundError::new_err(format!(
            "{}: no such dataset directory",
            path.display()
        )));
    }
    let cancel = AtomicBool::new(false);
    let data = interruptible(py, &cancel, || Dataset::load(&path))?
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let manifest =
        serde_json::to_string(&data.manifest).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    for (name, column) in data.table.columns {
        match column {
            Column::I32(v) => out.set_item(name, v.into_pyarray(py))?,
            Column::F64(v) => out.set_item(name, v.into_pyarray(py))?,
            Column::Bool(v) => out.set_item(name, v.into_pyarray(py))?,
            Column::Str(v) => out.set_item(name, v)?,
        }
    }
    Ok((out.unbind(), manifest))
}

/// Generates a random-exploration (or failures-from-exploration) dataset into `out`, as
/// `verti data generate KIND --from random` does; evaluation worlds are refused. Returns the
/// manifest as JSON text.
#[pyfunction]
#[pyo3(signature = (out, kind, hours, worlds, vehicle, seed, rate, profile, max_trial_seconds, force))]
#[allow(clippy::too_many_arguments)]
pub(super) fn _generate_dataset(
    py: Python<'_>,
    out: PathBuf,
    kind: String,
    hours: f64,
    worlds: String,
    vehicle: String,
    seed: u64,
    rate: f64,
    profile: String,
    max_trial_seconds: f64,
    force: bool,
) -> PyResult<String> {
    use std::sync::Arc;
    use verti_data::generate::{Source, eval_world_reason};
    use verti_data::{GenerateConfig, Kind, Profile, WriteInfo, write_dataset};
    let value = |e: String| PyValueError::new_err(e);
    let kind = Kind::from_name(&kind).map_err(|e| value(e.to_string()))?;
    if kind == Kind::Expert {
        return Err(value(
            "expert data need a system: use `verti data generate expert`".into(),
        ));
    }
    let profile = Profile::from_name(&profile).ok_or_else(|| {
        value(format!(
            "unknown profile `{profile}`: use paper or vertiadaptor"
        ))
    })?;
    let spec = verti_sim::vehicles::builtin(&vehicle).map_err(super::spec_err)?;
    let cancel = AtomicBool::new(false);
    let result = interruptible(py, &cancel, || -> Result<String, String> {
        let set =
            verti_world::sets::resolve_set(&worlds, 1.0, &|| {}).map_err(|e| e.to_string())?;
        let list: Vec<Arc<verti_world::World>> = set.worlds.into_iter().map(Arc::new).collect();
        if let Some(reason) = eval_world_reason(&list) {
            return Err(reason);
        }
        let cfg = GenerateConfig {
            kind,
            source: Source::Random(profile),
            worlds: list,
            vehicle: spec,
            hours,
            rate,
            seed,
            max_trial_seconds,
        };
        let info = WriteInfo {
            set: worlds.clone(),
            set_name: set.name,
            command: "verti.data.generate (Python)".into(),
            eval_worlds: false,
            force,
        };
        let m = write_dataset(&out, &cfg, &info, &|_| {}).map_err(|e| e.to_string())?;
        serde_json::to_string(&m).map_err(|e| e.to_string())
    })?;
    result.map_err(value)
}
