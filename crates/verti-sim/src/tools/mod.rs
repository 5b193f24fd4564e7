//! Tooling around the engine, not part of it: the speed benchmark ([`bench()`], behind
//! `verti sim bench`) and the random-input robustness run ([`soak()`], behind
//! `verti sim soak`).
//!
//! Why a module and not a cargo feature or the CLI: the tools need nothing the engine does not
//! already depend on, so a feature would only add `required-features` bookkeeping to the
//! examples and the CLI; and they belong next to the engine they measure, where its examples
//! (`bench`, `soak`, `replay`, `trace`) use them too. Keeping them under `verti_sim::tools`
//! keeps the crate root the engine's API alone.

mod bench;
mod soak;

pub use bench::{
    BenchCase, BenchReport, BenchWorldPair, BenchWorlds, bench, bench_controls, bench_route,
};
pub use soak::{SOAK_CONTROL_DT, SoakEpisode, SoakFailure, SoakReport, soak, soak_episode};
