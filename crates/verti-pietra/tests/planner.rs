//! The risk-aware planner: CVaR dynamics against eq. 2 on constructed terrain, the cost's
//! constraint, and the `pietra` system driving a task (physics prior and shipped model).

use std::sync::Arc;
use verti_bench::observation::test_observation;
use verti_bench::{EpisodeConfig, Outcome, SystemRegistry, run_episode, task_info};
use verti_core::params::ParamValue;
use verti_pietra::maps::{Split, map};
use verti_pietra::planner::{CvarRollout, TimeToGoalCost, TimeWeights, TravSource};
use verti_systems::rollout::{ControlSamples, PlanContext, RolloutCost, RolloutModel, Rollouts};
use verti_world::{Heightfield, World};

/// A PIETRA map with its terrain replaced by a plane rising `slope` (rise over run) to +x.
fn plane_world(slope: f64) -> World {
    let mut w = map(Split::Train, 1);
    let n = w.terrain.size();
    let cell = w.terrain.cell();
    let h: Vec<f64> = (0..n * n)
        .map(|i| 5.0 + slope * ((i % n) as f64 - 0.5 * (n - 1) as f64) * cell)
        .collect();
    w.terrain = Heightfield::new(n, cell, h);
    w.meta.name = format!("plane-{slope}");
    w
}

fn rollout_forward(world: &World, yaw: f64) -> (f64, f64, Rollouts) {
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    let info = task_info(&Arc::new(world.clone()), &spec, 0, &Default::default()).unwrap();
    let mut model = CvarRollout::new(
        TravSource::Physics,
        verti_pietra::dataset::WheelLayout::of(&spec),
        0.5,
        0.5,
    );
    model.reset(&info);
    let obs = test_observation(world, [0.0, 0.0], yaw, [20.0, 0.0], &[]);
    let ctx = PlanContext {
        start: obs.pose,
        local_goal: [20.0, 0.0],
        samples: 1,
        horizon: 10,
        step: 0.1,
        nominal_speed: 1.0,
        speed_range: (0.3, 1.0),
        lambda: 0.1,
        sigma: (0.5, 0.5),
        scale: 1.0,
    };
    model.prepare(&obs, &ctx);
    let controls = vec![(1.0, 0.0); 10];
    let samples = ControlSamples {
        samples: 1,
        horizon: 10,
        controls: &controls,
        nominal: &controls,
        noise: &controls,
    };
    let mut out = Rollouts::default();
    out.resize(1, 10);
    model.rollout(&ctx, &samples, &mut out);
    let end = out.sample(0)[9];
    let psi = model.map().unwrap().at(0.0, 0.0, yaw).unwrap();
    (end.x.hypot(end.y), f64::from(psi[0]), out)
}

#[test]
fn cvar_dynamics_follow_equation_two() {
    // flat ground: 1 s at 1 m/s goes ψ̄1 metres straight ahead
    let (d, psi1, _) = rollout_forward(&plane_world(0.0), 0.0);
    assert!((d - psi1).abs() < 1e-6, "{d} vs ψ̄1 {psi1}");
    assert!(psi1 > 0.7, "flat ground keeps most of its traction: {psi1}");
    // climbing a 20° slope loses traction (prior: (30° − 20°)/30°); across it does not
    let (up, psi_up, _) = rollout_forward(&plane_world(20f64.to_radians().tan()), 0.0);
    let (across, _, out) = rollout_forward(
        &plane_world(20f64.to_radians().tan()),
        std::f64::consts::FRAC_PI_2,
    );
    assert!(psi_up < 0.6 * psi1, "climbing ψ̄1 {psi_up} vs flat {psi1}");
    assert!(up < across, "climbing goes {up} m, across {across} m");
    // across the slope the CVaR of |roll| is about the slope
    let roll = out.channel("cvar_roll").unwrap()[0];
    assert!(roll > 15f64.to_radians(), "CVaR roll {roll}");
}

#[test]
fn the_attitude_constraint_costs_a_step() {
    let world = plane_world(35f64.to_radians().tan());
    let (_, _, out) = rollout_forward(&world, std::f64::consts::FRAC_PI_2);
    let controls = vec![(1.0, 0.0); 10];
    let samples = ControlSamples {
        samples: 1,
        horizon: 10,
        controls: &controls,
        nominal: &controls,
        noise: &controls,
    };
    let obs = test_observation(&world, [0.0, 0.0], 0.0, [20.0, 0.0], &[]);
    let ctx = PlanContext {
        start: obs.pose,
        local_goal: [20.0, 0.0],
        samples: 1,
        horizon: 10,
        step: 0.1,
        nominal_speed: 1.0,
        speed_range: (0.3, 1.0),
        lambda: 0.1,
        sigma: (0.5, 0.5),
        scale: 1.0,
    };
    let w = TimeWeights::default();
    let mut cost = TimeToGoalCost::new(w.clone());
    cost.prepare(&obs, &ctx);
    let mut c = [0.0];
    cost.evaluate(&ctx, &samples, &out, &mut c);
    // ten steps across a 35° side slope break the 30° roll limit at every step
    assert!(c[0] >= 10.0 * w.constraint, "cost {}", c[0]);
}

#[test]
fn pietra_drives_a_training_map_task() {
    let mut registry = SystemRegistry::new();
    verti_pietra::system::register(&mut registry, verti_pietra::shipped::pietra_v1).unwrap();
    let world = Arc::new(map(Split::Train, 2));
    let spec = verti_sim::vehicles::builtin("hmmwv").unwrap();
    // the semantics-aware prior too (these maps are dirt, so it plans as the plain one)
    for (prior_only, semantics) in [(true, false), (false, false), (false, true)] {
        let given = [
            ("prior_only".to_string(), ParamValue::Bool(prior_only)),
            ("semantics".to_string(), ParamValue::Bool(semantics)),
            ("speed".to_string(), ParamValue::Float(2.0)),
            ("lookahead".to_string(), ParamValue::Float(60.0)),
            // a light planner keeps the test quick; the dynamics and cost are the same
            ("samples".to_string(), ParamValue::Int(128)),
        ];
        let mut system = registry.create("pietra", &given).unwrap();
        let r = run_episode(
            &world,
            &spec,
            3,
            system.as_mut(),
            &EpisodeConfig {
                max_time: 60.0,
                ..Default::default()
            },
            None,
        );
        assert_eq!(
            r.outcome,
            Outcome::Success,
            "prior_only {prior_only}, semantics {semantics}: {r:?}"
        );
    }
}

#[test]
fn attitude_limit_parameter_reads_thirty_degrees() {
    let mut registry = SystemRegistry::new();
    verti_pietra::system::register(&mut registry, verti_pietra::shipped::pietra_v1).unwrap();
    let info = registry.info("pietra").unwrap();
    let spec = info
        .params
        .iter()
        .find(|s| s.name == "max_attitude_deg")
        .unwrap();
    // shown as the paper's 30, and converting it gives the planner's own default exactly
    assert_eq!(spec.default, ParamValue::Float(30.0));
    assert_eq!(
        30f64.to_radians(),
        TimeWeights::default().max_attitude,
        "the default limit"
    );
}
