//! What VertiAdaptor knows about the terrain under the vehicle (paper §III-B, §IV-A): an
//! elevation patch and a semantic patch of 12.8 m × 12.8 m, centred under the vehicle and
//! aligned with its heading, each reduced to a 64-number latent.
//!
//! * Elevation: the paper's 128 × 128 crop at 0.1 m is taken as 64 × 64 cells of 0.2 m (the
//!   2 × 2 average of the paper's cells; verti's worlds have 1 m vertices, so nothing finer is
//!   lost) and encoded by the shipped SWAE patch encoder `patch-v1` (latent 64, frozen).
//! * Semantics: the paper encodes bird's-eye RGB with a second SWAE. verti knows each patch's
//!   physics directly, so the semantic latent is the physics itself on a 4 × 4 grid of 3.2 m
//!   cells: friction (Coulomb for rigid ground, tan φ for soil), deformable or not, and soil
//!   softness (0 for rigid ground; snow 0.85, mud 0.35, sand 0.14) — 48 numbers. The model's
//!   learned compression maps it to 8, as it maps the elevation latent.
//!
//! Lengths are in full-scale metres: on a world of scale s the patches are 12.8 s wide.

use verti_bench::observation::Pose6;
use verti_nn::patch::PatchEncoder;
use verti_world::{Surface, World};

/// Side of the square patches, full-scale metres.
pub const PATCH_SIDE: f64 = 12.8;
/// Elevation cells per side (the encoder's input).
pub const ELEVATION_CELLS: usize = 64;
/// Length of the elevation latent.
pub const ELEVATION_LATENT: usize = 64;
/// Semantic cells per side.
pub const SEMANTIC_CELLS: usize = 4;
/// Values per semantic cell: friction, deformable, softness.
pub const SEMANTIC_CHANNELS: usize = 3;
/// Length of the semantic latent.
pub const SEMANTIC_LATENT: usize = SEMANTIC_CELLS * SEMANTIC_CELLS * SEMANTIC_CHANNELS;
/// Terrain values per pose: the elevation latent, then the semantic one.
pub const TERRAIN_DIM: usize = ELEVATION_LATENT + SEMANTIC_LATENT;

/// World (x, y) of cell (row, col) of an `n`-cell heading-aligned square of side `side`
/// centred on `pose`: row 0 ahead, column 0 to the left (verti-bench's crop convention).
fn cell_xy(
    pose: &Pose6,
    (s, c): (f64, f64),
    n: usize,
    side: f64,
    row: usize,
    col: usize,
) -> (f64, f64) {
    let cell = side / n as f64;
    let half = 0.5 * (n as f64 - 1.0);
    let ahead = (half - row as f64) * cell;
    let left = (half - col as f64) * cell;
    (pose.x + ahead * c - left * s, pose.y + ahead * s + left * c)
}

/// Soil softness in [0, 1] from the Bekker frictional modulus: 1 − log10(kφ / 1e5) / 2.
fn softness(surface: &Surface) -> f64 {
    match surface {
        Surface::Rigid { .. } => 0.0,
        Surface::Deformable { soil } => {
            (1.0 - (soil.bekker_kphi / 1e5).max(1.0).log10() / 2.0).clamp(0.0, 1.0)
        }
    }
}

/// The 48 semantic values under `pose` (world of length scale `scale`).
pub fn semantic_latent(world: &World, pose: &Pose6, scale: f64, out: &mut [f32]) {
    let sc = pose.yaw.sin_cos();
    let side = PATCH_SIDE * scale;
    for r in 0..SEMANTIC_CELLS {
        for c in 0..SEMANTIC_CELLS {
            let (x, y) = cell_xy(pose, sc, SEMANTIC_CELLS, side, r, c);
            let surface = &world.patches.at(x, y).surface;
            let at = (r * SEMANTIC_CELLS + c) * SEMANTIC_CHANNELS;
            out[at] = surface.effective_friction() as f32;
            out[at + 1] = f32::from(u8::from(surface.is_deformable()));
            out[at + 2] = softness(surface) as f32;
        }
    }
}

/// The 64 × 64 heights (m, world units) of the elevation patch under `pose`.
pub fn elevation_patch(world: &World, pose: &Pose6, scale: f64) -> Vec<f64> {
    let sc = pose.yaw.sin_cos();
    let side = PATCH_SIDE * scale;
    let mut out = Vec::with_capacity(ELEVATION_CELLS * ELEVATION_CELLS);
    for r in 0..ELEVATION_CELLS {
        for c in 0..ELEVATION_CELLS {
            let (x, y) = cell_xy(pose, sc, ELEVATION_CELLS, side, r, c);
            out.push(world.terrain.height_at(x, y));
        }
    }
    out
}

/// Both latents under `pose` into `out` ([`TERRAIN_DIM`] values). Heights are divided by the
/// scale first, so the encoder sees full-scale relief on every world scale.
pub fn terrain_latent(
    world: &World,
    pose: &Pose6,
    scale: f64,
    encoder: &PatchEncoder,
    out: &mut [f32],
) {
    let heights: Vec<f64> = elevation_patch(world, pose, scale)
        .into_iter()
        .map(|h| h / scale)
        .collect();
    out[..ELEVATION_LATENT].copy_from_slice(&encoder.embed(&heights));
    semantic_latent(world, pose, scale, &mut out[ELEVATION_LATENT..TERRAIN_DIM]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_world::{SoilParams, Surface};

    #[test]
    fn softness_orders_the_soils() {
        let s = |soil| softness(&Surface::Deformable { soil });
        let (snow, mud, sand) = (s(SoilParams::SOFT), s(SoilParams::MID), s(SoilParams::HARD));
        assert!(
            snow > mud && mud > sand && sand > 0.0,
            "{snow} {mud} {sand}"
        );
        let rock = Surface::Rigid {
            friction: 0.8,
            restitution: 0.01,
        };
        assert_eq!(softness(&rock), 0.0);
    }

    #[test]
    fn cells_are_heading_aligned() {
        let pose = Pose6 {
            x: 1.0,
            y: 2.0,
            yaw: std::f64::consts::FRAC_PI_2,
            ..Default::default()
        };
        // facing north, row 0 (ahead) lies north of the vehicle and column 0 (left) west
        let (x, y) = cell_xy(&pose, pose.yaw.sin_cos(), 4, 12.8, 0, 0);
        assert!(
            (y - (2.0 + 4.8)).abs() < 1e-9 && (x - (1.0 - 4.8)).abs() < 1e-9,
            "{x} {y}"
        );
    }
}
