//! The chassis box's bottom face against the terrain *between* the body lattice points: a ridge
//! or a step edge under the belly that none of the nine bottom points stands on.
//!
//! The lattice (see [`super::body`]) samples the ground under the bottom face at a 3x3 grid,
//! 2.3 m x 1.05 m apart on the HMMWV, and Verti-Bench's terrain has 1 m cells whose vertices
//! differ by up to 0.8 m on high-relief worlds. A ridge between two sample points passes
//! through the belly unseen, so a vehicle that Chrono leaves high-centred drives on.
//!
//! # The contact law
//! Over the bottom face the terrain is a piecewise-linear surface, and the face is a plane, so
//! the terrain's intrusion into the face is largest at terrain vertices (or on the face's
//! boundary). Each terrain vertex under the face therefore stands for the terrain around it:
//! * **Where**: the vertex's vertical projection onto the bottom face; a vertex up to half a
//!   cell outside the face acts at the nearest point of the face, with the terrain height there.
//! * **How much of the face it stands for** (`share`): the overlap of its dual cell (the square
//!   of one cell centred on it, taken along the face's axes) with the face, as a fraction of a
//!   cell. The shares of the vertices tile the face, so they sum to its area in cells, and a
//!   vertex that slides in over the face's edge gains its share gradually (no force jump).
//! * **Depth**: only the part of the terrain the lattice does not already see. The lattice's
//!   view of the ground is the bilinear surface through its nine samples; a vertex's depth is
//!   the smaller of its height above the face and its height above that surface (measured
//!   vertically, turned into the distance along the face normal). On any plane the bilinear
//!   surface *is* the terrain, so these contacts add nothing: on flat or uniformly sloping
//!   ground the body is pushed exactly as before, whatever its attitude.
//! * **Stiffness**: the lattice's nine points share the face, k each, so the face has k·9/A per
//!   unit area; a vertex gets that times its share of cell area, k·9·c²·share/A (0.93 k for a
//!   full cell under the HMMWV's 4.6 x 2.1 m box). Damping scales the same way, so the
//!   contacts of a face split into parts sum to the face's (a damping ratio per area).
//! * **Normal**: the face normal (a terrain vertex pressing on a flat face), friction as for
//!   every body contact: regularised Coulomb with `min(surface μ, chassis μ)`.
//!
//! Only the bottom face, and only while it faces down: a height field has no overhangs, so
//! the ground meets an upright box's other faces only along the bottom face's edges, which
//! the lattice's edge points and the vertices within half a cell of the edge (sampled on the
//! edge) cover; an upturned vehicle has rolled over, and there the lattice acts as before.
//!
//! Only rigid ground: on a deformable patch the chassis passes through the soil, as in
//! Chrono's SCM (see [`super::body`]), down to a floor well below any upright vehicle's
//! reach; vertices on soil patches are left to the lattice.

use crate::friction::surface_mu;
use crate::model::Model;
use crate::terrain::Terrain;
use verti_core::{Mat3, Vec3};

/// Residual depths below this many cells are rounding, not terrain: the bilinear surface and a
/// vertex's own height are computed differently, and on a plane they differ by the rounding of
/// coordinates of up to 100 m (about 1e-14 m). Far below any feature a vehicle can feel.
const ROUNDING: f64 = 1e-9;

/// Below this vertical component of the face normal the face does not face the ground (the
/// vertical projection onto it degenerates); the contacts' depths scale with it, so they have
/// faded out long before.
const MIN_UP: f64 = 1e-3;

/// A body contact to apply: point, normal, depth along the normal, friction coefficient and
/// the contact's share of one lattice point's stiffness and damping.
pub(crate) struct Push {
    pub point: Vec3,
    pub normal: Vec3,
    pub depth: f64,
    pub mu: f64,
    pub share: f64,
}

/// The contacts of the terrain vertices under the bottom face (module docs) handed to `push`,
/// which applies one and says whether it pressed. `bottom`: the nine bottom lattice points
/// (world), in the model's order (x from rear to front, y from right to left within each x);
/// `known`: the ground heights under them already sampled (NaN where not). Returns the number
/// of contacts that pressed.
#[inline]
pub(crate) fn belly_contacts(
    terrain: &Terrain,
    model: &Model,
    rm: &Mat3,
    bottom: &[Vec3],
    known: &[f64; 9],
    mu_body: f64,
    mut push: impl FnMut(Push) -> bool,
) -> u32 {
    let up = rm.col(2);
    if up.z <= MIN_UP || !terrain.rigid_patches {
        return 0;
    }
    let ground = &terrain.ground;
    let cell = ground.cell();
    let margin = 0.5 * cell;
    let (ex, ey) = (rm.col(0), rm.col(1));
    let (hx, hy) = (model.box_half.x, model.box_half.y);
    let centre = bottom[4];
    // rows: the y extent of the face grown by half a cell (where a vertex can have a share);
    // columns are found per row below
    let (rx, ry) = (hx + margin, hy + margin);
    let half_y = rx * ex.y.abs() + ry * ey.y.abs();
    let Some(rows) = ground.rows_in(centre.y - half_y, centre.y + half_y) else {
        return 0;
    };
    let inv_up = 1.0 / up.z;
    let cell_stiffness = 9.0 * cell * cell / (4.0 * hx * hy);
    let patches = terrain.world.patches.patches();
    // the lattice's ground, sampled only once a vertex needs it
    let mut gaps: Option<[f64; 9]> = None;
    let mut pressed = 0;
    // the face's plane as a height over the map: z = centre.z + zx·(x − cx) + zy·(y − cy)
    let (zx, zy) = (-up.x * inv_up, -up.y * inv_up);
    // a vertex has a share when its face coordinates are within half a cell of the face:
    // s·up.z = ey.y·dx − ey.x·dy and t·up.z = ex.x·dy − ex.y·dx, so along a row each is in
    // reach on an interval of dx
    let s_band = Band::new(ey.y, ey.x, rx * up.z);
    let t_band = Band::new(ex.y, ex.x, ry * up.z);
    for r in rows {
        let y = ground.vertex_y(r);
        let dy = y - centre.y;
        let (Some(a), Some(b)) = (s_band.at(dy), t_band.at(dy)) else {
            continue;
        };
        let (xa, xb) = (a.0.max(b.0), a.1.min(b.1));
        if xa > xb {
            continue;
        }
        let Some(cols) = ground.columns_in(centre.x + xa, centre.x + xb) else {
            continue;
        };
        let heights = ground.row_heights(r, &cols);
        let first = *cols.start();
        // the plane's height over the row's first vertex and its step per column
        let (x_first, step) = (ground.vertex_x(first), zx * cell);
        let mut plane = centre.z + zy * dy + zx * (x_first - centre.x);
        for (k, &h) in heights.iter().enumerate() {
            // cheapest test first (most vertices fail it): is the vertex above the face's
            // plane (a screen: the exact gap is computed below)
            let above = h > plane;
            plane += step;
            if !above {
                continue;
            }
            let v = Vec3::new(ground.vertex_x(first + k), y, h);
            let rel = v - centre;
            // face coordinates of the vertical projection: solve rel.xy = s·ex.xy + t·ey.xy
            // (the determinant ex.x·ey.y − ex.y·ey.x is up.z)
            let s = (rel.x * ey.y - rel.y * ey.x) * inv_up;
            let t = (ex.x * rel.y - ex.y * rel.x) * inv_up;
            let share = overlap(s, hx, cell) * overlap(t, hy, cell);
            if share <= 0.0 {
                continue;
            }
            let (sc, tc) = (s.clamp(-hx, hx), t.clamp(-hy, hy));
            let at = centre + ex * sc + ey * tc;
            let h = if sc == s && tc == t {
                v.z
            } else {
                ground.sample(at.x, at.y).0
            };
            let gap = h - at.z;
            if gap <= 0.0 {
                continue;
            }
            // the vertex's own patch (fixed, so a contact cannot flicker as the box moves)
            let patch = ground.patch_index(v.x, v.y);
            let surface = &patches[patch].surface;
            if surface.is_deformable() {
                continue;
            }
            let g = gaps.get_or_insert_with(|| lattice_gaps(terrain, bottom, known));
            let residual = gap - bilinear(g, sc / hx, tc / hy);
            let depth = gap.min(residual);
            if depth <= ROUNDING * cell {
                continue;
            }
            let (depth, normal) = terrain.rigid_exit(at, patch, depth * up.z, up);
            let contact = Push {
                point: at,
                normal,
                depth,
                mu: surface_mu(surface).min(mu_body),
                share: share * cell_stiffness,
            };
            if push(contact) {
                pressed += 1;
            }
        }
    }
    pressed
}

/// Where a face coordinate u, with u·up.z = a·dx − b·dy (dx, dy from the face centre), is
/// within `reach` (times up.z) along a row of vertices: dx ∈ dy·b/a ± reach/|a|.
struct Band {
    /// b/a and reach/|a|; for a face axis (nearly) along y, where the coordinate does not
    /// change along a row (and the division would lose the interval to rounding): None, with
    /// (b, reach) kept for the row test.
    line: Option<(f64, f64)>,
    b: f64,
    reach: f64,
}

impl Band {
    #[inline]
    fn new(a: f64, b: f64, reach: f64) -> Band {
        let line = (a.abs() >= 1e-9).then(|| (b / a, reach / a.abs()));
        Band { line, b, reach }
    }

    /// The interval of dx on the row at `dy`, or `None` when the row is out of reach.
    #[inline]
    fn at(&self, dy: f64) -> Option<(f64, f64)> {
        match self.line {
            Some((slope, half)) => Some((dy * slope - half, dy * slope + half)),
            None => {
                ((self.b * dy).abs() <= self.reach).then_some((f64::NEG_INFINITY, f64::INFINITY))
            }
        }
    }
}

/// Fraction of the interval of one `cell` centred on `s` that lies in \[−half, half\].
#[inline]
fn overlap(s: f64, half: f64, cell: f64) -> f64 {
    let inside = (s + 0.5 * cell).min(half) - (s - 0.5 * cell).max(-half);
    (inside / cell).max(0.0)
}

/// Vertical gaps (terrain height minus point height) at the nine bottom lattice points, with
/// the heights already `known` (NaN: not sampled yet).
#[inline]
fn lattice_gaps(terrain: &Terrain, bottom: &[Vec3], known: &[f64; 9]) -> [f64; 9] {
    let mut g = [0.0; 9];
    for ((gk, p), &h) in g.iter_mut().zip(bottom).zip(known) {
        let h = if h.is_nan() {
            terrain.ground.sample(p.x, p.y).0
        } else {
            h
        };
        *gk = h - p.z;
    }
    g
}

/// The bilinear surface through the 3x3 lattice values `g` at face coordinates (a, b), each in
/// \[−1, 1\] (−1, 0, 1 are the lattice lines).
#[inline]
fn bilinear(g: &[f64; 9], a: f64, b: f64) -> f64 {
    let (i, fa) = if a < 0.0 { (0, a + 1.0) } else { (1, a) };
    let (j, fb) = if b < 0.0 { (0, b + 1.0) } else { (1, b) };
    let k = 3 * i + j;
    (1.0 - fa) * ((1.0 - fb) * g[k] + fb * g[k + 1]) + fa * ((1.0 - fb) * g[k + 3] + fb * g[k + 4])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_tile_a_face() {
        // a 4.6 m x 2.1 m face over 1 m cells: the vertices' shares sum to its area
        for offset in [0.0, 0.13, 0.5, 0.77] {
            let sum: f64 = (-8..=8)
                .flat_map(|i| (-8..=8).map(move |j| (i, j)))
                .map(|(i, j)| {
                    overlap(i as f64 + offset, 2.3, 1.0) * overlap(j as f64 - offset, 1.05, 1.0)
                })
                .sum();
            assert!((sum - 4.6 * 2.1).abs() < 1e-12, "{sum}");
        }
        // a face narrower than a cell: the share is the face's width
        assert!((overlap(0.1, 0.2, 1.0) - 0.4).abs() < 1e-15);
    }

    #[test]
    fn bilinear_hits_the_nodes_and_planes() {
        let plane = |a: f64, b: f64| 0.3 + 0.7 * a - 1.1 * b;
        let mut g = [0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                g[3 * i + j] = plane(i as f64 - 1.0, j as f64 - 1.0);
            }
        }
        for (a, b) in [
            (-1.0, -1.0),
            (0.0, 1.0),
            (0.4, -0.3),
            (-0.9, 0.99),
            (1.0, 1.0),
        ] {
            assert!((bilinear(&g, a, b) - plane(a, b)).abs() < 1e-14);
        }
    }
}
