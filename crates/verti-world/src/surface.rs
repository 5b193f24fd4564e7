//! Terrain semantics: the ten classes, their physical parameters, and the 16x16 patch grid.
//!
//! Seven rigid classes carry a Coulomb friction coefficient sampled per patch from a clipped
//! normal distribution (restitution fixed at 0.01); three deformable classes carry a Bekker–Wong
//! / Janosi soil parameter set (SCM). The numbers are those of the Verti-Bench reference
//! (research spec §3.6, §3.7).

use serde::{Deserialize, Serialize};
use std::fmt;

/// The ten terrain classes. The numeric id is the Verti-Bench label id (rigid classes in
/// alphabetical order 0..6, then mud 7, sand 8, snow 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TerrainClass {
    Clay,
    Concrete,
    Dirt,
    Grass,
    Gravel,
    Rock,
    Wood,
    Mud,
    Sand,
    Snow,
}

/// Restitution of every rigid class.
pub const RIGID_RESTITUTION: f64 = 0.01;
/// Per-patch friction samples are clipped to this range.
pub const FRICTION_RANGE: (f64, f64) = (0.1, 1.0);

impl TerrainClass {
    pub const ALL: [TerrainClass; 10] = [
        TerrainClass::Clay,
        TerrainClass::Concrete,
        TerrainClass::Dirt,
        TerrainClass::Grass,
        TerrainClass::Gravel,
        TerrainClass::Rock,
        TerrainClass::Wood,
        TerrainClass::Mud,
        TerrainClass::Sand,
        TerrainClass::Snow,
    ];
    pub const RIGID: [TerrainClass; 7] = [
        TerrainClass::Clay,
        TerrainClass::Concrete,
        TerrainClass::Dirt,
        TerrainClass::Grass,
        TerrainClass::Gravel,
        TerrainClass::Rock,
        TerrainClass::Wood,
    ];
    pub const DEFORMABLE: [TerrainClass; 3] =
        [TerrainClass::Mud, TerrainClass::Sand, TerrainClass::Snow];

    /// Verti-Bench label id (0..9).
    pub fn id(self) -> u8 {
        self as u8
    }
    pub fn from_id(id: i64) -> Option<TerrainClass> {
        usize::try_from(id)
            .ok()
            .and_then(|i| Self::ALL.get(i).copied())
    }
    pub fn name(self) -> &'static str {
        match self {
            TerrainClass::Clay => "clay",
            TerrainClass::Concrete => "concrete",
            TerrainClass::Dirt => "dirt",
            TerrainClass::Grass => "grass",
            TerrainClass::Gravel => "gravel",
            TerrainClass::Rock => "rock",
            TerrainClass::Wood => "wood",
            TerrainClass::Mud => "mud",
            TerrainClass::Sand => "sand",
            TerrainClass::Snow => "snow",
        }
    }
    pub fn from_name(name: &str) -> Option<TerrainClass> {
        Self::ALL.iter().copied().find(|c| c.name() == name)
    }
    pub fn is_deformable(self) -> bool {
        matches!(
            self,
            TerrainClass::Mud | TerrainClass::Sand | TerrainClass::Snow
        )
    }
    /// (mean, standard deviation) of the friction coefficient of a rigid class.
    pub fn friction_distribution(self) -> Option<(f64, f64)> {
        Some(match self {
            TerrainClass::Clay => (0.60, 0.05),
            TerrainClass::Concrete => (0.85, 0.08),
            TerrainClass::Dirt => (0.60, 0.10),
            TerrainClass::Grass => (0.36, 0.07),
            TerrainClass::Gravel => (0.55, 0.10),
            TerrainClass::Rock => (0.65, 0.08),
            TerrainClass::Wood => (0.45, 0.06),
            _ => return None,
        })
    }
    /// The soil of a deformable class: snow = soft, mud = mid, sand = hard.
    pub fn soil(self) -> Option<SoilParams> {
        match self {
            TerrainClass::Snow => Some(SoilParams::SOFT),
            TerrainClass::Mud => Some(SoilParams::MID),
            TerrainClass::Sand => Some(SoilParams::HARD),
            _ => None,
        }
    }
}

impl fmt::Display for TerrainClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Soil Contact Model parameters (Bekker–Wong pressure-sinkage, Mohr–Coulomb + Janosi–Hanamoto
/// shear, elastic unloading). SI units throughout.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SoilParams {
    /// Bekker frictional modulus Kφ [Pa/m^n].
    pub bekker_kphi: f64,
    /// Bekker cohesive modulus Kc [Pa/m^(n-1)].
    pub bekker_kc: f64,
    /// Bekker sinkage exponent n [-].
    pub bekker_n: f64,
    /// Mohr cohesion c \[Pa\].
    pub cohesion: f64,
    /// Mohr internal friction angle φ \[deg\].
    pub friction_angle_deg: f64,
    /// Janosi shear modulus K \[m\].
    pub janosi_k: f64,
    /// Elastic stiffness for unloading/reloading [Pa/m].
    pub elastic_k: f64,
    /// Vertical damping [Pa·s/m].
    pub damping: f64,
}

impl SoilParams {
    /// Snow ("soft").
    pub const SOFT: SoilParams = SoilParams {
        bekker_kphi: 0.2e6,
        bekker_kc: 0.0,
        bekker_n: 1.1,
        cohesion: 0.0,
        friction_angle_deg: 30.0,
        janosi_k: 0.01,
        elastic_k: 4e7,
        damping: 3e4,
    };
    /// Mud ("mid").
    pub const MID: SoilParams = SoilParams {
        bekker_kphi: 2e6,
        bekker_kc: 0.0,
        bekker_n: 1.1,
        cohesion: 0.0,
        friction_angle_deg: 30.0,
        janosi_k: 0.01,
        elastic_k: 2e8,
        damping: 3e4,
    };
    /// Sand ("hard", LETE sand).
    pub const HARD: SoilParams = SoilParams {
        bekker_kphi: 5301e3,
        bekker_kc: 102e3,
        bekker_n: 0.793,
        cohesion: 1.3e3,
        friction_angle_deg: 31.1,
        janosi_k: 0.012,
        elastic_k: 4e8,
        damping: 3e4,
    };

    /// Checks every parameter is finite and physically meaningful; names the first bad one.
    pub fn validate(&self) -> Result<(), String> {
        let fields = [
            ("bekker_kphi", self.bekker_kphi, 0.0, 1e12),
            ("bekker_kc", self.bekker_kc, 0.0, 1e12),
            ("bekker_n", self.bekker_n, 0.1, 3.0),
            ("cohesion", self.cohesion, 0.0, 1e9),
            ("friction_angle_deg", self.friction_angle_deg, 0.0, 89.0),
            ("janosi_k", self.janosi_k, 1e-6, 10.0),
            ("elastic_k", self.elastic_k, 1.0, 1e13),
            ("damping", self.damping, 0.0, 1e10),
        ];
        for (name, v, lo, hi) in fields {
            if !v.is_finite() || v < lo || v > hi {
                return Err(format!("{name} = {v} is outside [{lo}, {hi}]"));
            }
        }
        Ok(())
    }
}

/// What the ground of a patch is made of, physically.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Surface {
    Rigid { friction: f64, restitution: f64 },
    Deformable { soil: SoilParams },
}

impl Surface {
    pub fn is_deformable(&self) -> bool {
        matches!(self, Surface::Deformable { .. })
    }
    /// Coulomb friction for rigid ground; for soil, tan φ (the Mohr–Coulomb limit), which is
    /// what a planner would use as an effective friction.
    pub fn effective_friction(&self) -> f64 {
        match self {
            Surface::Rigid { friction, .. } => *friction,
            Surface::Deformable { soil } => soil.friction_angle_deg.to_radians().tan(),
        }
    }
}

/// One 9x9-vertex semantic patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    pub class: TerrainClass,
    pub surface: Surface,
}

/// Patches per side of the semantic grid.
pub const PATCHES_PER_SIDE: usize = 16;
/// Heightfield cells per patch side (9 vertices, sharing one with each neighbour).
pub const CELLS_PER_PATCH: usize = 8;

/// The 16x16 grid of patches, row-major, row 0 = north.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchGrid {
    patches: Vec<Patch>,
    /// Side length of a patch in metres (8 cells).
    patch_size: f64,
    half_extent: f64,
}

impl PatchGrid {
    pub fn new(patches: Vec<Patch>, cell: f64) -> Self {
        assert_eq!(
            patches.len(),
            PATCHES_PER_SIDE * PATCHES_PER_SIDE,
            "patch count"
        );
        let patch_size = CELLS_PER_PATCH as f64 * cell;
        PatchGrid {
            patches,
            patch_size,
            half_extent: 0.5 * PATCHES_PER_SIDE as f64 * patch_size,
        }
    }
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }
    #[inline]
    pub fn get(&self, row: usize, col: usize) -> &Patch {
        &self.patches[row * PATCHES_PER_SIDE + col]
    }
    pub fn patch_size(&self) -> f64 {
        self.patch_size
    }
    /// (row, col) of the patch under (x, y); points off the map use the nearest edge patch.
    #[inline]
    pub fn index_at(&self, x: f64, y: f64) -> (usize, usize) {
        let m = (PATCHES_PER_SIDE - 1) as f64;
        let col = ((x + self.half_extent) / self.patch_size)
            .floor()
            .clamp(0.0, m) as usize;
        let row = ((self.half_extent - y) / self.patch_size)
            .floor()
            .clamp(0.0, m) as usize;
        (row, col)
    }
    #[inline]
    pub fn at(&self, x: f64, y: f64) -> &Patch {
        let (r, c) = self.index_at(x, y);
        self.get(r, c)
    }
    /// Centre (x, y) of patch (row, col).
    pub fn centre(&self, row: usize, col: usize) -> (f64, f64) {
        (
            -self.half_extent + (col as f64 + 0.5) * self.patch_size,
            self.half_extent - (row as f64 + 0.5) * self.patch_size,
        )
    }
    /// Per-vertex class labels on an n x n grid like Verti-Bench's `labels*.npy`: vertex (r, c)
    /// belongs to patch (min(r / 8, 15), min(c / 8, 15)).
    pub fn label_grid(&self, n: usize) -> Vec<u8> {
        let mut out = Vec::with_capacity(n * n);
        for r in 0..n {
            for c in 0..n {
                let pr = (r / CELLS_PER_PATCH).min(PATCHES_PER_SIDE - 1);
                let pc = (c / CELLS_PER_PATCH).min(PATCHES_PER_SIDE - 1);
                out.push(self.get(pr, pc).class.id());
            }
        }
        out
    }
    /// True when any patch is deformable.
    pub fn has_soil(&self) -> bool {
        self.patches.iter().any(|p| p.surface.is_deformable())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_ids_follow_verti_bench() {
        assert_eq!(TerrainClass::Clay.id(), 0);
        assert_eq!(TerrainClass::Wood.id(), 6);
        assert_eq!(TerrainClass::Mud.id(), 7);
        assert_eq!(TerrainClass::Snow.id(), 9);
        for c in TerrainClass::ALL {
            assert_eq!(TerrainClass::from_id(i64::from(c.id())), Some(c));
            assert_eq!(TerrainClass::from_name(c.name()), Some(c));
            assert_eq!(c.is_deformable(), c.soil().is_some());
            assert_eq!(!c.is_deformable(), c.friction_distribution().is_some());
        }
        assert_eq!(TerrainClass::from_id(10), None);
        for s in [SoilParams::SOFT, SoilParams::MID, SoilParams::HARD] {
            s.validate().unwrap();
        }
    }

    #[test]
    fn patch_lookup_matches_grid() {
        let p = Patch {
            class: TerrainClass::Clay,
            surface: Surface::Rigid {
                friction: 0.6,
                restitution: RIGID_RESTITUTION,
            },
        };
        let mut patches = vec![p; 256];
        patches[17].class = TerrainClass::Rock; // row 1, col 1
        let g = PatchGrid::new(patches, 1.0);
        assert_eq!(g.centre(0, 0), (-60.0, 60.0));
        assert_eq!(g.index_at(-60.0, 60.0), (0, 0));
        assert_eq!(g.at(-52.0, 52.0).class, TerrainClass::Rock);
        assert_eq!(g.index_at(1000.0, -1000.0), (15, 15));
        let labels = g.label_grid(129);
        assert_eq!(labels[8 * 129 + 8], TerrainClass::Rock.id());
        assert_eq!(labels[16 * 129 + 16], TerrainClass::Clay.id());
    }
}
