//! Settings of an environment and the pool of tasks it samples from.

use crate::error::EnvError;
use crate::reward::RewardConfig;
use std::sync::Arc;
use verti_bench::episode::EpisodeConfig;
use verti_bench::features::{ENV_STATE, Feature};
use verti_bench::observation::CropSpec;
use verti_world::{ElevationLevel, ObstacleDensity, TerrainType, World};

/// What an action means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActionMode {
    /// (target speed, steering): the benchmark's speed controller turns the target speed into
    /// throttle and brake every inner step, as for the benchmark's high-level systems.
    HighLevel,
    /// (throttle, brake, steering), held for the whole control period.
    LowLevel,
}

impl ActionMode {
    pub fn dim(self) -> usize {
        match self {
            ActionMode::HighLevel => 2,
            ActionMode::LowLevel => 3,
        }
    }
}

/// Which tasks a core samples from at reset.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TaskFilter {
    /// Global task numbers (as in `verti eval --tasks`); empty = every task of the worlds.
    pub tasks: Vec<u32>,
    pub levels: Vec<ElevationLevel>,
    pub densities: Vec<ObstacleDensity>,
    pub terrain_types: Vec<TerrainType>,
}

/// Settings of an environment.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvConfig {
    /// Rules, time limit and inner step of the benchmark.
    pub episode: EpisodeConfig,
    /// Actions per simulated second; the control period must be a whole number of inner steps.
    pub control_rate: f64,
    pub action: ActionMode,
    /// Target speed of a normalised high-level action of 1, full-scale m/s (scaled by √scale).
    pub max_speed: f64,
    /// Local goal distance along the global path, full-scale metres (scaled by the world).
    pub lookahead: f64,
    pub elevation: Option<CropSpec>,
    pub semantic: Option<CropSpec>,
    pub occupancy: Option<CropSpec>,
    pub reward: RewardConfig,
    /// The entries of the observation's state vector, from the feature schema.
    pub state_features: Vec<Feature>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        EnvConfig {
            episode: EpisodeConfig::default(),
            control_rate: 10.0,
            action: ActionMode::HighLevel,
            max_speed: 4.0,
            lookahead: 10.0,
            elevation: None,
            semantic: None,
            occupancy: None,
            reward: RewardConfig::default(),
            state_features: ENV_STATE.to_vec(),
        }
    }
}

impl EnvConfig {
    /// Inner steps per control step.
    pub fn inner_steps(&self) -> usize {
        (1.0 / self.control_rate / self.episode.inner_dt).round() as usize
    }

    pub fn validate(&self) -> Result<(), EnvError> {
        self.check().map_err(EnvError::InvalidConfig)
    }

    fn check(&self) -> Result<(), String> {
        self.episode.validate()?;
        if !(self.control_rate.is_finite()
            && self.control_rate > 0.0
            && self.control_rate <= 1000.0)
        {
            return Err(format!(
                "control_rate = {} Hz must be in (0, 1000]",
                self.control_rate
            ));
        }
        let period = 1.0 / self.control_rate;
        let k = (period / self.episode.inner_dt).round();
        if k < 1.0 || (k * self.episode.inner_dt - period).abs() > 1e-9 * period.max(1.0) {
            return Err(format!(
                "the control period 1/control_rate = {period} s must be a whole number of inner steps of {} s",
                self.episode.inner_dt
            ));
        }
        if !(self.max_speed.is_finite() && self.max_speed > 0.0 && self.max_speed <= 50.0) {
            return Err(format!(
                "max_speed = {} m/s must be in (0, 50]",
                self.max_speed
            ));
        }
        if !(self.lookahead.is_finite() && self.lookahead > 0.0 && self.lookahead <= 100.0) {
            return Err(format!(
                "lookahead = {} m must be in (0, 100]",
                self.lookahead
            ));
        }
        for (name, crop) in [
            ("elevation", self.elevation),
            ("semantic", self.semantic),
            ("occupancy", self.occupancy),
        ] {
            if let Some(c) = crop
                && !(c.size >= 1
                    && c.size <= 512
                    && c.resolution.is_finite()
                    && c.resolution > 0.0
                    && c.resolution <= 100.0)
            {
                return Err(format!(
                    "{name} patch: size {} must be in 1..=512 cells and resolution {} in (0, 100] m",
                    c.size, c.resolution
                ));
            }
        }
        if self.state_features.is_empty() {
            return Err("state_features must name at least one feature".into());
        }
        self.reward.validate()
    }
}

/// The tasks of `worlds` that pass `filter`, as (world position in `worlds`, pair).
pub fn task_pool(
    worlds: &[Arc<World>],
    filter: &TaskFilter,
) -> Result<Vec<(usize, u32)>, EnvError> {
    if worlds.is_empty() {
        return Err(EnvError::NoTasks("no worlds given".into()));
    }
    let all = verti_bench::eval::select_tasks(worlds, &filter.tasks)
        .map_err(|e| EnvError::NoTasks(e.to_string()))?;
    let keep = |w: &World| {
        (filter.levels.is_empty() || filter.levels.contains(&w.meta.level))
            && (filter.densities.is_empty() || filter.densities.contains(&w.meta.density))
            && (filter.terrain_types.is_empty()
                || filter.terrain_types.contains(&w.meta.terrain_type))
    };
    let pool: Vec<(usize, u32)> = all
        .into_iter()
        .filter(|&(wi, _)| keep(&worlds[wi]))
        .collect();
    if pool.is_empty() {
        let names = |v: Vec<&str>| {
            if v.is_empty() {
                "any".to_string()
            } else {
                v.join("/")
            }
        };
        return Err(EnvError::NoTasks(format!(
            "no task of the {} world(s) matches the filters (levels: {}, densities: {}, terrain types: {}{})",
            worlds.len(),
            names(filter.levels.iter().map(|l| l.name()).collect()),
            names(filter.densities.iter().map(|d| d.name()).collect()),
            names(filter.terrain_types.iter().map(|t| t.name()).collect()),
            if filter.tasks.is_empty() {
                String::new()
            } else {
                format!(", {} selected task numbers", filter.tasks.len())
            }
        )));
    }
    Ok(pool)
}
