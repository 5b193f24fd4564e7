//! Shared foundations for verti.
//!
//! * [`rng`]: a small, portable, seedable random number generator. Everything random in verti
//!   (world generation, noise in planners, random exploration) draws from it, so a seed means
//!   the same bits on every machine and with every thread count.
//! * [`math`]: `Vec3`, `Quat` and `Mat3` in `f64`, just what a vehicle engine needs.
//! * [`digest`]: content digests, so a run records what it ran by content.
//! * [`params`] and [`registry`]: typed, documented parameters and open registries of things
//!   built by name from them (mobility systems, elevation sources).
//! * [`messages`]: file-reading errors (serde) in plain words naming the field.
//! * [`output`]: checks of output paths (known format, existing parent directory).

pub mod digest;
pub mod math;
pub mod memory;
pub mod messages;
pub mod output;
pub mod params;
pub mod registry;
pub mod rng;

pub use math::{Mat3, Quat, Vec3};
pub use params::{ParamError, ParamKind, ParamSpec, ParamValue, Params};
pub use registry::{Factory, FactoryInfo, Registrable, Registry};
pub use rng::Rng;
