//! The extension module `verti._verti`: worlds, the simulator, evaluation and the environment
//! cores, for the Python package in `python/verti`.
//!
//! Conventions, so Python users get what Rust users get:
//! * every Rust error becomes a Python exception carrying the Rust message unchanged
//!   (`ValueError` for bad input, `FileNotFoundError`/`OSError` for files, `SimulationError` for
//!   a blown-up simulation); a panic becomes `RuntimeError` instead of crossing the boundary;
//! * calls that can take long run with the GIL released, on a helper thread, while the calling
//!   thread polls for signals, so Ctrl-C interrupts them with `KeyboardInterrupt`.

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
use verti_bench::episode::{EpisodeConfig, Outcome, Rules, TrialResult, run_episode};
use verti_bench::eval::{EvalError, EvalSetup, RunInfo, parse_tasks, select_tasks};
use verti_bench::features::{ENV_STATE, Feature, FeatureSource, SIM_STATE, names_of};
use verti_bench::observation::CropSpec;
use verti_bench::pose6;
use verti_bench::{Action, MobilitySystem, Observation, ParamValue, TaskInfo};
use verti_env::{
    ActionMode, EnvConfig, EnvCore, EnvError, Episode, ObsBuf, RewardConfig, StepReport,
    TaskFilter, VecCore, encode_observation, outcome_code,
};
use verti_registry::systems as system_registry;
use verti_sim::{Controls, SimError, SpecError, VehicleSpec};
use verti_world::generate::elevation::ElevationSource;
use verti_world::generate::{SetConfig, composition, generate_world};
use verti_world::{ElevationLevel, ObstacleDensity, TaskId, TerrainType, World, WorldError};

pyo3::create_exception!(
    _verti,
    SimulationError,
    PyRuntimeError,
    "The simulation blew up: the vehicle state stopped being finite or physical."
);

pub(super) fn io_error(message: String, source: &std::io::Error) -> PyErr {
    if source.kind() == std::io::ErrorKind::NotFound {
        PyFileNotFoundError::new_err(message)
    } else {
        PyOSError::new_err(message)
    }
}

pub(super) fn world_err(e: WorldError) -> PyErr {
    match &e {
        WorldError::Io { source, .. } => io_error(e.to_string(), source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub(super) fn spec_err(e: SpecError) -> PyErr {
    match &e {
        SpecError::Io { source, .. } => io_error(e.to_string(), source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub(super) fn sim_err(e: SimError) -> PyErr {
    match e {
        SimError::NonFinite { .. } | SimError::BlowUp { .. } => {
            SimulationError::new_err(e.to_string())
        }
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub(super) fn eval_err(e: EvalError) -> PyErr {
    match &e {
        EvalError::Io { source, .. } => io_error(e.to_string(), source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub(super) fn env_err(e: EnvError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

pub(super) fn value_err(e: String) -> PyErr {
    PyValueError::new_err(e)
}

pub(super) fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

pub(super) fn internal(p: Box<dyn std::any::Any + Send>) -> PyErr {
    PyRuntimeError::new_err(format!(
        "internal error in verti (please report it): {}",
        panic_message(p)
    ))
}

/// Checks an output directory argument (`out`, `World.save`'s path) as the command line does:
/// it may be created, but only inside an existing directory (FileNotFoundError otherwise).
pub(super) fn out_dir_arg(what: &str, path: &std::path::Path) -> PyResult<()> {
    verti_core::output::check_output_dir(path).map_err(|problem| {
        let message = format!("{what} {}: {problem}", path.display());
        let parent_missing = path
            .parent()
            .is_some_and(|p| !p.as_os_str().is_empty() && !p.exists());
        if parent_missing {
            PyFileNotFoundError::new_err(message)
        } else {
            PyValueError::new_err(message)
        }
    })
}

/// Runs short work with the GIL released; a panic becomes `RuntimeError`.
pub(super) fn detached<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(work)))
        .map_err(internal)
}

/// A thread pool of its own for one call's parallel work (world loading and generation run
/// rayon's `par_iter` inside it), never rayon's global pool: a process forked once the global
/// pool has started (gymnasium's async vector env, `multiprocessing` with fork) inherits the
/// pool's bookkeeping but none of its threads, and its first parallel call would wait forever.
/// A pool made per call holds no state across a fork; it costs a few thread starts per call.
fn call_pool() -> PyResult<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .thread_name(|i| format!("verti-{i}"))
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start worker threads: {e}")))
}

/// Runs long work on a helper thread with the GIL released while this thread checks for
/// signals every 50 ms. On a signal (Ctrl-C) `cancel` is raised, the work (which polls it) is
/// waited for, and the signal's exception (`KeyboardInterrupt`) is returned. Parallel work
/// inside runs on a pool made for this call (see `call_pool`).
pub(super) fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let pool = call_pool()?;
    let (outcome, interrupted) = py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = std::sync::mpsc::channel::<()>();
            let handle = s.spawn(move || {
                let r = catch_unwind(AssertUnwindSafe(|| pool.install(work)));
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

mod data;
mod env;
mod eval;
mod pysystem;
mod replay;
mod sim;
mod world;
use env::*;
use eval::*;
use pysystem::*;
use sim::*;
use world::*;

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
    m.add_function(wrap_pyfunction!(replay::_replay, m)?)?;
    m.add_function(wrap_pyfunction!(data::_load_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(data::_generate_dataset, m)?)?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    // the feature schema: every feature's name, and the default selections
    m.add("STATE_FIELDS", names_of(&ENV_STATE))?;
    m.add("SIM_STATE_FIELDS", names_of(&SIM_STATE))?;
    m.add("FEATURES", feature_table(py)?)?;
    m.add(
        "OUTCOMES",
        Outcome::ALL.iter().map(|o| o.name()).collect::<Vec<_>>(),
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
