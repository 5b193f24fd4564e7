//! Proximal policy optimisation (Schulman et al., 2017) over verti-env, in one file.
//!
//! One update of [`Trainer::update`], in order:
//! 1. export the actor and the critic to verti-nn MLPs: the rollout runs the network code that
//!    evaluation runs, and it is fast for one observation at a time;
//! 2. collect `steps` control steps (0.1 s each) from each of `envs` environments in parallel:
//!    actions drawn from a Gaussian around the actor's mean (state-independent log std),
//!    rewards of verti-env's default reward times `reward_scale`; an episode that ends
//!    restarts at once on the task the curriculum picks;
//! 3. advantages by GAE(γ, λ), bootstrapped from the critic after the last step; the end of an
//!    episode (success, failure or time-out, all of which the reward pays for) cuts the
//!    bootstrap; returns = advantages + values;
//! 4. the curriculum learns: each episode's outcome (manual stages) and the mean |advantage| of
//!    each task's stretch of the rollout (prioritised replay);
//! 5. `epochs` passes over the rollout in shuffled minibatches: advantages normalised per
//!    minibatch, clipped surrogate objective, squared-error value loss, entropy bonus, the
//!    gradient clipped to a global norm, one Adam step per minibatch.
//!
//! Deterministic for a seed and thread count: environments step in parallel but every random
//! draw (action noise, tasks, minibatch order) happens on the calling thread in a fixed order.

use crate::inputs::{INPUT_DIM, policy_input};
use crate::policy::{ACTION_DIM, LOG_STD};
use crate::train::curriculum::{TaskMeta, TaskSampler};
use burn::module::{Module, ModuleVisitor, Param};
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Tensor, TensorData};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::time::Instant;
use verti_bench::episode::Outcome;
use verti_core::Rng;
use verti_env::{EnvCore, EnvError, ObsBuf, StepReport};
use verti_nn::train::seq::{Act, SeqNet, mlp_layers, values};
use verti_nn::{LayerSpec, Mlp, ModelCard, Network, Shape};

/// PPO settings. Defaults follow the reference's stored hyper-parameters (spec §6.4: γ 0.99,
/// λ 0.95, clip 0.2, no entropy bonus, value weight 0.5, gradient norm 0.5, Adam 5e-4) with a
/// rollout of 16 x 256 steps, 5 epochs in minibatches of 1024 (the reference: 15 x 400, 10
/// epochs in batches of 200). verti's simulator makes fresh data cheaper than reuse: with 10
/// epochs of 512, learning took 70 % of an update; with 5 of 1024, under half.
#[derive(Clone, Debug, PartialEq)]
pub struct PpoConfig {
    pub envs: usize,
    /// Control steps per environment per update.
    pub steps: usize,
    pub epochs: usize,
    pub minibatch: usize,
    pub gamma: f64,
    pub lambda: f64,
    pub clip: f64,
    pub ent_coef: f64,
    pub vf_coef: f64,
    pub max_grad_norm: f64,
    pub lr: f64,
    /// Hidden widths of actor and critic (tanh).
    pub hidden: Vec<usize>,
    pub init_log_std: f64,
    /// Rewards are multiplied by this before learning (the reference reward pays 3000 for a
    /// success: unscaled, value targets in the thousands slow the critic down).
    pub reward_scale: f64,
    pub seed: u64,
    /// Threads stepping the environments.
    pub threads: usize,
}

impl Default for PpoConfig {
    fn default() -> Self {
        PpoConfig {
            envs: 16,
            steps: 256,
            epochs: 5,
            minibatch: 1024,
            gamma: 0.99,
            lambda: 0.95,
            clip: 0.2,
            ent_coef: 0.0,
            vf_coef: 0.5,
            max_grad_norm: 0.5,
            lr: 5e-4,
            hidden: vec![64, 64],
            init_log_std: -0.5,
            reward_scale: 0.01,
            seed: 0,
            threads: 2,
        }
    }
}

impl PpoConfig {
    pub fn validate(&self) -> Result<(), String> {
        if self.envs == 0 || self.steps == 0 || self.epochs == 0 || self.minibatch == 0 {
            return Err("envs, steps, epochs and minibatch must be at least 1".into());
        }
        if self.threads == 0 {
            return Err("threads must be at least 1".into());
        }
        if self.hidden.is_empty() || self.hidden.contains(&0) {
            return Err(format!("hidden widths {:?} must be positive", self.hidden));
        }
        let unit = |name: &str, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(format!("{name} = {v} must lie in [0, 1]"))
            }
        };
        unit("gamma", self.gamma)?;
        unit("lambda", self.lambda)?;
        unit("clip", self.clip)?;
        for (name, v) in [
            ("lr", self.lr),
            ("max_grad_norm", self.max_grad_norm),
            ("reward_scale", self.reward_scale),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} = {v} must be positive"));
            }
        }
        if !(self.ent_coef >= 0.0 && self.vf_coef >= 0.0 && self.init_log_std.is_finite()) {
            return Err("ent_coef and vf_coef must be >= 0, init_log_std finite".into());
        }
        Ok(())
    }

    /// Control steps per update.
    pub fn batch(&self) -> usize {
        self.envs * self.steps
    }

    /// Layers of a network from the policy's inputs to `outputs` (tanh hidden layers).
    pub fn layers(&self, outputs: usize) -> Vec<LayerSpec> {
        mlp_layers(INPUT_DIM, &self.hidden, outputs, LayerSpec::Tanh)
    }
}

/// The actor (mean action), the critic (state value) and the Gaussian's log std.
#[derive(Module, Debug)]
pub struct ActorCritic {
    pub actor: SeqNet,
    pub critic: SeqNet,
    pub log_std: Param<Tensor<1>>,
}

impl ActorCritic {
    /// Fresh networks (burn's default initialisers, from its generator as seeded by
    /// [`Trainer::new`]); the actor's last layer starts small (outputs near zero) except for a
    /// speed bias of 0.5, so the first rollouts already drive forward at half speed.
    pub fn new(cfg: &PpoConfig, device: &Device) -> Result<ActorCritic, String> {
        let actor = SeqNet::new(Shape::Flat(INPUT_DIM), &cfg.layers(ACTION_DIM), device)?;
        let critic_layers = cfg.layers(1);
        let mut params = actor.export_params();
        let last = *cfg.hidden.last().expect("validated");
        let n = params.len();
        let (w, b) = params[n - last * ACTION_DIM - ACTION_DIM..].split_at_mut(last * ACTION_DIM);
        w.iter_mut().for_each(|x| *x *= 0.01);
        b.copy_from_slice(&[0.5, 0.0]);
        let actor = actor.import_params(&params, device)?;
        let critic = SeqNet::new(Shape::Flat(INPUT_DIM), &critic_layers, device)?;
        let log_std = Param::from_tensor(Tensor::from_data(
            TensorData::new(vec![cfg.init_log_std as f32; ACTION_DIM], [ACTION_DIM]),
            device,
        ));
        Ok(ActorCritic {
            actor,
            critic,
            log_std,
        })
    }

    /// Log-probabilities of `actions` [B, 2] under the policy at `obs` [B, D], and the
    /// entropy of the Gaussian (the same for every state).
    pub fn log_prob(&self, obs: Tensor<2>, actions: Tensor<2>) -> (Tensor<1>, Tensor<1>) {
        let mean = self.actor.forward(Act::Flat(obs)).flat();
        let [b, _] = mean.dims();
        let log_std = self.log_std.val();
        let ls = log_std.clone().unsqueeze_dim::<2>(0).repeat_dim(0, b);
        let z = (actions - mean) / ls.clone().exp();
        let half_log_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
        let logp = (z.powi_scalar(2) * (-0.5) - ls - half_log_2pi)
            .sum_dim(1)
            .reshape([b]);
        let entropy = (log_std + (0.5 + half_log_2pi)).sum();
        (logp, entropy)
    }

    fn values(&self, obs: Tensor<2>) -> Tensor<1> {
        let v = self.critic.forward(Act::Flat(obs)).flat();
        let [b, _] = v.dims();
        v.reshape([b])
    }
}

/// Sums the squares of every parameter's gradient.
struct GradNorm<'a> {
    grads: &'a GradientsParams,
    sum: f64,
}

impl ModuleVisitor for GradNorm<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if let Some(g) = self.grads.get::<D>(param.id) {
            self.sum += f64::from(values(g.powi_scalar(2).sum())[0]);
        }
    }
}

/// Multiplies every parameter's gradient by a factor.
struct GradScale<'a> {
    grads: &'a mut GradientsParams,
    factor: f32,
}

impl ModuleVisitor for GradScale<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if let Some(g) = self.grads.remove::<D>(param.id) {
            self.grads.register(param.id, g * self.factor);
        }
    }
}

/// Clips the gradient of the whole module to a global L2 norm (as PyTorch's
/// `clip_grad_norm_`; burn's own clipping is per parameter tensor). Returns the norm before.
fn clip_global_norm(module: &ActorCritic, grads: &mut GradientsParams, max_norm: f64) -> f64 {
    let mut norm = GradNorm { grads, sum: 0.0 };
    module.visit(&mut norm);
    let total = norm.sum.sqrt();
    if total > max_norm {
        let mut scale = GradScale {
            grads,
            factor: (max_norm / (total + 1e-6)) as f32,
        };
        module.visit(&mut scale);
    }
    total
}

/// A network of the module as a verti-nn network, for rollouts, evaluation and files.
pub fn export(net: &SeqNet, name: &str, constants: BTreeMap<String, Vec<f64>>) -> Network {
    let card = ModelCard {
        constants,
        ..ModelCard::new(name, net.input_shape(), net.layers().to_vec())
    };
    Network::from_params(card, &net.export_params()).expect("a module's own layers are valid")
}

/// How one finished training episode went.
#[derive(Clone, Debug, PartialEq)]
pub struct EpisodeEnd {
    pub task: usize,
    pub outcome: Outcome,
    /// Unscaled return.
    pub ret: f64,
    pub steps: u64,
}

/// What one update did.
#[derive(Clone, Debug, PartialEq)]
pub struct UpdateStats {
    pub update: u64,
    /// Environment (control) steps so far.
    pub env_steps: u64,
    pub episodes: Vec<EpisodeEnd>,
    pub policy_loss: f64,
    pub value_loss: f64,
    pub entropy: f64,
    pub approx_kl: f64,
    pub clip_fraction: f64,
    /// 1 − Var(returns − values)/Var(returns) over the rollout.
    pub explained_variance: f64,
    pub grad_norm: f64,
    pub collect_s: f64,
    pub learn_s: f64,
    pub log_std: [f64; ACTION_DIM],
}

/// Rollout storage, one row per (step, environment).
struct Rollout {
    obs: Vec<f32>,
    actions: Vec<f32>,
    logp: Vec<f32>,
    values: Vec<f32>,
    rewards: Vec<f32>,
    /// The episode ended with this step.
    dones: Vec<bool>,
    /// The task of the row's episode.
    tasks: Vec<usize>,
}

/// PPO with its environments, curriculum and optimiser.
pub struct Trainer {
    pub cfg: PpoConfig,
    pub model: ActorCritic,
    optim: ModuleOptimizer,
    device: Device,
    envs: Vec<EnvCore>,
    obs: Vec<ObsBuf>,
    /// Task index (into `tasks`) of each environment's episode, its return and length.
    running: Vec<(usize, f64, u64)>,
    pub tasks: Vec<TaskMeta>,
    pub sampler: Box<dyn TaskSampler>,
    rng: Rng,
    pool: rayon::ThreadPool,
    pub updates: u64,
    pub env_steps: u64,
}

impl Trainer {
    /// `template` defines worlds, vehicle and settings (its task pool is not used: episodes
    /// start on `tasks` as the sampler picks them).
    pub fn new(
        cfg: PpoConfig,
        template: &EnvCore,
        tasks: Vec<TaskMeta>,
        sampler: Box<dyn TaskSampler>,
        device: &Device,
    ) -> Result<Trainer, String> {
        cfg.validate()?;
        if tasks.is_empty() {
            return Err("no training tasks".into());
        }
        // burn draws initial weights from one process-wide generator: seeded here, so a run
        // is reproducible as long as nothing else in the process draws from it meanwhile
        device.seed(cfg.seed);
        let model = ActorCritic::new(&cfg, device)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(cfg.threads)
            .build()
            .map_err(|e| format!("cannot start {} threads: {e}", cfg.threads))?;
        let mut t = Trainer {
            optim: AdamConfig::new().with_epsilon(1e-5).init(),
            envs: (0..cfg.envs).map(|i| template.sibling(i as u64)).collect(),
            obs: vec![ObsBuf::default(); cfg.envs],
            running: vec![(0, 0.0, 0); cfg.envs],
            rng: Rng::derive(cfg.seed, "ppo-start", 0),
            device: device.clone(),
            cfg,
            model,
            tasks,
            sampler,
            pool,
            updates: 0,
            env_steps: 0,
        };
        let all: Vec<usize> = (0..t.envs.len()).collect();
        t.restart(&all)?;
        Ok(t)
    }

    /// Starts new episodes in the given environments on tasks the curriculum picks, and
    /// observes every environment.
    fn restart(&mut self, which: &[usize]) -> Result<(), String> {
        let mut next: Vec<Option<u32>> = vec![None; self.envs.len()];
        for &i in which {
            let task = self.sampler.next_task(&mut self.rng);
            self.running[i] = (task, 0.0, 0);
            next[i] = Some(self.tasks[task].number);
        }
        let (envs, obs) = (&mut self.envs, &mut self.obs);
        self.pool
            .install(|| {
                envs.par_iter_mut()
                    .zip(obs.par_iter_mut())
                    .zip(next.par_iter())
                    .try_for_each(|((env, buf), task)| {
                        if let Some(n) = task {
                            env.reset(None, Some(*n))?;
                        }
                        env.observe(buf)
                    })
            })
            .map_err(|e: EnvError| e.to_string())
    }

    /// The actor as a policy network (constants: the Gaussian's log std).
    pub fn actor_network(&self, name: &str) -> Network {
        let log_std = values(self.model.log_std.val());
        let constants = BTreeMap::from([(
            LOG_STD.to_string(),
            log_std.iter().map(|v| f64::from(*v)).collect(),
        )]);
        export(&self.model.actor, name, constants)
    }

    pub fn critic_network(&self, name: &str) -> Network {
        export(&self.model.critic, name, BTreeMap::new())
    }

    /// Continues from a checkpoint: actor and critic parameters, the update and step
    /// counters, and what the curriculum learned; episodes restart on tasks the restored
    /// curriculum picks. Adam's moment estimates are not checkpointed: they restart (they
    /// re-converge within a few dozen minibatches).
    pub fn resume(
        &mut self,
        actor: &Network,
        critic: &Network,
        (updates, env_steps): (u64, u64),
        sampler_state: &[f64],
    ) -> Result<(), String> {
        self.load(actor, critic)?;
        self.sampler.restore(sampler_state)?;
        self.updates = updates;
        self.env_steps = env_steps;
        self.rng = Rng::derive(self.cfg.seed, "ppo-resume", updates);
        let all: Vec<usize> = (0..self.envs.len()).collect();
        self.restart(&all)
    }

    /// Loads actor and critic parameters; Adam starts afresh.
    pub fn load(&mut self, actor: &Network, critic: &Network) -> Result<(), String> {
        let m = self.model.clone();
        let log_std = actor
            .card()
            .constants
            .get(LOG_STD)
            .ok_or("checkpoint actor has no log_std constant")?;
        self.model = ActorCritic {
            actor: m.actor.import_params(actor.params(), &self.device)?,
            critic: m.critic.import_params(critic.params(), &self.device)?,
            log_std: Param::from_tensor(Tensor::from_data(
                TensorData::new(
                    log_std.iter().map(|v| *v as f32).collect::<Vec<_>>(),
                    [ACTION_DIM],
                ),
                &self.device,
            )),
        };
        self.optim = AdamConfig::new().with_epsilon(1e-5).init();
        Ok(())
    }

    /// The policy input of environment `i`'s current observation.
    fn input_of(&self, i: usize, x: &mut Vec<f32>) {
        let env = &self.envs[i];
        let scale = env
            .episode()
            .map_or(1.0, |e| env.worlds()[e.world].meta.scale);
        policy_input(&self.obs[i], scale, x);
    }

    /// 2. collect a rollout with the current policy.
    fn collect(&mut self, actor: &Mlp, critic: &Mlp) -> Result<(Rollout, Vec<EpisodeEnd>), String> {
        let (n, t_max) = (self.envs.len(), self.cfg.steps);
        let rows = n * t_max;
        let mut r = Rollout {
            obs: Vec::with_capacity(rows * INPUT_DIM),
            actions: Vec::with_capacity(rows * ACTION_DIM),
            logp: Vec::with_capacity(rows),
            values: Vec::with_capacity(rows),
            rewards: Vec::with_capacity(rows),
            dones: Vec::with_capacity(rows),
            tasks: Vec::with_capacity(rows),
        };
        let log_std: Vec<f32> = values(self.model.log_std.val());
        let std: Vec<f32> = log_std.iter().map(|l| l.exp()).collect();
        let log_norm: f32 = log_std.iter().sum::<f32>()
            + ACTION_DIM as f32 * 0.5 * (2.0 * std::f32::consts::PI).ln();
        let (mut sa, mut sc) = (actor.scratch(), critic.scratch());
        let mut x = Vec::with_capacity(INPUT_DIM);
        let mut ended = Vec::new();
        let mut env_actions = vec![[0.0f64; ACTION_DIM]; n];
        let mut reports = vec![StepReport::idle(); n];
        for _ in 0..t_max {
            for (i, env_action) in env_actions.iter_mut().enumerate() {
                self.input_of(i, &mut x);
                let mut mean = [0.0f32; ACTION_DIM];
                let mut v = [0.0f32];
                actor.forward_into(&x, &mut sa, &mut mean);
                critic.forward_into(&x, &mut sc, &mut v);
                let mut sq = 0.0f32;
                for k in 0..ACTION_DIM {
                    let z = self.rng.normal() as f32;
                    let a = mean[k] + std[k] * z;
                    sq += z * z;
                    r.actions.push(a);
                    env_action[k] = f64::from(a);
                }
                r.obs.extend_from_slice(&x);
                r.logp.push(-0.5 * sq - log_norm);
                r.values.push(v[0]);
                r.tasks.push(self.running[i].0);
            }
            let envs = &mut self.envs;
            let acts = &env_actions;
            self.pool
                .install(|| {
                    envs.par_iter_mut()
                        .zip(reports.par_iter_mut())
                        .zip(acts.par_iter())
                        .try_for_each(|((env, rep), a)| {
                            let action = env.action_from_normalized(a)?;
                            *rep = env.step(action)?;
                            Ok(())
                        })
                })
                .map_err(|e: EnvError| e.to_string())?;
            let mut done_now = Vec::new();
            for (i, rep) in reports.iter().enumerate() {
                r.rewards.push((rep.reward * self.cfg.reward_scale) as f32);
                let run = &mut self.running[i];
                run.1 += rep.reward;
                run.2 += 1;
                let done = rep.terminated || rep.truncated;
                r.dones.push(done);
                if done {
                    let outcome = rep.outcome.unwrap_or(Outcome::Error);
                    self.sampler.episode_end(run.0, outcome == Outcome::Success);
                    ended.push(EpisodeEnd {
                        task: run.0,
                        outcome,
                        ret: run.1,
                        steps: run.2,
                    });
                    done_now.push(i);
                }
            }
            self.restart(&done_now)?;
        }
        Ok((r, ended))
    }

    /// One PPO update (collect, advantages, curriculum, learn).
    pub fn update(&mut self) -> Result<UpdateStats, String> {
        let cfg = self.cfg.clone();
        let (n, t_max) = (cfg.envs, cfg.steps);
        // every update draws from its own stream, so a resumed run draws what an
        // uninterrupted one would have
        self.rng = Rng::derive(cfg.seed, "ppo-update", self.updates);
        // 1. the current networks as fast MLPs
        let actor = Mlp::from_network(&self.actor_network("actor"))?;
        let critic = Mlp::from_network(&self.critic_network("critic"))?;
        // 2. rollout
        let started = Instant::now();
        let (ro, episodes) = self.collect(&actor, &critic)?;
        let collect_s = started.elapsed().as_secs_f64();
        let learn_started = Instant::now();
        // 3. GAE, bootstrapped from the value of each environment's current observation
        let mut last_values = vec![0.0f32; n];
        let mut sc = critic.scratch();
        let mut x = Vec::new();
        for (i, lv) in last_values.iter_mut().enumerate() {
            self.input_of(i, &mut x);
            let mut v = [0.0f32];
            critic.forward_into(&x, &mut sc, &mut v);
            *lv = v[0];
        }
        let rows = n * t_max;
        let mut adv = vec![0.0f32; rows];
        let (g, l) = (cfg.gamma as f32, cfg.lambda as f32);
        for (i, &last) in last_values.iter().enumerate() {
            let mut next_adv = 0.0f32;
            let mut next_value = last;
            for t in (0..t_max).rev() {
                let k = t * n + i;
                let live = if ro.dones[k] { 0.0 } else { 1.0 };
                let delta = ro.rewards[k] + g * next_value * live - ro.values[k];
                next_adv = delta + g * l * live * next_adv;
                adv[k] = next_adv;
                next_value = ro.values[k];
            }
        }
        let returns: Vec<f32> = adv.iter().zip(&ro.values).map(|(a, v)| a + v).collect();
        // 4. curriculum: mean |advantage| of each environment's stretch on one task
        for i in 0..n {
            let (mut sum, mut count) = (0.0f64, 0usize);
            for t in 0..t_max {
                let k = t * n + i;
                sum += f64::from(adv[k].abs());
                count += 1;
                let last = t + 1 == t_max;
                if ro.dones[k] || last {
                    self.sampler.score(ro.tasks[k], sum / count as f64);
                    (sum, count) = (0.0, 0);
                }
            }
        }
        // 5. epochs of minibatch updates
        let mut order: Vec<usize> = (0..rows).collect();
        let (mut pl, mut vl, mut ent, mut kl, mut cf, mut gn, mut batches) =
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0usize);
        let dev = self.device.clone();
        let take = |data: &[f32], dim: usize, idx: &[usize]| -> Tensor<2> {
            let mut v = Vec::with_capacity(idx.len() * dim);
            for &k in idx {
                v.extend_from_slice(&data[k * dim..(k + 1) * dim]);
            }
            Tensor::from_data(TensorData::new(v, [idx.len(), dim]), &dev)
        };
        let take1 = |data: &[f32], idx: &[usize]| -> Tensor<1> {
            let v: Vec<f32> = idx.iter().map(|&k| data[k]).collect();
            Tensor::from_data(TensorData::new(v, [idx.len()]), &dev)
        };
        for _ in 0..cfg.epochs {
            self.rng.shuffle(&mut order);
            for idx in order.chunks(cfg.minibatch) {
                let obs = take(&ro.obs, INPUT_DIM, idx);
                let actions = take(&ro.actions, ACTION_DIM, idx);
                let old_logp = take1(&ro.logp, idx);
                let ret = take1(&returns, idx);
                // advantages normalised within the minibatch
                let a: Vec<f32> = idx.iter().map(|&k| adv[k]).collect();
                let m = a.iter().sum::<f32>() / a.len() as f32;
                let s = (a.iter().map(|v| (v - m).powi(2)).sum::<f32>() / a.len() as f32).sqrt();
                let a: Vec<f32> = a.iter().map(|v| (v - m) / (s + 1e-8)).collect();
                let a = Tensor::from_data(TensorData::new(a, [idx.len()]), &dev);

                let (logp, entropy) = self.model.log_prob(obs.clone(), actions);
                let log_ratio = logp - old_logp;
                let ratio = log_ratio.clone().exp();
                let surrogate = (a.clone() * ratio.clone()).min_pair(
                    a * ratio
                        .clone()
                        .clamp(1.0 - cfg.clip as f32, 1.0 + cfg.clip as f32),
                );
                let policy_loss = surrogate.mean().neg();
                let value_loss = (self.model.values(obs) - ret).powi_scalar(2).mean() * 0.5;
                let loss = policy_loss.clone() + value_loss.clone() * cfg.vf_coef
                    - entropy.clone() * cfg.ent_coef;

                let mut grads = GradientsParams::from_grads(loss.backward(), &self.model);
                gn += clip_global_norm(&self.model, &mut grads, cfg.max_grad_norm);
                self.model = self.optim.step(cfg.lr, self.model.clone(), grads);

                // diagnostics
                let r = values(ratio);
                let lr = values(log_ratio);
                kl += r
                    .iter()
                    .zip(&lr)
                    .map(|(r, l)| f64::from((r - 1.0) - l))
                    .sum::<f64>()
                    / r.len() as f64;
                cf += r
                    .iter()
                    .filter(|v| (**v - 1.0).abs() > cfg.clip as f32)
                    .count() as f64
                    / r.len() as f64;
                pl += f64::from(values(policy_loss)[0]);
                vl += f64::from(values(value_loss)[0]);
                ent += f64::from(values(entropy)[0]);
                batches += 1;
            }
        }
        let var = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64
        };
        let resid: Vec<f64> = returns
            .iter()
            .zip(&ro.values)
            .map(|(r, v)| f64::from(r - v))
            .collect();
        let rets: Vec<f64> = returns.iter().map(|r| f64::from(*r)).collect();
        let var_ret = var(&rets);
        let explained_variance = if var_ret > 0.0 {
            1.0 - var(&resid) / var_ret
        } else {
            0.0
        };
        self.updates += 1;
        self.env_steps += rows as u64;
        let b = batches.max(1) as f64;
        let ls = values(self.model.log_std.val());
        Ok(UpdateStats {
            update: self.updates,
            env_steps: self.env_steps,
            episodes,
            policy_loss: pl / b,
            value_loss: vl / b,
            entropy: ent / b,
            approx_kl: kl / b,
            clip_fraction: cf / b,
            explained_variance,
            grad_norm: gn / b,
            collect_s,
            learn_s: learn_started.elapsed().as_secs_f64(),
            log_std: [f64::from(ls[0]), f64::from(ls[1])],
        })
    }
}
