//! The model the `va` system plans with by default (`va-small-v1`: 24 basis fields of
//! [32, 32]), compiled in so a fresh clone plans without training (`verti learn va --hidden
//! 32,32 --out crates/verti-va/models/va-small-v1.yaml` reproduces it).

use crate::model::{VaCard, VaModel};
use std::sync::Arc;
use verti_nn::{Embedded, embed};

const VA_SMALL_V1: Embedded = embed!("va-small-v1");

/// The shipped `va-small-v1`.
pub fn va_small_v1() -> Result<Arc<VaModel>, String> {
    let (card, weights) = VA_SMALL_V1.checked::<VaCard>().map_err(|e| e.to_string())?;
    VaModel::from_bytes(card, weights, VA_SMALL_V1.origin())
        .map(Arc::new)
        .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_shipped_model_loads_and_predicts_forward_motion() {
        let m = super::va_small_v1().unwrap();
        assert_eq!(m.card.bases, 24);
        // 2 m/s straight ahead on flat, rigid ground: the vehicle moves forward
        let d = m.predict(&m.card.alpha_prior, 0.0, 0.0, &[0.0; 16], (2.0, 0.0));
        assert!(d[0] > 0.05 && d[0] < 0.4, "{d:?}");
    }
}
