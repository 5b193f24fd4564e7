//! # verti-world
//!
//! Everything about *worlds and tasks* in verti: the immutable [`World`] description
//! (elevation [`Heightfield`], semantic [`PatchGrid`], [`Obstacle`]s, [`Task`]s and their
//! [`GlobalPath`]s), the procedural generator of the 100-world / 1000-task benchmark set, the
//! versioned on-disk format, and the importer for original Verti-Bench worlds.
//!
//! # Example
//!
//! One world of the built-in evaluation set, generated on the spot (bit-identical on every
//! machine), with its ten start/goal tasks and the ground under a point:
//!
//! ```
//! let world = verti_world::sets::resolve_world("verti-100:42", 1.0).unwrap();
//! assert_eq!(world.tasks.len(), 10);
//! let task = &world.tasks[0];
//! let z = world.terrain.height_at(task.start[0], task.start[1]);
//! println!(
//!     "{} ({:?}, {:?}, {:?}): first start at {:?}, {z:.2} m up",
//!     world.meta.name, world.meta.level, world.meta.terrain_type, world.meta.density, task.start
//! );
//! ```

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
