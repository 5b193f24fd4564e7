//! verti's training code, on burn (flex backend by default; any burn device works).
//!
//! Everything here trains; nothing here is needed to *run* a trained model: networks export
//! to `verti-nn`'s model cards and weight files ([`seq::SeqNet::export_params`]), which the
//! benchmark evaluates without burn. Choose the device with burn's `BURN_DEVICE` environment
//! variable where a GPU backend is compiled in (feature `cuda`).

/// The device type training functions take.
pub use burn::tensor::Device;

pub mod commands;
pub mod curriculum;
pub mod elev_maps;
pub mod kino;
pub mod kino_command;
pub mod kino_shared;
pub mod patches;
pub mod pietra;
pub mod ppo;
pub mod rl;
pub mod seq;
pub mod swae;
pub mod tal;
pub mod trav;
pub mod va;

/// The device training runs on: burn's default device (the flex CPU backend here; with the
/// `cuda` feature, `BURN_DEVICE=cuda` picks the GPU) with automatic differentiation.
pub fn training_device() -> burn::tensor::Device {
    burn::tensor::Device::default().autodiff()
}
