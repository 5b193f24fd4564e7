//! `verti.replay`: one evaluated trial as a 3-D page (the same as `verti replay --3d`).

use super::*;

/// Re-runs task `task` of the run in directory `run` (written by `verti eval` or
/// `verti.evaluate(..., out=...)`) and writes its 3-D recording to `out`, a self-contained
/// HTML page (terrain, obstacles, vehicle body and wheels, path, trail, time series). Returns
/// the replayed trial's result dict; warns if it ended otherwise than the recorded one.
/// A `.json` output gets the recording itself (what `verti.rerun` converts to Rerun's format).
/// `worlds` (a World, a list of Worlds or a set name, resolved at the run's scale) replaces the
/// set the run names, checked by content: needed for a run made on worlds held in memory.
#[pyfunction]
#[pyo3(signature = (run, task, out, worlds = None))]
pub(super) fn _replay(
    py: Python<'_>,
    run: PathBuf,
    task: u32,
    out: PathBuf,
    worlds: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    verti_core::output::check_output_file(&out, &["html", "json"])
        .map_err(|p| value_err(format!("{}: {p}", out.display())))?;
    let as_json = out.extension().and_then(|e| e.to_str()) == Some("json");
    let registry = system_registry();
    let by_name = |name: &str| vehicle_spec(name).map_err(|e| e.to_string());
    use verti_bench::replay::ReplayWorlds;
    let worlds = match worlds {
        None => ReplayWorlds::Recorded,
        Some(w) if w.is_none() => ReplayWorlds::Recorded,
        Some(w) => match w.cast::<PyString>() {
            Ok(name) => ReplayWorlds::Named(name.extract()?),
            Err(_) => ReplayWorlds::Given(worlds_arg(py, w, None)?.0),
        },
    };
    let mut setup =
        verti_bench::replay::prepare(&run, task, &registry, &by_name, worlds).map_err(value_err)?;
    let cancel = AtomicBool::new(false);
    let (recording, replayed) = interruptible(py, &cancel, || {
        verti_view::record_trial(
            &setup.world,
            &setup.vehicle,
            setup.pair,
            setup.system.as_mut(),
            &setup.cfg,
        )
    })?;
    if let Some(w) = setup.mismatch(&replayed) {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        let text = std::ffi::CString::new(w.replace('\0', " ")).expect("no NUL left");
        PyErr::warn(py, &category, &text, 1)?;
    }
    let written = if as_json {
        verti_view::write_json(&recording, &out)
    } else {
        verti_view::write_html(&recording, &out)
    };
    written.map_err(|e| PyOSError::new_err(format!("{}: {e}", out.display())))?;
    results_to_py(py, &[replayed])?
        .pop()
        .ok_or_else(|| PyRuntimeError::new_err("no result"))
}
