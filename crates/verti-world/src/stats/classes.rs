//! Semantic classes: patch counts and friction samples per terrain class (the paper's Fig. 3).

use super::Summary;
use crate::surface::{Surface, TerrainClass};
use crate::world::World;
use serde::Serialize;

/// Patch counts and friction samples of one terrain class.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassStats {
    pub class: String,
    pub deformable: bool,
    pub patches: usize,
    /// Share of all patches of the set.
    pub share: f64,
    /// Worlds with at least one patch of the class.
    pub worlds: usize,
    /// Coulomb friction of the class's rigid patches (`None` for soils or unused classes).
    pub friction: Option<Summary>,
}

pub(super) fn class_stats(worlds: &[World]) -> Vec<ClassStats> {
    let total: usize = worlds.iter().map(|w| w.patches.patches().len()).sum();
    TerrainClass::ALL
        .iter()
        .map(|&class| {
            let mut patches = 0usize;
            let mut in_worlds = 0usize;
            let mut friction = Vec::new();
            for w in worlds {
                let before = patches;
                for p in w.patches.patches().iter().filter(|p| p.class == class) {
                    patches += 1;
                    if let Surface::Rigid { friction: f, .. } = p.surface {
                        friction.push(f);
                    }
                }
                if patches > before {
                    in_worlds += 1;
                }
            }
            ClassStats {
                class: class.name().to_string(),
                deformable: class.is_deformable(),
                patches,
                share: if total > 0 {
                    patches as f64 / total as f64
                } else {
                    0.0
                },
                worlds: in_worlds,
                friction: Summary::of(friction),
            }
        })
        .collect()
}
