//! One surface everywhere: a world transform for experiments that must rule out the ground's
//! variety, such as the fidelity comparison against Chrono, whose reference runs give every
//! patch the same friction.
//!
//! Elevation, obstacles, tasks and global paths are kept: the paths depend only on obstacles
//! and elevation, so they stay the ones the original world planned.

use crate::error::{Result, WorldError};
use crate::surface::{Patch, PatchGrid, Surface, TerrainClass};
use crate::world::{TerrainType, World};

impl World {
    /// This world with every patch of class `class` and ground `surface`, and its terrain type
    /// made to match (rigid or deformable). Refuses a surface that contradicts the class (soil
    /// on a rigid class or the reverse) and physical parameters out of range, naming them.
    pub fn with_uniform_surface(&self, class: TerrainClass, surface: Surface) -> Result<World> {
        let bad = |problem: String| {
            WorldError::Argument(format!("uniform surface for {}: {problem}", self.meta.name))
        };
        if class.is_deformable() != surface.is_deformable() {
            return Err(bad(format!(
                "class {class} is {} but the surface is {}",
                kind(class.is_deformable()),
                kind(surface.is_deformable())
            )));
        }
        match surface {
            Surface::Rigid {
                friction,
                restitution,
            } => {
                // the same bounds the importer and the world format accept
                if !(friction.is_finite() && (0.0..=2.0).contains(&friction)) {
                    return Err(bad(format!("friction {friction} is outside [0, 2]")));
                }
                if !(restitution.is_finite() && (0.0..=1.0).contains(&restitution)) {
                    return Err(bad(format!("restitution {restitution} is outside [0, 1]")));
                }
            }
            Surface::Deformable { soil } => {
                soil.validate().map_err(|e| bad(format!("soil {e}")))?
            }
        }
        let patch = Patch { class, surface };
        let count = self.patches.patches().len();
        let cell = self.terrain.cell();
        let mut world = self.clone();
        world.patches = PatchGrid::new(vec![patch; count], cell);
        world.meta.terrain_type = if surface.is_deformable() {
            TerrainType::Deformable
        } else {
            TerrainType::Rigid
        };
        Ok(world)
    }
}

fn kind(deformable: bool) -> &'static str {
    if deformable { "deformable" } else { "rigid" }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{SetConfig, generate_set};
    use crate::surface::{RIGID_RESTITUTION, SoilParams};

    fn mixed_world() -> World {
        let cfg = SetConfig {
            count: 3,
            ..Default::default()
        };
        let set = generate_set(&cfg, &|| {}).unwrap();
        // a world with soil somewhere, so the transform has something to replace
        set.into_iter()
            .find(|w| w.patches.has_soil())
            .expect("a small set has a world with soil")
    }

    #[test]
    fn every_patch_becomes_the_surface_and_the_rest_stays() {
        let w = mixed_world();
        let dirt = Surface::Rigid {
            friction: 0.8,
            restitution: RIGID_RESTITUTION,
        };
        let u = w.with_uniform_surface(TerrainClass::Dirt, dirt).unwrap();
        assert!(
            u.patches
                .patches()
                .iter()
                .all(|p| p.class == TerrainClass::Dirt && p.surface == dirt)
        );
        assert!(u.labels().iter().all(|&l| l == 2), "dirt is label 2");
        assert_eq!(u.meta.terrain_type, TerrainType::Rigid);
        assert!(!u.patches.has_soil());
        assert_eq!(u.patches.patch_size(), w.patches.patch_size());
        // everything but the ground is untouched
        assert_eq!(
            (&u.terrain, &u.obstacles, &u.tasks, &u.paths),
            (&w.terrain, &w.obstacles, &w.tasks, &w.paths)
        );
        assert_eq!(u.meta.name, w.meta.name);
        // the other way round: all soil
        let mud = Surface::Deformable {
            soil: SoilParams::MID,
        };
        let m = w.with_uniform_surface(TerrainClass::Mud, mud).unwrap();
        assert_eq!(m.meta.terrain_type, TerrainType::Deformable);
    }

    #[test]
    fn contradictions_and_bad_numbers_are_refused() {
        let w = mixed_world();
        let err = |c, s| w.with_uniform_surface(c, s).unwrap_err().to_string();
        let rigid = |friction, restitution| Surface::Rigid {
            friction,
            restitution,
        };
        assert!(err(TerrainClass::Mud, rigid(0.8, 0.01)).contains("class mud is deformable"));
        assert!(err(TerrainClass::Dirt, rigid(f64::NAN, 0.01)).contains("friction NaN"));
        assert!(err(TerrainClass::Dirt, rigid(0.8, 1.5)).contains("restitution 1.5"));
        let mut soil = SoilParams::MID;
        soil.bekker_n = 0.0;
        let e = err(TerrainClass::Sand, Surface::Deformable { soil });
        assert!(e.contains("bekker_n"), "{e}");
    }
}
