//! The learned planners as mobility systems: MPPI ([`verti_systems::mppi::Mppi`]) with a
//! learned model ([`LearnedRollout`]) and the attitude-aware cost ([`AttitudeCost`]).

use crate::card::KinoFile;
use crate::model::KinoModel;
use crate::rollout::{AttitudeCost, AttitudeWeights, LearnedRollout};
use crate::traversability::Traversability;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use verti_bench::{MobilitySystem, SystemInfo, SystemRegistry};
use verti_core::Factory;
use verti_core::params::{ParamError, ParamSpec, ParamValue, Params};
use verti_systems::mppi::Mppi;
use verti_systems::registry::{mppi_among, mppi_params};
use verti_systems::rollout::PathCostWeights;

/// Where a system's default model comes from (the shipped weights, loaded once).
pub type ModelSource = fn() -> Result<Arc<KinoFile>, String>;

/// Where a system's default traversability network comes from.
pub type TravSource = fn() -> Result<Traversability, String>;

/// A learned planner: a name, a summary, its default model, and (TNT) a traversability
/// network whose value is a rollout cost.
pub struct LearnedSystem {
    pub name: &'static str,
    pub summary: &'static str,
    pub default_model: ModelSource,
    loaded: OnceLock<Result<Arc<KinoFile>, String>>,
    traversability: Option<(TravSource, OnceLock<Result<Traversability, String>>)>,
}

impl LearnedSystem {
    pub fn new(name: &'static str, summary: &'static str, default_model: ModelSource) -> Self {
        LearnedSystem {
            name,
            summary,
            default_model,
            loaded: OnceLock::new(),
            traversability: None,
        }
    }

    /// Adds the traversability cost (parameters `w_trav` and `trav_model`).
    pub fn with_traversability(mut self, source: TravSource) -> Self {
        self.traversability = Some((source, OnceLock::new()));
        self
    }
}

/// Default weight of the traversability cost, chosen on 20 tasks of verti-100-s2 (never the
/// evaluation set): success 65 % at 10, 45 % at 50, 10 % at 200 (TAL alone: 65 %); heavier
/// weights make the planner too timid to finish.
const W_TRAV: f64 = 10.0;

/// MPPI defaults for learned models: the reference's 800 samples x 20 steps; one step is one
/// model step (0.2 s for the shipped models), so the horizon spans 4 s.
fn params(traversability: bool) -> Vec<ParamSpec> {
    let w = AttitudeWeights::default();
    let mut specs: Vec<ParamSpec> = mppi_params()
        .into_iter()
        .filter(|s| s.name != "step")
        .map(|mut s| {
            if s.name == "horizon" {
                s.default = ParamValue::Int(20);
            }
            s
        })
        .collect();
    let rate = specs.pop().expect("rate is last");
    specs.extend([
        ParamSpec::float(
            "w_goal",
            w.path.goal,
            0.0,
            1e6,
            "weight of the distance to the local goal",
        ),
        ParamSpec::float(
            "w_obstacle",
            w.path.obstacle,
            0.0,
            1e6,
            "cost per rollout step inside an obstacle or off the map",
        ),
        ParamSpec::float(
            "w_control",
            w.path.control,
            0.0,
            1e6,
            "weight of the control cost",
        ),
        ParamSpec::float(
            "w_attitude",
            w.attitude,
            0.0,
            1e6,
            "weight of predicted roll and pitch beyond 10 degrees (squared, radians)",
        ),
        ParamSpec::float(
            "w_tip",
            w.tip,
            0.0,
            1e6,
            "cost per step with predicted roll or pitch beyond 30 degrees",
        ),
        ParamSpec::path(
            "model",
            "",
            "model card (YAML) to use instead of the shipped one",
        ),
    ]);
    if traversability {
        specs.extend([
            ParamSpec::float(
                "w_trav",
                W_TRAV,
                0.0,
                1e6,
                "weight of the predicted traversal difficulty under each rollout pose",
            ),
            ParamSpec::path(
                "trav_model",
                "",
                "traversability network card (YAML) to use instead of the shipped one",
            ),
        ]);
    }
    specs.push(rate);
    specs
}

impl Factory<dyn MobilitySystem> for LearnedSystem {
    fn info(&self) -> SystemInfo {
        SystemInfo {
            name: self.name.into(),
            summary: self.summary.into(),
            params: params(self.traversability.is_some()),
        }
    }

    fn inputs(&self, p: &Params, _worlds: &[u32]) -> Result<Vec<std::path::PathBuf>, String> {
        verti_nn::files::cards_in(p)
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        let file = match p.path("model") {
            Some(path) if path != Path::new("") => {
                Arc::new(KinoFile::load(path).map_err(|e| e.to_string())?)
            }
            _ => self.loaded.get_or_init(|| (self.default_model)()).clone()?,
        };
        let mppi = mppi_among(self.name, p, Some(file.card.dt))?;
        let weights = AttitudeWeights {
            path: PathCostWeights {
                goal: p.float("w_goal"),
                obstacle: p.float("w_obstacle"),
                control: p.float("w_control"),
            },
            attitude: p.float("w_attitude"),
            tip: p.float("w_tip"),
            ..AttitudeWeights::default()
        };
        let model = LearnedRollout::new(KinoModel::new(file));
        let mut cost = AttitudeCost::new(weights);
        if let Some((source, loaded)) = &self.traversability {
            let net = match p.path("trav_model") {
                Some(path) if path != Path::new("") => Traversability::load(path)?,
                _ => loaded.get_or_init(source).clone()?,
            };
            cost = cost.with_traversability(net, p.float("w_trav"));
        }
        Ok(Box::new(Mppi::with_model(
            self.name,
            mppi,
            Box::new(model),
            Box::new(cost),
        )))
    }
}

/// Registers the learned planners whose models ship with verti.
pub fn register(
    registry: &mut SystemRegistry,
    systems: Vec<LearnedSystem>,
) -> Result<(), ParamError> {
    for s in systems {
        registry.register(s)?;
    }
    Ok(())
}
