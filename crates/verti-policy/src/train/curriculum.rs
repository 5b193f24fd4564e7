//! Which task a training episode drives: the three curricula of the RL family.
//!
//! * [`Uniform`] (`rl`): every training task equally often.
//! * [`Manual`] (`mcl`): hand-made stages over elevation level, terrain type and obstacle
//!   density; the next stage opens when the success rate of the last [`Manual::window`]
//!   episodes of the current stage reaches [`Manual::threshold`].
//! * [`Prioritised`] (`acl`): prioritised level replay (Jiang et al., 2021), the mechanism of
//!   Verti-Selector: each task keeps the mean absolute TD error (GAE advantage) of its last
//!   episode as a score; a new episode either tries an unseen task or replays a seen one with
//!   probability mixed from score ranks and staleness.
//!
//! Samplers work on indices into a task list ([`TaskMeta`]) and draw from the caller's
//! random stream, so training stays deterministic.

use verti_core::Rng;
use verti_world::{ElevationLevel, ObstacleDensity, TerrainType};

/// A training task with what the curricula sort by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaskMeta {
    /// Global task number (as `verti eval --tasks`).
    pub number: u32,
    pub level: ElevationLevel,
    pub density: ObstacleDensity,
    pub terrain: TerrainType,
}

/// Chooses training tasks and learns from how episodes went.
pub trait TaskSampler: Send {
    /// Index of the task of the next episode.
    fn next_task(&mut self, rng: &mut Rng) -> usize;
    /// An episode on `task` ended (successfully or not).
    fn episode_end(&mut self, _task: usize, _success: bool) {}
    /// The learning signal of a stretch of `task`'s episode (mean |advantage|).
    fn score(&mut self, _task: usize, _score: f64) {}
    /// A short description of the current state (stage, tasks seen) for logs.
    fn status(&self) -> String;
    /// What the sampler has learned, as numbers (for checkpoints).
    fn state(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Restores what [`TaskSampler::state`] saved.
    fn restore(&mut self, state: &[f64]) -> Result<(), String> {
        if state.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "expected no sampler state, got {} numbers",
                state.len()
            ))
        }
    }
}

/// Every task with equal probability.
pub struct Uniform {
    tasks: usize,
}

impl Uniform {
    pub fn new(tasks: usize) -> Uniform {
        assert!(tasks > 0, "a curriculum needs at least one task");
        Uniform { tasks }
    }
}

impl TaskSampler for Uniform {
    fn next_task(&mut self, rng: &mut Rng) -> usize {
        rng.below(self.tasks as u64) as usize
    }
    fn status(&self) -> String {
        format!("uniform over {} tasks", self.tasks)
    }
}

/// One stage of the manual curriculum: which tasks it admits.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    pub name: &'static str,
    pub levels: Vec<ElevationLevel>,
    pub terrains: Vec<TerrainType>,
    pub densities: Vec<ObstacleDensity>,
}

impl Stage {
    fn admits(&self, t: &TaskMeta) -> bool {
        self.levels.contains(&t.level)
            && self.terrains.contains(&t.terrain)
            && self.densities.contains(&t.density)
    }
}

/// The manual curriculum's stages: gentle rigid ground first, then mid elevation and soft
/// ground, then everything.
pub fn default_stages() -> Vec<Stage> {
    use ElevationLevel::*;
    use ObstacleDensity::*;
    use TerrainType::*;
    vec![
        Stage {
            name: "low elevation, rigid ground, sparse or medium obstacles",
            levels: vec![Low],
            terrains: vec![Rigid],
            densities: vec![Sparse, Medium],
        },
        Stage {
            name: "low and mid elevation, every ground and density",
            levels: vec![Low, Mid],
            terrains: TerrainType::ALL.to_vec(),
            densities: ObstacleDensity::ALL.to_vec(),
        },
        Stage {
            name: "every task",
            levels: vec![Low, Mid, High],
            terrains: TerrainType::ALL.to_vec(),
            densities: ObstacleDensity::ALL.to_vec(),
        },
    ]
}

/// Stages promoted on a success threshold.
pub struct Manual {
    /// Task indices of each non-empty stage, with its name.
    stages: Vec<(&'static str, Vec<usize>)>,
    current: usize,
    /// Outcomes of the current stage's recent episodes (true = success).
    recent: Vec<bool>,
    pub window: usize,
    pub threshold: f64,
    /// Episodes ended when each later stage opened.
    pub promotions: Vec<u64>,
    episodes: u64,
}

impl Manual {
    pub fn new(tasks: &[TaskMeta], stages: &[Stage], window: usize, threshold: f64) -> Manual {
        let stages: Vec<(&'static str, Vec<usize>)> = stages
            .iter()
            .map(|s| {
                let idx = (0..tasks.len()).filter(|&i| s.admits(&tasks[i])).collect();
                (s.name, idx)
            })
            .filter(|(_, idx): &(&str, Vec<usize>)| !idx.is_empty())
            .collect();
        assert!(!stages.is_empty(), "no stage admits any training task");
        Manual {
            stages,
            current: 0,
            recent: Vec::new(),
            window: window.max(1),
            threshold,
            promotions: Vec::new(),
            episodes: 0,
        }
    }

    pub fn stage(&self) -> usize {
        self.current
    }

    pub fn stage_tasks(&self, stage: usize) -> &[usize] {
        &self.stages[stage].1
    }
}

impl TaskSampler for Manual {
    fn next_task(&mut self, rng: &mut Rng) -> usize {
        let idx = &self.stages[self.current].1;
        idx[rng.below(idx.len() as u64) as usize]
    }

    fn episode_end(&mut self, task: usize, success: bool) {
        self.episodes += 1;
        // an episode started before a promotion does not count toward the new stage
        if !self.stages[self.current].1.contains(&task) {
            return;
        }
        self.recent.push(success);
        if self.recent.len() > self.window {
            self.recent.remove(0);
        }
        let rate = self.recent.iter().filter(|s| **s).count() as f64 / self.window as f64;
        if self.recent.len() == self.window
            && rate >= self.threshold
            && self.current + 1 < self.stages.len()
        {
            self.current += 1;
            self.recent.clear();
            self.promotions.push(self.episodes);
        }
    }

    /// [stage, episodes, recent outcomes (n, then 0/1 each), promotions...]
    fn state(&self) -> Vec<f64> {
        let mut v = vec![
            self.current as f64,
            self.episodes as f64,
            self.recent.len() as f64,
        ];
        v.extend(self.recent.iter().map(|s| f64::from(u8::from(*s))));
        v.extend(self.promotions.iter().map(|p| *p as f64));
        v
    }

    fn restore(&mut self, state: &[f64]) -> Result<(), String> {
        let bad = || format!("manual curriculum state {state:?} is not one this sampler saved");
        if state.len() < 3 {
            return Err(bad());
        }
        let (current, episodes, n) = (state[0] as usize, state[1] as u64, state[2] as usize);
        if current >= self.stages.len() || state.len() < 3 + n {
            return Err(bad());
        }
        self.current = current;
        self.episodes = episodes;
        self.recent = state[3..3 + n].iter().map(|v| *v > 0.5).collect();
        self.promotions = state[3 + n..].iter().map(|v| *v as u64).collect();
        Ok(())
    }

    fn status(&self) -> String {
        let rate = if self.recent.is_empty() {
            0.0
        } else {
            self.recent.iter().filter(|s| **s).count() as f64 / self.recent.len() as f64
        };
        format!(
            "stage {}/{} ({}), recent success {:.0} %",
            self.current + 1,
            self.stages.len(),
            self.stages[self.current].0,
            100.0 * rate
        )
    }
}

/// Prioritised level replay over tasks.
pub struct Prioritised {
    /// Latest score of each task (None = never scored).
    scores: Vec<Option<f64>>,
    /// Episode counter when each task was last chosen.
    last_chosen: Vec<u64>,
    chosen: u64,
    /// Chance of replaying a seen task rather than trying an unseen one.
    pub replay: f64,
    /// Temperature of the rank prioritisation (smaller = greedier).
    pub beta: f64,
    /// Weight of staleness in the replay distribution.
    pub staleness: f64,
}

impl Prioritised {
    /// PLR's defaults: replay half the time, β = 0.1, staleness weight 0.1.
    pub fn new(tasks: usize) -> Prioritised {
        assert!(tasks > 0, "a curriculum needs at least one task");
        Prioritised {
            scores: vec![None; tasks],
            last_chosen: vec![0; tasks],
            chosen: 0,
            replay: 0.5,
            beta: 0.1,
            staleness: 0.1,
        }
    }

    /// The replay distribution over tasks (0 for unseen ones):
    /// (1 − ρ)·h(rank)^(1/β)/Σ + ρ·(c − C_i)/Σ, h(rank) = 1/rank, rank 1 = highest score.
    pub fn replay_distribution(&self) -> Vec<f64> {
        let seen: Vec<usize> = (0..self.scores.len())
            .filter(|&i| self.scores[i].is_some())
            .collect();
        let mut p = vec![0.0; self.scores.len()];
        if seen.is_empty() {
            return p;
        }
        let mut by_score = seen.clone();
        // highest score first; ties by index so the order is deterministic
        by_score.sort_by(|&a, &b| {
            self.scores[b]
                .partial_cmp(&self.scores[a])
                .unwrap_or(std::cmp::Ordering::Equal)
                .then(a.cmp(&b))
        });
        let mut rank_w = vec![0.0; self.scores.len()];
        for (r, &i) in by_score.iter().enumerate() {
            rank_w[i] = (1.0 / (r + 1) as f64).powf(1.0 / self.beta);
        }
        let rank_sum: f64 = rank_w.iter().sum();
        let stale: Vec<f64> = (0..self.scores.len())
            .map(|i| {
                if self.scores[i].is_some() {
                    (self.chosen - self.last_chosen[i]) as f64
                } else {
                    0.0
                }
            })
            .collect();
        let stale_sum: f64 = stale.iter().sum();
        for &i in &seen {
            let s = if stale_sum > 0.0 {
                stale[i] / stale_sum
            } else {
                1.0 / seen.len() as f64
            };
            p[i] = (1.0 - self.staleness) * rank_w[i] / rank_sum + self.staleness * s;
        }
        p
    }

    pub fn seen(&self) -> usize {
        self.scores.iter().filter(|s| s.is_some()).count()
    }
}

/// Index drawn from an unnormalised distribution.
fn draw(p: &[f64], rng: &mut Rng) -> usize {
    let total: f64 = p.iter().sum();
    let mut u = rng.uniform() * total;
    for (i, w) in p.iter().enumerate() {
        if u < *w {
            return i;
        }
        u -= w;
    }
    p.iter().rposition(|w| *w > 0.0).unwrap_or(0)
}

impl TaskSampler for Prioritised {
    fn next_task(&mut self, rng: &mut Rng) -> usize {
        let n = self.scores.len();
        let seen = self.seen();
        let replay = seen == n || (seen > 0 && rng.uniform() < self.replay);
        let task = if replay {
            draw(&self.replay_distribution(), rng)
        } else {
            let unseen: Vec<usize> = (0..n).filter(|&i| self.scores[i].is_none()).collect();
            unseen[rng.below(unseen.len() as u64) as usize]
        };
        self.chosen += 1;
        self.last_chosen[task] = self.chosen;
        task
    }

    fn score(&mut self, task: usize, score: f64) {
        if score.is_finite() {
            self.scores[task] = Some(score);
        }
    }

    fn status(&self) -> String {
        format!("{} of {} tasks seen", self.seen(), self.scores.len())
    }

    /// [episodes chosen, score per task (NaN = unseen)..., last chosen per task...]
    fn state(&self) -> Vec<f64> {
        let mut v = vec![self.chosen as f64];
        v.extend(self.scores.iter().map(|s| s.unwrap_or(f64::NAN)));
        v.extend(self.last_chosen.iter().map(|c| *c as f64));
        v
    }

    fn restore(&mut self, state: &[f64]) -> Result<(), String> {
        let n = self.scores.len();
        if state.len() != 1 + 2 * n {
            return Err(format!(
                "prioritised replay state holds {} numbers, expected {} for {n} tasks",
                state.len(),
                1 + 2 * n
            ));
        }
        self.chosen = state[0] as u64;
        self.scores = state[1..=n]
            .iter()
            .map(|s| if s.is_nan() { None } else { Some(*s) })
            .collect();
        self.last_chosen = state[1 + n..].iter().map(|c| *c as u64).collect();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tasks() -> Vec<TaskMeta> {
        let mut v = Vec::new();
        let mut n = 0;
        for level in [
            ElevationLevel::Low,
            ElevationLevel::Mid,
            ElevationLevel::High,
        ] {
            for terrain in TerrainType::ALL {
                for density in ObstacleDensity::ALL {
                    v.push(TaskMeta {
                        number: n,
                        level,
                        density,
                        terrain,
                    });
                    n += 1;
                }
            }
        }
        v
    }

    #[test]
    fn uniform_visits_every_task_equally() {
        let mut s = Uniform::new(10);
        let mut rng = Rng::new(1);
        let mut count = [0usize; 10];
        for _ in 0..50_000 {
            count[s.next_task(&mut rng)] += 1;
        }
        for c in count {
            // binomial sd = sqrt(50000 * 0.1 * 0.9) ≈ 67
            assert!((c as i64 - 5000).abs() < 300, "{count:?}");
        }
    }

    #[test]
    fn manual_stages_admit_what_they_name_and_promote_on_success() {
        let t = tasks();
        let mut m = Manual::new(&t, &default_stages(), 10, 0.6);
        assert_eq!(m.stage_tasks(0).len(), 2, "low, rigid, sparse/medium");
        assert_eq!(m.stage_tasks(1).len(), 18);
        assert_eq!(m.stage_tasks(2).len(), 27);
        let mut rng = Rng::new(2);
        for _ in 0..100 {
            let i = m.next_task(&mut rng);
            assert!(m.stage_tasks(0).contains(&i));
        }
        // 5 of 10 successes: stays; 6 of the last 10: promoted
        for k in 0..10 {
            m.episode_end(m.stage_tasks(0)[0], k >= 5);
        }
        assert_eq!(m.stage(), 0);
        m.episode_end(m.stage_tasks(0)[0], true);
        assert_eq!(m.stage(), 1, "{}", m.status());
        // stages are nested (stage 2 admits stage 1's tasks); a task outside the current
        // stage (high elevation in stage 2) does not count toward its promotion
        let high = 26;
        assert!(!m.stage_tasks(1).contains(&high));
        m.episode_end(high, true);
        for _ in 0..9 {
            m.episode_end(m.stage_tasks(1)[3], true);
        }
        assert_eq!(m.stage(), 1);
        m.episode_end(m.stage_tasks(1)[3], true);
        assert_eq!(m.stage(), 2);
        for _ in 0..20 {
            m.episode_end(m.stage_tasks(2)[0], true);
        }
        assert_eq!(m.stage(), 2, "the last stage stays");
        assert_eq!(
            m.promotions,
            vec![11, 22],
            "episodes ended at each promotion"
        );
    }

    #[test]
    fn prioritised_tries_unseen_tasks_then_replays_by_rank() {
        let mut p = Prioritised::new(4);
        p.replay = 0.0;
        let mut rng = Rng::new(3);
        // without replay, episodes go to unseen tasks while there are any
        let mut first = Vec::new();
        for _ in 0..4 {
            let i = p.next_task(&mut rng);
            assert!(!first.contains(&i), "an unseen task each time");
            first.push(i);
            p.score(i, [0.1, 0.4, 0.2, 0.3][i]);
        }
        // rank weights (1/r)^(1/0.1): task 1 (rank 1) dominates the score part
        let d = p.replay_distribution();
        assert!((d.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let rank: f64 = [1.0f64, 2.0, 3.0, 4.0].iter().map(|r| r.powf(-10.0)).sum();
        let stale_sum: f64 = (0..4).map(|i| (4 - p.last_chosen[i]) as f64).sum();
        let expect1 = 0.9 / rank + 0.1 * (4 - p.last_chosen[1]) as f64 / stale_sum;
        assert!((d[1] - expect1).abs() < 1e-12, "{d:?}");
        // sampled frequencies follow the distribution (all seen: always replay)
        let mut count = [0usize; 4];
        let n = 20_000;
        let mut q = Prioritised::new(4);
        q.staleness = 0.0;
        for (i, s) in [0.1, 0.4, 0.2, 0.3].into_iter().enumerate() {
            q.score(i, s);
        }
        let dq = q.replay_distribution();
        for _ in 0..n {
            count[q.next_task(&mut rng)] += 1;
        }
        for i in 0..4 {
            let f = count[i] as f64 / n as f64;
            assert!((f - dq[i]).abs() < 0.01, "{count:?} vs {dq:?}");
        }
    }

    #[test]
    fn sampler_state_survives_a_checkpoint() {
        let t = tasks();
        let mut rng = Rng::new(6);
        let mut m = Manual::new(&t, &default_stages(), 4, 0.5);
        let mut p = Prioritised::new(t.len());
        for k in 0..9 {
            let i = m.next_task(&mut rng);
            m.episode_end(i, k % 2 == 0);
            let j = p.next_task(&mut rng);
            p.score(j, k as f64 * 0.1);
        }
        let mut m2 = Manual::new(&t, &default_stages(), 4, 0.5);
        m2.restore(&m.state()).unwrap();
        assert_eq!((m2.stage(), m2.status()), (m.stage(), m.status()));
        assert_eq!(m2.state(), m.state());
        let mut p2 = Prioritised::new(t.len());
        p2.restore(&p.state()).unwrap();
        assert_eq!(p2.replay_distribution(), p.replay_distribution());
        let (mut r1, mut r2) = (Rng::new(8), Rng::new(8));
        for _ in 0..20 {
            assert_eq!(p.next_task(&mut r1), p2.next_task(&mut r2));
        }
        assert!(Prioritised::new(3).restore(&[1.0]).is_err());
        assert!(Uniform::new(3).restore(&[1.0]).is_err());
    }

    #[test]
    fn staleness_brings_back_neglected_tasks() {
        let mut p = Prioritised::new(3);
        p.staleness = 1.0;
        let mut rng = Rng::new(4);
        for i in 0..3 {
            p.score(i, 1.0 + i as f64);
        }
        // choose some tasks: the one never chosen since scoring grows stalest
        for _ in 0..30 {
            p.next_task(&mut rng);
        }
        let d = p.replay_distribution();
        let stalest = (0..3).min_by_key(|&i| p.last_chosen[i]).unwrap();
        let top = (0..3)
            .max_by(|&a, &b| d[a].partial_cmp(&d[b]).unwrap())
            .unwrap();
        assert_eq!(stalest, top, "{d:?}");
    }
}
