//! Precomputed, immutable acceleration structures over a world, built once per [`crate::Sim`]:
//! a coarse grid of maximum heights (so contact samples far above the ground are skipped
//! without touching the heightfield), a fast copy of the ground surface, a broad-phase grid of
//! obstacle indices and the soil node layout, bundled with the world as [`Terrain`].

use crate::error::SimError;
use crate::soil::{SOIL_DELTA_FULL_SCALE, SoilLayout};
use crate::soil_edges::{Curb, Disc, SoilEdges};
use std::ops::RangeInclusive;
use std::sync::Arc;
use verti_core::Vec3;
use verti_world::World;

/// The world a vehicle drives on, with the lookup structures the contact stages use.
#[derive(Clone, Debug)]
pub(crate) struct Terrain {
    pub world: Arc<World>,
    pub bound: HeightBound,
    pub ground: Ground,
    /// Broad phase: obstacles within the vehicle's reach of each cell.
    pub obstacles: ObstacleGrid,
    /// `world.obstacles` in the form the contact loops want, same indices.
    pub fast_obstacles: Vec<FastObstacle>,
    /// The soil node grid, when the world has deformable patches.
    pub soil: Option<SoilLayout>,
    /// Whether any patch is rigid (the belly contacts act on rigid ground only).
    pub rigid_patches: bool,
    /// The sides of rigid patches that border soil, when any do.
    pub soil_edges: Option<SoilEdges>,
}

impl Terrain {
    /// `reach`: the vehicle's bounding radius around its centre of mass (plus a margin).
    pub fn new(world: &Arc<World>, reach: f64) -> Result<Terrain, SimError> {
        let soil = if world.patches.has_soil() {
            let delta = SOIL_DELTA_FULL_SCALE * world.meta.scale;
            let layout = SoilLayout::new(world.terrain.half_extent(), delta);
            if layout.chunks > 4096 {
                return Err(SimError::InvalidSetup(format!(
                    "soil grid of {} chunks per side is too large",
                    layout.chunks
                )));
            }
            Some(layout)
        } else {
            None
        };
        Ok(Terrain {
            bound: HeightBound::new(world),
            ground: Ground::new(world),
            fast_obstacles: world.obstacles.iter().map(FastObstacle::new).collect(),
            obstacles: ObstacleGrid::new(world, reach),
            world: Arc::clone(world),
            soil,
            rigid_patches: world
                .patches
                .patches()
                .iter()
                .any(|p| !p.surface.is_deformable()),
            soil_edges: SoilEdges::new(world),
        })
    }

    /// The shortest way out of the ground for a point `p` in patch `patch` that is `depth`
    /// under its surface along `normal`: that, or, in a rigid patch, sideways through a side
    /// it shares with soil (`soil_edges`).
    #[inline]
    pub fn rigid_exit(&self, p: Vec3, patch: usize, depth: f64, normal: Vec3) -> (f64, Vec3) {
        match &self.soil_edges {
            Some(edges) => edges.exit(p, patch, depth, normal),
            None => (depth, normal),
        }
    }

    /// The same for a point `p` of a wheel's tread with axle `axle`: `None` where the wheel
    /// meets a side's edge as a curb instead ([`Terrain::wheel_corner`]).
    #[inline]
    pub fn wheel_rigid_point(
        &self,
        p: Vec3,
        patch: usize,
        depth: f64,
        normal: Vec3,
        axle: Vec3,
    ) -> Option<(f64, Vec3)> {
        match &self.soil_edges {
            Some(edges) => edges.wheel_point(p, patch, depth, normal, axle),
            None => Some((depth, normal)),
        }
    }

    /// `SoilEdges::exit_along`, for worlds with soil edges.
    #[inline]
    pub fn rigid_exit_along(
        &self,
        p: Vec3,
        patch: usize,
        rise: f64,
        slope: (f64, f64),
        u: Vec3,
    ) -> Option<f64> {
        self.soil_edges
            .as_ref()?
            .exit_along(p, patch, rise, slope, u)
    }

    /// A wheel over soil against the top edges of the rigid patches beside it
    /// (`SoilEdges::wheel_corner`).
    #[inline]
    pub fn wheel_corner(&self, wheel: Disc) -> Option<Curb> {
        let edges = self.soil_edges.as_ref()?;
        let hub = wheel.0;
        edges.wheel_corner(
            |x, y| self.ground.height(x, y),
            self.ground.patch_index(hub.x, hub.y),
            wheel,
        )
    }
}

/// Heightfield cells per side of one bound block.
const BLOCK_CELLS: usize = 2;

/// Maximum terrain height per block of 2x2 heightfield cells.
#[derive(Clone, Debug)]
pub struct HeightBound {
    blocks: usize,
    /// 1 / world size of one block \[1/m\].
    inv_block: f64,
    half_extent: f64,
    max: Vec<f64>,
}

impl HeightBound {
    pub fn new(world: &World) -> HeightBound {
        let hf = &world.terrain;
        let n = hf.size();
        let blocks = (n - 1).div_ceil(BLOCK_CELLS);
        let mut max = vec![f64::NEG_INFINITY; blocks * blocks];
        for br in 0..blocks {
            for bc in 0..blocks {
                let mut m = f64::NEG_INFINITY;
                for r in br * BLOCK_CELLS..=((br + 1) * BLOCK_CELLS).min(n - 1) {
                    for c in bc * BLOCK_CELLS..=((bc + 1) * BLOCK_CELLS).min(n - 1) {
                        m = m.max(hf.vertex(r, c));
                    }
                }
                max[br * blocks + bc] = m;
            }
        }
        HeightBound {
            blocks,
            inv_block: 1.0 / (BLOCK_CELLS as f64 * hf.cell()),
            half_extent: hf.half_extent(),
            max,
        }
    }

    /// Block (row, col) of a world point, clamped to the map (off-map points read the edge,
    /// like the heightfield itself).
    #[inline]
    fn block_of(&self, x: f64, y: f64) -> (usize, usize) {
        let m = (self.blocks - 1) as f64;
        // clamp first, then truncate: equals floor for the non-negative values left
        let col = ((x + self.half_extent) * self.inv_block).max(0.0).min(m) as usize;
        let row = ((self.half_extent - y) * self.inv_block).max(0.0).min(m) as usize;
        (row, col)
    }

    /// An upper bound of the terrain height at (x, y).
    #[inline]
    pub fn max_at(&self, x: f64, y: f64) -> f64 {
        let (r, c) = self.block_of(x, y);
        self.max[r * self.blocks + c]
    }

    /// An upper bound of the terrain height over the box \[x0, x1\] x \[y0, y1\].
    pub fn max_in(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
        let (r0, c0) = self.block_of(x0, y1);
        let (r1, c1) = self.block_of(x1, y0);
        let mut m = f64::NEG_INFINITY;
        for r in r0..=r1 {
            for c in c0..=c1 {
                m = m.max(self.max[r * self.blocks + c]);
            }
        }
        m
    }
}

/// A uniform grid over the map listing, per cell, the obstacles whose footprint circle,
/// grown by the vehicle's bounding radius, overlaps the cell. One lookup at the vehicle's
/// centre of mass then gives every obstacle any part of the vehicle could touch.
#[derive(Clone, Debug)]
pub struct ObstacleGrid {
    cells: usize,
    cell: f64,
    origin: f64,
    /// Start offsets into `items` per cell (`cells² + 1` entries, CSR layout).
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl ObstacleGrid {
    /// `reach`: the vehicle's bounding radius around its centre of mass (plus a margin).
    pub fn new(world: &World, reach: f64) -> ObstacleGrid {
        let extent = world.terrain.half_extent() + reach;
        let cell = (2.0 * reach).max(world.terrain.cell() * 2.0);
        let cells = ((2.0 * extent / cell).ceil() as usize).clamp(1, 512);
        let cell = 2.0 * extent / cells as f64;
        let origin = -extent;
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
        for (k, o) in world.obstacles.iter().enumerate() {
            let p = o.position();
            let r = o.radius_xy() + reach;
            let lo_c = (((p.x - r) - origin) / cell).floor().max(0.0) as usize;
            let hi_c = ((((p.x + r) - origin) / cell).floor().max(0.0) as usize).min(cells - 1);
            let lo_r = (((p.y - r) - origin) / cell).floor().max(0.0) as usize;
            let hi_r = ((((p.y + r) - origin) / cell).floor().max(0.0) as usize).min(cells - 1);
            if lo_c > hi_c || lo_r > hi_r {
                continue;
            }
            for row in lo_r..=hi_r {
                for col in lo_c..=hi_c {
                    lists[row * cells + col].push(k as u32);
                }
            }
        }
        let mut starts = Vec::with_capacity(cells * cells + 1);
        let mut items = Vec::new();
        for l in &lists {
            starts.push(items.len() as u32);
            items.extend_from_slice(l);
        }
        starts.push(items.len() as u32);
        ObstacleGrid {
            cells,
            cell,
            origin,
            starts,
            items,
        }
    }

    /// Indices of the obstacles near (x, y); empty off the grid.
    #[inline]
    pub fn near(&self, x: f64, y: f64) -> &[u32] {
        let c = (x - self.origin) / self.cell;
        let r = (y - self.origin) / self.cell;
        if !(c >= 0.0 && r >= 0.0) {
            return &[];
        }
        let (c, r) = (c as usize, r as usize);
        if c >= self.cells || r >= self.cells {
            return &[];
        }
        let k = r * self.cells + c;
        &self.items[self.starts[k] as usize..self.starts[k + 1] as usize]
    }
}

/// A copy of the heightfield's triangle sampling tuned for the inner loops of the engine.
///
/// Same surface as [`verti_world::Heightfield::sample`] (cells split along the south-west to
/// north-east diagonal, off-map points read the edge), but the cell index comes from a
/// truncating cast of an already clamped, non-negative coordinate: on the baseline x86-64
/// target `f64::floor` is a library call, and it was the largest single cost in the profile.
#[derive(Clone, Debug)]
pub struct Ground {
    n: usize,
    cell: f64,
    inv_cell: f64,
    half: f64,
    max_index: f64,
    heights: Vec<f64>,
    /// Per-vertex slopes (dz/dx, dz/dy) by central differences (one-sided at the border), the
    /// vertex normals Chrono smooths its height-map meshes with and SCM uses for its nodes.
    vertex_slopes: Vec<[f64; 2]>,
    /// Patch grid lookup: patches per side, 1 / patch size, half extent of the patch grid.
    patch_inv: f64,
    patch_half: f64,
}

impl Ground {
    pub fn new(world: &World) -> Ground {
        let hf = &world.terrain;
        let n = hf.size();
        let cell = hf.cell();
        let mut vertex_slopes = Vec::with_capacity(n * n);
        for r in 0..n {
            for c in 0..n {
                let (c0, c1) = (c.saturating_sub(1), (c + 1).min(n - 1));
                let (r0, r1) = (r.saturating_sub(1), (r + 1).min(n - 1));
                // x grows with the column, y with decreasing row
                let sx = (hf.vertex(r, c1) - hf.vertex(r, c0)) / ((c1 - c0) as f64 * cell);
                let sy = (hf.vertex(r0, c) - hf.vertex(r1, c)) / ((r1 - r0) as f64 * cell);
                vertex_slopes.push([sx, sy]);
            }
        }
        Ground {
            n,
            cell,
            inv_cell: 1.0 / cell,
            half: 0.5 * (n - 1) as f64,
            max_index: (n - 1) as f64,
            heights: hf.heights().to_vec(),
            vertex_slopes,
            patch_inv: 1.0 / world.patches.patch_size(),
            patch_half: 0.5
                * verti_world::surface::PATCHES_PER_SIDE as f64
                * world.patches.patch_size(),
        }
    }

    /// Height and slopes (dz/dx, dz/dy) at (x, y).
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> (f64, f64, f64) {
        // max/min compile to single instructions (a NaN coordinate reads cell 0, never panics)
        let gc_raw = x * self.inv_cell + self.half;
        let gr_raw = self.half - y * self.inv_cell;
        let gc = gc_raw.max(0.0).min(self.max_index);
        let gr = gr_raw.max(0.0).min(self.max_index);
        // Off the map the ground extends flat-edged: the height no longer changes across the
        // edge, so neither may the slope (the heightfield's own `sample` keeps the edge cell's
        // slope there, which would push a vehicle along with a tilted normal on level ground).
        let keep_x = if gc == gc_raw { 1.0 } else { 0.0 };
        let keep_y = if gr == gr_raw { 1.0 } else { 0.0 };
        let c0 = (gc as usize).min(self.n - 2);
        let r0 = (gr as usize).min(self.n - 2);
        let u = gc - c0 as f64;
        let v = 1.0 - (gr - r0 as f64);
        self.eval(r0 * self.n + c0, u, v, keep_x, keep_y)
    }

    /// Height of the triangle under the point (the surface Chrono builds from a height map)
    /// and slopes interpolated from the vertex slopes, so the normal varies continuously
    /// across cell edges: a wheel rolling over a triangle edge sees no jump in its contact
    /// normal (the seam jitter of physics_spec §5.7). On a plane both are exact.
    /// `base` is the north-west vertex of the cell, (u, v) the position in it (east, north).
    #[inline]
    fn eval(&self, base: usize, u: f64, v: f64, keep_x: f64, keep_y: f64) -> (f64, f64, f64) {
        let n = self.n;
        let (nw, ne, sw, se) = (base, base + 1, base + n, base + n + 1);
        let h = &self.heights;
        let g = &self.vertex_slopes;
        // barycentric weights of (SW, SE or NW, NE) in the cell's two triangles
        let (height, w_sw, w_mid, w_ne, mid) = if u >= v {
            // triangle (SW, SE, NE)
            (
                h[sw] + u * (h[se] - h[sw]) + v * (h[ne] - h[se]),
                1.0 - u,
                u - v,
                v,
                se,
            )
        } else {
            // triangle (SW, NE, NW)
            (
                h[sw] + v * (h[nw] - h[sw]) + u * (h[ne] - h[nw]),
                1.0 - v,
                v - u,
                u,
                nw,
            )
        };
        let sx = w_sw * g[sw][0] + w_mid * g[mid][0] + w_ne * g[ne][0];
        let sy = w_sw * g[sw][1] + w_mid * g[mid][1] + w_ne * g[ne][1];
        (height, sx * keep_x, sy * keep_y)
    }

    /// Size of one heightfield cell \[m\].
    #[inline]
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The rows of vertices whose world y lies in \[y0, y1\], clamped to the map.
    #[inline]
    pub fn rows_in(&self, y0: f64, y1: f64) -> Option<RangeInclusive<usize>> {
        index_span(
            self.half - y1 * self.inv_cell,
            self.half - y0 * self.inv_cell,
            self.max_index,
        )
    }

    /// The columns of vertices whose world x lies in \[x0, x1\], clamped to the map.
    #[inline]
    pub fn columns_in(&self, x0: f64, x1: f64) -> Option<RangeInclusive<usize>> {
        index_span(
            x0 * self.inv_cell + self.half,
            x1 * self.inv_cell + self.half,
            self.max_index,
        )
    }

    /// World x of the vertices of column `col` (`Heightfield::vertex_xy`'s numbers).
    #[inline]
    pub fn vertex_x(&self, col: usize) -> f64 {
        // via i64 (one instruction; the same value, far below 2^53)
        (col as i64 as f64 - self.half) * self.cell
    }

    /// World y of the vertices of row `row` (row 0 = north).
    #[inline]
    pub fn vertex_y(&self, row: usize) -> f64 {
        (self.half - row as i64 as f64) * self.cell
    }

    /// Heights of the vertices of row `row` in the columns `cols` (from [`Ground::columns_in`]).
    #[inline]
    pub fn row_heights(&self, row: usize, cols: &RangeInclusive<usize>) -> &[f64] {
        let base = row * self.n;
        &self.heights[base + *cols.start()..=base + *cols.end()]
    }

    /// A sampler for points on one line of constant y: the row-dependent half of [`Ground::sample`]
    /// is done once (the soil loop samples tens of nodes per row).
    #[inline]
    pub fn row(&self, y: f64) -> GroundRow<'_> {
        let gr_raw = self.half - y * self.inv_cell;
        let gr = gr_raw.max(0.0).min(self.max_index);
        let r0 = (gr as usize).min(self.n - 2);
        GroundRow {
            ground: self,
            base: r0 * self.n,
            v: 1.0 - (gr - r0 as f64),
            keep_y: if gr == gr_raw { 1.0 } else { 0.0 },
        }
    }

    /// Index into `PatchGrid::patches()` of the patch under (x, y) (edge patch off the map).
    #[inline]
    pub fn patch_index(&self, x: f64, y: f64) -> usize {
        let m = (verti_world::surface::PATCHES_PER_SIDE - 1) as f64;
        let col = ((x + self.patch_half) * self.patch_inv).max(0.0).min(m) as usize;
        let row = ((self.patch_half - y) * self.patch_inv).max(0.0).min(m) as usize;
        row * verti_world::surface::PATCHES_PER_SIDE + col
    }
}

/// A height-only probe of the same surface, for contact samples that are usually above the
/// ground (the rigid tyre's fan of points along its tread): the slopes are computed only for
/// the few that touch.
impl Ground {
    /// Exactly the height of [`Ground::sample`] at (x, y), without the slopes.
    #[inline]
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let gc = (x * self.inv_cell + self.half).max(0.0).min(self.max_index);
        let gr = (self.half - y * self.inv_cell).max(0.0).min(self.max_index);
        let c0 = (gc as usize).min(self.n - 2);
        let r0 = (gr as usize).min(self.n - 2);
        let u = gc - c0 as f64;
        let v = 1.0 - (gr - r0 as f64);
        let base = r0 * self.n + c0;
        let (nw, ne, sw, se) = (base, base + 1, base + self.n, base + self.n + 1);
        let h = &self.heights;
        if u >= v {
            h[sw] + u * (h[se] - h[sw]) + v * (h[ne] - h[se])
        } else {
            h[sw] + v * (h[nw] - h[sw]) + u * (h[ne] - h[nw])
        }
    }
}

/// The integers in \[lo, hi\] ∩ \[0, max\] as an inclusive range; `None` when there are none.
/// Clamped before the casts, so truncation is floor and no library call is made.
#[inline]
fn index_span(lo: f64, hi: f64, max: f64) -> Option<RangeInclusive<usize>> {
    // written so that NaN bounds give None
    if !(hi >= 0.0 && lo <= max && lo <= hi) {
        return None;
    }
    // via i64: a single instruction each way on x86-64, where usize takes several
    let lo = lo.max(0.0);
    let mut first = lo as i64;
    if (first as f64) < lo {
        first += 1;
    }
    let last = hi.min(max) as i64;
    (first <= last).then_some(first as usize..=last as usize)
}

/// See [`Ground::row`].
pub struct GroundRow<'a> {
    ground: &'a Ground,
    base: usize,
    v: f64,
    keep_y: f64,
}

impl GroundRow<'_> {
    /// Exactly `Ground::sample(x, y)` for this row's y.
    #[inline]
    pub fn sample(&self, x: f64) -> (f64, f64, f64) {
        let g = self.ground;
        let gc_raw = x * g.inv_cell + g.half;
        let gc = gc_raw.max(0.0).min(g.max_index);
        let keep_x = if gc == gc_raw { 1.0 } else { 0.0 };
        let c0 = (gc as usize).min(g.n - 2);
        g.eval(self.base + c0, gc - c0 as f64, self.v, keep_x, self.keep_y)
    }
}

/// An obstacle in the form the contact loops want: world-frame face planes for rocks (no
/// rotation per query), the vertical axis for trees.
#[derive(Clone, Debug)]
pub struct FastObstacle {
    /// Rock faces as (outward unit normal, offset) in the world frame: inside when every
    /// `n·p − d < 0`. Empty for trees.
    pub faces: Vec<(verti_core::Vec3, f64)>,
    /// Tree: (centre x, centre y, radius, z min, z max).
    pub tree: Option<(f64, f64, f64, f64, f64)>,
    /// Centre and radius of a sphere containing a rock (points outside cannot be inside).
    pub center: verti_core::Vec3,
    pub radius: f64,
}

impl FastObstacle {
    pub fn new(o: &verti_world::Obstacle) -> FastObstacle {
        match o.shape() {
            verti_world::ObstacleShape::Rock { faces, .. } => {
                let (sy, cy) = libm::sincos(o.yaw());
                let p = o.position();
                let faces = faces
                    .iter()
                    .map(|f| {
                        let m = f.normal;
                        let n =
                            verti_core::Vec3::new(cy * m.x - sy * m.y, sy * m.x + cy * m.y, m.z);
                        (n, f.offset + n.dot(p))
                    })
                    .collect();
                let center = p;
                let radius = o
                    .vertices()
                    .iter()
                    .map(|v| (*v - center).norm())
                    .fold(0.0, f64::max);
                FastObstacle {
                    faces,
                    tree: None,
                    center,
                    radius,
                }
            }
            verti_world::ObstacleShape::Tree { radius, height } => {
                let p = o.position();
                FastObstacle {
                    faces: Vec::new(),
                    tree: Some((p.x, p.y, *radius, p.z - 0.5 * height, p.z + 0.5 * height)),
                    center: p,
                    radius: (radius * radius + 0.25 * height * height).sqrt(),
                }
            }
        }
    }

    /// True when an oriented box (centre, rotation with the box axes as columns, half sizes)
    /// is certainly disjoint from the obstacle: it lies entirely outside one face plane of a
    /// rock, or outside a tree's bounding cylinder.
    #[inline]
    pub fn separated_from_box(
        &self,
        center: verti_core::Vec3,
        rot: &verti_core::Mat3,
        half: verti_core::Vec3,
    ) -> bool {
        let (ax, ay, az) = (rot.col(0), rot.col(1), rot.col(2));
        if let Some((cx, cy, radius, z0, z1)) = self.tree {
            // horizontal and vertical extents of the box
            let ex = half.x * ax.x.abs() + half.y * ay.x.abs() + half.z * az.x.abs();
            let ey = half.x * ax.y.abs() + half.y * ay.y.abs() + half.z * az.y.abs();
            let ez = half.x * ax.z.abs() + half.y * ay.z.abs() + half.z * az.z.abs();
            let r = ex.max(ey) * std::f64::consts::SQRT_2;
            let (dx, dy) = (center.x - cx, center.y - cy);
            return dx * dx + dy * dy > (radius + r).powi(2)
                || center.z - ez > z1
                || center.z + ez < z0;
        }
        self.faces.iter().any(|&(n, d)| {
            let support =
                half.x * n.dot(ax).abs() + half.y * n.dot(ay).abs() + half.z * n.dot(az).abs();
            n.dot(center) - d > support
        })
    }

    /// How far a point `p` inside a rock must move along the unit direction `u` to leave it
    /// (the nearest face it exits through); `None` for a tree, for a point outside, or when
    /// `u` leaves through no face.
    #[inline]
    pub fn exit_along(&self, p: verti_core::Vec3, u: verti_core::Vec3) -> Option<f64> {
        if self.tree.is_some() {
            return None;
        }
        let mut best = f64::INFINITY;
        for &(n, d) in &self.faces {
            let inside = d - n.dot(p);
            if inside < 0.0 {
                return None;
            }
            let rate = n.dot(u);
            if rate > 1e-9 {
                best = best.min(inside / rate);
            }
        }
        best.is_finite().then_some(best)
    }

    /// Same contract as `Obstacle::signed_distance`: signed distance (negative inside, exact
    /// inside, a lower bound outside a rock) and the outward normal of the nearest surface.
    #[inline]
    pub fn signed_distance(&self, p: verti_core::Vec3) -> (f64, verti_core::Vec3) {
        use verti_core::Vec3;
        if let Some((cx, cy, radius, z0, z1)) = self.tree {
            let (dx, dy) = (p.x - cx, p.y - cy);
            let r = (dx * dx + dy * dy).sqrt();
            let dr = r - radius;
            let half = 0.5 * (z1 - z0);
            let zc = 0.5 * (z0 + z1);
            let dz = (p.z - zc).abs() - half;
            let radial = if r > 1e-12 {
                Vec3::new(dx / r, dy / r, 0.0)
            } else {
                Vec3::X
            };
            let vertical = Vec3::new(0.0, 0.0, (p.z - zc).signum());
            return if dr > 0.0 && dz > 0.0 {
                let d = (dr * dr + dz * dz).sqrt();
                (d, (radial * dr + vertical * dz) / d)
            } else if dr > dz {
                (dr, radial)
            } else {
                (dz, vertical)
            };
        }
        let mut best = f64::NEG_INFINITY;
        let mut normal = Vec3::Z;
        for &(n, d) in &self.faces {
            let s = n.dot(p) - d;
            if s > best {
                best = s;
                normal = n;
            }
        }
        (best, normal)
    }
}

#[cfg(test)]
mod fast_obstacle_tests {
    use super::*;
    use verti_core::{Rng, Vec3};

    #[test]
    fn matches_world_obstacles() {
        let w = crate::testing::rough_world(1.0, 4, 8.0, crate::testing::RoughSurface::Rigid);
        let mut rng = Rng::new(9);
        for o in &w.obstacles {
            let f = FastObstacle::new(o);
            for _ in 0..50 {
                let p = o.position()
                    + Vec3::new(
                        rng.range(-4.0, 4.0),
                        rng.range(-4.0, 4.0),
                        rng.range(-3.0, 3.0),
                    );
                let (a, na) = f.signed_distance(p);
                let (b, nb) = o.signed_distance(p);
                assert!((a - b).abs() < 1e-9 && (na - nb).norm() < 1e-9, "{a} {b}");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ground_matches_heightfield() {
        let w = crate::testing::rough_world(1.0, 3, 16.0, crate::testing::RoughSurface::Mixed);
        let g = Ground::new(&w);
        let mut rng = verti_core::Rng::new(5);
        for _ in 0..2000 {
            let (x, y) = (rng.range(-64.0, 64.0), rng.range(-64.0, 64.0));
            let a = g.sample(x, y);
            assert!((a.0 - w.terrain.height_at(x, y)).abs() < 1e-9);
            let (r, c) = w.patches.index_at(x, y);
            assert_eq!(g.patch_index(x, y), r * 16 + c);
        }
        // the height probe is the same surface, to the bit
        for _ in 0..2000 {
            let (x, y) = (rng.range(-70.0, 70.0), rng.range(-70.0, 70.0));
            assert_eq!(g.height(x, y), g.sample(x, y).0);
        }
        // the row sampler is the same function
        for _ in 0..500 {
            let (x, y) = (rng.range(-70.0, 70.0), rng.range(-70.0, 70.0));
            assert_eq!(g.row(y).sample(x), g.sample(x, y));
        }
        // slopes are continuous across cell edges: tiny steps never jump
        for _ in 0..500 {
            let (x, y) = (rng.range(-60.0, 60.0), rng.range(-60.0, 60.0));
            let (a, b) = (g.sample(x, y), g.sample(x + 1e-7, y + 1e-7));
            assert!((a.1 - b.1).abs() < 1e-4 && (a.2 - b.2).abs() < 1e-4);
        }
        // off the map: same height as the edge, level across the edge
        let (h, gx, _) = g.sample(80.0, 3.0);
        assert!((h - w.terrain.height_at(64.0, 3.0)).abs() < 1e-9 && gx == 0.0);
        // on a plane the slopes are exact everywhere
        let p = crate::testing::plane_world(1.0, 0.3, -0.2, 0.8);
        let gp = Ground::new(&p);
        for _ in 0..200 {
            let (x, y) = (rng.range(-60.0, 60.0), rng.range(-60.0, 60.0));
            let (_, sx, sy) = gp.sample(x, y);
            assert!((sx - 0.3f64.tan()).abs() < 1e-9 && (sy + 0.2f64.tan()).abs() < 1e-9);
        }
    }
}
