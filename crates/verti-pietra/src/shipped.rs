//! The traversability model that ships in `models/` (`pietra-v1`), compiled into the binary so
//! a fresh clone plans with it without training (`verti learn pietra` reproduces it).

use crate::model::TravModel;
use std::path::Path;
use std::sync::Arc;
use verti_nn::Network;

const CARD: &str = include_str!("../../../models/pietra-v1.yaml");

macro_rules! net {
    ($stem:literal) => {
        (
            concat!($stem, ".yaml"),
            include_str!(concat!("../../../models/", $stem, ".yaml")),
            include_bytes!(concat!("../../../models/", $stem, ".bin")).as_slice(),
        )
    };
}

const NETWORKS: [(&str, &str, &[u8]); 6] = [
    net!("pietra-v1.encoder"),
    net!("pietra-v1.decoder1"),
    net!("pietra-v1.decoder2"),
    net!("pietra-v1.decoder3"),
    net!("pietra-v1.decoder4"),
    net!("pietra-v1.scaler"),
];

/// The shipped `pietra-v1`.
pub fn pietra_v1() -> Result<Arc<TravModel>, String> {
    let origin = Path::new("models/pietra-v1.yaml");
    TravModel::parse(CARD, origin, &|file| {
        let (_, card, weights) = NETWORKS
            .iter()
            .find(|(name, _, _)| *name == file)
            .ok_or_else(|| format!("{file} is not a shipped network"))?;
        let card =
            verti_nn::network::parse_card(card, Path::new(file)).map_err(|e| e.to_string())?;
        Network::from_bytes(card, weights, Path::new(file)).map_err(|e| e.to_string())
    })
    .map(Arc::new)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_shipped_model_loads_and_predicts_pmfs() {
        let m = super::pietra_v1().unwrap();
        let f = [0.0f32; crate::dataset::FEATURES];
        let physics = [crate::bins::uniform(); crate::bins::PARAMS];
        let p = m.predict(&f, &physics, &mut m.scratch());
        for pmf in p.pmf {
            assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        }
    }
}
