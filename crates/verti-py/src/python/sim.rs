//! Vehicles and the simulator: specs, states, stepping and rollouts.

use super::*;

/// A vehicle by built-in name (`hmmwv`, `artcar`, ...) or path to a vehicle YAML file.
pub(super) fn vehicle_spec(name: &str) -> PyResult<VehicleSpec> {
    verti_registry::vehicle(name).map_err(spec_err)
}

/// Names of the built-in vehicles.
#[pyfunction]
pub(super) fn vehicles() -> Vec<&'static str> {
    verti_sim::vehicles::builtin_names()
}

/// A snapshot of a vehicle's state (immutable; restore it with `Sim.state = snapshot`).
#[pyclass(name = "SimState", module = "verti", frozen)]
pub struct PySimState {
    pub(super) sim: Arc<verti_sim::Sim>,
    pub(super) state: verti_sim::SimState,
}

/// The simulator state vector: the features of `verti.SIM_STATE_FIELDS` (the time is the
/// simulator's own clock, the controls those the state last applied).
pub(super) fn state_vector(sim: &verti_sim::Sim, s: &verti_sim::SimState) -> [f64; 16] {
    FeatureSource::new(s, pose6(sim, s), s.time(), f64::INFINITY, s.controls()).extract(&SIM_STATE)
}

/// Every feature of the schema: name -> (unit, description).
pub(super) fn feature_table(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    for f in Feature::ALL {
        d.set_item(f.name(), (f.unit(), f.doc()))?;
    }
    Ok(d)
}

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
        for (k, v) in names_of(&SIM_STATE)
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
    pub(super) sim: Arc<verti_sim::Sim>,
    pub(super) state: verti_sim::SimState,
    /// Where `reset` puts the vehicle back.
    pub(super) start: verti_sim::StartPose,
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
        let start = verti_sim::StartPose::new(x, y, yaw);
        let (sim, state) = detached(py, || {
            let sim = verti_sim::Sim::new(&w, &spec)?;
            let state = sim.state_at(start)?;
            Ok::<_, verti_sim::SimError>((sim, state))
        })?
        .map_err(sim_err)?;
        Ok(PySim {
            sim: Arc::new(sim),
            state,
            start,
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
    fn reset(&mut self) -> PyResult<()> {
        self.state = self.sim.state_at(self.start).map_err(sim_err)?;
        Ok(())
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
            start: self.start,
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

pub(super) fn start_of_pair(w: &World, pair: u32) -> PyResult<(f64, f64, f64)> {
    let t = w.tasks.iter().find(|t| t.pair == pair).ok_or_else(|| {
        value_err(format!(
            "world {} has no pair {pair} (pairs 0..{})",
            w.meta.name,
            w.tasks.len()
        ))
    })?;
    Ok((t.start[0], t.start[1], t.start_yaw()))
}
