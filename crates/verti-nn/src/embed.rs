//! Models compiled into the binary: how every family crate ships its trained models from its
//! own `models/` directory (`crates/NAME/models/`), so a fresh clone (and an installed wheel)
//! needs no training and no file lookup.
//!
//! [`embed!`](crate::embed!) compiles a card in, with the weights file beside it (`NAME.bin`)
//! or, for a composite card (a kinodynamic model's, PIETRA's), the cards and weights of the
//! parts it lists. [`Embedded::checked`] gives the card and its weights once they are checked
//! against the count and digest the card records ([`WeightsInfo::check`], the check files on
//! disk pass too); [`Embedded::network`] builds a network from them and [`Embedded::part`]
//! finds a composite card's part. Errors are [`ModelError`]s that name the card's path in the
//! repository (`crates/CRATE/models/NAME.yaml`).

use crate::card::{ModelCard, WeightsCard, WeightsInfo, parse};
use crate::error::ModelError;
use crate::network::Network;
use std::path::Path;

/// A model card compiled in with [`embed!`](crate::embed!), and what it brings with it.
#[derive(Clone, Copy, Debug)]
pub struct Embedded {
    /// The card's path in the repository, `crates/CRATE/models/NAME.yaml`: it names the model in
    /// errors.
    pub path: &'static str,
    /// The card's text.
    pub card: &'static str,
    /// The weights file beside the card (its name, `NAME.bin`, and bytes); `None` for a
    /// composite card, whose weights are its parts'.
    pub weights: Option<(&'static str, &'static [u8])>,
    /// The parts a composite card lists, each compiled in the same way.
    pub parts: &'static [Embedded],
}

/// Compiles a model card of the calling crate's `models/` directory (`crates/CRATE/models/`)
/// into it, as an [`Embedded`]:
///
/// * `embed!("swae-v1")` in verti-nn: `crates/verti-nn/models/swae-v1.yaml` and its weights,
///   `crates/verti-nn/models/swae-v1.bin`;
/// * `embed!("tal-v1", ["tal-v1.encoder", "tal-v1.gate"])`: the composite card
///   `crates/verti-kino/models/tal-v1.yaml` and the listed parts, each `embed!`ded with its weights.
#[macro_export]
macro_rules! embed {
    ($stem:literal) => {
        $crate::embed::Embedded {
            path: concat!("crates/", env!("CARGO_PKG_NAME"), "/models/", $stem, ".yaml"),
            card: include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/models/",
                $stem,
                ".yaml"
            )),
            weights: Some((
                concat!($stem, ".bin"),
                include_bytes!(concat!(
                    env!("CARGO_MANIFEST_DIR"),
                    "/models/",
                    $stem,
                    ".bin"
                )),
            )),
            parts: &[],
        }
    };
    ($stem:literal, [$($part:literal),+ $(,)?]) => {
        $crate::embed::Embedded {
            path: concat!("crates/", env!("CARGO_PKG_NAME"), "/models/", $stem, ".yaml"),
            card: include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/models/",
                $stem,
                ".yaml"
            )),
            weights: None,
            parts: &[$($crate::embed!($part)),+],
        }
    };
}

impl Embedded {
    /// The card's path, for errors and for the callers' own card checks.
    pub fn origin(&self) -> &'static Path {
        Path::new(self.path)
    }

    /// The model's name: the card's file name without `.yaml`.
    pub fn name(&self) -> &'static str {
        let file = self.path.rsplit('/').next().unwrap_or(self.path);
        file.strip_suffix(".yaml").unwrap_or(file)
    }

    /// The card, parsed as `C`, and the bytes of the weights file it names, checked against
    /// the count and digest the card records.
    pub fn checked<C: WeightsCard>(&self) -> Result<(C, &'static [u8]), ModelError> {
        let (card, weights) = self.parsed::<C>()?;
        card.weights_info().check(weights, self.origin())?;
        Ok((card, weights))
    }

    /// The network this card describes ([`Network::from_bytes`] runs [`Embedded::checked`]'s
    /// weight check after its own checks of the layers).
    pub fn network(&self) -> Result<Network, ModelError> {
        let (card, weights) = self.parsed::<ModelCard>()?;
        Network::from_bytes(card, weights, self.origin())
    }

    /// The part a composite card lists as `file` (relative to the card, as its list says).
    pub fn part(&self, file: &str) -> Result<&'static Embedded, ModelError> {
        let want = self.origin().with_file_name(file);
        self.parts
            .iter()
            .find(|p| p.origin() == want)
            .ok_or_else(|| {
                let parts: Vec<&str> = self.parts.iter().map(|p| p.name()).collect();
                ModelError::invalid(
                    self.origin(),
                    format!(
                        "part {file} is not compiled in with this card (parts compiled in: {})",
                        if parts.is_empty() {
                            "none".to_string()
                        } else {
                            parts.join(", ")
                        }
                    ),
                )
            })
    }

    /// The card, parsed, and the weights compiled in with it, which must be the file the card
    /// names (their count and digest are not checked yet).
    fn parsed<C: WeightsCard>(&self) -> Result<(C, &'static [u8]), ModelError> {
        let card: C = parse(self.card, self.origin())?;
        let info: &WeightsInfo = card.weights_info();
        match self.weights {
            Some((file, bytes)) if file == info.file => Ok((card, bytes)),
            Some((file, _)) => Err(ModelError::card(
                self.origin(),
                "weights.file",
                format!(
                    "the card names {}, {file} is compiled in with it",
                    info.file
                ),
            )),
            None => Err(ModelError::card(
                self.origin(),
                "weights.file",
                format!(
                    "the card names {}, but no weights are compiled in with it (a composite card)",
                    info.file
                ),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SWAE: Embedded = crate::embed!("swae-v1");

    #[test]
    fn an_embedded_card_brings_its_checked_weights() {
        assert_eq!(SWAE.name(), "swae-v1");
        let (card, weights) = SWAE.checked::<ModelCard>().unwrap();
        assert_eq!(card.name, "swae-v1");
        assert_eq!(weights.len(), 4 * card.weights.floats);
        assert_eq!(SWAE.network().unwrap().params().len(), card.weights.floats);
    }

    #[test]
    fn damaged_or_mismatched_weights_are_refused_by_name() {
        let (_, good) = SWAE.weights.unwrap();
        let mut bytes = good.to_vec();
        bytes[100] ^= 1;
        let damaged = Embedded {
            weights: Some(("swae-v1.bin", bytes.leak())),
            ..SWAE
        };
        let e = damaged.checked::<ModelCard>().unwrap_err().to_string();
        assert!(
            e.starts_with("crates/verti-nn/models/swae-v1.yaml: ") && e.contains("digest"),
            "{e}"
        );
        let e = damaged.network().unwrap_err().to_string();
        assert!(e.contains("does not belong to this card"), "{e}");
        let truncated = Embedded {
            weights: Some(("swae-v1.bin", &good[..good.len() - 4])),
            ..SWAE
        };
        let e = truncated.network().unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        let swapped = Embedded {
            weights: Some(("patch-v1.bin", good)),
            ..SWAE
        };
        let e = swapped.network().unwrap_err().to_string();
        assert!(
            e.contains("weights.file") && e.contains("patch-v1.bin"),
            "{e}"
        );
    }
}
