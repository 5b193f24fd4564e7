//! The trained kinodynamic models that ship in `models/`, compiled into the binary so a fresh
//! clone plans with them without training (`verti learn kino --model NAME` reproduces each).

use crate::card::{KinoFile, parse_card};
use crate::systems::LearnedSystem;
use crate::traversability::Traversability;
use std::path::Path;
use std::sync::Arc;
use verti_nn::Network;

/// One shipped network: its card and weights.
struct EmbeddedNet {
    card: &'static str,
    weights: &'static [u8],
    path: &'static str,
}

/// One shipped model: its card and networks.
struct Embedded {
    card: &'static str,
    path: &'static str,
    networks: &'static [EmbeddedNet],
}

macro_rules! net {
    ($stem:literal) => {
        EmbeddedNet {
            card: include_str!(concat!("../../../models/", $stem, ".yaml")),
            weights: include_bytes!(concat!("../../../models/", $stem, ".bin")),
            path: concat!("models/", $stem, ".yaml"),
        }
    };
}

const SHIPPED: &[Embedded] = &[
    Embedded {
        card: include_str!("../../../models/mppi6-v1.yaml"),
        path: "models/mppi6-v1.yaml",
        networks: &[net!("mppi6-v1.net0"), net!("mppi6-v1.net1")],
    },
    Embedded {
        card: include_str!("../../../models/wmvct-v1.yaml"),
        path: "models/wmvct-v1.yaml",
        networks: &[net!("wmvct-v1.net0")],
    },
    Embedded {
        card: include_str!("../../../models/tal-v1.yaml"),
        path: "models/tal-v1.yaml",
        networks: &[
            net!("tal-v1.encoder"),
            net!("tal-v1.gate"),
            net!("tal-v1.dynamics"),
        ],
    },
];

fn load(e: &Embedded) -> Result<Arc<KinoFile>, String> {
    let path = Path::new(e.path);
    let card = parse_card(e.card, path).map_err(|x| x.to_string())?;
    let networks = e
        .networks
        .iter()
        .map(|n| {
            let p = Path::new(n.path);
            let c = verti_nn::network::parse_card(n.card, p).map_err(|x| x.to_string())?;
            Network::from_bytes(c, n.weights, p)
                .map(Arc::new)
                .map_err(|x| x.to_string())
        })
        .collect::<Result<Vec<_>, String>>()?;
    KinoFile::new(card, networks, path)
        .map(Arc::new)
        .map_err(|x| x.to_string())
}

/// A shipped model by name (`mppi6-v1`, ...).
pub fn model(name: &str) -> Result<Arc<KinoFile>, String> {
    let e = SHIPPED
        .iter()
        .find(|e| e.path == format!("models/{name}.yaml"))
        .ok_or_else(|| format!("no shipped kinodynamic model `{name}`"))?;
    load(e)
}

/// Every shipped model.
pub fn all() -> Result<Vec<Arc<KinoFile>>, String> {
    SHIPPED.iter().map(load).collect()
}

/// The shipped traversability network of TNT (`verti learn kino --model tnt --steps 2000`).
pub fn traversability() -> Result<Traversability, String> {
    let n = net!("tnt-v1");
    let p = Path::new(n.path);
    let card = verti_nn::network::parse_card(n.card, p).map_err(|x| x.to_string())?;
    let net = Network::from_bytes(card, n.weights, p).map_err(|x| x.to_string())?;
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
