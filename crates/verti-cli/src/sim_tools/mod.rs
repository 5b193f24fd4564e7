//! Tooling around the engine, not part of it: the speed benchmark ([`bench()`], behind
//! `verti sim bench`) and the random-input robustness run ([`soak()`], behind
//! `verti sim soak`).
//!
//! Why here and not in `verti-sim`: like rapier's benchmarks, they measure the engine from the
//! outside, through its public API alone (`Sim`, `SimState`, `VehicleSpec`), so the engine
//! library carries no benchmark code and no benchmark-only surface. The CLI is their only
//! caller. A soak failure is traced by replaying its episode through the same code
//! ([`soak::replay`], `verti sim soak --replay SEED`), and the benchmark's drive by
//! [`bench_trace`] (`verti sim bench --trace WORLD`, also the drive to profile).

mod bench;
mod soak;
mod trace;

pub use bench::{BenchWorlds, bench};
pub use soak::{replay, soak};
pub use trace::{bench_trace, traced_world};

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use verti_sim::testing::{self, RoughSurface};
    use verti_sim::vehicles;

    // `verti sim bench` prints this table; its layout is what users and docs read.
    #[test]
    fn bench_runs_a_rigid_a_soil_and_a_mixed_case_per_vehicle() {
        let specs = vec![vehicles::builtin("verti4").unwrap()];
        let worlds = BenchWorlds::generated_for(&specs).unwrap();
        let report = bench(&worlds, &specs, 1.0, 2);
        let kinds: Vec<&str> = report.cases.iter().map(|c| c.terrain.as_str()).collect();
        assert_eq!(kinds, ["rigid", "soil", "mixed"]);
        for c in &report.cases {
            assert_eq!(c.error, None, "{c:?}");
            assert_eq!(c.runs.len(), 2);
            assert!((c.sim_seconds - 1.0).abs() < 1e-6 && c.real_time_factor > 0.0);
        }
        let text = report.to_string();
        assert!(text.starts_with("vehicle     ground    sim s        RTF   best RTF"));
        assert_eq!(text.lines().count(), 4);
    }

    // A reported episode seed must reproduce the run: everything but the wall time repeats.
    #[test]
    fn soak_is_deterministic_per_seed() {
        let specs = vec![vehicles::builtin("verti4").unwrap()];
        let world = Arc::new(testing::rough_world(0.1, 10, 16.0, RoughSurface::Mixed));
        let run = || soak(std::slice::from_ref(&world), &specs, 3000, 5, |_| {});
        let (a, b) = (run(), run());
        assert_eq!(a.steps, 3000);
        assert!(a.failures.is_empty(), "{a}");
        assert_eq!(
            (a.episodes, a.simulated_seconds, a.rollovers, a.max_speed),
            (b.episodes, b.simulated_seconds, b.rollovers, b.max_speed)
        );
    }

    // `--replay SEED` must trace the very episode the soak ran and reported.
    #[test]
    fn a_replay_is_the_soak_episode_of_its_seed() {
        let spec = vehicles::builtin("verti4").unwrap();
        let world = Arc::new(testing::rough_world(0.1, 10, 16.0, RoughSurface::Mixed));
        let ran = soak::soak_episode(&world, &spec, 77, 6000, |_, _, _| {});
        let mut lines = Vec::new();
        let traced = replay(&world, &spec, 77, 25, |l| lines.push(l.to_string()));
        assert_eq!(
            (traced.steps, traced.simulated_seconds, traced.max_speed),
            (ran.steps, ran.simulated_seconds, ran.max_speed)
        );
        assert_eq!(lines.len() as u64, ran.steps / 25 + 1);
        assert!(lines[0].starts_with("t   0.25 p ("), "{}", lines[0]);
        assert!(lines.last().unwrap().contains("error: none"));
        assert_eq!(trace::world_argument("verti-100/017"), "verti-100:17");
        assert_eq!(trace::world_argument("verti-100/100"), "verti-100:100");
        assert_eq!(trace::world_argument("rough-mixed"), "rough-mixed");
    }
}
