//! # verti-py
//!
//! verti's Python face. With the `python` feature, `python` binds worlds, the simulator, the
//! evaluation and the environments of `verti-env` into the extension module `verti._verti`,
//! which maturin builds from `python/` into the `verti` package. Without the feature (plain
//! `cargo build`/`cargo test`) the crate is empty, so the workspace builds without Python.

#[cfg(feature = "python")]
mod python;
