//! The `va` mobility system: MPPI over VertiAdaptor's adapted model ([`VaRollout`]) with the
//! attitude-aware cost of verti's learned planners, and the online adaptation of
//! [`Adapter`].
//!
//! `adapt=once` (VA*) adapts before the task on data from the task's world: `explore_trials`
//! drives of `explore_seconds` with VertiAdaptor's sinusoidal exploration from random starts,
//! driven on clones of the trial's simulator. This uses the trial privileged (as the paper's
//! VA* uses data "sampled from the entire new environment"); every task of a world gets the
//! same drives and so the same coefficients (computed once per process and world). The other
//! modes use only the trial's own driving.

use crate::adapter::{AdaptMode, Adapter};
use crate::explore::{drives_to_examples, explore_world};
use crate::model::{EMBED, Example, VaModel};
use crate::planner::VaRollout;
use crate::terrain::{TERRAIN_DIM, terrain_latent};
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};
use verti_bench::{Action, MobilitySystem, Observation, SystemInfo, TaskInfo};
use verti_core::Factory;
use verti_core::params::{ParamSpec, ParamValue, Params};
use verti_kino::rollout::{AttitudeCost, AttitudeWeights};
use verti_nn::patch::PatchEncoder;
use verti_systems::mppi::Mppi;
use verti_systems::registry::{mppi_among, mppi_params};
use verti_systems::rollout::PathCostWeights;

/// Coefficients of `once` per (world, model, exploration), shared by the trials of a process.
type OnceCache = Mutex<HashMap<String, Vec<f64>>>;

fn once_cache() -> &'static OnceCache {
    static CACHE: OnceLock<OnceCache> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

/// The adaptation data of `once`: exploration drives of the trial's world.
fn exploration_examples(
    obs: &Observation,
    model: &VaModel,
    encoder: &PatchEncoder,
    trials: usize,
    seconds: f64,
) -> Result<Vec<Example>, String> {
    let trial = obs.trial().ok_or(
        "va with adapt=once explores the task's world before the task, which needs the \
         privileged trial (run it in verti eval, not from hand-made observations)",
    )?;
    let drives = explore_world(
        trial.world(),
        trial.sim().clone(),
        model.card.dt,
        trials,
        seconds,
    )?;
    Ok(drives_to_examples(&drives, trial.world(), model, encoder))
}

/// MPPI with VertiAdaptor and the adaptation state it shares with the rollout model.
pub struct VaDriver {
    mppi: Mppi,
    adapter: Arc<Mutex<Adapter>>,
    encoder: PatchEncoder,
    explore: (usize, f64),
    last_command: (f64, f64),
    once_done: bool,
    failure: Option<String>,
    /// A model path with `{world}` in it: the card of each task's world, loaded at reset.
    per_world: Option<String>,
    /// MPPI plans at every `plan_every`-th control step (the adapter sees every one).
    plan_every: usize,
    acts: usize,
    held: Action,
}

/// The card of world `world` under a `model_per_world` pattern: `{world}` replaced by the
/// world's index in three digits (001, 002, ...).
fn card_for_world(pattern: &str, world: u32) -> String {
    pattern.replace("{world}", &format!("{world:03}"))
}

/// Models loaded for `{world}` paths, shared by the trials of a process.
fn per_world_model(path: &str) -> Result<Arc<VaModel>, String> {
    static CACHE: OnceLock<Mutex<HashMap<String, Arc<VaModel>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(m) = cache.lock().map_err(|e| e.to_string())?.get(path) {
        return Ok(m.clone());
    }
    let m = Arc::new(VaModel::load(Path::new(path)).map_err(|e| e.to_string())?);
    cache
        .lock()
        .map_err(|e| e.to_string())?
        .insert(path.to_string(), m.clone());
    Ok(m)
}

impl VaDriver {
    fn adapt_once(&mut self, obs: &Observation) -> Result<(), String> {
        let model = self
            .adapter
            .lock()
            .map_err(|e| e.to_string())?
            .model()
            .clone();
        let world = obs.world();
        let key = format!(
            "{}#{}@{}|{}|{:?}",
            world.meta.name,
            world.meta.index,
            world.meta.scale,
            model.card.weights.fnv1a64,
            self.explore
        );
        let cached = once_cache()
            .lock()
            .map_err(|e| e.to_string())?
            .get(&key)
            .cloned();
        let alpha = match cached {
            Some(a) => a,
            None => {
                let ex = exploration_examples(
                    obs,
                    &model,
                    &self.encoder,
                    self.explore.0,
                    self.explore.1,
                )?;
                let a = model.adapt(&ex).map_err(|e| e.to_string())?;
                once_cache()
                    .lock()
                    .map_err(|e| e.to_string())?
                    .insert(key, a.clone());
                a
            }
        };
        self.adapter
            .lock()
            .map_err(|e| e.to_string())?
            .set_alpha(alpha);
        Ok(())
    }
}

impl MobilitySystem for VaDriver {
    fn name(&self) -> &str {
        self.mppi.name()
    }
    fn control_rate(&self) -> f64 {
        self.mppi.control_rate()
    }
    fn reset(&mut self, task: &TaskInfo) {
        self.mppi.reset(task);
        self.last_command = (0.0, 0.0);
        self.once_done = false;
        self.failure = None;
        self.acts = 0;
        if let Ok(mut a) = self.adapter.lock() {
            if let Some(pattern) = &self.per_world {
                let path = card_for_world(pattern, task.id.world);
                match per_world_model(&path) {
                    Ok(m) if m.card.method != crate::Method::Va && a.mode() != AdaptMode::None => {
                        self.failure = Some(format!(
                            "{path} is a {} card: run it with adapt=none",
                            m.card.method.name()
                        ))
                    }
                    Ok(m) => *a = Adapter::new(m, a.mode()),
                    Err(e) => {
                        self.failure = Some(format!("model for world {}: {e}", task.id.world))
                    }
                }
            }
            a.reset(task.world_scale);
        }
    }
    fn act(&mut self, obs: &Observation) -> Action {
        if self.failure.is_some() {
            return Action::HighLevel {
                speed: 0.0,
                steering: 0.0,
            };
        }
        let mode = self
            .adapter
            .lock()
            .map(|a| a.mode())
            .unwrap_or(AdaptMode::None);
        if mode == AdaptMode::Once && !self.once_done {
            self.once_done = true;
            if let Err(e) = self.adapt_once(obs) {
                self.failure = Some(e);
                return Action::HighLevel {
                    speed: 0.0,
                    steering: 0.0,
                };
            }
        }
        {
            let encoder = &self.encoder;
            let mut a = self
                .adapter
                .lock()
                .expect("the adapter lock is never poisoned");
            let model = a.model().clone();
            let mut latent = [0f32; TERRAIN_DIM];
            let mut embed = |p: &verti_bench::observation::Pose6| -> [f32; 2 * EMBED] {
                terrain_latent(obs.world(), p, obs.world_scale, encoder, &mut latent);
                model.embed(&latent)
            };
            a.observe(obs.time, obs.pose, self.last_command, &mut embed);
        }
        if self.acts.is_multiple_of(self.plan_every) {
            self.held = self.mppi.act(obs);
        }
        self.acts += 1;
        if let Action::HighLevel { speed, steering } = self.held {
            self.last_command = (speed, steering);
        }
        self.held
    }
    fn failure(&self) -> Option<String> {
        self.failure.clone()
    }
}

/// Where the system's default model comes from.
pub type ModelSource = fn() -> Result<Arc<VaModel>, String>;

/// The `va` factory.
pub struct VaSystem {
    pub default_model: ModelSource,
    loaded: OnceLock<Result<Arc<VaModel>, String>>,
}

impl VaSystem {
    pub fn new(default_model: ModelSource) -> VaSystem {
        VaSystem {
            default_model,
            loaded: OnceLock::new(),
        }
    }
}

/// MPPI defaults for VertiAdaptor: 128 samples x 15 steps of one model step (0.1 s; 1.5 s
/// ahead), planned at 5 Hz within a 10 Hz control loop — what one CPU core affords with 24
/// basis fields (see the README). The control rate must be one per model step (10 Hz at full
/// scale, 10/√s Hz on a world of scale s) for `every` and `rls` to see examples.
fn params() -> Vec<ParamSpec> {
    let w = AttitudeWeights::default();
    let mut specs: Vec<ParamSpec> = mppi_params()
        .into_iter()
        .filter(|s| s.name != "step")
        .map(|mut s| {
            match s.name.as_str() {
                "samples" => s.default = ParamValue::Int(128),
                "horizon" => s.default = ParamValue::Int(15),
                "rate" => s.default = ParamValue::Float(10.0),
                _ => {}
            }
            s
        })
        .collect();
    specs.extend([
        ParamSpec::float("w_attitude", w.attitude, 0.0, 1e6, "weight of predicted roll and pitch beyond 10 degrees (squared, radians)"),
        ParamSpec::float("w_tip", w.tip, 0.0, 1e6, "cost per step with predicted roll or pitch beyond 30 degrees"),
        ParamSpec::path("model", "", "model card (YAML) to use instead of the shipped va-small-v1 (also node, mlp or maml cards)"),
        ParamSpec::string("model_per_world", "", "a card path with {world} in it, replaced by each task's world index (001, 002, ...): cards adapted to each world (verti learn va --adapt-to); overrides model"),
        ParamSpec::choice("adapt", "once", &["none", "once", "every", "rls"], "coefficient adaptation: none (training prior), once (VA*: before the task, on exploration of its world; privileged), every (VA†: least squares on the last `window` s every `period` s), rls (recursive least squares with forgetting)"),
        ParamSpec::float("period", 5.0, 0.1, 1e4, "every: seconds between solves (full scale)"),
        ParamSpec::float("window", 5.0, 0.1, 1e4, "every: seconds of driving each solve uses (full scale)"),
        ParamSpec::float("forgetting", 0.98, 0.5, 1.0, "rls: forgetting factor per model step (0.98: a memory of ~5 s)"),
        ParamSpec::int("plan_every", 2, 1, 100, "plan at every n-th control step (10 Hz control, 5 Hz planning by default); the adapter sees every step"),
        ParamSpec::int("explore_trials", 4, 1, 100, "once: exploration drives of the task's world"),
        ParamSpec::float("explore_seconds", 20.0, 1.0, 600.0, "once: length of each drive (full-scale s)"),
    ]);
    specs
}

impl Factory<dyn MobilitySystem> for VaSystem {
    fn info(&self) -> SystemInfo {
        SystemInfo {
            name: "va".into(),
            summary: "VertiAdaptor: MPPI over 24 neural-ODE basis functions combined by online least-squares coefficients".into(),
            params: params(),
        }
    }

    /// The given card, or with `model_per_world` each selected world's card (a card missing
    /// for one of them is refused before the run, not met as an error trial in it).
    fn inputs(&self, p: &Params, worlds: &[u32]) -> Result<Vec<std::path::PathBuf>, String> {
        let mut files = verti_nn::files::cards_in(p)?;
        let pattern = p.str("model_per_world");
        if !pattern.is_empty() {
            for world in worlds {
                let card = card_for_world(pattern, *world);
                let card = Path::new(&card);
                if !card.is_file() {
                    return Err(format!(
                        "model_per_world {pattern}: no card for world {world} ({} is missing)",
                        card.display()
                    ));
                }
                files.extend(verti_nn::files::card_files(card)?);
            }
        }
        Ok(files)
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        let given = p.path("model").filter(|path| *path != Path::new(""));
        let per_world = Some(p.str("model_per_world").to_string()).filter(|s| !s.is_empty());
        if let Some(pattern) = &per_world
            && !pattern.contains("{world}")
        {
            return Err(format!(
                "model_per_world {pattern}: the path has no {{world}} in it"
            ));
        }
        let model = match (given, &per_world) {
            (Some(path), None) => Arc::new(VaModel::load(path).map_err(|e| e.to_string())?),
            // with {world}, the shipped model stands in until a reset loads the task's own card
            _ => self.loaded.get_or_init(|| (self.default_model)()).clone()?,
        };
        let mppi = mppi_among("va", p, Some(model.card.dt))?;
        let weights = AttitudeWeights {
            path: PathCostWeights {
                goal: mppi.w_goal,
                obstacle: mppi.w_obstacle,
                control: mppi.w_control,
            },
            attitude: p.float("w_attitude"),
            tip: p.float("w_tip"),
            ..AttitudeWeights::default()
        };
        let mode = match p.str("adapt") {
            "none" => AdaptMode::None,
            "once" => AdaptMode::Once,
            "every" => AdaptMode::Every {
                period: p.float("period"),
                window: p.float("window"),
            },
            _ => AdaptMode::Rls {
                forgetting: p.float("forgetting"),
            },
        };
        if per_world.is_none() && model.card.method != crate::Method::Va && mode != AdaptMode::None
        {
            return Err(format!(
                "{} is a {} card: its adaptation is gradient steps (verti learn va), so run it with adapt=none",
                model.card.name,
                model.card.method.name()
            ));
        }
        let encoder = verti_nn::shipped::patch_v1()?;
        let adapter = Arc::new(Mutex::new(Adapter::new(model, mode)));
        let rollout = VaRollout::new(adapter.clone(), encoder.clone());
        let mppi = Mppi::with_model(
            "va",
            mppi,
            Box::new(rollout),
            Box::new(AttitudeCost::new(weights)),
        );
        Ok(Box::new(VaDriver {
            mppi,
            adapter,
            encoder,
            explore: (p.usize("explore_trials"), p.float("explore_seconds")),
            last_command: (0.0, 0.0),
            once_done: false,
            failure: None,
            per_world,
            plan_every: p.usize("plan_every"),
            acts: 0,
            held: Action::HighLevel {
                speed: 0.0,
                steering: 0.0,
            },
        }))
    }
}

/// Registers `va` with its default model.
pub fn register(
    registry: &mut verti_bench::SystemRegistry,
    default_model: ModelSource,
) -> Result<(), verti_core::params::ParamError> {
    registry.register(VaSystem::new(default_model))
}
