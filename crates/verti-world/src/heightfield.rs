//! The elevation of a world: a square grid of vertex heights, centred on the origin.
//!
//! Vertex (row r, column c) of an n x n grid with spacing `cell` sits at
//! `x = (c - (n-1)/2)·cell`, `y = ((n-1)/2 - r)·cell`: row 0 is north (+Y), column 0 is west
//! (−X), as in Verti-Bench's BMPs. Between vertices the surface is the triangle mesh Chrono
//! builds from a height map: each cell is split along its south-west to north-east diagonal.
//! The surface is therefore continuous everywhere and exact for imported worlds.

use verti_core::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Heightfield {
    n: usize,
    cell: f64,
    heights: Vec<f64>,
}

impl Heightfield {
    /// Builds a grid from row-major heights (row 0 = north). Panics only on programmer error
    /// (length mismatch); file loaders validate before calling.
    pub fn new(n: usize, cell: f64, heights: Vec<f64>) -> Self {
        assert!(n >= 2, "a heightfield needs at least 2x2 vertices");
        assert_eq!(heights.len(), n * n, "heightfield data length");
        assert!(cell > 0.0 && cell.is_finite(), "cell size must be positive");
        Heightfield { n, cell, heights }
    }

    /// Vertices per side.
    #[inline]
    pub fn size(&self) -> usize {
        self.n
    }
    /// Spacing between vertices in metres.
    #[inline]
    pub fn cell(&self) -> f64 {
        self.cell
    }
    /// Half of the side length: the map spans [-half, half] in x and y.
    #[inline]
    pub fn half_extent(&self) -> f64 {
        0.5 * (self.n - 1) as f64 * self.cell
    }
    /// Row-major heights, row 0 = north.
    #[inline]
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }
    #[inline]
    pub fn vertex(&self, row: usize, col: usize) -> f64 {
        self.heights[row * self.n + col]
    }
    /// World (x, y) of a vertex.
    #[inline]
    pub fn vertex_xy(&self, row: usize, col: usize) -> (f64, f64) {
        let h = 0.5 * (self.n - 1) as f64;
        ((col as f64 - h) * self.cell, (h - row as f64) * self.cell)
    }
    /// Continuous grid coordinates (column, row) of a world point, not clamped.
    #[inline]
    pub fn grid_coords(&self, x: f64, y: f64) -> (f64, f64) {
        let h = 0.5 * (self.n - 1) as f64;
        (x / self.cell + h, h - y / self.cell)
    }
    /// Nearest vertex (row, col) of a world point, clamped to the grid.
    pub fn nearest_vertex(&self, x: f64, y: f64) -> (usize, usize) {
        let (c, r) = self.grid_coords(x, y);
        let m = (self.n - 1) as f64;
        (
            r.round().clamp(0.0, m) as usize,
            c.round().clamp(0.0, m) as usize,
        )
    }
    /// True when (x, y) lies on the map.
    #[inline]
    pub fn contains(&self, x: f64, y: f64) -> bool {
        let h = self.half_extent();
        x.abs() <= h && y.abs() <= h
    }
    pub fn min_height(&self) -> f64 {
        self.heights.iter().copied().fold(f64::INFINITY, f64::min)
    }
    pub fn max_height(&self) -> f64 {
        self.heights
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Height and the two slopes (dz/dx, dz/dy) of the triangle under (x, y). Points off the
    /// map read the nearest edge (the terrain extends flat-edged, like Chrono's patches), and
    /// the slope across the edge is zero there, since the height no longer changes along it.
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let (gc_raw, gr_raw) = self.grid_coords(x, y);
        let m = (self.n - 1) as f64;
        let gc = gc_raw.clamp(0.0, m);
        let gr = gr_raw.clamp(0.0, m);
        let (h, hx, hy) = self.sample_on_grid(gc, gr);
        (
            h,
            if gc != gc_raw { 0.0 } else { hx },
            if gr != gr_raw { 0.0 } else { hy },
        )
    }

    /// [`Heightfield::sample`] at grid coordinates already on the map.
    #[inline]
    fn sample_on_grid(&self, gc: f64, gr: f64) -> (f64, f64, f64) {
        // Cell whose north-west vertex is (r0, c0); u runs east, v runs north inside it.
        let c0 = (gc.floor() as usize).min(self.n - 2);
        let r0 = (gr.floor() as usize).min(self.n - 2);
        let u = gc - c0 as f64;
        let v = 1.0 - (gr - r0 as f64);
        let nw = self.vertex(r0, c0);
        let ne = self.vertex(r0, c0 + 1);
        let sw = self.vertex(r0 + 1, c0);
        let se = self.vertex(r0 + 1, c0 + 1);
        let inv = 1.0 / self.cell;
        if u >= v {
            // triangle (SW, SE, NE)
            let dx = se - sw;
            let dy = ne - se;
            (sw + u * dx + v * dy, dx * inv, dy * inv)
        } else {
            // triangle (SW, NE, NW)
            let dy = nw - sw;
            let dx = ne - nw;
            (sw + v * dy + u * dx, dx * inv, dy * inv)
        }
    }

    /// Terrain height at (x, y).
    #[inline]
    pub fn height_at(&self, x: f64, y: f64) -> f64 {
        self.sample(x, y).0
    }

    /// Upward unit normal of the triangle under (x, y).
    #[inline]
    pub fn normal_at(&self, x: f64, y: f64) -> Vec3 {
        let (_, hx, hy) = self.sample(x, y);
        Vec3::new(-hx, -hy, 1.0).normalized()
    }

    /// Slope angle (radians from horizontal) of the triangle under (x, y).
    pub fn slope_at(&self, x: f64, y: f64) -> f64 {
        let (_, hx, hy) = self.sample(x, y);
        (hx * hx + hy * hy).sqrt().atan()
    }

    /// Minimum and maximum height over the axis-aligned box [x0, x1] x [y0, y1] (vertices inside
    /// plus the corners), used to seat obstacles on the ground.
    pub fn range_in_box(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (x, y) in [(x0, y0), (x0, y1), (x1, y0), (x1, y1)] {
            let h = self.height_at(x, y);
            lo = lo.min(h);
            hi = hi.max(h);
        }
        let (c0, r1) = self.grid_coords(x0, y0);
        let (c1, r0) = self.grid_coords(x1, y1);
        let m = (self.n - 1) as f64;
        let (c0, c1) = (
            c0.ceil().clamp(0.0, m) as usize,
            c1.floor().clamp(0.0, m) as usize,
        );
        let (r0, r1) = (
            r0.ceil().clamp(0.0, m) as usize,
            r1.floor().clamp(0.0, m) as usize,
        );
        for r in r0..=r1.max(r0) {
            for c in c0..=c1.max(c0) {
                if r <= r1 && c <= c1 {
                    let h = self.vertex(r, c);
                    lo = lo.min(h);
                    hi = hi.max(h);
                }
            }
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(n: usize, cell: f64, a: f64, b: f64, c: f64) -> Heightfield {
        let mut hf = Vec::with_capacity(n * n);
        let half = 0.5 * (n - 1) as f64;
        for r in 0..n {
            for col in 0..n {
                let x = (col as f64 - half) * cell;
                let y = (half - r as f64) * cell;
                hf.push(a * x + b * y + c);
            }
        }
        Heightfield::new(n, cell, hf)
    }

    #[test]
    fn reproduces_planes_exactly() {
        let hf = plane(9, 0.5, 0.3, -0.2, 1.0);
        for &(x, y) in &[(0.1, 0.2), (-1.73, 1.11), (1.9, -1.99), (0.0, 0.0)] {
            let (h, hx, hy) = hf.sample(x, y);
            assert!((h - (0.3 * x - 0.2 * y + 1.0)).abs() < 1e-12);
            assert!((hx - 0.3).abs() < 1e-12 && (hy + 0.2).abs() < 1e-12);
        }
        let n = hf.normal_at(0.3, 0.3);
        assert!(n.cross(Vec3::new(-0.3, 0.2, 1.0)).norm() < 1e-12 && n.z > 0.0);
    }

    #[test]
    fn vertex_positions_and_orientation() {
        // a single bump at the north-west corner vertex
        let mut h = vec![0.0; 9];
        h[0] = 1.0;
        let hf = Heightfield::new(3, 1.0, h);
        assert_eq!(hf.vertex_xy(0, 0), (-1.0, 1.0));
        assert!((hf.height_at(-1.0, 1.0) - 1.0).abs() < 1e-12);
        assert_eq!(hf.height_at(1.0, -1.0), 0.0);
        // The NW-corner cell splits along SW-NE: the NW triangle sees the bump, the SE one not.
        assert!(hf.height_at(-0.9, 0.9) > 0.5);
        assert_eq!(hf.height_at(-0.1, 0.1), 0.0);
        assert_eq!(hf.nearest_vertex(-0.9, 0.9), (0, 0));
    }

    #[test]
    fn off_map_reads_the_edge() {
        let hf = plane(5, 1.0, 1.0, 0.0, 0.0);
        assert!((hf.height_at(100.0, 0.0) - 2.0).abs() < 1e-12);
        // level beyond the east edge, still sloped along it on the map
        assert_eq!(hf.sample(100.0, 0.5).1, 0.0);
        assert_eq!(hf.sample(1.5, 100.0).1, 1.0);
        assert_eq!(hf.normal_at(100.0, 0.0), Vec3::Z);
        assert!(!hf.contains(2.5, 0.0));
        assert!(hf.contains(2.0, -2.0));
    }
}
