//! A trial's step log survives the Parquet round trip exactly, and keeps the last 10 s.

use std::sync::Arc;
use verti_bench::episode::{EpisodeLog, Outcome};
use verti_bench::{Action, EpisodeConfig, MobilitySystem, Observation, TaskInfo, run_episode};
use verti_sim::{Controls, testing, vehicles};
use verti_world::{GlobalPath, Task};

struct Brake;
impl MobilitySystem for Brake {
    fn name(&self) -> &str {
        "brake"
    }
    fn control_rate(&self) -> f64 {
        10.0
    }
    fn reset(&mut self, _: &TaskInfo) {}
    fn act(&mut self, _: &Observation) -> Action {
        Action::LowLevel(Controls::new(0.0, 1.0, 0.2))
    }
}

#[test]
fn logs_round_trip_exactly() {
    let mut w = testing::flat_world(1.0, 0.8);
    w.meta.index = 3;
    w.tasks = vec![Task {
        pair: 4,
        start: [-40.0, 0.0],
        goal: [40.0, 0.0],
    }];
    w.paths = vec![GlobalPath { points: vec![] }];
    let w = Arc::new(w);
    let spec = vehicles::builtin("hmmwv").unwrap();
    let mut log = EpisodeLog::default();
    let cfg = EpisodeConfig {
        log_seconds: Some(10.0),
        ..Default::default()
    };
    let r = run_episode(&w, &spec, 4, &mut Brake, &cfg, Some(&mut log));
    assert_eq!(r.outcome, Outcome::Stuck);
    let dir = std::env::temp_dir().join(format!("verti-log-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(verti_log::log_file_name(r.task));
    verti_log::write_steps(&path, &r, &log.steps).unwrap();
    let (task, back) = verti_log::read_steps(&path).unwrap();
    assert_eq!(task, 25); // world 3, pair 4
    assert_eq!(back, log.steps);
    assert!(back.first().unwrap().t() <= r.time - 10.0 + 0.011);
    assert!(
        !dir.join(format!("task-{:05}.parquet.partial", r.task))
            .exists()
    );
    let e = verti_log::read_steps(&dir.join("missing.parquet"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.parquet"), "{e}");
    std::fs::write(dir.join("bad.parquet"), b"not parquet").unwrap();
    let e = verti_log::read_steps(&dir.join("bad.parquet"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.parquet"), "{e}");
    std::fs::remove_dir_all(dir).ok();
}
