//! A learned kinodynamic model inside MPPI ([`LearnedRollout`]), and the cost that reads what
//! only a 6-DoF model predicts: roll and pitch ([`AttitudeCost`]).

use crate::features::{KinoState, OUTPUT_DIM, Units, heading_delta};
use crate::model::{Geometry, KinoModel, StepScratch};
use crate::traversability::{TravMap, Traversability};
use std::collections::VecDeque;
use verti_bench::observation::Pose6;
use verti_bench::{Observation, TaskInfo};
use verti_systems::rollout::{
    ControlSamples, PathCost, PathCostWeights, PlanContext, RolloutCost, RolloutModel, Rollouts,
};
use verti_world::Heightfield;

/// Rolls MPPI's samples out with a learned model. One rollout step is one model step
/// (`dt`·√s world seconds), whatever MPPI's `step` says.
pub struct LearnedRollout {
    model: KinoModel,
    /// One per sample of a pair (samples are rolled out two at a time).
    scratch: [StepScratch; 2],
    units: Units,
    geometry: Geometry,
    /// The trial's ground, copied at its first plan (a 129 x 129 grid: ~130 kB).
    terrain: Option<Heightfield>,
    /// Recent observed poses, to form the rates of the first rollout step as training did:
    /// from the pose one model step ago.
    history: VecDeque<(f64, Pose6)>,
    start: KinoState,
}

impl LearnedRollout {
    pub fn new(model: KinoModel) -> LearnedRollout {
        LearnedRollout {
            scratch: [model.scratch(), model.scratch()],
            model,
            units: Units::new(1.0),
            geometry: Geometry::default(),
            terrain: None,
            history: VecDeque::new(),
            start: KinoState {
                pose: Pose6::default(),
                last_delta: [0.0; OUTPUT_DIM],
            },
        }
    }

    fn dt_world(&self) -> f64 {
        self.model.dt() / self.units.time_factor()
    }
}

impl RolloutModel for LearnedRollout {
    fn reset(&mut self, task: &TaskInfo) {
        self.units = Units::new(task.world_scale);
        self.geometry = Geometry {
            wheelbase: task.wheelbase.max(1e-3),
            max_steer: task.max_steer_angle.max(1e-3),
        };
        self.history.clear();
        self.terrain = None;
    }

    fn prepare(&mut self, obs: &Observation, _ctx: &PlanContext) {
        if self.terrain.is_none() {
            self.terrain = Some(obs.world().terrain.clone());
        }
        let dt = self.dt_world();
        let now = obs.time;
        self.history.push_back((now, obs.pose));
        while self.history.len() > 2 && self.history[1].0 <= now - dt + 1e-9 {
            self.history.pop_front();
        }
        let last_delta = match self.history.front() {
            Some(&(t, p)) if now - t >= dt - 1e-9 => heading_delta(&p, &obs.pose),
            // at the start of a trial: the current velocity held for one step
            _ => [obs.forward_speed * dt, 0.0, 0.0, 0.0, 0.0, 0.0],
        };
        self.start = KinoState {
            pose: obs.pose,
            last_delta,
        };
    }

    fn rollout(&mut self, _ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts) {
        let terrain = self
            .terrain
            .as_ref()
            .expect("LearnedRollout::prepare runs before rollout");
        let h = controls.horizon;
        for scratch in &mut self.scratch {
            self.model
                .begin(&self.start.pose, terrain, self.units, scratch);
        }
        // samples two at a time: their networks run side by side (bit for bit what one at a
        // time gives; an odd last sample steps alone)
        let n = controls.samples;
        for s in (0..n - n % 2).step_by(2) {
            let mut states = [self.start; 2];
            for t in 0..h {
                let commands = [
                    controls.controls[s * h + t],
                    controls.controls[(s + 1) * h + t],
                ];
                states = self.model.step_pair(
                    [&states[0], &states[1]],
                    commands,
                    terrain,
                    self.units,
                    self.geometry,
                    &mut self.scratch,
                );
                out.poses[s * h + t] = states[0].pose;
                out.poses[(s + 1) * h + t] = states[1].pose;
            }
        }
        if n % 2 == 1 {
            let s = n - 1;
            let mut state = self.start;
            for t in 0..h {
                state = self.model.step(
                    &state,
                    controls.controls[s * h + t],
                    terrain,
                    self.units,
                    self.geometry,
                    &mut self.scratch[0],
                );
                out.poses[s * h + t] = state.pose;
            }
        }
    }
}

/// Weights of [`AttitudeCost`].
#[derive(Clone, Debug, PartialEq)]
pub struct AttitudeWeights {
    pub path: PathCostWeights,
    /// Per step, (|angle| − free)² summed over roll and pitch (radians), averaged over the
    /// horizon: tilting beyond `free` costs progressively more.
    pub attitude: f64,
    pub free: f64,
    /// Per step beyond `limit` in roll or pitch (the paper's rollover threshold is 30°).
    pub tip: f64,
    pub limit: f64,
}

impl Default for AttitudeWeights {
    fn default() -> Self {
        AttitudeWeights {
            path: PathCostWeights {
                goal: 10.0,
                obstacle: 50.0,
                control: 0.1,
            },
            attitude: 200.0,
            free: 10f64.to_radians(),
            tip: 50.0,
            limit: 30f64.to_radians(),
        }
    }
}

/// [`PathCost`] plus penalties on the predicted roll and pitch (TAL's cost in spirit:
/// distance, attitude, obstacles), accumulated over the horizon.
pub struct AttitudeCost {
    path: PathCost,
    weights: AttitudeWeights,
    /// TNT: a traversability network and its weight (per step, averaged over the horizon).
    traversability: Option<(Traversability, f64)>,
    map: Option<TravMap>,
    units: Units,
}

impl AttitudeCost {
    pub fn new(weights: AttitudeWeights) -> AttitudeCost {
        AttitudeCost {
            path: PathCost::new(weights.path.clone()),
            weights,
            traversability: None,
            map: None,
            units: Units::new(1.0),
        }
    }

    /// The same cost plus `weight` × the predicted difficulty of the ground under every
    /// rollout pose (TNT).
    pub fn with_traversability(mut self, net: Traversability, weight: f64) -> AttitudeCost {
        self.traversability = Some((net, weight));
        self
    }
}

impl RolloutCost for AttitudeCost {
    fn reset(&mut self, task: &TaskInfo) {
        self.path.reset(task);
        self.units = Units::new(task.world_scale);
        self.map = None;
    }
    fn prepare(&mut self, obs: &Observation, ctx: &PlanContext) {
        self.path.prepare(obs, ctx);
        if let Some((net, _)) = &self.traversability {
            self.map = Some(net.plan_map(&obs.pose, &obs.world().terrain, self.units));
        }
    }
    fn evaluate(
        &mut self,
        ctx: &PlanContext,
        controls: &ControlSamples,
        rollouts: &Rollouts,
        costs: &mut [f64],
    ) {
        self.path.evaluate(ctx, controls, rollouts, costs);
        let w = &self.weights;
        let inv_h = 1.0 / controls.horizon as f64;
        let trav = match (&self.traversability, &self.map) {
            (Some((_, weight)), Some(map)) => Some((*weight * inv_h, map)),
            _ => None,
        };
        for (s, cost) in costs.iter_mut().enumerate() {
            let mut extra = 0.0;
            for p in rollouts.sample(s) {
                if let Some((w, map)) = trav {
                    extra += w * map.at(p);
                }
                for a in [p.roll.abs(), p.pitch.abs()] {
                    let over = (a - w.free).max(0.0);
                    extra += w.attitude * over * over * inv_h;
                    if a > w.limit {
                        extra += w.tip;
                    }
                }
            }
            *cost += extra;
        }
    }
}
