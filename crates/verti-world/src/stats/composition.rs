//! Composition: how many worlds of each elevation level, terrain type and obstacle density a
//! set holds, and the level x terrain type table.

use crate::world::{ElevationLevel, ObstacleDensity, TerrainType, World};
use serde::Serialize;

/// A count under a name.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct NamedCount {
    pub name: String,
    pub count: usize,
}

/// How many worlds of each kind the set holds.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Composition {
    /// low, mid, high.
    pub by_level: Vec<NamedCount>,
    /// rigid, deformable, mixed.
    pub by_terrain_type: Vec<NamedCount>,
    /// sparse, medium, dense.
    pub by_density: Vec<NamedCount>,
    /// World counts per (level, terrain type), one row per level.
    pub level_by_type: Vec<LevelTypeRow>,
}

/// One row of the level x terrain type table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LevelTypeRow {
    pub level: String,
    pub rigid: usize,
    pub deformable: usize,
    pub mixed: usize,
}

fn counts_by<T: Copy + PartialEq>(
    worlds: &[World],
    all: &[T],
    key: impl Fn(&World) -> T,
    name: impl Fn(T) -> &'static str,
) -> Vec<NamedCount> {
    all.iter()
        .map(|&v| NamedCount {
            name: name(v).to_string(),
            count: worlds.iter().filter(|w| key(w) == v).count(),
        })
        .collect()
}

pub(super) fn composition(worlds: &[World]) -> Composition {
    let level_by_type = ElevationLevel::ALL
        .iter()
        .map(|&l| {
            let n = |t: TerrainType| {
                worlds
                    .iter()
                    .filter(|w| w.meta.level == l && w.meta.terrain_type == t)
                    .count()
            };
            LevelTypeRow {
                level: l.name().to_string(),
                rigid: n(TerrainType::Rigid),
                deformable: n(TerrainType::Deformable),
                mixed: n(TerrainType::Mixed),
            }
        })
        .collect();
    Composition {
        by_level: counts_by(
            worlds,
            &ElevationLevel::ALL,
            |w| w.meta.level,
            ElevationLevel::name,
        ),
        by_terrain_type: counts_by(
            worlds,
            &TerrainType::ALL,
            |w| w.meta.terrain_type,
            TerrainType::name,
        ),
        by_density: counts_by(
            worlds,
            &ObstacleDensity::ALL,
            |w| w.meta.density,
            ObstacleDensity::name,
        ),
        level_by_type,
    }
}
