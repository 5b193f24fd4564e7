//! The trained policies that ship in this crate's `models/`, compiled into the binary so a fresh clone
//! evaluates `rl`, `mcl` and `acl` without training (`verti learn rl --curriculum ...`
//! reproduces each; the command is in its card).

use crate::policy::Policy;
use crate::system::PolicySystem;
use std::sync::{Arc, OnceLock};
use verti_nn::{Embedded, embed};

const RL: Embedded = embed!("rl-v1");
const MCL: Embedded = embed!("mcl-v1");
const ACL: Embedded = embed!("acl-v1");

fn load(e: &Embedded) -> Result<Arc<Policy>, String> {
    let net = e.network().map_err(|x| x.to_string())?;
    Policy::new(Arc::new(net)).map(Arc::new)
}

fn cached(
    cell: &'static OnceLock<Result<Arc<Policy>, String>>,
    e: &Embedded,
) -> Result<Arc<Policy>, String> {
    cell.get_or_init(|| load(e)).clone()
}

/// The shipped `rl-v1` policy (PPO, uniform tasks).
pub fn rl_v1() -> Result<Arc<Policy>, String> {
    static CELL: OnceLock<Result<Arc<Policy>, String>> = OnceLock::new();
    cached(&CELL, &RL)
}

/// The shipped `mcl-v1` policy (PPO, manual curriculum).
pub fn mcl_v1() -> Result<Arc<Policy>, String> {
    static CELL: OnceLock<Result<Arc<Policy>, String>> = OnceLock::new();
    cached(&CELL, &MCL)
}

/// The shipped `acl-v1` policy (PPO, prioritised replay of tasks by TD error).
pub fn acl_v1() -> Result<Arc<Policy>, String> {
    static CELL: OnceLock<Result<Arc<Policy>, String>> = OnceLock::new();
    cached(&CELL, &ACL)
}

/// Every shipped policy by name, for listing and tests.
pub fn all() -> Vec<(&'static str, Result<Arc<Policy>, String>)> {
    vec![
        ("rl-v1", rl_v1()),
        ("mcl-v1", mcl_v1()),
        ("acl-v1", acl_v1()),
    ]
}

/// The three policy systems with their shipped policies.
pub fn systems() -> Vec<PolicySystem> {
    vec![
        PolicySystem::new(
            "rl",
            "PPO policy trained in verti with uniform task sampling (elevation patch, heading \
             error, speed, attitude -> target speed, steering)",
            rl_v1,
        ),
        PolicySystem::new(
            "mcl",
            "PPO policy trained with a manual curriculum (stages: low rigid ground, then low and \
             mid elevation on every ground, then everything)",
            mcl_v1,
        ),
        PolicySystem::new(
            "acl",
            "PPO policy trained with an automatic curriculum (prioritised replay of training \
             tasks by TD error, with staleness: Verti-Selector's mechanism)",
            acl_v1,
        ),
    ]
}
