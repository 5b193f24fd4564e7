//! A driving policy as a benchmark system: every 0.1 s it finds the local goal on the global
//! path, encodes the observation exactly as the training environment does
//! ([`verti_env::encode_observation`] with [`crate::inputs::env_config`]) and applies the
//! policy's mean action (target speed and steering).

use crate::inputs::{LOOKAHEAD, MAX_SPEED, env_config, policy_input};
use crate::policy::Policy;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use verti_bench::path::PathFollower;
use verti_bench::{Action, MobilitySystem, Observation, SystemInfo, SystemRegistry, TaskInfo};
use verti_core::Factory;
use verti_core::params::{ParamError, ParamSpec, Params};
use verti_env::{EnvConfig, ObsBuf, encode_observation};
use verti_nn::MlpScratch;

/// A policy driving one trial at a time.
pub struct PolicyDriver {
    name: String,
    policy: Arc<Policy>,
    cfg: EnvConfig,
    follower: PathFollower,
    goal: [f64; 2],
    scale: f64,
    buf: ObsBuf,
    input: Vec<f32>,
    scratch: MlpScratch,
}

impl PolicyDriver {
    pub fn new(name: &str, policy: Arc<Policy>) -> PolicyDriver {
        let scratch = policy.scratch();
        PolicyDriver {
            name: name.to_string(),
            policy,
            cfg: env_config(),
            follower: PathFollower::default(),
            goal: [0.0; 2],
            scale: 1.0,
            buf: ObsBuf::default(),
            input: Vec::new(),
            scratch,
        }
    }
}

impl MobilitySystem for PolicyDriver {
    fn name(&self) -> &str {
        &self.name
    }

    fn control_rate(&self) -> f64 {
        self.cfg.control_rate
    }

    fn reset(&mut self, task: &TaskInfo) {
        self.follower = PathFollower::new(task.global_path.clone());
        self.goal = task.goal;
        self.scale = task.world_scale;
    }

    fn act(&mut self, obs: &Observation) -> Action {
        let p = obs.pose;
        let local_goal = self
            .follower
            .local_goal(p.x, p.y, LOOKAHEAD * self.scale, self.goal);
        encode_observation(&self.cfg, obs, local_goal, &mut self.buf);
        policy_input(&self.buf, self.scale, &mut self.input);
        let [speed, steering] = self.policy.act(&self.input, &mut self.scratch);
        Action::HighLevel {
            speed: f64::from(speed) * MAX_SPEED * self.scale.sqrt(),
            steering: f64::from(steering),
        }
    }
}

/// Where a system's default policy comes from (the shipped weights).
pub type PolicySource = fn() -> Result<Arc<Policy>, String>;

/// A registered policy system: a name, a summary and its default (shipped) policy; the
/// parameter `model` swaps in any policy card.
pub struct PolicySystem {
    pub name: &'static str,
    pub summary: &'static str,
    pub default_policy: PolicySource,
    loaded: OnceLock<Result<Arc<Policy>, String>>,
}

impl PolicySystem {
    pub fn new(name: &'static str, summary: &'static str, default_policy: PolicySource) -> Self {
        PolicySystem {
            name,
            summary,
            default_policy,
            loaded: OnceLock::new(),
        }
    }
}

impl Factory<dyn MobilitySystem> for PolicySystem {
    fn info(&self) -> SystemInfo {
        SystemInfo {
            name: self.name.into(),
            summary: self.summary.into(),
            params: vec![ParamSpec::path(
                "model",
                "",
                "policy card (YAML, from `verti learn rl`) to drive instead of the shipped one",
            )],
        }
    }

    fn inputs(&self, p: &Params, _worlds: &[u32]) -> Result<Vec<std::path::PathBuf>, String> {
        verti_nn::files::cards_in(p)
    }
    fn build(&self, p: &Params) -> Result<Box<dyn MobilitySystem>, String> {
        let policy = match p.path("model") {
            Some(path) if path != Path::new("") => Arc::new(Policy::load(path)?),
            _ => self
                .loaded
                .get_or_init(|| (self.default_policy)())
                .clone()?,
        };
        Ok(Box::new(PolicyDriver::new(self.name, policy)))
    }
}

/// Registers policy systems (the shipped ones: [`crate::shipped::systems`]).
pub fn register(
    registry: &mut SystemRegistry,
    systems: Vec<PolicySystem>,
) -> Result<(), ParamError> {
    for s in systems {
        registry.register(s)?;
    }
    Ok(())
}
