//! Risk-aware MPPI (paper §III-B, §V-D): verti's MPPI with the CVaR dynamics of eq. 2 as its
//! rollout model and the time-to-goal objective of EVORA's planner as its cost.
//!
//! * [`CvarRollout`]: x' = x + Δ ψ̄1 v cos θ, y' = y + Δ ψ̄1 v sin θ, θ' = θ + Δ ψ̄2 v tan δ / L,
//!   with ψ̄ the left-tail CVaR_α of traction looked up in a [`CvarMap`] at each state's cell
//!   and heading; the right-tail CVaR of roll and pitch and the OOD flag go out as channels.
//!   The map covers the whole world and is computed once per trial (the terrain is static and
//!   known, as the elevation map every verti system reads).
//! * [`TimeToGoalCost`]: Δ per step until the goal is within reach, a constraint penalty per
//!   step whose CVaR roll or pitch exceeds the limit (eq. 5), an obstacle / off-map penalty, an
//!   optional OOD-avoidance penalty (EVORA), and the remaining distance / v_post at the end.

use crate::bins::param_bins;
use crate::cvar_map::{CvarMap, MapSpec, Region, Source};
use crate::dataset::WheelLayout;
use crate::model::TravModel;
use crate::prior::PriorConfig;
use std::sync::Arc;
use verti_bench::{Observation, TaskInfo};
use verti_systems::rollout::{
    ControlSamples, PlanContext, Pose6, RolloutCost, RolloutModel, Rollouts,
};

/// How the planner sees traversability.
#[derive(Clone)]
pub enum TravSource {
    Physics,
    Model(Arc<TravModel>),
}

/// The CVaR-dynamics rollout model.
pub struct CvarRollout {
    source: TravSource,
    layout: WheelLayout,
    alpha: f64,
    cell: f64,
    map: Option<Arc<CvarMap>>,
    world_name: String,
    wheelbase: f64,
    max_steer: f64,
    /// Read the world's terrain classes into the prior ([`MapSpec::surface`]).
    semantics: bool,
}

/// Channels the rollout writes for the cost.
pub const CH_ROLL: &str = "cvar_roll";
pub const CH_PITCH: &str = "cvar_pitch";
pub const CH_OOD: &str = "ood";
pub const CH_OFF: &str = "off_map";

impl CvarRollout {
    pub fn new(source: TravSource, layout: WheelLayout, alpha: f64, cell: f64) -> CvarRollout {
        CvarRollout {
            source,
            layout,
            alpha,
            cell,
            map: None,
            world_name: String::new(),
            wheelbase: layout.wheelbase,
            max_steer: 0.5,
            semantics: false,
        }
    }

    /// The semantics-aware variant: the prior's slope limits follow each wheel's ground
    /// friction from the world's terrain classes (the paper's maps are dirt only).
    pub fn with_semantics(mut self, on: bool) -> CvarRollout {
        self.semantics = on;
        self
    }

    /// The map of the current trial's world (after the first plan).
    pub fn map(&self) -> Option<&Arc<CvarMap>> {
        self.map.as_ref()
    }
}

impl RolloutModel for CvarRollout {
    fn reset(&mut self, task: &TaskInfo) {
        self.wheelbase = task.wheelbase;
        self.max_steer = task.max_steer_angle;
    }

    fn prepare(&mut self, obs: &Observation, _ctx: &PlanContext) {
        let world = obs.world();
        if self.map.is_none() || self.world_name != world.meta.name {
            // the running vehicle's wheels (a geometric fact, not privileged state)
            if let Some(trial) = obs.trial() {
                self.layout = WheelLayout::of(trial.sim().spec());
            }
            let (prior, bins) = match &self.source {
                TravSource::Model(m) => (
                    m.card.prior.clone(),
                    std::array::from_fn(|k| m.card.bins[k].clone()),
                ),
                TravSource::Physics => (PriorConfig::default(), param_bins()),
            };
            let spec = MapSpec {
                layout: self.layout,
                prior,
                bins,
                alpha: self.alpha,
                surface: self.semantics.then(|| Arc::new(world.patches.clone())),
            };
            let source = match &self.source {
                TravSource::Physics => Source::Physics,
                TravSource::Model(m) => Source::Model(m),
            };
            let region = Region::whole(&world.terrain, self.cell.max(world.terrain.cell() * 0.25));
            let key = MapKey {
                world: world.meta.name.clone(),
                terrain: terrain_digest(&world.terrain),
                model: match &self.source {
                    TravSource::Physics => "physics prior".into(),
                    // the weights' digests: two cards of one name are two models
                    TravSource::Model(m) => m
                        .networks
                        .iter()
                        .map(|n| n.card().weights.fnv1a64.as_str())
                        .collect::<Vec<_>>()
                        .join(","),
                },
                alpha: self.alpha.to_bits(),
                cell: region.cell.to_bits(),
                // the classes matter only to the semantics-aware prior; perception noise can
                // change them without the terrain, so they are keyed by content
                semantics: self.semantics.then(|| patches_digest(&world.patches)),
                wheels: self
                    .layout
                    .wheels
                    .as_flattened()
                    .iter()
                    .map(|v| v.to_bits())
                    .collect(),
            };
            self.map = Some(cached_map(key, || {
                CvarMap::build(&world.terrain, &spec, source, region)
            }));
            self.world_name = world.meta.name.clone();
        }
    }

    fn rollout(&mut self, ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts) {
        let Some(map) = self.map.clone() else {
            return;
        };
        let (k, h) = (controls.samples, controls.horizon);
        let dt = ctx.step;
        let mut chans: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; k * h]);
        for s in 0..k {
            let (mut x, mut y, mut yaw) = (ctx.start.x, ctx.start.y, ctx.start.yaw);
            for t in 0..h {
                let (v, steer) = controls.controls[s * h + t];
                let i = s * h + t;
                let psi = map.at(x, y, yaw);
                let [lin, ang, roll, pitch] = match psi {
                    Some(p) => p.map(f64::from),
                    // off the map: no traction (the cost stops such rollouts)
                    None => [0.0, 0.0, 0.0, 0.0],
                };
                x += dt * lin * v * yaw.cos();
                y += dt * lin * v * yaw.sin();
                yaw += dt * ang * v * (steer * self.max_steer).tan() / self.wheelbase;
                out.poses[i] = Pose6 {
                    x,
                    y,
                    z: ctx.start.z,
                    roll,
                    pitch,
                    yaw,
                };
                chans[0][i] = roll;
                chans[1][i] = pitch;
                chans[2][i] = f64::from(u8::from(map.is_ood(x, y, yaw)));
                chans[3][i] = f64::from(u8::from(psi.is_none()));
            }
        }
        for (name, c) in [CH_ROLL, CH_PITCH, CH_OOD, CH_OFF].into_iter().zip(chans) {
            out.channel_mut(name).copy_from_slice(&c);
        }
    }
}

/// What a CVaR map depends on: its world, model, α, cell and wheels.
#[derive(Clone, Debug, PartialEq, Eq)]
struct MapKey {
    world: String,
    terrain: u64,
    model: String,
    alpha: u64,
    cell: u64,
    semantics: Option<u64>,
    wheels: Vec<u64>,
}

/// A fingerprint of the terrain classes and their physics.
fn patches_digest(p: &verti_world::PatchGrid) -> u64 {
    let mut h = 0u64;
    for (i, patch) in p.patches().iter().enumerate() {
        h = verti_core::rng::mix_seed(&[
            h,
            i as u64,
            u64::from(patch.class.id()),
            patch.surface.effective_friction().to_bits(),
        ]);
    }
    h
}

/// A cheap fingerprint of a heightfield (two worlds of one name never share a map).
fn terrain_digest(t: &verti_world::Heightfield) -> u64 {
    let mut h = verti_core::rng::mix_seed(&[t.size() as u64, t.cell().to_bits()]);
    for (i, v) in t.heights().iter().enumerate().step_by(97) {
        h = verti_core::rng::mix_seed(&[h, i as u64, v.to_bits()]);
    }
    h
}

/// Maps built in this process, most recent last: every task of a world (and every trial of a
/// benchmark) plans on the same static terrain, so its map is built once, not once per trial.
const CACHED_MAPS: usize = 24;

fn cached_map(key: MapKey, build: impl FnOnce() -> CvarMap) -> Arc<CvarMap> {
    static CACHE: std::sync::Mutex<Vec<(MapKey, Arc<CvarMap>)>> = std::sync::Mutex::new(Vec::new());
    if let Some((_, m)) = CACHE
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .iter()
        .find(|(k, _)| *k == key)
    {
        return m.clone();
    }
    // built outside the lock: trials of other worlds go on meanwhile (two trials of one world
    // may both build it; the results are identical)
    let map = Arc::new(build());
    let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if !cache.iter().any(|(k, _)| *k == key) {
        cache.push((key, map.clone()));
        if cache.len() > CACHED_MAPS {
            cache.remove(0);
        }
    }
    map
}

/// The paper's roll/pitch limit (eq. 5), degrees: the default of [`TimeWeights::max_attitude`]
/// and of the `pietra` system's `max_attitude_deg` (written once so the parameter list shows 30,
/// not the 29.999999999999996 that converting the radians back gives).
pub const MAX_ATTITUDE_DEG: f64 = 30.0;

/// The time-to-goal cost's weights.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeWeights {
    /// Goal radius within which a rollout stops accumulating time, m.
    pub goal_tolerance: f64,
    /// Terminal speed: the time still to go is the remaining distance / this (m/s).
    pub v_post: f64,
    /// Roll/pitch limit of eq. 5, radians, and the penalty per step beyond it.
    pub max_attitude: f64,
    pub constraint: f64,
    /// Penalty per step inside an obstacle (clearance included) or off the map.
    pub obstacle: f64,
    /// Penalty per step on OOD terrain (0: no avoidance).
    pub ood: f64,
    pub clearance: f64,
}

impl Default for TimeWeights {
    fn default() -> Self {
        TimeWeights {
            goal_tolerance: 1.0,
            v_post: 0.1,
            max_attitude: MAX_ATTITUDE_DEG.to_radians(),
            constraint: 1e3,
            obstacle: 1e3,
            ood: 0.0,
            clearance: 1.0,
        }
    }
}

/// EVORA's time-to-goal objective with eq. 5's constraint.
pub struct TimeToGoalCost {
    pub weights: TimeWeights,
    obstacles: Vec<(f64, f64)>,
    scale: f64,
    blocked: Option<Arc<Vec<bool>>>,
    grid: Option<(Region, String)>,
}

impl TimeToGoalCost {
    pub fn new(weights: TimeWeights) -> TimeToGoalCost {
        TimeToGoalCost {
            weights,
            obstacles: Vec::new(),
            scale: 1.0,
            blocked: None,
            grid: None,
        }
    }
}

impl RolloutCost for TimeToGoalCost {
    fn reset(&mut self, task: &TaskInfo) {
        self.scale = task.world_scale;
        self.obstacles.clear();
    }

    fn prepare(&mut self, obs: &Observation, _ctx: &PlanContext) {
        let world = obs.world();
        let fresh = self
            .grid
            .as_ref()
            .is_none_or(|(_, n)| *n != world.meta.name);
        if fresh {
            // obstacle cells (clearance included) at 0.5 m, once per world
            let region = Region::whole(&world.terrain, 0.5 * self.scale);
            let clear = self.weights.clearance * self.scale;
            let mut blocked = vec![false; region.cells()];
            if !world.obstacles.is_empty() {
                for r in 0..region.rows {
                    for c in 0..region.cols {
                        let (x, y) = (
                            region.x0 + c as f64 * region.cell,
                            region.y0 + r as f64 * region.cell,
                        );
                        blocked[r * region.cols + c] = obs.obstacle_distance(x, y) < clear;
                    }
                }
            }
            self.blocked = Some(Arc::new(blocked));
            self.grid = Some((region, world.meta.name.clone()));
        }
    }

    fn evaluate(
        &mut self,
        ctx: &PlanContext,
        controls: &ControlSamples,
        rollouts: &Rollouts,
        costs: &mut [f64],
    ) {
        let w = &self.weights;
        let (roll, pitch, ood, off) = (
            rollouts.channel(CH_ROLL),
            rollouts.channel(CH_PITCH),
            rollouts.channel(CH_OOD),
            rollouts.channel(CH_OFF),
        );
        let (Some(roll), Some(pitch), Some(ood), Some(off)) = (roll, pitch, ood, off) else {
            costs.iter_mut().for_each(|c| *c = 0.0);
            return;
        };
        let blocked = |x: f64, y: f64| -> bool {
            match (&self.grid, &self.blocked) {
                (Some((g, _)), Some(b)) => {
                    let c = ((x - g.x0) / g.cell).round();
                    let r = ((y - g.y0) / g.cell).round();
                    c >= 0.0
                        && r >= 0.0
                        && (c as usize) < g.cols
                        && (r as usize) < g.rows
                        && b[r as usize * g.cols + c as usize]
                }
                _ => false,
            }
        };
        let h = controls.horizon;
        let goal = ctx.local_goal;
        let tol = w.goal_tolerance * self.scale;
        for (s, cost) in costs.iter_mut().enumerate() {
            let mut c = 0.0;
            let mut reached = false;
            let poses = rollouts.sample(s);
            for (t, p) in poses.iter().enumerate() {
                let i = s * h + t;
                if (p.x - goal[0]).hypot(p.y - goal[1]) <= tol {
                    reached = true;
                    break;
                }
                c += ctx.step;
                if roll[i] > w.max_attitude || pitch[i] > w.max_attitude {
                    c += w.constraint;
                }
                if off[i] > 0.5 || blocked(p.x, p.y) {
                    c += w.obstacle;
                }
                if ood[i] > 0.5 {
                    c += w.ood;
                }
            }
            if !reached {
                let last = poses[poses.len() - 1];
                c += (last.x - goal[0]).hypot(last.y - goal[1]) / (w.v_post * self.scale.sqrt());
            }
            *cost = c;
        }
    }
}
