//! One trial driven a control period at a time, by a person's keys or by a system, under the
//! benchmark's rules; every step is recorded as a dataset row and a 3-D frame.

use crate::driver::{Driver, Keys};
use std::sync::Arc;
use verti_bench::{Action, EpisodeConfig, MobilitySystem, Outcome, Trial, TrialResult};
use verti_data::manifest::DataOutcome;
use verti_data::table::{Row, TrialRecord};
use verti_sim::VehicleSpec;
use verti_view::{Frame, Recording};
use verti_world::World;

/// Control rate of a person at the wheel (Hz): the datasets' row rate.
pub const HUMAN_RATE: f64 = 10.0;

/// Who drives.
enum Pilot {
    Person(Driver),
    System(Box<dyn MobilitySystem>),
}

/// A trial being driven.
pub struct DriveSession {
    trial: Trial,
    pilot: Pilot,
    period: f64,
    rows: Vec<Row>,
    recording: Recording,
}

/// What a finished session leaves: the result line, the dataset record and the recording.
pub struct SessionEnd {
    pub result: TrialResult,
    pub record: TrialRecord,
    pub recording: Recording,
}

impl DriveSession {
    /// Starts task `pair` of `world` with `spec`, driven by a person (`system` None) or by a
    /// system, under `cfg`'s rules. `who` names the driver in the results (`human`).
    pub fn start(
        world: &Arc<World>,
        spec: &VehicleSpec,
        pair: u32,
        cfg: &EpisodeConfig,
        system: Option<Box<dyn MobilitySystem>>,
    ) -> Result<DriveSession, String> {
        let who = system
            .as_ref()
            .map_or_else(|| "human".to_string(), |s| s.name().to_string());
        let trial = Trial::start(world, spec, pair, cfg, &who)?;
        let (pilot, period) = match system {
            None => (
                Pilot::Person(Driver::new(world.meta.scale)),
                1.0 / HUMAN_RATE,
            ),
            Some(mut s) => {
                s.reset(trial.info());
                let period = verti_bench::episode::control_period(s.as_ref())?;
                (Pilot::System(s), period)
            }
        };
        let mut recording = Recording::start(world, spec, pair, cfg);
        recording.frames.push(verti_view::frame(&trial));
        Ok(DriveSession {
            trial,
            pilot,
            period,
            rows: Vec::new(),
            recording,
        })
    }

    /// Seconds of simulated time per step.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.trial.time()
    }

    /// How the trial ended, once it has.
    pub fn ended(&self) -> Option<Outcome> {
        self.trial.outcome()
    }

    /// Every frame so far (the start first).
    pub fn frames(&self) -> &[Frame] {
        &self.recording.frames
    }

    /// The recording so far (the still scene and the frames).
    pub fn recording(&self) -> &Recording {
        &self.recording
    }

    /// Drives one control period holding `keys` (ignored when a system drives). Returns the
    /// outcome when the trial ends in it; does nothing once it has ended.
    pub fn step(&mut self, keys: Keys) -> Option<Outcome> {
        if let Some(o) = self.trial.outcome() {
            return Some(o);
        }
        let action = match &mut self.pilot {
            Pilot::Person(d) => {
                let (speed, steering) = d.update(keys, self.period);
                Action::HighLevel { speed, steering }
            }
            Pilot::System(s) => {
                let Some(a) = verti_bench::episode::next_action(&mut self.trial, s.as_mut()) else {
                    return self.trial.outcome();
                };
                a
            }
        };
        // the row holds the state and the command given from it, as in generated data
        self.rows
            .push(verti_data::generate::row(&self.trial, action));
        let ended = self.trial.step(action, self.period).ended;
        self.recording.frames.push(verti_view::frame(&self.trial));
        ended
    }

    /// Ends the session (a trial still running is recorded as stopped: outcome error, with
    /// the time it stopped at) and hands over what it recorded.
    pub fn finish(self) -> SessionEnd {
        let world = self.trial.world().meta.index;
        let result = self.trial.finish();
        let mut recording = self.recording;
        recording.finish(&result);
        let record = TrialRecord {
            trial: 0,
            world,
            first_step: 0,
            rows: self.rows,
            outcome: DataOutcome::from_bench(result.outcome),
        };
        SessionEnd {
            result,
            record,
            recording,
        }
    }
}
