//! The world as a noisy perception stack maps it: built once per trial (map errors persist
//! through a trial, as a mapped error does), from the true world and a seed.

use super::model::PerceptionModel;
use verti_core::Vec3;
use verti_core::rng::Rng;
use verti_world::{Heightfield, Obstacle, Patch, PatchGrid, Surface, TerrainClass, World};

/// Phantom obstacles are posts of this radius and height range (full scale, m): the size of
/// the clutter a detector most often invents (bushes, stumps, sensor artefacts).
const PHANTOM_RADIUS: (f64, f64) = (0.3, 1.0);
const PHANTOM_HEIGHT: f64 = 1.5;

/// A perceived copy of `world`: noisy heights with in-painted holes, confused classes, missed
/// and phantom obstacles. Tasks and paths are kept (the route is given, not perceived).
pub fn perceived_world(world: &World, model: &PerceptionModel, seed: u64) -> World {
    let scale = world.meta.scale;
    World {
        meta: world.meta.clone(),
        terrain: noisy_terrain(&world.terrain, model, scale, seed),
        patches: confused_patches(&world.patches, model, world.terrain.cell(), seed),
        obstacles: seen_obstacles(world, model, seed),
        tasks: world.tasks.clone(),
        paths: world.paths.clone(),
        path_clearance: world.path_clearance,
    }
}

fn noisy_terrain(
    terrain: &Heightfield,
    model: &PerceptionModel,
    scale: f64,
    seed: u64,
) -> Heightfield {
    let e = &model.elevation;
    let n = terrain.size();
    let mut heights = terrain.heights().to_vec();
    if e.sigma > 0.0 {
        let mut rng = Rng::derive(seed, "perception.elevation", 0);
        for h in &mut heights {
            *h += rng.gauss(0.0, e.sigma * scale);
        }
    }
    if e.hole_fraction > 0.0 {
        let mut rng = Rng::derive(seed, "perception.holes", 0);
        let mut hole: Vec<bool> = (0..n * n)
            .map(|_| rng.uniform() < e.hole_fraction)
            .collect();
        // in-paint from the known neighbours, ring by ring, as a mapping stack fills gaps; a
        // hole surrounded by holes waits for a later pass
        while hole.iter().any(|&h| h) {
            let mut filled = Vec::new();
            for r in 0..n {
                for c in 0..n {
                    if !hole[r * n + c] {
                        continue;
                    }
                    let (mut sum, mut count) = (0.0, 0);
                    for (dr, dc) in NEIGHBOURS {
                        let (rr, cc) = (r as i64 + dr, c as i64 + dc);
                        if rr < 0 || cc < 0 || rr >= n as i64 || cc >= n as i64 {
                            continue;
                        }
                        let k = rr as usize * n + cc as usize;
                        if !hole[k] {
                            sum += heights[k];
                            count += 1;
                        }
                    }
                    if count > 0 {
                        filled.push((r * n + c, sum / count as f64));
                    }
                }
            }
            if filled.is_empty() {
                break; // cannot happen with hole_fraction <= 0.9 on a 2x2 grid or larger
            }
            for (k, h) in filled {
                heights[k] = h;
                hole[k] = false;
            }
        }
    }
    Heightfield::new(n, terrain.cell(), heights)
}

const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (0, -1),
    (0, 1),
    (1, -1),
    (1, 0),
    (1, 1),
];

/// The surface a perception stack would assume for `class`: its mean friction if rigid, its
/// soil if deformable (a planner that reads physics from classes reads this).
fn nominal_surface(class: TerrainClass, like: &Surface) -> Surface {
    match (class.friction_distribution(), class.soil()) {
        (Some((friction, _)), _) => Surface::Rigid {
            friction,
            restitution: match like {
                Surface::Rigid { restitution, .. } => *restitution,
                Surface::Deformable { .. } => 0.0,
            },
        },
        (None, Some(soil)) => Surface::Deformable { soil },
        (None, None) => *like,
    }
}

fn confused_patches(
    patches: &PatchGrid,
    model: &PerceptionModel,
    cell: f64,
    seed: u64,
) -> PatchGrid {
    let mut rng = Rng::derive(seed, "perception.semantics", 0);
    let seen: Vec<Patch> = patches
        .patches()
        .iter()
        .map(|p| {
            let truth = p.class.id() as usize;
            let row = model.confusion_row(truth);
            let u = rng.uniform();
            let mut acc = 0.0;
            let mut j = truth;
            for (k, pk) in row.iter().enumerate() {
                acc += pk;
                if u < acc {
                    j = k;
                    break;
                }
            }
            if j == truth {
                return *p;
            }
            let class = TerrainClass::from_id(j as i64).unwrap_or(p.class);
            Patch {
                class,
                surface: nominal_surface(class, &p.surface),
            }
        })
        .collect();
    PatchGrid::new(seen, cell)
}

fn seen_obstacles(world: &World, model: &PerceptionModel, seed: u64) -> Vec<Obstacle> {
    let o = &model.obstacles;
    let mut rng = Rng::derive(seed, "perception.obstacles", 0);
    let mut seen: Vec<Obstacle> = world
        .obstacles
        .iter()
        .filter(|_| rng.uniform() >= o.miss_probability)
        .cloned()
        .collect();
    if o.false_per_hectare > 0.0 {
        let scale = world.meta.scale;
        let half = world.terrain.half_extent();
        let hectares = (2.0 * half / scale).powi(2) / 10_000.0;
        let count = poisson(&mut rng, o.false_per_hectare * hectares);
        for _ in 0..count {
            let (x, y) = (rng.range(-half, half), rng.range(-half, half));
            let radius = rng.range(PHANTOM_RADIUS.0, PHANTOM_RADIUS.1) * scale;
            let height = PHANTOM_HEIGHT * scale;
            let z = world.terrain.height_at(x, y) + 0.5 * height;
            if let Ok(post) = Obstacle::tree(radius, height, Vec3::new(x, y, z)) {
                seen.push(post);
            }
        }
    }
    seen
}

/// A Poisson draw by counting exponential gaps (means here are a few dozen at most).
pub(crate) fn poisson(rng: &mut Rng, mean: f64) -> usize {
    let mut count = 0;
    let mut t = 0.0;
    loop {
        t += -(1.0 - rng.uniform()).ln() / mean;
        if t > 1.0 || count > 100_000 {
            return count;
        }
        count += 1;
    }
}
