//! What a CVaR map is computed over and from: the grid of cells ([`Region`]), the 13 yaw bins,
//! where the PMFs come from ([`Source`]) and the rest of the [`MapSpec`]; and the reduction of
//! one footprint's PMFs to the four CVaRs the map stores. Apart from `cvar_map` because both
//! it and the fast row code of `map_rows`, which `CvarMap::build` calls, need them. Public
//! through `crate::cvar_map`.

use crate::bins::{Bins, PARAMS, Pmf};
use crate::cvar::{cvar_left, cvar_right};
use crate::dataset::WheelLayout;
use crate::model::TravModel;
use crate::prior::PriorConfig;
use verti_world::Heightfield;

/// Headings per cell: −180° to 180° in steps of 30°, both ends kept (the paper's 13).
pub const YAWS: usize = 13;

/// The heading of yaw bin `k`, radians.
pub fn yaw_of(k: usize) -> f64 {
    -std::f64::consts::PI + k as f64 * std::f64::consts::PI / 6.0
}

/// The nearest yaw bin to a heading.
pub fn yaw_bin(yaw: f64) -> usize {
    let a = (yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
    ((a / (std::f64::consts::PI / 6.0)).round() as usize).min(YAWS - 1)
}

/// A grid of cells: `cols` x `rows` of side `cell`, cell (0, 0) centred at (`x0`, `y0`), rows
/// going +y, columns +x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub x0: f64,
    pub y0: f64,
    pub cell: f64,
    pub cols: usize,
    pub rows: usize,
}

impl Region {
    /// The whole square map of `terrain` at `cell` metres.
    pub fn whole(terrain: &Heightfield, cell: f64) -> Region {
        let half = terrain.half_extent();
        let n = ((2.0 * half) / cell).floor() as usize + 1;
        Region {
            x0: -half,
            y0: -half,
            cell,
            cols: n,
            rows: n,
        }
    }
    /// A `cols` x `rows` window centred on (x, y).
    pub fn around(x: f64, y: f64, cell: f64, cols: usize, rows: usize) -> Region {
        Region {
            x0: x - 0.5 * (cols as f64 - 1.0) * cell,
            y0: y - 0.5 * (rows as f64 - 1.0) * cell,
            cell,
            cols,
            rows,
        }
    }
    pub fn cells(&self) -> usize {
        self.cols * self.rows
    }
}

/// Where the PMFs come from.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    /// The physics prior of eq. 18 alone.
    Physics,
    /// A trained model (its posterior includes the prior where it says so).
    Model(&'a TravModel),
}

/// What the map is made of besides the source.
#[derive(Clone, Debug)]
pub struct MapSpec {
    pub layout: WheelLayout,
    pub prior: PriorConfig,
    pub bins: [Bins; PARAMS],
    /// Risk tolerance α ∈ (0, 1] (1: the mean).
    pub alpha: f64,
    /// The world's terrain classes, for the semantics-aware prior (beyond the paper, which
    /// maps dirt only): each wheel's slope limit scales with its ground's friction
    /// ([`crate::prior::slope_limit`]). None: dirt everywhere, the paper's prior.
    pub surface: Option<std::sync::Arc<verti_world::PatchGrid>>,
}

impl MapSpec {
    /// Ground friction under (x, y): the class's (Coulomb μ of rigid ground, tan φ of soil),
    /// or dirt's without semantics.
    #[inline(always)]
    pub fn friction_at(&self, x: f64, y: f64) -> f64 {
        match &self.surface {
            None => crate::prior::DIRT_FRICTION,
            Some(p) => p.at(x, y).surface.effective_friction(),
        }
    }
}

/// The four CVaRs the map stores, of the four PMFs of one footprint.
pub(crate) fn pmf_cvars(pmf: &[Pmf; PARAMS], spec: &MapSpec) -> [f64; PARAMS] {
    std::array::from_fn(|k| {
        let v = spec.bins[k].values();
        if k < 2 {
            cvar_left(&pmf[k], &v, spec.alpha)
        } else {
            cvar_right(&pmf[k], &v, spec.alpha)
        }
    })
}
