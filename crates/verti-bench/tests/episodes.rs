//! Episode rules and metrics on scripted drives whose outcome can be worked out by hand.

use std::sync::Arc;
use verti_bench::episode::{EpisodeLog, Outcome, Rules};
use verti_bench::{Action, EpisodeConfig, MobilitySystem, Observation, TaskInfo, run_episode};
use verti_sim::{Controls, testing, vehicles};
use verti_world::{GlobalPath, Task, World};

/// Drives with a fixed high-level or low-level command.
struct Scripted {
    action: Action,
    rate: f64,
}

impl MobilitySystem for Scripted {
    fn name(&self) -> &str {
        "scripted"
    }
    fn control_rate(&self) -> f64 {
        self.rate
    }
    fn reset(&mut self, _task: &TaskInfo) {}
    fn act(&mut self, _obs: &Observation) -> Action {
        self.action
    }
}

/// A flat world with one task from (-40, 0) heading east to (40, 0).
fn flat_task_world() -> Arc<World> {
    let mut w = testing::flat_world(1.0, 0.8);
    w.meta.index = 1;
    w.tasks = vec![Task {
        pair: 0,
        start: [-40.0, 0.0],
        goal: [40.0, 0.0],
    }];
    w.paths = vec![GlobalPath {
        points: vec![[-40.0, 0.0], [40.0, 0.0]],
    }];
    Arc::new(w)
}

fn run(world: &Arc<World>, action: Action, cfg: &EpisodeConfig) -> verti_bench::TrialResult {
    let spec = vehicles::builtin("hmmwv").unwrap();
    let mut s = Scripted { action, rate: 20.0 };
    run_episode(world, &spec, 0, &mut s, cfg, None)
}

#[test]
fn braking_in_place_is_stuck_after_ten_seconds() {
    let w = flat_task_world();
    let r = run(
        &w,
        Action::LowLevel(Controls::new(0.0, 1.0, 0.0)),
        &EpisodeConfig::default(),
    );
    assert_eq!(r.outcome, Outcome::Stuck);
    // the window is full once a sample 10 s old exists; samples are 0.1 s apart
    assert!((10.0..=10.2).contains(&r.time), "{}", r.time);
    assert!(r.path_length < 0.2, "{}", r.path_length);
    assert!(r.roll.abs.max < 1.0 && r.pitch.abs.max < 2.0);
    assert_eq!(r.traversal_time, None);
    assert!((r.final_distance - 80.0).abs() < 0.5);
    // throttle signal is -brake = -1 throughout: mean |.| 1, no variation
    assert!((r.throttle.mean_abs - 1.0).abs() < 1e-12 && r.throttle.total_variation == 0.0);
}

#[test]
fn driving_straight_reaches_the_goal_in_the_expected_time() {
    let w = flat_task_world();
    let r = run(
        &w,
        Action::HighLevel {
            speed: 5.0,
            steering: 0.0,
        },
        &EpisodeConfig::default(),
    );
    assert_eq!(r.outcome, Outcome::Success, "{r:?}");
    // 70 m (80 m less the 10 m success radius) at 5 m/s is 14 s, plus a few seconds to speed up
    let t = r.traversal_time.unwrap();
    assert!((14.0..20.0).contains(&t), "{t}");
    assert!(r.final_distance < 10.0 && r.final_distance > 9.0);
    assert!((r.path_length - 70.0).abs() < 2.0, "{}", r.path_length);
    assert!(r.steering.mean_abs < 1e-9);
}

#[test]
fn reference_rules_call_slow_driving_stuck_but_the_paper_does_not() {
    let w = flat_task_world();
    // 1.5 m/s: 15 m per 10 s, so not stuck by the paper; under 2 m/s, so stuck for the reference
    let action = Action::HighLevel {
        speed: 1.5,
        steering: 0.0,
    };
    let paper = run(
        &w,
        action,
        &EpisodeConfig {
            max_time: 20.0,
            ..Default::default()
        },
    );
    assert_eq!(paper.outcome, Outcome::Timeout);
    let reference = run(
        &w,
        action,
        &EpisodeConfig {
            rules: Rules::VertiBench,
            max_time: 20.0,
            ..Default::default()
        },
    );
    assert_eq!(reference.outcome, Outcome::Stuck);
    assert!(
        (10.0..=10.5).contains(&reference.time),
        "{}",
        reference.time
    );
    // and the reference's 8 m 3-D sphere is stricter than the paper's 10 m circle
    let fast = Action::HighLevel {
        speed: 5.0,
        steering: 0.0,
    };
    let p = run(&w, fast, &EpisodeConfig::default());
    let v = run(
        &w,
        fast,
        &EpisodeConfig {
            rules: Rules::VertiBench,
            ..Default::default()
        },
    );
    assert_eq!((p.outcome, v.outcome), (Outcome::Success, Outcome::Success));
    assert!(v.traversal_time.unwrap() > p.traversal_time.unwrap());
    assert!(v.final_distance < 8.0);
}

#[test]
fn a_nan_action_ends_the_trial_with_a_clear_error() {
    let w = flat_task_world();
    let r = run(
        &w,
        Action::HighLevel {
            speed: f64::NAN,
            steering: 0.0,
        },
        &EpisodeConfig::default(),
    );
    assert_eq!(r.outcome, Outcome::Error);
    let msg = r.error.unwrap();
    assert!(
        msg.contains("invalid action") && msg.contains("NaN"),
        "{msg}"
    );
    let r = run(
        &w,
        Action::LowLevel(Controls::new(2.0, 0.0, 0.0)),
        &EpisodeConfig::default(),
    );
    assert_eq!(r.outcome, Outcome::Error);
    let spec = vehicles::builtin("hmmwv").unwrap();
    let mut s = Scripted {
        action: Action::HighLevel {
            speed: 1.0,
            steering: 0.0,
        },
        rate: 20.0,
    };
    let r = run_episode(&w, &spec, 7, &mut s, &EpisodeConfig::default(), None);
    assert!(r.error.unwrap().contains("no pair 7"));
}

#[test]
fn rolling_over_on_a_steep_side_slope_is_classified_rollover() {
    // A 48° side slope rising to the north of an east-bound vehicle: steeper than the HMMWV's
    // static rollover angle (tan φ = t / 2h, about 45°), so it must tip over.
    let mut w = testing::plane_world(1.0, 0.0, 48f64.to_radians(), 1.0);
    w.meta.index = 1;
    w.tasks = vec![Task {
        pair: 0,
        start: [-40.0, 0.0],
        goal: [40.0, 0.0],
    }];
    w.paths = vec![GlobalPath {
        points: vec![[-40.0, 0.0], [40.0, 0.0]],
    }];
    let w = Arc::new(w);
    let r = run(
        &w,
        Action::HighLevel {
            speed: 6.0,
            steering: -1.0,
        },
        &EpisodeConfig::default(),
    );
    assert_eq!(r.outcome, Outcome::Rollover, "{r:?}");
    // it ends the moment it passes 90° of tilt (capsized), long before the time limit
    assert!(r.roll.abs.max > 90.0 && r.final_roll > 30.0, "{r:?}");
    assert!(r.time < 30.0, "{}", r.time);
}

#[test]
fn the_log_keeps_the_last_seconds() {
    let w = flat_task_world();
    let spec = vehicles::builtin("hmmwv").unwrap();
    // 1.5 m/s for 40 s: a timeout, long enough for the log to be trimmed
    let mut s = Scripted {
        action: Action::HighLevel {
            speed: 1.5,
            steering: 0.0,
        },
        rate: 20.0,
    };
    let mut log = EpisodeLog::default();
    let cfg = EpisodeConfig {
        log_seconds: Some(10.0),
        max_time: 40.0,
        ..Default::default()
    };
    let r = run_episode(&w, &spec, 0, &mut s, &cfg, Some(&mut log));
    assert_eq!(r.outcome, Outcome::Timeout);
    let first = log.steps.first().unwrap().t();
    let last = log.steps.last().unwrap().t();
    assert!((last - r.time).abs() < 1e-9);
    // everything from 10 s before the end is kept, and old steps are dropped (in blocks of
    // 1024 steps, so at most 10.24 s more than asked)
    let dt = cfg.inner_dt;
    assert!(first <= r.time - 10.0 + dt + 1e-9, "{first}");
    assert!(first >= r.time - 10.0 - 10.25, "{first}");
    // consecutive, no gaps
    assert!(
        log.steps
            .windows(2)
            .all(|p| (p[1].t() - p[0].t() - dt).abs() < 1e-9)
    );
}
