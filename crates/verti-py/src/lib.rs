//! # verti-py
//!
//! verti's Python face. [`env`] is the step-wise navigation environment (plain Rust, tested by
//! `cargo test`); with the `python` feature, `python` binds it, worlds, the simulator and the
//! evaluation into the extension module `verti._verti`, which maturin builds from `python/`
//! into the `verti` package.

pub mod env;

#[cfg(feature = "python")]
mod python;
