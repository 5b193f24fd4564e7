//! The immutable description of one world and its tasks.

use crate::heightfield::Heightfield;
use crate::obstacle::Obstacle;
use crate::surface::PatchGrid;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Elevation level: the share of the maximum relief a world uses (paper §III-B).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElevationLevel {
    Low,
    Mid,
    High,
}

/// Maximum terrain height at full scale, metres (the "100 %" elevation level).
pub const MAX_RELIEF_FULL_SCALE: f64 = 16.0;

impl ElevationLevel {
    pub const ALL: [ElevationLevel; 3] = [
        ElevationLevel::Low,
        ElevationLevel::Mid,
        ElevationLevel::High,
    ];
    /// 30 / 60 / 100 % of the maximum relief.
    pub fn fraction(self) -> f64 {
        match self {
            ElevationLevel::Low => 0.3,
            ElevationLevel::Mid => 0.6,
            ElevationLevel::High => 1.0,
        }
    }
    /// Maximum height at full scale: 4.8, 9.6 or 16 m.
    pub fn max_height(self) -> f64 {
        MAX_RELIEF_FULL_SCALE * self.fraction()
    }
    pub fn name(self) -> &'static str {
        match self {
            ElevationLevel::Low => "low",
            ElevationLevel::Mid => "mid",
            ElevationLevel::High => "high",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|l| l.name() == s || (s == "medium" && *l == ElevationLevel::Mid))
    }
}

/// Terrain type of a world: which kinds of ground its patches may have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TerrainType {
    Rigid,
    Deformable,
    Mixed,
}

impl TerrainType {
    pub const ALL: [TerrainType; 3] = [
        TerrainType::Rigid,
        TerrainType::Deformable,
        TerrainType::Mixed,
    ];
    pub fn name(self) -> &'static str {
        match self {
            TerrainType::Rigid => "rigid",
            TerrainType::Deformable => "deformable",
            TerrainType::Mixed => "mixed",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == s)
    }
}

/// Obstacle density: how many rocks and trees a world has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObstacleDensity {
    Sparse,
    Medium,
    Dense,
}

impl ObstacleDensity {
    pub const ALL: [ObstacleDensity; 3] = [
        ObstacleDensity::Sparse,
        ObstacleDensity::Medium,
        ObstacleDensity::Dense,
    ];
    /// (rocks, trees): 10 + 1, 20 + 2, 40 + 3.
    pub fn counts(self) -> (usize, usize) {
        match self {
            ObstacleDensity::Sparse => (10, 1),
            ObstacleDensity::Medium => (20, 2),
            ObstacleDensity::Dense => (40, 3),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            ObstacleDensity::Sparse => "sparse",
            ObstacleDensity::Medium => "medium",
            ObstacleDensity::Dense => "dense",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|d| d.name() == s)
    }
}

macro_rules! display_by_name {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result { f.write_str(self.name()) }
        }
    )*};
}
display_by_name!(ElevationLevel, TerrainType, ObstacleDensity);

/// Where a world came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum WorldSource {
    /// Made by `verti world generate`.
    Generated { set_seed: u64, generator: String },
    /// Imported from an original Verti-Bench world.
    VertiBench { config: String, heightmap: String },
}

/// Descriptive facts about a world.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldMeta {
    /// Human-readable name, e.g. `verti-100/042` or `vb/config12_high`.
    pub name: String,
    /// 1-based index in its set (Verti-Bench world id for imports).
    pub index: u32,
    pub source: WorldSource,
    pub level: ElevationLevel,
    pub terrain_type: TerrainType,
    pub density: ObstacleDensity,
    /// Length scale relative to the full-scale (HMMWV) world.
    pub scale: f64,
    /// Height of grey level 255 / the level's ceiling, metres (already scaled).
    pub max_height: f64,
}

/// Start/goal pairs per world.
pub const PAIRS_PER_WORLD: u32 = 10;
/// Radius of the start/goal circle at full scale, metres.
pub const TASK_CIRCLE_RADIUS: f64 = 60.0;

/// Identifies a task: world index (1-based) and pair (0..9).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct TaskId {
    pub world: u32,
    pub pair: u32,
}

impl TaskId {
    /// 1-based global number: world 1 pair 0 is task 1, world 100 pair 9 is task 1000.
    /// World indices start at 1; an unindexed world (0, as in hand-built test worlds) numbers
    /// its tasks like world 1 instead of overflowing.
    pub fn number(self) -> u32 {
        self.world.saturating_sub(1) * PAIRS_PER_WORLD + self.pair + 1
    }
    pub fn from_number(n: u32) -> Option<TaskId> {
        if n == 0 {
            return None;
        }
        Some(TaskId {
            world: (n - 1) / PAIRS_PER_WORLD + 1,
            pair: (n - 1) % PAIRS_PER_WORLD,
        })
    }
}

impl fmt::Display for TaskId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "w{:03}p{}", self.world, self.pair)
    }
}

/// A navigation task: drive from `start` to `goal` (planar world coordinates).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Task {
    pub pair: u32,
    pub start: [f64; 2],
    pub goal: [f64; 2],
}

impl Task {
    /// Heading from start to goal (the initial yaw), radians.
    pub fn start_yaw(&self) -> f64 {
        (self.goal[1] - self.start[1]).atan2(self.goal[0] - self.start[0])
    }
    pub fn distance(&self) -> f64 {
        ((self.goal[0] - self.start[0]).powi(2) + (self.goal[1] - self.start[1]).powi(2)).sqrt()
    }
}

/// A pre-planned global path for a holonomic point mass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GlobalPath {
    /// Waypoints from start to goal, world (x, y).
    pub points: Vec<[f64; 2]>,
}

impl GlobalPath {
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum()
    }
}

/// One world: elevation, semantics, obstacles, tasks and their global paths. Immutable once
/// built; simulators and systems share it behind an `Arc`.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    pub meta: WorldMeta,
    pub terrain: Heightfield,
    pub patches: PatchGrid,
    pub obstacles: Vec<Obstacle>,
    pub tasks: Vec<Task>,
    /// One path per task (same order); empty when no path exists.
    pub paths: Vec<GlobalPath>,
    /// Clearance the paths keep from every obstacle footprint, metres (already scaled).
    pub path_clearance: f64,
}

impl World {
    pub fn task_id(&self, pair: u32) -> TaskId {
        TaskId {
            world: self.meta.index,
            pair,
        }
    }
    /// Class label grid (n x n, Verti-Bench label ids).
    pub fn labels(&self) -> Vec<u8> {
        self.patches.label_grid(self.terrain.size())
    }
    /// Smallest horizontal distance from (x, y) to any obstacle footprint (negative inside).
    pub fn obstacle_distance(&self, x: f64, y: f64) -> f64 {
        self.obstacles
            .iter()
            .map(|o| o.footprint_distance(x, y))
            .fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn task_numbers_round_trip() {
        for n in [1u32, 10, 11, 999, 1000] {
            assert_eq!(TaskId::from_number(n).unwrap().number(), n);
        }
        assert_eq!(
            TaskId::from_number(1000).unwrap(),
            TaskId {
                world: 100,
                pair: 9
            }
        );
        assert_eq!(TaskId::from_number(0), None);
    }

    #[test]
    fn levels() {
        assert_eq!(ElevationLevel::Low.max_height(), 16.0 * 0.3);
        assert_eq!(
            ElevationLevel::from_name("medium"),
            Some(ElevationLevel::Mid)
        );
        assert_eq!(ObstacleDensity::Dense.counts(), (40, 3));
    }
}
