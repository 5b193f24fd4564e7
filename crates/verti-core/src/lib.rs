//! Shared foundations for verti.
//!
//! * [`rng`]: a small, portable, seedable random number generator. Everything random in verti
//!   (world generation, noise in planners, random exploration) draws from it, so a seed means
//!   the same bits on every machine and with every thread count.
//! * [`math`]: `Vec3`, `Quat` and `Mat3` in `f64`, just what a vehicle engine needs.

pub mod math;
pub mod rng;

pub use math::{Mat3, Quat, Vec3};
pub use rng::Rng;
