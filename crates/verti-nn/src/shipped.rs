//! verti-nn's trained models that ship in this crate's `models/` directory, compiled in
//! ([`crate::embed!`]).

use crate::embed::Embedded;
use crate::network::Network;
use crate::patch::PatchEncoder;
use crate::swae::SwaeFactory;
use std::sync::{Arc, OnceLock};
use verti_world::generate::sources::ElevationRegistry;

const SWAE_V1: Embedded = crate::embed!("swae-v1");
const PATCH_V1: Embedded = crate::embed!("patch-v1");

/// The network of `model`, loaded once into `cell`.
fn cached(
    cell: &'static OnceLock<Result<Arc<Network>, String>>,
    model: &Embedded,
) -> Result<Arc<Network>, String> {
    cell.get_or_init(|| model.network().map(Arc::new).map_err(|e| e.to_string()))
        .clone()
}

/// The shipped SWAE terrain decoder (`swae-v1`).
pub fn swae_v1() -> Result<Arc<Network>, String> {
    static CELL: OnceLock<Result<Arc<Network>, String>> = OnceLock::new();
    cached(&CELL, &SWAE_V1)
}

/// The shipped local-patch encoder (`patch-v1`).
pub fn patch_v1() -> Result<PatchEncoder, String> {
    static CELL: OnceLock<Result<Arc<Network>, String>> = OnceLock::new();
    PatchEncoder::new(cached(&CELL, &PATCH_V1)?)
}

/// Adds the learned elevation sources (`swae-v1`) to a registry.
pub fn register_sources(registry: &mut ElevationRegistry) {
    let decoder = swae_v1().expect("the shipped swae-v1 model is compiled in and checked by tests");
    registry
        .register(SwaeFactory { decoder })
        .expect("swae-v1 is registered once");
}
