//! Deformable soil: Chrono's Soil Contact Model (SCM) on a node grid, physics_spec §1.
//!
//! Nodes sit at `(i·δ, j·δ)` with δ = 0.1 m × world scale. Each node remembers its plastic
//! sinkage and the largest Bekker pressure it has carried (`sigma_yield`). Under a wheel the
//! vertical ray from the node meets the wheel cylinder; the total sinkage gives an elastic
//! trial pressure `K_e·(z − z_plastic)`; above the yield pressure the node follows Bekker's
//! `(K_c/b + K_φ)·zⁿ` and the plastic sinkage grows. Unloading and reloading are elastic, so
//! ruts persist and later wheels roll in them.
//!
//! Storage is copy-on-write: the grid is a table of optional 32x32-node chunks behind `Arc`s,
//! and the table itself is behind an `Arc`. Cloning a [`SoilState`] copies one pointer; the
//! first write after a clone copies the table (pointers only) and the one chunk written. Only
//! nodes under wheels are ever visited, so the cost per step does not depend on the map size.

use std::sync::Arc;

/// Soil node spacing at full scale \[m\] (Verti-Bench's SCM `terrain_delta`).
pub const SOIL_DELTA_FULL_SCALE: f64 = 0.1;

/// Nodes per chunk side.
pub const CHUNK: usize = 32;
const CHUNK_NODES: usize = CHUNK * CHUNK;

/// Per-node memory of one chunk (f32: millimetre-scale quantities, half the memory to copy).
#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    /// Plastic sinkage along the undeformed normal \[m\].
    pub plastic: [f32; CHUNK_NODES],
    /// Largest pressure carried so far \[Pa\].
    pub yield_pressure: [f32; CHUNK_NODES],
    /// Soil heaped onto the node by bulldozing: its undeformed level rose by this much \[m\].
    pub heap: [f32; CHUNK_NODES],
    /// Displaced soil waiting to flow on to the node's neighbours (SCM's mass remainder) \[m\].
    pub remainder: [f32; CHUNK_NODES],
    /// The highest heap the chunk has held: a bound on how far above the undeformed ground
    /// its soil may lie.
    pub max_heap: f32,
}

impl Default for Chunk {
    fn default() -> Self {
        Chunk {
            plastic: [0.0; CHUNK_NODES],
            yield_pressure: [0.0; CHUNK_NODES],
            heap: [0.0; CHUNK_NODES],
            remainder: [0.0; CHUNK_NODES],
            max_heap: 0.0,
        }
    }
}

/// Immutable layout of the node grid over a world.
#[derive(Clone, Copy, Debug)]
pub struct SoilLayout {
    /// Node spacing \[m\].
    pub delta: f64,
    /// Nodes run from index -half to +half on each axis.
    pub half: i64,
    /// Chunks per side.
    pub chunks: usize,
}

impl SoilLayout {
    pub fn new(half_extent: f64, delta: f64) -> SoilLayout {
        let half = (half_extent / delta).ceil() as i64;
        let nodes = (2 * half + 1) as usize;
        SoilLayout {
            delta,
            half,
            chunks: nodes.div_ceil(CHUNK),
        }
    }

    /// (chunk index, index inside the chunk) of node (i, j), or None off the grid.
    #[inline]
    pub fn locate(&self, i: i64, j: i64) -> Option<(usize, usize)> {
        let (a, b) = (i + self.half, j + self.half);
        let n = 2 * self.half + 1;
        if a < 0 || b < 0 || a >= n || b >= n {
            return None;
        }
        let (a, b) = (a as usize, b as usize);
        Some((
            (b / CHUNK) * self.chunks + a / CHUNK,
            (b % CHUNK) * CHUNK + a % CHUNK,
        ))
    }
}

/// What one node remembers (as [`Chunk`] stores it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeState {
    /// Plastic sinkage along the undeformed normal \[m\].
    pub plastic: f64,
    /// Largest pressure carried so far \[Pa\].
    pub yield_pressure: f64,
    /// Soil heaped on the node by bulldozing \[m\].
    pub heap: f64,
    /// Displaced soil waiting to flow on \[m\].
    pub remainder: f64,
}

/// The mutable soil deformation: cheap to clone (one `Arc`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SoilState {
    table: Arc<Vec<Option<Arc<Chunk>>>>,
}

impl SoilState {
    pub fn new(layout: Option<&SoilLayout>) -> SoilState {
        let n = layout.map_or(0, |l| l.chunks * l.chunks);
        SoilState {
            table: Arc::new(vec![None; n]),
        }
    }

    /// Everything a node remembers; untouched nodes read zero.
    #[inline]
    pub fn node(&self, at: (usize, usize)) -> NodeState {
        match &self.table[at.0] {
            Some(c) => NodeState {
                plastic: f64::from(c.plastic[at.1]),
                yield_pressure: f64::from(c.yield_pressure[at.1]),
                heap: f64::from(c.heap[at.1]),
                remainder: f64::from(c.remainder[at.1]),
            },
            None => NodeState::default(),
        }
    }

    /// The chunk holding node `at`, for writing: copies the table and the chunk first if
    /// another state shares them.
    #[inline]
    fn chunk_mut(&mut self, at: (usize, usize)) -> &mut Chunk {
        let table = Arc::make_mut(&mut self.table);
        Arc::make_mut(table[at.0].get_or_insert_with(|| Arc::new(Chunk::default())))
    }

    /// Writes a node's plastic sinkage and yield pressure.
    #[inline]
    pub fn set_node(&mut self, at: (usize, usize), plastic: f64, yield_pressure: f64) {
        let chunk = self.chunk_mut(at);
        chunk.plastic[at.1] = plastic as f32;
        chunk.yield_pressure[at.1] = yield_pressure as f32;
    }

    /// Writes a node's heap and remainder.
    #[inline]
    pub fn set_heap(&mut self, at: (usize, usize), heap: f64, remainder: f64) {
        let chunk = self.chunk_mut(at);
        chunk.heap[at.1] = heap as f32;
        chunk.remainder[at.1] = remainder as f32;
        chunk.max_heap = chunk.max_heap.max(heap as f32);
    }

    /// A bound on the heaps of nodes `i0..=i1` × `j0..=j1` \[m\]: the highest any chunk they
    /// lie in has held (zero on undisturbed soil).
    pub fn max_heap_in(&self, layout: &SoilLayout, (i0, i1, j0, j1): (i64, i64, i64, i64)) -> f64 {
        let n = 2 * layout.half + 1;
        let chunk_of = |i: i64| ((i + layout.half).clamp(0, n - 1) as usize) / CHUNK;
        let mut max = 0.0f32;
        for cj in chunk_of(j0)..=chunk_of(j1) {
            for ci in chunk_of(i0)..=chunk_of(i1) {
                if let Some(c) = &self.table[cj * layout.chunks + ci] {
                    max = max.max(c.max_heap);
                }
            }
        }
        f64::from(max)
    }

    /// Number of chunks that hold deformation.
    pub fn touched_chunks(&self) -> usize {
        self.table.iter().filter(|c| c.is_some()).count()
    }

    /// Number of nodes with non-zero plastic sinkage.
    pub fn deformed_nodes(&self) -> usize {
        self.table
            .iter()
            .flatten()
            .map(|c| c.plastic.iter().filter(|p| **p != 0.0).count())
            .sum()
    }

    /// Largest plastic sinkage anywhere \[m\].
    pub fn max_plastic_sinkage(&self) -> f64 {
        self.table
            .iter()
            .flatten()
            .flat_map(|c| c.plastic.iter())
            .fold(0.0f64, |m, p| m.max(f64::from(*p)))
    }

    /// True when the two states share the same storage (a clone not yet written to).
    pub fn shares_storage_with(&self, other: &SoilState) -> bool {
        Arc::ptr_eq(&self.table, &other.table)
    }
}

/// Bekker pressure for sinkage `z` \[Pa\] with patch size `b` \[m\].
#[inline]
pub fn bekker_pressure(soil: &verti_world::SoilParams, b: f64, z: f64) -> f64 {
    (soil.bekker_kc / b + soil.bekker_kphi) * libm::pow(z.max(0.0), soil.bekker_n)
}

/// Derivative of the Bekker pressure with respect to sinkage \[Pa/m\], from the pressure
/// `sigma` already computed at sinkage `z` (n·σ/z, no second `powf`).
#[inline]
pub fn bekker_slope(soil: &verti_world::SoilParams, sigma: f64, z: f64) -> f64 {
    soil.bekker_n * sigma / z.max(1e-4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clone_shares_until_written() {
        let layout = SoilLayout::new(10.0, 0.1);
        let mut a = SoilState::new(Some(&layout));
        let at = layout.locate(3, -4).unwrap();
        a.set_node(at, 0.05, 1000.0);
        let mut b = a.clone();
        assert!(a.shares_storage_with(&b));
        b.set_node(at, 0.07, 2000.0);
        assert!(!a.shares_storage_with(&b));
        let read = |n: NodeState| (n.plastic, n.yield_pressure);
        assert_eq!(read(a.node(at)), (0.05f32 as f64, 1000.0));
        assert_eq!(read(b.node(at)), (0.07f32 as f64, 2000.0));
        assert_eq!(a.touched_chunks(), 1);
        assert!(layout.locate(1000, 0).is_none());
    }
}
