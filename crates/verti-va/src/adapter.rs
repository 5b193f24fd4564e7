//! Online adaptation of VertiAdaptor's coefficients while driving (paper §III-D-2, §V-C):
//!
//! * `none`: the prior coefficients (the least-squares fit on all training data);
//! * `once` (VA*): one least-squares solve on data from the task's world gathered before the
//!   task (see [`crate::system`]);
//! * `every` (VA†): every `period` seconds, a least-squares solve on the last `window` seconds
//!   of the trial's own driving;
//! * `rls` (beyond the paper, its stated future work): recursive least squares over the
//!   trial's own driving, one update per model step, forgetting factor μ per step.
//!
//! Each model step of driving (the pose, command and terrain at t, the pose at t + dt)
//! becomes one example; its basis changes are computed once, when it arrives (one model
//! evaluation), so a solve is only the k × k normal equations of the window and a Cholesky
//! factorisation.

use crate::lsq::{NormalEquations, Rls};
use crate::model::{EMBED, POSE_DIM, VaModel};
use std::collections::VecDeque;
use std::sync::Arc;
use verti_bench::observation::Pose6;
use verti_kino::features::{Units, heading_delta};

/// How the coefficients follow the terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AdaptMode {
    None,
    Once,
    Every { period: f64, window: f64 },
    Rls { forgetting: f64 },
}

impl AdaptMode {
    pub fn name(&self) -> &'static str {
        match self {
            AdaptMode::None => "none",
            AdaptMode::Once => "once",
            AdaptMode::Every { .. } => "every",
            AdaptMode::Rls { .. } => "rls",
        }
    }
}

/// The state observed at one model step, waiting for the next pose to become an example.
#[derive(Clone, Debug)]
struct Pending {
    time: f64,
    pose: Pose6,
    embedding: [f32; 2 * EMBED],
    command: (f64, f64),
}

/// Coefficients and the driving data behind them.
pub struct Adapter {
    model: Arc<VaModel>,
    mode: AdaptMode,
    alpha: Vec<f64>,
    units: Units,
    pending: Option<Pending>,
    /// (time, basis changes k × 6, true change) of recent examples (`every`).
    window: VecDeque<(f64, Vec<f64>, [f64; POSE_DIM])>,
    rls: Option<Rls>,
    last_solve: f64,
    /// Examples taken in, and solves made, this trial.
    pub examples: usize,
    pub solves: usize,
}

impl Adapter {
    pub fn new(model: Arc<VaModel>, mode: AdaptMode) -> Adapter {
        let alpha = model.card.alpha_prior.clone();
        Adapter {
            model,
            mode,
            alpha,
            units: Units::new(1.0),
            pending: None,
            window: VecDeque::new(),
            rls: None,
            last_solve: 0.0,
            examples: 0,
            solves: 0,
        }
    }

    pub fn model(&self) -> &Arc<VaModel> {
        &self.model
    }
    pub fn mode(&self) -> AdaptMode {
        self.mode
    }
    pub fn alpha(&self) -> &[f64] {
        &self.alpha
    }
    /// Full-scale model step in world seconds.
    pub fn dt_world(&self) -> f64 {
        self.model.card.dt / self.units.time_factor()
    }

    /// Starts a trial on a world of length scale `scale`, from the prior coefficients.
    pub fn reset(&mut self, scale: f64) {
        self.units = Units::new(scale);
        self.alpha = self.model.card.alpha_prior.clone();
        self.pending = None;
        self.window.clear();
        self.last_solve = 0.0;
        self.examples = 0;
        self.solves = 0;
        self.rls = self.fresh_rls();
    }

    /// A recursive least-squares state starting from the current coefficients (`rls` only):
    /// they count like ten seconds of data (100 model steps).
    fn fresh_rls(&self) -> Option<Rls> {
        match self.mode {
            AdaptMode::Rls { forgetting } => {
                let information = 100.0 * self.model.card.lambda.max(1e-6);
                Some(Rls::new(
                    self.alpha.clone(),
                    POSE_DIM,
                    information,
                    forgetting,
                ))
            }
            _ => None,
        }
    }

    /// Sets the coefficients outright (`once`: the solve on pre-task data).
    /// Recursive least squares then continues from them.
    pub fn set_alpha(&mut self, alpha: Vec<f64>) {
        debug_assert_eq!(alpha.len(), self.alpha.len());
        self.alpha = alpha;
        self.rls = self.fresh_rls();
        self.solves += 1;
    }

    /// Takes in the vehicle's state at `time` (world seconds) with the command it holds until
    /// the next model step; `embedding` computes the terrain embedding under a pose (called
    /// only when the state is kept). States closer than one model step to the last kept one
    /// are ignored, so any control rate that divides the model step works.
    pub fn observe(
        &mut self,
        time: f64,
        pose: Pose6,
        command_world: (f64, f64),
        embedding: &mut dyn FnMut(&Pose6) -> [f32; 2 * EMBED],
    ) {
        if matches!(self.mode, AdaptMode::None | AdaptMode::Once) {
            return;
        }
        let dt = self.dt_world();
        if let Some(p) = &self.pending {
            let elapsed = time - p.time;
            if elapsed < dt - 1e-6 {
                return;
            }
            if elapsed < dt + 1e-6 {
                let delta = self.units.delta_to_model(&heading_delta(&p.pose, &pose));
                let mut phi = vec![0.0; self.model.card.bases * POSE_DIM];
                self.model.basis_changes(
                    p.pose.roll,
                    p.pose.pitch,
                    &p.embedding,
                    p.command,
                    &mut phi,
                );
                self.take_example(time, phi, delta);
            }
        }
        self.pending = Some(Pending {
            time,
            pose,
            embedding: embedding(&pose),
            command: (command_world.0 / self.units.scale.sqrt(), command_world.1),
        });
    }

    fn take_example(&mut self, time: f64, phi: Vec<f64>, delta: [f64; POSE_DIM]) {
        self.examples += 1;
        match self.mode {
            AdaptMode::Rls { .. } => {
                let rls = self.rls.as_mut().expect("reset made the RLS state");
                rls.update(&phi, &delta);
                self.alpha = rls.alpha().to_vec();
                self.solves += 1;
            }
            AdaptMode::Every { period, window } => {
                self.window.push_back((time, phi, delta));
                while self
                    .window
                    .front()
                    .is_some_and(|(t, _, _)| *t < time - window - 1e-9)
                {
                    self.window.pop_front();
                }
                if time - self.last_solve >= period - 1e-9 {
                    let mut ne = NormalEquations::new(self.model.card.bases, POSE_DIM);
                    for (_, phi, y) in &self.window {
                        ne.add(phi, y);
                    }
                    // a singular window (the vehicle stood still) keeps the old coefficients
                    if let Ok(a) = ne.solve(self.model.card.lambda) {
                        self.alpha = a;
                        self.solves += 1;
                    }
                    self.last_solve = time;
                }
            }
            AdaptMode::None | AdaptMode::Once => {}
        }
    }
}
