//! # verti-systems
//!
//! The classical mobility systems of the paper (§IV-A), built by name with typed, documented
//! parameters (see [`registry`]):
//!
//! * [`pid::Pid`]: follows the global path toward a local goal 10 m ahead, steering from the
//!   heading error, at 3 m/s.
//! * [`eh::ElevationHeuristic`]: like PID, but blends in the direction of the region ahead
//!   whose elevation is most like the ground under the vehicle and least rough.
//! * [`mppi::Mppi`]: model-predictive path integral control over a pluggable
//!   [`rollout::RolloutModel`] and [`rollout::RolloutCost`]; by default a kinematic bicycle
//!   model and obstacle avoidance, the cost accumulated over the whole horizon.
//! * [`oracle::Oracle`]: **privileged**: sampling MPC whose rollouts are branches of the
//!   running trial (the true simulator); an upper bound (which tasks are feasible) and an
//!   expert demonstrator, not a system to compare with the paper's.
//!
//! All speeds and distances are given at full scale and scaled with the world: lengths by the
//! world scale s, speeds by √s (Froude similarity, so a 1/10-scale vehicle drives the 1/10
//! world with the same dynamics as the full-scale one drives the full world).
//!
//! [`register`] adds PID, EH, MPPI and the oracle to a `verti_bench::SystemRegistry`; the command line
//! and the Python module compose their registry from it and from the crates above this one.

pub mod eh;
pub mod mppi;
pub mod oracle;
/// Path following lives in verti-bench (rewards need it too); re-exported for the systems.
pub use verti_bench::path;
pub mod pid;
pub mod registry;
pub mod rollout;

pub use registry::{builtin, create, list, register};
