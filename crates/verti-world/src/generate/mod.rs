//! Deterministic generation of world sets.
//!
//! A set is a function of (seed, count, scale): the composition (which world gets which
//! elevation level, terrain type and obstacle density) is stratified to the paper's
//! proportions and shuffled with the set seed, and every world then draws from its own
//! sub-streams derived from (seed, world index), so worlds can be generated in parallel and in
//! any order with identical results.

pub mod elevation;
pub mod obstacles;
pub mod semantics;
pub mod sources;

use crate::error::{Result, WorldError};
use crate::heightfield::Heightfield;
use crate::paths::{DEFAULT_CLEARANCE, PlanningGrid};
use crate::scale::check_scale;
use crate::surface::PatchGrid;
use crate::world::{
    ElevationLevel, GlobalPath, ObstacleDensity, PAIRS_PER_WORLD, TASK_CIRCLE_RADIUS, Task,
    TerrainType, World, WorldMeta, WorldSource,
};
use elevation::{ElevationSource, ProceduralRock};
use rayon::prelude::*;
use verti_core::Rng;

/// Vertices per side of every world (129 x 129, 1 m apart at full scale).
pub const GRID_SIZE: usize = 129;
/// Name of the built-in default set.
pub const DEFAULT_SET: &str = "verti-100";

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct SetConfig {
    pub seed: u64,
    pub count: u32,
    pub scale: f64,
    /// Clearance kept by global paths at full scale (multiplied by `scale`).
    pub clearance: f64,
}

impl Default for SetConfig {
    fn default() -> Self {
        SetConfig {
            seed: 0,
            count: 100,
            scale: 1.0,
            clearance: DEFAULT_CLEARANCE,
        }
    }
}

impl SetConfig {
    pub fn validate(&self) -> Result<()> {
        check_scale(self.scale)?;
        if self.count == 0 || self.count > 100_000 {
            return Err(WorldError::Argument(format!(
                "world count {} is out of range: it must be 1..=100000",
                self.count
            )));
        }
        if !self.clearance.is_finite() || self.clearance < 0.0 || self.clearance > 20.0 {
            return Err(WorldError::Argument(format!(
                "clearance {} m is out of range: it must be in [0, 20] (full-scale metres)",
                self.clearance
            )));
        }
        Ok(())
    }
}

/// Splits `count` items into groups by weight with the largest-remainder rule (ties to the
/// first group), so 100 worlds split 1:1:1 are 34/33/33 and 6:3:1 are 60/30/10.
pub fn apportion(count: u32, weights: &[f64]) -> Vec<u32> {
    let total: f64 = weights.iter().sum();
    let exact: Vec<f64> = weights
        .iter()
        .map(|w| w / total * f64::from(count))
        .collect();
    let mut out: Vec<u32> = exact.iter().map(|e| e.floor() as u32).collect();
    let mut left = count - out.iter().sum::<u32>();
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| {
        (exact[b] - exact[b].floor())
            .total_cmp(&(exact[a] - exact[a].floor()))
            .then(a.cmp(&b))
    });
    for i in order {
        if left == 0 {
            break;
        }
        out[i] += 1;
        left -= 1;
    }
    out
}

/// Interleaves categories in exact proportions: at each position, the category furthest behind
/// its target share (ties to the first) gets the slot, so every contiguous block of the result
/// holds nearly the target mix. 100 slots at 6:3:1 give exactly 60/30/10.
fn interleave<T: Copy>(count: usize, values: &[T], weights: &[f64]) -> Vec<T> {
    let total: f64 = weights.iter().sum();
    let mut assigned = vec![0usize; values.len()];
    (0..count)
        .map(|i| {
            let deficit = |k: usize| weights[k] / total * (i + 1) as f64 - assigned[k] as f64;
            let k = (0..values.len()).fold(0, |best, k| {
                if deficit(k) > deficit(best) + 1e-12 {
                    k
                } else {
                    best
                }
            });
            assigned[k] += 1;
            values[k]
        })
        .collect()
}

/// The (level, type, density) of every world of a set, in world order.
///
/// The design is balanced so that the breakdowns of the paper's Fig. 6 compare like with like:
/// elevation level and obstacle density are crossed (each of the 9 cells gets 1/9 of the
/// worlds, largest remainders first, so 100 worlds give 12 + 8 x 11 and the marginals are
/// 34/33/33 each), and terrain types (60/30/10 %) are interleaved through the cells so every
/// cell holds nearly the same type mix. The world order is then shuffled with the set seed.
pub fn composition(config: &SetConfig) -> Vec<(ElevationLevel, TerrainType, ObstacleDensity)> {
    let mut rng = Rng::derive(config.seed, "composition", 0);
    let cells: Vec<(ElevationLevel, ObstacleDensity)> = ElevationLevel::ALL
        .iter()
        .flat_map(|&l| ObstacleDensity::ALL.iter().map(move |&d| (l, d)))
        .collect();
    let mut design = Vec::with_capacity(config.count as usize);
    for (cell, k) in cells.iter().zip(apportion(config.count, &[1.0; 9])) {
        design.extend(std::iter::repeat_n(*cell, k as usize));
    }
    let types = interleave(design.len(), &TerrainType::ALL, &[0.6, 0.3, 0.1]);
    let mut worlds: Vec<(ElevationLevel, TerrainType, ObstacleDensity)> = design
        .into_iter()
        .zip(types)
        .map(|((l, d), t)| (l, t, d))
        .collect();
    rng.shuffle(&mut worlds);
    worlds
}

/// The 10 start/goal pairs on the task circle: start k at k·36°, goal opposite.
pub fn task_pairs(scale: f64) -> Vec<Task> {
    let r = TASK_CIRCLE_RADIUS * scale;
    (0..PAIRS_PER_WORLD)
        .map(|k| {
            let a = (f64::from(k) * 36.0).to_radians();
            let (s, c) = (libm::sin(a), libm::cos(a));
            Task {
                pair: k,
                start: [r * c, r * s],
                goal: [-r * c, -r * s],
            }
        })
        .collect()
}

/// Plans the global path of every task of a world.
pub fn plan_paths(
    world_obstacles: &[crate::Obstacle],
    terrain: &Heightfield,
    tasks: &[Task],
    clearance: f64,
) -> Vec<GlobalPath> {
    let grid = PlanningGrid::new(terrain.size(), terrain.cell(), world_obstacles, clearance);
    tasks
        .iter()
        .map(|t| GlobalPath {
            points: grid.plan(t.start, t.goal).unwrap_or_default(),
        })
        .collect()
}

/// Generates world `index` (1-based) of a set.
pub fn generate_world(
    config: &SetConfig,
    index: u32,
    level: ElevationLevel,
    terrain_type: TerrainType,
    density: ObstacleDensity,
    source: &dyn ElevationSource,
) -> Result<World> {
    // callers may come straight here (Python, benches): a bad scale must be an error, not a
    // panic deep inside the heightfield or the obstacle geometry
    config.validate()?;
    if index == 0 {
        return Err(WorldError::Argument(
            "world indices start at 1, not 0".into(),
        ));
    }
    let scale = config.scale;
    let cell = scale;
    let max_height = level.max_height() * scale;
    let seed = config.seed;
    let fractions = source.generate(
        &mut Rng::derive(seed, "elevation", u64::from(index)),
        GRID_SIZE,
    );
    // elevation sources are pluggable: hold them to their contract (n x n fractions in [0, 1])
    if fractions.len() != GRID_SIZE * GRID_SIZE {
        return Err(WorldError::Argument(format!(
            "elevation source `{}` returned {} heights, expected {}",
            source.name(),
            fractions.len(),
            GRID_SIZE * GRID_SIZE
        )));
    }
    if let Some(k) = fractions
        .iter()
        .position(|f| !(f.is_finite() && (0.0..=1.0).contains(f)))
    {
        return Err(WorldError::Argument(format!(
            "elevation source `{}` returned height fraction {} at row {}, column {}: fractions must be in [0, 1]",
            source.name(),
            fractions[k],
            k / GRID_SIZE,
            k % GRID_SIZE
        )));
    }
    // Heights are rounded to f32 here, the precision of the file format, so a world in memory
    // is bit-identical to the same world loaded back from disk.
    let heights: Vec<f64> = fractions
        .iter()
        .map(|f| f64::from((f * max_height) as f32))
        .collect();
    let terrain = Heightfield::new(GRID_SIZE, cell, heights);
    let patches = semantics::generate_patches(
        &mut Rng::derive(seed, "semantics", u64::from(index)),
        terrain_type,
    );
    let tasks = task_pairs(scale);
    let keep_clear: Vec<[f64; 2]> = tasks.iter().flat_map(|t| [t.start, t.goal]).collect();
    let obstacles = obstacles::place_obstacles(
        &mut Rng::derive(seed, "obstacles", u64::from(index)),
        &terrain,
        density,
        &keep_clear,
        scale,
    )
    .map_err(|e| WorldError::Argument(format!("world {index}: {e}")))?;
    let clearance = config.clearance * scale;
    let paths = plan_paths(&obstacles, &terrain, &tasks, clearance);
    Ok(World {
        meta: WorldMeta {
            name: format!("{}/{:03}", set_name(config), index),
            index,
            source: WorldSource::Generated {
                set_seed: seed,
                generator: source.name().to_string(),
            },
            level,
            terrain_type,
            density,
            scale,
            max_height,
        },
        patches: PatchGrid::new(patches, cell),
        terrain,
        obstacles,
        tasks,
        paths,
        path_clearance: clearance,
    })
}

/// Conventional name of a generated set: `verti-100` for the default, otherwise
/// `verti-{count}-s{seed}` with a scale suffix when not 1.
pub fn set_name(config: &SetConfig) -> String {
    let mut name = if config.seed == 0 {
        format!("verti-{}", config.count)
    } else {
        format!("verti-{}-s{}", config.count, config.seed)
    };
    if (config.scale - 1.0).abs() > 1e-12 {
        name.push_str(&format!(
            "-x{}",
            crate::scale::scale_label(config.scale).replace('/', "_")
        ));
    }
    name
}

/// Generates a whole set in parallel with the default elevation source; `progress` is called
/// once per finished world.
pub fn generate_set(config: &SetConfig, progress: &(dyn Fn() + Sync)) -> Result<Vec<World>> {
    generate_set_with(config, &ProceduralRock::default(), progress)
}

/// The world of a one-world set with default settings: a full-scale world generated on its own
/// in well under a second, for tests, examples and benchmarks.
pub fn one_default_world() -> Result<World> {
    let config = SetConfig {
        count: 1,
        ..Default::default()
    };
    Ok(generate_set(&config, &|| {})?.remove(0))
}

/// [`generate_set`] with another elevation source (see [`sources`]).
pub fn generate_set_with(
    config: &SetConfig,
    source: &dyn ElevationSource,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<World>> {
    config.validate()?;
    let comp = composition(config);
    comp.par_iter()
        .enumerate()
        .map(|(i, &(level, ty, density))| {
            let w = generate_world(config, i as u32 + 1, level, ty, density, source);
            progress();
            w
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apportion_matches_paper_proportions() {
        assert_eq!(apportion(100, &[1.0, 1.0, 1.0]), vec![34, 33, 33]);
        assert_eq!(apportion(100, &[0.6, 0.3, 0.1]), vec![60, 30, 10]);
        assert_eq!(apportion(7, &[0.6, 0.3, 0.1]), vec![4, 2, 1]);
        assert_eq!(apportion(1, &[1.0, 1.0, 1.0]).iter().sum::<u32>(), 1);
    }

    #[test]
    fn composition_is_a_balanced_design() {
        let comp = composition(&SetConfig::default());
        let count = |f: &dyn Fn(&(ElevationLevel, TerrainType, ObstacleDensity)) -> bool| {
            comp.iter().filter(|c| f(c)).count()
        };
        for l in ElevationLevel::ALL {
            for d in ObstacleDensity::ALL {
                let n = count(&|c| c.0 == l && c.2 == d);
                assert!((11..=12).contains(&n), "{l} x {d}: {n}");
            }
            // each level holds 20 ± 1 rigid, 10 ± 1 deformable and 3 ± 1 mixed worlds
            let rigid = count(&|c| c.0 == l && c.1 == TerrainType::Rigid);
            let soil = count(&|c| c.0 == l && c.1 == TerrainType::Deformable);
            let mixed = count(&|c| c.0 == l && c.1 == TerrainType::Mixed);
            assert!(
                (19..=21).contains(&rigid) && (9..=11).contains(&soil) && (2..=4).contains(&mixed),
                "{l}: {rigid} {soil} {mixed}"
            );
        }
        assert_eq!(count(&|c| c.1 == TerrainType::Rigid), 60);
        assert_eq!(count(&|c| c.1 == TerrainType::Mixed), 10);
        // traced by hand: ties (i = 3: 0.4 vs 0.4; i = 4: 0.5 vs 0.5) go to the first category
        assert_eq!(
            interleave(10, &[0u8, 1, 2], &[0.6, 0.3, 0.1]),
            vec![0, 1, 0, 0, 1, 0, 2, 0, 1, 0]
        );
    }

    #[test]
    fn tasks_lie_on_the_circle_opposite() {
        let t = task_pairs(1.0);
        assert_eq!(t.len(), 10);
        for task in &t {
            assert!((task.distance() - 120.0).abs() < 1e-9);
            assert!((task.start[0].hypot(task.start[1]) - 60.0).abs() < 1e-9);
        }
        assert!((t[1].start[1] - 60.0 * 36f64.to_radians().sin()).abs() < 1e-12);
        let small = task_pairs(0.1);
        assert!((small[0].distance() - 12.0).abs() < 1e-9);
    }

    #[test]
    fn bad_configs_are_rejected() {
        assert!(
            SetConfig {
                count: 0,
                ..Default::default()
            }
            .validate()
            .is_err()
        );
        assert!(
            SetConfig {
                scale: -1.0,
                ..Default::default()
            }
            .validate()
            .is_err()
        );
        assert!(
            SetConfig {
                clearance: f64::NAN,
                ..Default::default()
            }
            .validate()
            .is_err()
        );
    }
}
