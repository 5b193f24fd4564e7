//! MPPI on scaled worlds: with lengths scaled by s, speeds by √s and so times by √s, its
//! rollouts reach as far ahead relative to the vehicle and to its look-ahead at every scale.
//! (Before the rollout step scaled, a 1/10-scale vehicle's rollouts reached 2.9 times its 1-m
//! look-ahead, and MPPI weaved on the Verti-4 until it timed out.)

use std::sync::{Arc, Mutex};
use verti_bench::observation::test_observation;
use verti_bench::task_info;
use verti_bench::{MobilitySystem, Observation};
use verti_systems::mppi::{Mppi, MppiParams};
use verti_systems::rollout::{
    Bicycle, ControlSamples, PathCost, PathCostWeights, PlanContext, RolloutModel, Rollouts,
};
use verti_world::generate::one_default_world;

/// The bicycle, recording the context of each plan.
struct Recording {
    inner: Bicycle,
    seen: Arc<Mutex<Vec<PlanContext>>>,
}

impl RolloutModel for Recording {
    fn reset(&mut self, task: &verti_bench::TaskInfo) {
        self.inner.reset(task);
    }
    fn prepare(&mut self, obs: &Observation, ctx: &PlanContext) {
        self.seen.lock().unwrap().push(*ctx);
        self.inner.prepare(obs, ctx);
    }
    fn rollout(&mut self, ctx: &PlanContext, controls: &ControlSamples, out: &mut Rollouts) {
        self.inner.rollout(ctx, controls, out);
    }
}

#[test]
fn rollouts_reach_as_far_ahead_at_every_scale() {
    let world = one_default_world().unwrap();
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let params = MppiParams::default();
    let mut reach = Vec::new();
    for scale in [1.0, 1.0 / 6.0, 0.1] {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let model = Recording {
            inner: Bicycle::default(),
            seen: seen.clone(),
        };
        let cost = PathCost::new(PathCostWeights {
            goal: params.w_goal,
            obstacle: params.w_obstacle,
            control: params.w_control,
        });
        let mut m = Mppi::with_model("mppi", params.clone(), Box::new(model), Box::new(cost));
        let mut info = task_info(&world, &spec, 0, &verti_bench::EpisodeConfig::default()).unwrap();
        info.world_scale = scale;
        m.reset(&info);
        let obs = test_observation(&world, info.start, 0.0, info.goal, &[]);
        m.plan_once(&obs);
        let ctx = seen.lock().unwrap()[0];
        // how far the nominal rollout runs, in look-aheads
        let ahead = ctx.nominal_speed * ctx.step * ctx.horizon as f64 / (params.lookahead * scale);
        println!(
            "scale {scale:.3}: step {:.4} s, nominal speed {:.3} m/s, reach {ahead:.3} look-aheads",
            ctx.step, ctx.nominal_speed
        );
        reach.push(ahead);
    }
    for r in &reach[1..] {
        assert!((r - reach[0]).abs() < 1e-12, "{reach:?}");
    }
    // and at full scale the step is the parameter itself, bit for bit
    assert_eq!(
        reach[0],
        params.speed * params.step * params.horizon as f64 / params.lookahead
    );
}
