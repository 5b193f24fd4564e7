//! How far one deterministic run can be trusted: each task re-run from starts a few
//! centimetres apart (`verti sim compare --ensemble N`).
//!
//! On rough ground a trial is chaotic: which side of a ridge a wheel meets decides whether the
//! vehicle climbs, tips or stays, and two starts 2 cm apart can end differently. One run per
//! task then says little about agreement with another engine, whose own run is just one draw
//! from the same spread. An ensemble gives, per task, the share `p_o` of runs ending in each
//! outcome `o`, and over the tasks:
//! * **expected agreement**: the mean of `p_ref` (the share ending as the reference did), the
//!   agreement to expect from one run started anywhere within the jitter;
//! * **self-agreement**: the mean of `Σ_o p_o²`, the chance that two of verti's own runs from
//!   starts within the jitter end alike. Agreement with another engine cannot be expected to
//!   exceed it much: it is the ceiling the chaos of the tasks sets;
//! * **expected rates** of each outcome (mean of `p_o`), against the reference's counts.
//!
//! Member 0 is the unjittered run (the one the per-task pages show); member k ≥ 1 starts
//! `jitter` metres or less from the task's start, in a direction and at a distance drawn from
//! a stream derived from the task and k, so the ensemble is the same on every machine and for
//! any number of jobs.

use crate::error::{CompareError, Result};
use crate::outcome_counts::OutcomeCounts;
use crate::run::{CompareSetup, pool, run_task};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;
use verti_bench::Outcome;
use verti_core::rng::Rng;
use verti_world::{ElevationLevel, World};

/// Default radius of the start jitter, metres: far below anything a task specifies (the
/// success radius is 10 m), far above the engine's rounding.
pub const DEFAULT_JITTER: f64 = 0.02;

/// The outcomes of one task's ensemble.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnsembleTask {
    pub world_index: u32,
    pub pair: u32,
    pub level: ElevationLevel,
    /// The reference's outcome.
    pub reference: Outcome,
    /// How many members ended each way.
    pub counts: OutcomeCounts,
    /// Share of members ending as the reference did.
    pub p_reference: f64,
    /// Σ p_o²: the chance two members end alike.
    pub self_agreement: f64,
}

/// An ensemble over a group of tasks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnsembleGroup {
    pub group: String,
    pub tasks: usize,
    pub expected_agreement: f64,
    pub self_agreement: f64,
    /// Tasks on which every member ended the same way.
    pub settled_tasks: usize,
    /// Of those, how many ended as the reference did.
    pub settled_agreeing: usize,
    /// Reference counts, and verti's expected counts (Σ over tasks of p_o).
    pub reference: OutcomeCounts,
    pub expected: ExpectedCounts,
}

/// Expected number of tasks ending each way (fractions of tasks summed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ExpectedCounts {
    pub success: f64,
    pub stuck: f64,
    pub rollover: f64,
    pub timeout: f64,
    pub error: f64,
}

/// The ensemble part of the summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ensemble {
    pub members: usize,
    pub jitter: f64,
    pub groups: Vec<EnsembleGroup>,
    pub tasks: Vec<EnsembleTask>,
}

/// `world` with task `pair` starting up to `jitter` metres from its own start (member k).
pub fn jittered_world(world: &World, pair: u32, member: u64, jitter: f64) -> World {
    let mut w = world.clone();
    let id = u64::from(world.meta.index) * 1000 + u64::from(pair);
    let mut rng = Rng::derive(id, "compare-jitter", member);
    // uniform over the disc: radius ∝ √u
    let r = jitter * rng.uniform().sqrt();
    let a = std::f64::consts::TAU * rng.uniform();
    if let Some(t) = w.tasks.iter_mut().find(|t| t.pair == pair) {
        t.start[0] += r * a.cos();
        t.start[1] += r * a.sin();
    }
    w
}

/// Runs members 1..`members` of every task (member 0 is `first`, the unjittered outcomes, in
/// the order of `tasks`) and summarises them against the reference outcomes.
#[allow(clippy::too_many_arguments)]
pub fn run_ensemble(
    worlds: &BTreeMap<u32, Arc<World>>,
    tasks: &[(u32, u32, ElevationLevel, Outcome)],
    first: &[Outcome],
    setup: &CompareSetup,
    members: usize,
    jitter: f64,
    jobs: usize,
    done: &(dyn Fn() + Sync),
) -> Result<Ensemble> {
    if members < 2 || !(jitter.is_finite() && jitter > 0.0) {
        return Err(CompareError::Argument(format!(
            "an ensemble needs at least 2 members and a positive jitter (got {members} and {jitter} m)"
        )));
    }
    let jobs_list: Vec<(usize, u64)> = (0..tasks.len())
        .flat_map(|i| (1..members as u64).map(move |k| (i, k)))
        .collect();
    let outcomes: Vec<Outcome> = pool(jobs)?.install(|| {
        jobs_list
            .par_iter()
            .map(|&(i, k)| {
                let (w, pair, _, _) = tasks[i];
                let world = Arc::new(jittered_world(&worlds[&w], pair, k, jitter));
                let o = run_task(&world, pair, setup).result.outcome;
                done();
                o
            })
            .collect()
    });
    let per_task = members - 1;
    let ens_tasks: Vec<EnsembleTask> = tasks
        .iter()
        .enumerate()
        .map(|(i, &(world_index, pair, level, reference))| {
            let mut counts = OutcomeCounts::default();
            counts.add(first[i]);
            for &o in &outcomes[i * per_task..(i + 1) * per_task] {
                counts.add(o);
            }
            task_stats(world_index, pair, level, reference, counts, members)
        })
        .collect();
    let mut groups = vec![group("all", ens_tasks.iter().collect())];
    for level in ElevationLevel::ALL {
        let of: Vec<&EnsembleTask> = ens_tasks.iter().filter(|t| t.level == level).collect();
        if !of.is_empty() {
            groups.push(group(level.name(), of));
        }
    }
    Ok(Ensemble {
        members,
        jitter,
        groups,
        tasks: ens_tasks,
    })
}

/// One task's shares from its counts over `members` runs.
pub fn task_stats(
    world_index: u32,
    pair: u32,
    level: ElevationLevel,
    reference: Outcome,
    counts: OutcomeCounts,
    members: usize,
) -> EnsembleTask {
    let n = members as f64;
    let self_agreement = Outcome::ALL
        .iter()
        .map(|&o| (counts.get(o) as f64 / n).powi(2))
        .sum();
    EnsembleTask {
        world_index,
        pair,
        level,
        reference,
        p_reference: counts.get(reference) as f64 / n,
        self_agreement,
        counts,
    }
}

/// Aggregates the tasks of one group.
pub fn group(name: &str, tasks: Vec<&EnsembleTask>) -> EnsembleGroup {
    let n = tasks.len().max(1) as f64;
    let mut reference = OutcomeCounts::default();
    let mut expected = ExpectedCounts::default();
    let mut settled_tasks = 0;
    let mut settled_agreeing = 0;
    for t in &tasks {
        reference.add(t.reference);
        let m: usize = Outcome::ALL.iter().map(|&o| t.counts.get(o)).sum();
        let p = |o| t.counts.get(o) as f64 / m as f64;
        expected.success += p(Outcome::Success);
        expected.stuck += p(Outcome::Stuck);
        expected.rollover += p(Outcome::Rollover);
        expected.timeout += p(Outcome::Timeout);
        expected.error += p(Outcome::Error);
        if Outcome::ALL.iter().any(|&o| t.counts.get(o) == m) {
            settled_tasks += 1;
            if t.p_reference == 1.0 {
                settled_agreeing += 1;
            }
        }
    }
    EnsembleGroup {
        group: name.to_string(),
        tasks: tasks.len(),
        expected_agreement: tasks.iter().map(|t| t.p_reference).sum::<f64>() / n,
        self_agreement: tasks.iter().map(|t| t.self_agreement).sum::<f64>() / n,
        settled_tasks,
        settled_agreeing,
        reference,
        expected,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(success: usize, stuck: usize, rollover: usize) -> OutcomeCounts {
        OutcomeCounts {
            success,
            stuck,
            rollover,
            ..Default::default()
        }
    }

    #[test]
    fn shares_and_self_agreement_by_hand() {
        // 6 of 10 succeed, 4 stuck: Σp² = 0.36 + 0.16 = 0.52
        let t = task_stats(
            1,
            0,
            ElevationLevel::High,
            Outcome::Stuck,
            counts(6, 4, 0),
            10,
        );
        assert!((t.p_reference - 0.4).abs() < 1e-12);
        assert!((t.self_agreement - 0.52).abs() < 1e-12);
        let u = task_stats(
            2,
            1,
            ElevationLevel::Low,
            Outcome::Success,
            counts(10, 0, 0),
            10,
        );
        assert_eq!(u.self_agreement, 1.0);
        let g = group("all", vec![&t, &u]);
        assert!((g.expected_agreement - 0.7).abs() < 1e-12);
        assert!((g.self_agreement - 0.76).abs() < 1e-12);
        assert_eq!((g.settled_tasks, g.settled_agreeing), (1, 1));
        assert!((g.expected.success - 1.6).abs() < 1e-12);
        assert!((g.expected.stuck - 0.4).abs() < 1e-12);
        assert_eq!(g.reference.stuck, 1);
    }

    #[test]
    fn jitter_stays_within_its_radius_and_is_reproducible() {
        let mut world = verti_sim::testing::flat_world(1.0, 0.8);
        world.tasks = (0..3)
            .map(|pair| verti_world::Task {
                pair,
                start: [-40.0, f64::from(pair) * 10.0],
                goal: [40.0, 0.0],
            })
            .collect();
        let pair = world.tasks[0].pair;
        let s0 = world.tasks[0].start;
        for k in 1..50 {
            let a = jittered_world(&world, pair, k, 0.02);
            let b = jittered_world(&world, pair, k, 0.02);
            assert_eq!(a.tasks[0].start, b.tasks[0].start);
            let d = ((a.tasks[0].start[0] - s0[0]).powi(2) + (a.tasks[0].start[1] - s0[1]).powi(2))
                .sqrt();
            assert!(d <= 0.02 && d > 0.0, "member {k}: moved {d} m");
            assert_eq!(a.tasks[1..], world.tasks[1..]);
        }
    }
}
