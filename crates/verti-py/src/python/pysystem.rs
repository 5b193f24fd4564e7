//! Bring your own system: a Python object with `reset(task)` and `act(obs)` driven through the
//! benchmark's `Trial`, exactly as the built-in systems are.
//!
//! The object may declare, as attributes (all optional):
//! * `name` (str, default: the class name in lower case), recorded as the results' `system`;
//! * `control_rate` (Hz, default 10);
//! * `action_mode`: `"high"` (default: `(target speed m/s, steering in [-1, 1])`, tracked by the
//!   benchmark's speed controller) or `"low"` (`(throttle, brake, steering)`);
//! * the environment's observation settings, so a policy trained in `verti.envs` sees the same
//!   inputs here: `state_features`, `lookahead` (m, full scale), `elevation`, `semantic`,
//!   `occupancy` (crops as `(size, resolution)`).
//!
//! `act` receives a dict: `time`, `pose` (x, y, z, roll, pitch, yaw), `velocity_body`,
//! `angular_velocity_body`, `forward_speed`, `controls` (throttle, brake, steering of the latest
//! inner step), `goal_xy` (world frame) and, encoded exactly as the environment encodes them,
//! `state`, `goal` and `local_goal` (heading frame) and the requested crops. `reset` receives the
//! task: `task`, `world`, `pair`, `start`, `goal`, `global_path` (N x 2), `world_scale`,
//! `vehicle`, `wheelbase`, `max_steer_angle`, `max_time`, `seed`.
//!
//! A Python exception inside `reset` or `act` stops the evaluation: the trial it happened in is
//! not recorded, and `evaluate` raises the exception.

use super::*;
use std::sync::Mutex;
use verti_bench::path::PathFollower;

/// How a Python system wants to be driven and observed (read once from its attributes).
#[derive(Clone)]
pub(super) struct PySystemSpec {
    pub(super) name: String,
    pub(super) rate: f64,
    pub(super) low_level: bool,
    pub(super) obs: EnvConfig,
}

fn attr<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
    if !obj.hasattr(name)? {
        return Ok(None);
    }
    let v = obj.getattr(name)?;
    Ok((!v.is_none()).then_some(v))
}

impl PySystemSpec {
    /// Reads and checks the object's declarations; errors name the attribute.
    pub(super) fn of(obj: &Bound<'_, PyAny>) -> PyResult<PySystemSpec> {
        for method in ["reset", "act"] {
            if !obj.hasattr(method)? || !obj.getattr(method)?.is_callable() {
                return Err(PyTypeError::new_err(format!(
                    "a system must be a built-in system's name or an object with methods reset(task) and act(obs); {} has no method {method}",
                    obj.get_type().name()?
                )));
            }
        }
        let name = match attr(obj, "name")? {
            Some(n) => n
                .extract::<String>()
                .map_err(|_| PyTypeError::new_err("system attribute `name` must be a str"))?,
            None => obj.get_type().name()?.to_string().to_lowercase(),
        };
        let rate = match attr(obj, "control_rate")? {
            Some(r) => r.extract::<f64>().map_err(|_| {
                PyTypeError::new_err("system attribute `control_rate` must be a number (Hz)")
            })?,
            None => 10.0,
        };
        if !(rate.is_finite() && rate > 0.0 && rate <= 1000.0) {
            return Err(value_err(format!(
                "system attribute control_rate = {rate} Hz must be in (0, 1000]"
            )));
        }
        let low_level = match attr(obj, "action_mode")? {
            None => false,
            Some(m) => match m.extract::<String>()?.as_str() {
                "high" | "high-level" | "speed" => false,
                "low" | "low-level" | "drive" => true,
                other => {
                    return Err(value_err(format!(
                        "system attribute action_mode = `{other}`: use 'high' (target speed, steering) or 'low' (throttle, brake, steering)"
                    )));
                }
            },
        };
        let mut obs = EnvConfig::default();
        if let Some(names) = attr(obj, "state_features")? {
            let names: Vec<String> = names.extract().map_err(|_| {
                PyTypeError::new_err("system attribute `state_features` must be a list of names")
            })?;
            obs.state_features = Feature::parse_list(&names).map_err(value_err)?;
        }
        if let Some(l) = attr(obj, "lookahead")? {
            obs.lookahead = l.extract().map_err(|_| {
                PyTypeError::new_err("system attribute `lookahead` must be a number")
            })?;
        }
        let none = obj.py().None().into_bound(obj.py());
        for (key, slot) in [
            ("elevation", &mut obs.elevation),
            ("semantic", &mut obs.semantic),
            ("occupancy", &mut obs.occupancy),
        ] {
            *slot = crop_arg(&attr(obj, key)?.unwrap_or_else(|| none.clone()), key)?;
        }
        obs.validate().map_err(env_err)?;
        Ok(PySystemSpec {
            name,
            rate,
            low_level,
            obs,
        })
    }
}

/// The first Python exception a system raised, shared with the evaluation that reports it.
pub(super) type RaisedError = Arc<Mutex<Option<PyErr>>>;

/// A Python object seen as a [`MobilitySystem`]. Every call takes the GIL; everything else
/// (physics, rules, metrics) runs without it.
pub(super) struct PySystem {
    obj: Py<PyAny>,
    spec: PySystemSpec,
    follower: PathFollower,
    scale: f64,
    buf: ObsBuf,
    raised: RaisedError,
    cancel: Arc<AtomicBool>,
}

impl PySystem {
    pub(super) fn new(
        obj: Py<PyAny>,
        spec: PySystemSpec,
        raised: RaisedError,
        cancel: Arc<AtomicBool>,
    ) -> PySystem {
        PySystem {
            obj,
            spec,
            follower: PathFollower::default(),
            scale: 1.0,
            buf: ObsBuf::default(),
            raised,
            cancel,
        }
    }

    /// Keeps the first exception and cancels the evaluation.
    fn record(&self, e: PyErr) {
        let mut slot = self.raised.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
        self.cancel.store(true, Ordering::SeqCst);
    }

    fn task_dict<'py>(py: Python<'py>, t: &TaskInfo) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("task", t.id.number())?;
        d.set_item("world", t.id.world)?;
        d.set_item("pair", t.id.pair)?;
        d.set_item("start", (t.start[0], t.start[1]))?;
        d.set_item("goal", (t.goal[0], t.goal[1]))?;
        let flat: Vec<f64> = t.global_path.iter().flatten().copied().collect();
        d.set_item(
            "global_path",
            PyArray1::from_vec(py, flat).reshape([t.global_path.len(), 2])?,
        )?;
        d.set_item("world_scale", t.world_scale)?;
        d.set_item("vehicle", t.vehicle.as_str())?;
        d.set_item("wheelbase", t.wheelbase)?;
        d.set_item("max_steer_angle", t.max_steer_angle)?;
        d.set_item("max_time", t.max_time)?;
        d.set_item("seed", t.seed)?;
        Ok(d)
    }

    fn obs_dict<'py>(&self, py: Python<'py>, obs: &Observation) -> PyResult<Bound<'py, PyDict>> {
        let d = obs_dict(py, &self.spec.obs, &self.buf)?;
        let p = obs.pose;
        let (v, w, c) = (obs.velocity_body, obs.angular_velocity_body, obs.controls);
        d.set_item("time", obs.time)?;
        d.set_item(
            "pose",
            PyArray1::from_slice(py, &[p.x, p.y, p.z, p.roll, p.pitch, p.yaw]),
        )?;
        d.set_item("velocity_body", PyArray1::from_slice(py, &[v.x, v.y, v.z]))?;
        d.set_item(
            "angular_velocity_body",
            PyArray1::from_slice(py, &[w.x, w.y, w.z]),
        )?;
        d.set_item("forward_speed", obs.forward_speed)?;
        d.set_item(
            "controls",
            PyArray1::from_slice(py, &[c.throttle, c.brake, c.steering]),
        )?;
        d.set_item("goal_xy", PyArray1::from_slice(py, &obs.goal))?;
        Ok(d)
    }

    fn action(&self, a: &Bound<'_, PyAny>) -> PyResult<Action> {
        let values: Vec<f64> = a.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{}.act must return a sequence of numbers: (target speed m/s, steering) or, with action_mode 'low', (throttle, brake, steering)",
                self.spec.name
            ))
        })?;
        match (self.spec.low_level, values.as_slice()) {
            (false, &[speed, steering]) => Ok(Action::HighLevel { speed, steering }),
            (true, &[throttle, brake, steering]) => {
                Ok(Action::LowLevel(Controls::new(throttle, brake, steering)))
            }
            (low, v) => Err(value_err(format!(
                "{}.act returned {} numbers; expected {}",
                self.spec.name,
                v.len(),
                if low {
                    "3 (throttle, brake, steering)"
                } else {
                    "2 (target speed m/s, steering)"
                }
            ))),
        }
    }
}

impl MobilitySystem for PySystem {
    fn name(&self) -> &str {
        &self.spec.name
    }
    fn control_rate(&self) -> f64 {
        self.spec.rate
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.follower = PathFollower::new(task.global_path.clone());
        self.scale = task.world_scale;
        let r = Python::attach(|py| -> PyResult<()> {
            let t = Self::task_dict(py, task)?;
            self.obj.bind(py).call_method1("reset", (t,))?;
            Ok(())
        });
        if let Err(e) = r {
            self.record(e);
        }
    }
    fn act(&mut self, obs: &Observation) -> Action {
        const STOP: Action = Action::HighLevel {
            speed: f64::NAN,
            steering: 0.0,
        };
        if self.cancel.load(Ordering::SeqCst) {
            return STOP;
        }
        let lookahead = self.spec.obs.lookahead * self.scale;
        let local_goal = self
            .follower
            .local_goal(obs.pose.x, obs.pose.y, lookahead, obs.goal);
        encode_observation(&self.spec.obs, obs, local_goal, &mut self.buf);
        let r = Python::attach(|py| -> PyResult<Action> {
            let d = self.obs_dict(py, obs)?;
            let a = self.obj.bind(py).call_method1("act", (d,))?;
            self.action(&a)
        });
        r.unwrap_or_else(|e| {
            self.record(e);
            STOP
        })
    }
}
