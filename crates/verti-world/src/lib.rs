//! # verti-world
//!
//! Everything about *worlds and tasks* in verti: the immutable [`World`] description
//! (elevation [`Heightfield`], semantic [`PatchGrid`], [`Obstacle`]s, [`Task`]s and their
//! [`GlobalPath`]s), the procedural generator of the 100-world / 1000-task benchmark set, the
//! versioned on-disk format, and the importer for original Verti-Bench worlds.

pub mod checks;
pub mod error;
pub mod format;
pub mod generate;
pub mod heightfield;
pub mod import_vb;
pub mod input;
pub mod npy;
pub mod obstacle;
pub mod paths;
pub mod scale;
pub mod sets;
pub mod stats;
pub mod surface;
pub mod uniform;
pub mod world;
pub mod yaml;

pub use error::{Result, WorldError};
pub use heightfield::Heightfield;
pub use npy::read_array2;
pub use obstacle::{Face, Obstacle, ObstacleShape};
pub use surface::{Patch, PatchGrid, SoilParams, Surface, TerrainClass};
pub use world::{
    ElevationLevel, GlobalPath, ObstacleDensity, Task, TaskId, TerrainType, World, WorldMeta,
    WorldSource,
};
