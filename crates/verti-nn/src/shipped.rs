//! The trained models that ship in the repository's `models/` directory, compiled into the
//! binary so a fresh clone (and an installed wheel) needs no training and no file lookup.

use crate::network::{ModelError, Network, parse_card};
use crate::patch::PatchEncoder;
use crate::swae::SwaeFactory;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use verti_world::generate::sources::ElevationRegistry;

/// A model shipped in `models/`: its card and weight bytes.
struct Shipped {
    card_path: &'static str,
    card: &'static str,
    weights: &'static [u8],
}

impl Shipped {
    fn load(&self) -> Result<Network, ModelError> {
        let path = Path::new(self.card_path);
        Network::from_bytes(parse_card(self.card, path)?, self.weights, path)
    }
}

const SWAE_V1: Shipped = Shipped {
    card_path: "models/swae-v1.yaml",
    card: include_str!("../../../models/swae-v1.yaml"),
    weights: include_bytes!("../../../models/swae-v1.bin"),
};

const PATCH_V1: Shipped = Shipped {
    card_path: "models/patch-v1.yaml",
    card: include_str!("../../../models/patch-v1.yaml"),
    weights: include_bytes!("../../../models/patch-v1.bin"),
};

fn cached(
    cell: &'static OnceLock<Result<Arc<Network>, String>>,
    model: &Shipped,
) -> Result<Arc<Network>, String> {
    cell.get_or_init(|| model.load().map(Arc::new).map_err(|e| e.to_string()))
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
