//! MPPI with custom rollout models and costs: the default parts reproduce `Mppi::new`, a
//! custom model is the one rolled out, and a cost can read a model's extra channels.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use verti_bench::observation::test_observation;
use verti_bench::task_info;
use verti_bench::{MobilitySystem, Observation, TaskInfo};
use verti_systems::mppi::{Mppi, MppiParams};
use verti_systems::rollout::{
    Bicycle, ControlSamples, PathCost, PathCostWeights, PlanContext, RolloutCost, RolloutModel,
    Rollouts,
};
use verti_world::World;
use verti_world::generate::one_default_world;

/// The bicycle with its steering reversed; counts its calls and writes each step's steering
/// as a channel.
struct Mirrored {
    inner: Bicycle,
    flipped: Vec<(f64, f64)>,
    prepared: Arc<AtomicUsize>,
    rolled: Arc<AtomicUsize>,
}

impl RolloutModel for Mirrored {
    fn reset(&mut self, task: &TaskInfo) {
        self.inner.reset(task);
    }
    fn prepare(&mut self, obs: &Observation, ctx: &PlanContext) {
        assert_eq!(ctx.start, obs.pose);
        self.prepared.fetch_add(1, Ordering::Relaxed);
    }
    fn rollout(&mut self, ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts) {
        self.rolled.fetch_add(1, Ordering::Relaxed);
        self.flipped.clear();
        self.flipped
            .extend(controls.controls.iter().map(|&(v, d)| (v, -d)));
        let flipped = ControlSamples {
            controls: &self.flipped,
            ..*controls
        };
        self.inner.rollout(ctx, &flipped, out);
        let steer = out.channel_mut("steering");
        for (s, &(_, d)) in steer.iter_mut().zip(controls.controls) {
            *s = d;
        }
    }
}

/// Prefers rollouts that steer right, read from the model's `steering` channel.
struct RightTurns;

impl RolloutCost for RightTurns {
    fn evaluate(
        &mut self,
        _ctx: &PlanContext,
        controls: &ControlSamples,
        rollouts: &Rollouts,
        costs: &mut [f64],
    ) {
        let steer = rollouts.channel("steering").expect("the model writes it");
        assert_eq!(rollouts.poses.len(), steer.len());
        for (k, c) in costs.iter_mut().enumerate() {
            *c = steer[k * controls.horizon..(k + 1) * controls.horizon]
                .iter()
                .sum();
        }
    }
}

fn world() -> World {
    one_default_world().unwrap()
}

/// A task whose goal lies 90° to the vehicle's left, with no global path; plans `n` times from
/// the start and returns the first steering of each plan.
fn plan_left_goal(w: &World, mut m: Mppi, n: usize) -> Vec<f64> {
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let cfg = verti_bench::EpisodeConfig {
        seed: 7,
        ..Default::default()
    };
    let mut info = task_info(w, &spec, 0, &cfg).unwrap();
    info.global_path.clear();
    let yaw = (info.goal[1] - info.start[1]).atan2(info.goal[0] - info.start[0])
        - std::f64::consts::FRAC_PI_2;
    m.reset(&info);
    let obs = test_observation(w, info.start, yaw, info.goal, &[]);
    (0..n).map(|_| m.plan_once(&obs).1).collect()
}

fn params() -> MppiParams {
    MppiParams {
        samples: 200,
        ..Default::default()
    }
}

fn default_cost() -> Box<PathCost> {
    let p = params();
    Box::new(PathCost::new(PathCostWeights {
        goal: p.w_goal,
        obstacle: p.w_obstacle,
        control: p.w_control,
    }))
}

#[test]
fn the_default_parts_are_the_default_mppi() {
    let w = world();
    let plain = plan_left_goal(&w, Mppi::new(params()), 5);
    let parts = Mppi::with_model(
        "mppi",
        params(),
        Box::new(Bicycle::default()),
        default_cost(),
    );
    assert_eq!(plain, plan_left_goal(&w, parts, 5));
    assert!(
        plain.iter().all(|&s| s > 0.1),
        "turns left to the goal: {plain:?}"
    );
}

#[test]
fn a_custom_rollout_model_and_cost_are_the_ones_used() {
    let w = world();
    let (prepared, rolled) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
    let mirrored = || Mirrored {
        inner: Bicycle::default(),
        flipped: Vec::new(),
        prepared: prepared.clone(),
        rolled: rolled.clone(),
    };
    // with the steering reversed in the model, MPPI steers right to reach the goal on the left
    let m = Mppi::with_model("mirrored", params(), Box::new(mirrored()), default_cost());
    assert_eq!(m.name(), "mirrored");
    let steer = plan_left_goal(&w, m, 5);
    assert!(steer.iter().all(|&s| s < 0.0), "{steer:?}");
    assert_eq!(prepared.load(Ordering::Relaxed), 5);
    assert_eq!(rolled.load(Ordering::Relaxed), 5);
    // a cost reading the model's channel: steer right whatever the goal
    let m = Mppi::with_model(
        "right",
        params(),
        Box::new(mirrored()),
        Box::new(RightTurns),
    );
    let steer = plan_left_goal(&w, m, 5);
    assert!(steer.iter().all(|&s| s < -0.1), "{steer:?}");
}
