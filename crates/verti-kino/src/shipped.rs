//! The trained kinodynamic models that ship in this crate's `models/`, compiled into the binary so a fresh
//! clone plans with them without training (`verti learn kino --model NAME` reproduces each).

use crate::card::{KinoFile, parse_card};
use crate::systems::LearnedSystem;
use crate::traversability::Traversability;
use std::sync::Arc;
use verti_nn::{Embedded, ModelError, embed};

const SHIPPED: &[Embedded] = &[
    embed!("mppi6-v1", ["mppi6-v1.net0", "mppi6-v1.net1"]),
    embed!("wmvct-v1", ["wmvct-v1.net0"]),
    embed!(
        "tal-v1",
        ["tal-v1.encoder", "tal-v1.gate", "tal-v1.dynamics"]
    ),
];

/// TNT's traversability network.
const TNT_V1: Embedded = embed!("tnt-v1");

/// A model card and the networks it lists, from what is compiled in.
fn load(e: &Embedded) -> Result<Arc<KinoFile>, ModelError> {
    let card = parse_card(e.card, e.origin())?;
    let networks = card
        .networks
        .iter()
        .map(|file| e.part(file)?.network().map(Arc::new))
        .collect::<Result<Vec<_>, _>>()?;
    KinoFile::new(card, networks, e.origin()).map(Arc::new)
}

/// A shipped model by name (`mppi6-v1`, ...).
pub fn model(name: &str) -> Result<Arc<KinoFile>, String> {
    let e = SHIPPED
        .iter()
        .find(|e| e.name() == name)
        .ok_or_else(|| format!("no shipped kinodynamic model `{name}`"))?;
    load(e).map_err(|e| e.to_string())
}

/// Every shipped model.
pub fn all() -> Result<Vec<Arc<KinoFile>>, String> {
    SHIPPED
        .iter()
        .map(|e| load(e).map_err(|e| e.to_string()))
        .collect()
}

/// The shipped traversability network of TNT (`verti learn kino --model tnt --steps 2000`).
pub fn traversability() -> Result<Traversability, String> {
    let net = TNT_V1.network().map_err(|e| e.to_string())?;
    Traversability::new(Arc::new(net))
}

/// The learned planners whose models ship.
pub fn systems() -> Vec<LearnedSystem> {
    vec![
        LearnedSystem::new(
            "mppi6",
            "MPPI-6: MPPI (800 x 20 steps of 0.2 s) over a learned 6-DoF ensemble model \
             (mppi6-v1), cost on goal distance, obstacles and predicted roll/pitch",
            || model("mppi6-v1"),
        ),
        LearnedSystem::new(
            "wmvct",
            "WMVCT: MPPI over a decomposed model (bicycle x/y/yaw, terrain z, learned \
             roll/pitch: wmvct-v1), cost on goal distance, obstacles and predicted roll/pitch",
            || model("wmvct-v1"),
        ),
        LearnedSystem::new(
            "tal",
            "TAL: MPPI over a terrain-attentive 6-DoF model (tal-v1: an elevation map encoded \
             once per plan, gated by the vehicle's offset within it), cost on goal distance, \
             obstacles and predicted roll/pitch",
            || model("tal-v1"),
        ),
        LearnedSystem::new(
            "tnt",
            "TNT: TAL's planner and model (tal-v1) plus a learned traversability cost (tnt-v1: \
             a convolutional network over terrain slopes predicting tilt and lost progress)",
            || model("tal-v1"),
        )
        .with_traversability(traversability),
    ]
}
