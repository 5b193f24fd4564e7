//! Training on burn (feature `train`): the sequential network every family trains with
//! ([`seq::SeqNet`], exported to this crate's cards), the SWAE terrain model ([`swae`]) on
//! Verti-Bench's elevation maps ([`elev_maps`]), the local-patch encoder's crops ([`patches`])
//! and the `verti learn swae` / `verti learn patch` runs ([`commands`]).
//!
//! Nothing here is needed to *run* a trained model: the families' `train` modules build on this
//! one, and the benchmark, world generation and the Python package build without burn. Choose
//! the device with burn's `BURN_DEVICE` environment variable where a GPU backend is compiled in
//! (feature `cuda`).

pub mod commands;
pub mod elev_maps;
pub mod patches;
pub mod seq;
pub mod swae;

/// The device type training functions take.
pub use burn::tensor::Device;

/// The device training runs on: burn's default device (the flex CPU backend here; with the
/// `cuda` feature, `BURN_DEVICE=cuda` picks the GPU) with automatic differentiation.
pub fn device() -> Device {
    Device::default().autodiff()
}
