//! The traversability model that ships in this crate's `models/` (`pietra-v1`), compiled into the binary so
//! a fresh clone plans with it without training (`verti learn pietra` reproduces it).

use crate::model::TravModel;
use std::sync::Arc;
use verti_nn::{Embedded, embed};

const PIETRA_V1: Embedded = embed!(
    "pietra-v1",
    [
        "pietra-v1.encoder",
        "pietra-v1.decoder1",
        "pietra-v1.decoder2",
        "pietra-v1.decoder3",
        "pietra-v1.decoder4",
        "pietra-v1.scaler",
    ]
);

/// The shipped `pietra-v1`.
pub fn pietra_v1() -> Result<Arc<TravModel>, String> {
    TravModel::parse(PIETRA_V1.card, PIETRA_V1.origin(), &|file| {
        PIETRA_V1
            .part(file)
            .and_then(|part| part.network())
            .map_err(|e| e.to_string())
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
