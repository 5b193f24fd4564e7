//! The risk-aware planner as a mobility system (`pietra`): verti's MPPI with the CVaR rollout
//! model and the time-to-goal cost, over a traversability model (by default the shipped
//! `pietra-v1`; any card with `model=`, or the physics prior alone with `prior_only=true`).
//!
//! Defaults follow the paper where it speaks (1024 rollouts, 5 s horizon, 10 Hz, α = 0.5 as on
//! the robot, roll/pitch limit 30°) and verti's MPPI where it does not (speed 3 m/s on the
//! benchmark's 120 m tasks; the paper's 1 m/s is `speed=1`; `verti pietra navigate` drives at 2
//! m/s, where the HMMWV does not stall on rock).

use crate::dataset::WheelLayout;
use crate::model::TravModel;
use crate::planner::{CvarRollout, MAX_ATTITUDE_DEG, TimeToGoalCost, TimeWeights, TravSource};
use std::path::Path;
use std::sync::{Arc, OnceLock};
use verti_bench::{MobilitySystem, SystemInfo, SystemRegistry};
use verti_core::Factory;
use verti_core::params::{ParamError, ParamSpec, ParamValue, Params};
use verti_systems::mppi::Mppi;
use verti_systems::registry::{mppi_among, mppi_params};

/// Where the default model comes from (the shipped weights, loaded once).
pub type ModelSource = fn() -> Result<Arc<TravModel>, String>;

/// The `pietra` system.
pub struct PietraSystem {
    pub default_model: ModelSource,
    loaded: OnceLock<Result<Arc<TravModel>, String>>,
}

impl PietraSystem {
    pub fn new(default_model: ModelSource) -> PietraSystem {
        PietraSystem {
            default_model,
            loaded: OnceLock::new(),
        }
    }
}

fn params() -> Vec<ParamSpec> {
    let t = TimeWeights::default();
    let mut specs: Vec<ParamSpec> = mppi_params()
        .into_iter()
        .map(|mut s| {
            s.default = match s.name.as_str() {
                "samples" => ParamValue::Int(1024),
                "horizon" => ParamValue::Int(50),
                "step" => ParamValue::Float(0.1),
                "rate" => ParamValue::Float(10.0),
                _ => s.default,
            };
            s
        })
        .collect();
    let rate = specs.pop().expect("rate is last");
    specs.extend([
        ParamSpec::float(
            "alpha",
            0.5,
            0.01,
            1.0,
            "risk tolerance α of the CVaRs (1: the mean)",
        ),
        ParamSpec::path(
            "model",
            "",
            "traversability model card (YAML) instead of the shipped pietra-v1",
        ),
        ParamSpec::bool(
            "prior_only",
            false,
            "plan with the physics prior alone (no learned model)",
        ),
        ParamSpec::bool(
            "semantics",
            false,
            "semantics-aware prior (beyond the paper's dirt-only maps): each wheel's slope limit scales with the friction of its terrain class",
        ),
        ParamSpec::float(
            "w_ood",
            t.ood,
            0.0,
            1e6,
            "cost per rollout step on OOD terrain (EVORA's OOD avoidance; 0: none)",
        ),
        ParamSpec::float(
            "v_post",
            t.v_post,
            0.001,
            100.0,
            "terminal speed: remaining distance / v_post is the time still to go",
        ),
        ParamSpec::float(
            "max_attitude_deg",
            MAX_ATTITUDE_DEG,
            1.0,
            90.0,
            "roll/pitch limit on the CVaR of |roll|, |pitch| (eq. 5)",
        ),
        ParamSpec::float("cell", 0.5, 0.1, 5.0, "CVaR map cell at full scale, m"),
        rate,
    ]);
    specs
}

impl Factory<dyn MobilitySystem> for PietraSystem {
    fn info(&self) -> SystemInfo {
        SystemInfo {
            name: "pietra".into(),
            summary: "PIETRA: risk-aware MPPI over CVaR maps of evidential traversability with a physics prior (CVaR dynamics, time-to-goal cost)".into(),
            params: params(),
        }
    }

    fn inputs(&self, p: &Params, _worlds: &[u32]) -> Result<Vec<std::path::PathBuf>, String> {
        verti_nn::files::cards_in(p)
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        let source = if p.bool("prior_only") {
            TravSource::Physics
        } else {
            TravSource::Model(match p.path("model") {
                Some(path) if path != Path::new("") => Arc::new(TravModel::load(path)?),
                _ => self.loaded.get_or_init(self.default_model).clone()?,
            })
        };
        let mppi = mppi_among("pietra", p, None)?;
        let weights = TimeWeights {
            ood: p.float("w_ood"),
            v_post: p.float("v_post"),
            max_attitude: p.float("max_attitude_deg").to_radians(),
            ..TimeWeights::default()
        };
        // the vehicle's wheel layout comes with the task; until then, the HMMWV's
        let layout = WheelLayout {
            wheels: [[1.7, 0.9], [-1.7, 0.9], [-1.7, -0.9], [1.7, -0.9]],
            track: 1.8,
            wheelbase: 3.4,
        };
        let model = CvarRollout::new(source, layout, p.float("alpha"), p.float("cell"))
            .with_semantics(p.bool("semantics"));
        Ok(Box::new(Mppi::with_model(
            "pietra",
            mppi,
            Box::new(model),
            Box::new(TimeToGoalCost::new(weights)),
        )))
    }
}

/// Registers `pietra` with its shipped model.
pub fn register(
    registry: &mut SystemRegistry,
    default_model: ModelSource,
) -> Result<(), ParamError> {
    registry.register(PietraSystem::new(default_model))
}
