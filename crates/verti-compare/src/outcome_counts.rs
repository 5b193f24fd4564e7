//! Outcome counts over trials. Their own module because both the per-task summary and the
//! ensemble count outcomes, and the summary holds the ensemble: kept in `summary`, they made
//! `ensemble` and `summary` import each other.

use serde::Serialize;
use verti_bench::Outcome;

/// How many trials ended each way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct OutcomeCounts {
    pub success: usize,
    pub stuck: usize,
    pub rollover: usize,
    pub timeout: usize,
    pub error: usize,
}

impl OutcomeCounts {
    pub fn add(&mut self, o: Outcome) {
        match o {
            Outcome::Success => self.success += 1,
            Outcome::Stuck => self.stuck += 1,
            Outcome::Rollover => self.rollover += 1,
            Outcome::Timeout => self.timeout += 1,
            Outcome::Error => self.error += 1,
        }
    }

    /// How many trials ended as `o`.
    pub fn get(&self, o: Outcome) -> usize {
        match o {
            Outcome::Success => self.success,
            Outcome::Stuck => self.stuck,
            Outcome::Rollover => self.rollover,
            Outcome::Timeout => self.timeout,
            Outcome::Error => self.error,
        }
    }
}
