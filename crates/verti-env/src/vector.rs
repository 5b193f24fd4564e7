//! [`VecCore`]: many environments stepped together, in parallel, in one call per batch.

use crate::core::{EnvCore, ObsBuf, StepReport};
use crate::error::EnvError;
use rayon::prelude::*;
use verti_bench::Action;

/// One environment's share of a batch step: index, core, observation, report, pending reset
/// and action.
type Slot<'a> = (
    usize,
    (
        (
            ((&'a mut EnvCore, &'a mut ObsBuf), &'a mut StepReport),
            &'a mut bool,
        ),
        &'a Action,
    ),
);

/// Many environments stepped together, in parallel, with next-step autoreset (gymnasium's
/// default): an environment whose episode ended is reset by the following `step`, which
/// ignores its action and reports reward 0 for it.
pub struct VecCore {
    pub envs: Vec<EnvCore>,
    pub obs: Vec<ObsBuf>,
    pub reports: Vec<StepReport>,
    /// Reset by the next step.
    pub pending_reset: Vec<bool>,
    pool: rayon::ThreadPool,
    /// The process the pool's threads run in (see [`VecCore::fresh_pool`]).
    pool_pid: u32,
    threads: usize,
}

fn build_pool(threads: usize) -> Result<rayon::ThreadPool, EnvError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| EnvError::InvalidConfig(format!("cannot start {threads} worker threads: {e}")))
}

impl VecCore {
    pub fn new(template: EnvCore, n: usize, threads: usize) -> Result<VecCore, EnvError> {
        verti_bench::eval::check_jobs(threads, "num_threads").map_err(EnvError::InvalidConfig)?;
        if n == 0 {
            return Err(EnvError::InvalidConfig(
                "num_envs must be at least 1".into(),
            ));
        }
        let pool = build_pool(threads)?;
        let envs: Vec<EnvCore> = (0..n).map(|i| template.sibling(i as u64)).collect();
        Ok(VecCore {
            obs: vec![ObsBuf::default(); n],
            reports: vec![StepReport::idle(); n],
            pending_reset: vec![false; n],
            envs,
            pool,
            pool_pid: std::process::id(),
            threads,
        })
    }

    /// Starts a new pool when this value lives in a forked child (Python's `multiprocessing`
    /// or gymnasium's async vector env forking a process that holds it): a fork copies the
    /// pool's bookkeeping but none of its threads, so work handed to it would wait forever.
    /// The copy is leaked, not dropped: dropping it would signal threads that do not exist.
    fn fresh_pool(&mut self) -> Result<(), EnvError> {
        let pid = std::process::id();
        if pid != self.pool_pid {
            let stale = std::mem::replace(&mut self.pool, build_pool(self.threads)?);
            std::mem::forget(stale);
            self.pool_pid = pid;
        }
        Ok(())
    }

    pub fn len(&self) -> usize {
        self.envs.len()
    }
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    /// Resets every environment, environment i with `seeds[i]` when seeds are given.
    pub fn reset(&mut self, seeds: Option<&[u64]>) -> Result<(), EnvError> {
        if let Some(s) = seeds
            && s.len() != self.envs.len()
        {
            return Err(EnvError::InvalidConfig(format!(
                "expected {} seeds (one per environment), got {}",
                self.envs.len(),
                s.len()
            )));
        }
        self.fresh_pool()?;
        let envs = &mut self.envs;
        let obs = &mut self.obs;
        self.pool.install(|| {
            envs.par_iter_mut()
                .zip(obs.par_iter_mut())
                .enumerate()
                .try_for_each(|(i, (env, buf))| {
                    env.reset(seeds.map(|s| s[i]), None)
                        .and_then(|_| env.observe(buf))
                        .map_err(|e| e.in_vector(i))
                })
        })?;
        self.pending_reset.iter_mut().for_each(|p| *p = false);
        for r in &mut self.reports {
            *r = StepReport::idle();
        }
        Ok(())
    }

    /// Steps every environment with its row of `actions` (normalised, `n × dim`, row-major).
    pub fn step(&mut self, actions: &[f64]) -> Result<(), EnvError> {
        let dim = self.envs.first().map_or(0, |e| e.config().action.dim());
        if actions.len() != dim * self.envs.len() {
            return Err(EnvError::InvalidAction(format!(
                "expected actions of shape ({}, {dim}), got {} numbers",
                self.envs.len(),
                actions.len()
            )));
        }
        // convert (and so validate) every action before stepping any environment
        let converted: Vec<Action> = self
            .envs
            .iter()
            .zip(actions.chunks(dim))
            .enumerate()
            .map(|(i, (env, a))| env.action_from_normalized(a).map_err(|e| e.in_vector(i)))
            .collect::<Result<_, _>>()?;
        let one =
            |(i, ((((env, buf), report), pending), action)): Slot<'_>| -> Result<(), EnvError> {
                if *pending {
                    env.reset(None, None).map_err(|e| e.in_vector(i))?;
                    *report = StepReport::idle();
                    *pending = false;
                } else {
                    *report = env.step(*action).map_err(|e| e.in_vector(i))?;
                    *pending = report.terminated || report.truncated;
                }
                env.observe(buf).map_err(|e| e.in_vector(i))
            };
        self.fresh_pool()?;
        let (envs, obs, reports, pending) = (
            &mut self.envs,
            &mut self.obs,
            &mut self.reports,
            &mut self.pending_reset,
        );
        if self.threads == 1 {
            // on the calling thread: handing a batch to a one-thread pool costs a wake-up
            // (tens of µs on a busy machine) for nothing
            return envs
                .iter_mut()
                .zip(obs.iter_mut())
                .zip(reports.iter_mut())
                .zip(pending.iter_mut())
                .zip(converted.iter())
                .enumerate()
                .try_for_each(one);
        }
        self.pool.install(|| {
            envs.par_iter_mut()
                .zip(obs.par_iter_mut())
                .zip(reports.par_iter_mut())
                .zip(pending.par_iter_mut())
                .zip(converted.par_iter())
                .enumerate()
                .try_for_each(one)
        })
    }
}
