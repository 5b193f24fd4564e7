//! Obstacle placement (paper §III-D): rocks and trees dropped uniformly over the map, each
//! resampled while it lies within 10 m (scaled) of another obstacle, a start or a goal, then
//! seated on the ground.
//!
//! Rocks are rock-like convex polytopes the size of the reference collision boxes
//! (4.4s x 4.4s x 3.8s, s ~ U(0.7, 1.2)): the half-spaces tangent to a slightly irregular
//! ellipsoid in ~16 jittered directions, each pulled in a little, plus a flat base. Trees are
//! cylinders of the reference tree box's size (1 m wide, 5 m tall).

use crate::heightfield::Heightfield;
use crate::obstacle::{Face, Obstacle, polytope_vertices};
use crate::world::ObstacleDensity;
use libm::{cos, sin, sqrt};
use verti_core::{Rng, Vec3};

/// Minimum centre-to-centre distance between obstacles, and from an obstacle to any start or
/// goal, at full scale (metres).
pub const MIN_SEPARATION: f64 = 10.0;
/// Obstacles are kept inside |x|, |y| <= this (full scale), like the reference.
pub const PLACEMENT_HALF_EXTENT: f64 = 58.0;
/// How deep obstacle bases are set into the ground below its lowest point under them (full scale).
const ROCK_BURY: f64 = 0.3;
const TREE_BURY: f64 = 0.5;
pub const TREE_RADIUS: f64 = 0.5;
pub const TREE_HEIGHT: f64 = 5.0;
const MAX_ATTEMPTS: usize = 10_000;

/// Faces of a rock-like polytope of Verti-Bench scale `s` at world scale `world_scale`, in its
/// local frame (origin at the ellipsoid centre).
pub fn rock_faces(rng: &mut Rng, s: f64, world_scale: f64) -> Vec<Face> {
    let a = 2.2 * s * world_scale * rng.range(0.85, 1.15);
    let b = 2.2 * s * world_scale * rng.range(0.85, 1.15);
    let c = 1.9 * s * world_scale * rng.range(0.9, 1.1);
    let count = 16;
    let golden = std::f64::consts::PI * (3.0 - sqrt(5.0));
    let mut faces = Vec::with_capacity(count + 1);
    for k in 0..count {
        // Fibonacci directions over the upper ~3/4 of the sphere, jittered.
        let z = 1.0 - 1.5 * (k as f64 + 0.5) / count as f64 + 0.08 * rng.normal();
        let z = z.clamp(-0.55, 1.0);
        let r = sqrt((1.0 - z * z).max(0.0));
        let phi = golden * k as f64 + 0.3 * rng.normal();
        let n = Vec3::new(r * cos(phi), r * sin(phi), z).normalized();
        // support of the ellipsoid in direction n, pulled in by up to 12 %
        let h =
            sqrt(a * a * n.x * n.x + b * b * n.y * n.y + c * c * n.z * n.z) * rng.range(0.88, 1.0);
        faces.push(Face {
            normal: n,
            offset: h,
        });
    }
    faces.push(Face {
        normal: -Vec3::Z,
        offset: 0.6 * c,
    });
    faces
}

/// Seats a rock: the position that puts its lowest vertex `bury` below the lowest ground under
/// its footprint.
fn seat_rock(
    terrain: &Heightfield,
    faces: Vec<Face>,
    s: f64,
    x: f64,
    y: f64,
    yaw: f64,
    world_scale: f64,
) -> Result<Obstacle, String> {
    let local = polytope_vertices(&faces);
    let reach = local.iter().map(|v| v.norm_xy()).fold(0.0, f64::max);
    let z_min_local = local.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
    let (ground, _) = terrain.range_in_box(x - reach, y - reach, x + reach, y + reach);
    let z = ground - ROCK_BURY * world_scale - z_min_local;
    Obstacle::rock(faces, s, Vec3::new(x, y, z), yaw)
}

fn seat_tree(terrain: &Heightfield, x: f64, y: f64, world_scale: f64) -> Result<Obstacle, String> {
    let r = TREE_RADIUS * world_scale;
    let h = TREE_HEIGHT * world_scale;
    let (ground, _) = terrain.range_in_box(x - r, y - r, x + r, y + r);
    let base = ground - TREE_BURY * world_scale;
    Obstacle::tree(
        r,
        h + TREE_BURY * world_scale,
        Vec3::new(x, y, base + 0.5 * (h + TREE_BURY * world_scale)),
    )
}

/// Places the obstacles of a density. `keep_clear` are the start and goal points.
pub fn place_obstacles(
    rng: &mut Rng,
    terrain: &Heightfield,
    density: ObstacleDensity,
    keep_clear: &[[f64; 2]],
    world_scale: f64,
) -> Result<Vec<Obstacle>, String> {
    let (rocks, trees) = density.counts();
    let min_d = MIN_SEPARATION * world_scale;
    let lim = PLACEMENT_HALF_EXTENT * world_scale;
    let mut centres: Vec<[f64; 2]> = Vec::new();
    let mut out = Vec::with_capacity(rocks + trees);
    for k in 0..rocks + trees {
        let mut placed = None;
        for _ in 0..MAX_ATTEMPTS {
            let p = [rng.range(-lim, lim), rng.range(-lim, lim)];
            let far = |q: &[f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) >= min_d * min_d;
            if centres.iter().all(far) && keep_clear.iter().all(far) {
                placed = Some(p);
                break;
            }
        }
        let p = placed.ok_or_else(|| {
            format!(
                "could not place obstacle {} of {} with {min_d} m separation",
                k + 1,
                rocks + trees
            )
        })?;
        centres.push(p);
        if k < rocks {
            let s = rng.range(0.7, 1.2);
            let faces = rock_faces(rng, s, world_scale);
            let yaw = rng.range(0.0, std::f64::consts::TAU);
            // an error here (a rock too small for f64) names the obstacle instead of panicking
            out.push(
                seat_rock(terrain, faces, s, p[0], p[1], yaw, world_scale)
                    .map_err(|e| format!("rock {}: {e}", k + 1))?,
            );
        } else {
            out.push(
                seat_tree(terrain, p[0], p[1], world_scale)
                    .map_err(|e| format!("tree {}: {e}", k + 1 - rocks))?,
            );
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rocks_are_rock_sized_and_rest_on_the_ground() {
        let terrain = Heightfield::new(
            129,
            1.0,
            (0..129 * 129)
                .map(|i| ((i % 129) as f64 * 0.05).sin())
                .collect(),
        );
        let mut rng = Rng::new(1);
        let obs = place_obstacles(
            &mut rng,
            &terrain,
            ObstacleDensity::Dense,
            &[[60.0, 0.0], [-60.0, 0.0]],
            1.0,
        )
        .unwrap();
        assert_eq!(obs.len(), 43);
        assert_eq!(obs.iter().filter(|o| o.is_rock()).count(), 40);
        for o in &obs {
            let (z0, z1) = o.z_range();
            let p = o.position();
            let (ground_lo, ground_hi) =
                terrain.range_in_box(p.x - 3.0, p.y - 3.0, p.x + 3.0, p.y + 3.0);
            assert!(
                z0 < ground_lo + 1e-9,
                "obstacle floats: base {z0} above ground {ground_lo}"
            );
            assert!(z1 > ground_hi, "obstacle is buried");
            if o.is_rock() {
                let span = 2.0 * o.radius_xy();
                assert!((2.5..=7.5).contains(&span), "rock span {span}");
                assert!(o.vertices().len() >= 8);
            }
        }
    }
}
