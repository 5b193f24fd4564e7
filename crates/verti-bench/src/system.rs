//! The interface between the benchmark and a mobility system, and the registry that builds
//! systems by name.

use crate::observation::Observation;
use verti_core::registry::{Factory, FactoryInfo, Registrable, Registry};
use verti_sim::Controls;
use verti_world::TaskId;

/// What a system is told at the start of a trial.
#[derive(Clone, Debug)]
pub struct TaskInfo {
    pub id: TaskId,
    pub start: [f64; 2],
    pub goal: [f64; 2],
    /// The world's pre-planned global path (empty when none exists).
    pub global_path: Vec<[f64; 2]>,
    /// Length scale of the world (1 = full scale); systems scale their distances with it.
    pub world_scale: f64,
    /// Name of the vehicle being driven.
    pub vehicle: String,
    /// Wheelbase and maximum road-wheel steer angle of the vehicle (for model-based systems).
    pub wheelbase: f64,
    pub max_steer_angle: f64,
    /// The trial's time limit, simulated seconds.
    pub max_time: f64,
    /// Seed for any randomness of the system (derived from the run seed and the task).
    pub seed: u64,
}

/// A command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Target forward speed (m/s, tracked by the benchmark's speed controller) and steering in
    /// [-1, 1] (positive = left).
    HighLevel { speed: f64, steering: f64 },
    /// Direct driver inputs.
    LowLevel(Controls),
}

/// A navigation system under evaluation.
pub trait MobilitySystem: Send {
    /// Short identifier, e.g. `pid`.
    fn name(&self) -> &str;
    /// How often `act` is called, in Hz of simulated time.
    fn control_rate(&self) -> f64;
    /// Called once before a trial.
    fn reset(&mut self, task: &TaskInfo);
    /// Called at the control rate; the action is held until the next call.
    fn act(&mut self, obs: &Observation) -> Action;
    /// Why the system cannot go on, if it cannot (asked after every `act`): the driver then
    /// ends the trial as an error with this message instead of applying the action. The
    /// `oracle` uses it when it is given an observation without privileged access. Default:
    /// never.
    fn failure(&self) -> Option<String> {
        None
    }
}

impl Registrable for dyn MobilitySystem {
    const WHAT: &'static str = "system";
}

/// Mobility systems by name, with typed parameters (`verti systems list`). The command line
/// and the Python module compose one from every crate's `register` function (PID, EH and MPPI:
/// `verti_systems::register`), so a crate above verti-systems adds its systems there.
pub type SystemRegistry = Registry<dyn MobilitySystem>;

/// A system's name, summary and parameter declarations.
pub type SystemInfo = FactoryInfo;

/// Builds one mobility system from resolved parameters. Implement it as
/// `impl Factory<dyn MobilitySystem> for MyFactory { fn info(..); fn build(..) }` (every such
/// factory is a `SystemFactory`) and add it with [`SystemRegistry::register`].
pub trait SystemFactory: Factory<dyn MobilitySystem> {}

impl<F: Factory<dyn MobilitySystem> + ?Sized> SystemFactory for F {}
