//! Training driving policies with PPO on burn (feature `train`): the algorithm, one update in
//! the order CleanRL writes it (rollout, GAE, minibatch epochs, clipped loss; [`ppo`]), the task
//! curricula of RL, MCL and ACL ([`curriculum`]) and the `verti learn rl` run with validation,
//! checkpoints and curves ([`rl`]). The exported policy runs without burn through
//! [`crate::Policy`].

pub mod curriculum;
pub mod ppo;
pub mod rl;
