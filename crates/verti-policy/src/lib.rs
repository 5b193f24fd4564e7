//! # verti-policy
//!
//! Driving policies trained by reinforcement learning (`verti learn rl`: the `train` module, feature `train`) at
//! inference time, in plain Rust, so that evaluation and the Python package never build burn:
//!
//! * [`inputs`]: what a policy observes (a heading-aligned elevation patch, the heading error
//!   to the local goal, speed and attitude) and how an environment observation becomes the
//!   network's input. Training and evaluation share it, so a policy sees the very same inputs
//!   in both.
//! * [`Policy`]: the actor network with its Gaussian's spread, read from a model card.
//! * [`system`]: a policy as a benchmark system, and the registered `rl`, `mcl` and `acl`.
//! * [`shipped`]: the trained policies that ship in this crate's `models/`.

pub mod inputs;
pub mod policy;
pub mod shipped;
pub mod system;
#[cfg(feature = "train")]
pub mod train;

pub use policy::Policy;
