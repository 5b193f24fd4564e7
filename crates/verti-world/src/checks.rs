//! Consistency rules a loaded world must satisfy beyond "every number is finite": values that
//! parse but cannot describe a real verti world (a 1e30 m spike, a "high" world whose ceiling is
//! a low world's, cells that do not match the scale) are refused with the value named, since
//! every generated and imported world satisfies them and the simulator would otherwise run on
//! nonsense without a word.
//!
//! Measured on the 100 worlds of verti-100 at scales 1, 1/6 and 1/10 and the 80 original
//! Verti-Bench worlds: heights run from 0 to at most 47 % of `max_height`, `max_height` is
//! exactly the level's ceiling times the scale, cells are exactly the scale, obstacles stand on
//! the map and touch the terrain's height band, and path points lie on the map.

use crate::error::{Result, WorldError};
use crate::obstacle::Obstacle;
use crate::world::ElevationLevel;
use std::path::Path;

/// Relative slack for values stored as f32 (heights) or recomputed in f64.
const REL_TOL: f64 = 1e-6;

/// The vertices per side of every world: 16 x 16 patches of 8 cells (the semantic grid and the
/// label layout assume it).
pub const WORLD_GRID: usize = 129;

/// `grid.size` must be 129: other sizes parse, but the 16 x 16 patches of 8 cells would cover
/// only part of the map or overrun it.
pub fn check_grid_size(mpath: &Path, n: usize) -> Result<()> {
    if n != WORLD_GRID {
        return Err(WorldError::invalid(
            mpath,
            "grid.size",
            format!(
                "{n} vertices per side: verti worlds are {WORLD_GRID} x {WORLD_GRID} (16 x 16 patches of 8 cells)"
            ),
        ));
    }
    Ok(())
}

/// A world at scale s has cells of s metres (1 m at full scale).
pub fn check_cell(mpath: &Path, cell: f64, scale: f64) -> Result<()> {
    if (cell - scale).abs() > REL_TOL * scale {
        return Err(WorldError::invalid(
            mpath,
            "grid.cell",
            format!(
                "{cell} m does not match scale {scale}: a world at scale s has cells of s metres (1 m at full scale)"
            ),
        ));
    }
    Ok(())
}

/// The level names the world's ceiling: 4.8, 9.6 or 16 m at full scale, times the scale.
pub fn check_level(mpath: &Path, level: ElevationLevel, max_height: f64, scale: f64) -> Result<()> {
    let want = level.max_height() * scale;
    if (max_height - want).abs() > REL_TOL * want {
        let matching = ElevationLevel::ALL
            .into_iter()
            .find(|l| (l.max_height() * scale - max_height).abs() <= REL_TOL * max_height);
        return Err(WorldError::invalid(
            mpath,
            "level",
            format!(
                "`{level}` contradicts max_height {max_height} m: a {level} world at scale {scale} has max_height {want} m{}",
                matching.map_or(String::new(), |l| format!(
                    " ({max_height} m is the ceiling of a {l} world)"
                ))
            ),
        ));
    }
    Ok(())
}

/// Heights are finite and run from 0 (grey 0) to `max_height` (grey 255).
pub fn check_heights(epath: &Path, heights: &[f64], n: usize, max_height: f64) -> Result<()> {
    let top = max_height * (1.0 + REL_TOL);
    if let Some(i) = heights
        .iter()
        .position(|h| !(h.is_finite() && (0.0..=top).contains(h)))
    {
        let h = heights[i];
        let why = if !h.is_finite() {
            "is not a finite number".to_string()
        } else if h < 0.0 {
            "is below 0: heights run from 0 to the world's max_height (shift the terrain up)"
                .to_string()
        } else {
            format!("is above the world's max_height {max_height} m")
        };
        return Err(WorldError::invalid(
            epath,
            "data",
            format!("height at row {}, column {} is {h} m: {why}", i / n, i % n),
        ));
    }
    Ok(())
}

/// An obstacle stands on the map, is smaller than the map, and reaches into the terrain's
/// height band (one that floats above the highest ground or lies below the lowest is a typo).
pub fn check_obstacle(
    mpath: &Path,
    k: usize,
    o: &Obstacle,
    half_extent: f64,
    ground: (f64, f64),
) -> Result<()> {
    let p = o.position();
    let field = format!("obstacles[{k}]");
    if p.x.abs() > half_extent || p.y.abs() > half_extent {
        return Err(WorldError::invalid(
            mpath,
            field,
            format!(
                "position ({}, {}) is off the map (|x|, |y| <= {half_extent})",
                p.x, p.y
            ),
        ));
    }
    if !o.radius_xy().is_finite() || o.radius_xy() > half_extent {
        return Err(WorldError::invalid(
            mpath,
            field,
            format!("is {} m across, wider than the map", 2.0 * o.radius_xy()),
        ));
    }
    let (z0, z1) = o.z_range();
    let slack = REL_TOL * (1.0 + ground.1.abs());
    if !(z0.is_finite() && z1.is_finite()) || z0 > ground.1 + slack || z1 < ground.0 - slack {
        return Err(WorldError::invalid(
            mpath,
            field,
            format!(
                "spans heights {z0}..{z1} m, which does not touch the terrain ({}..{} m): it floats or is buried",
                ground.0, ground.1
            ),
        ));
    }
    Ok(())
}

/// Path points lie on the map.
pub fn check_path_points(mpath: &Path, k: usize, points: &[[f64; 2]], half: f64) -> Result<()> {
    let edge = half * (1.0 + REL_TOL);
    if let Some(q) = points.iter().find(|q| {
        !(q[0].is_finite() && q[1].is_finite() && q[0].abs() <= edge && q[1].abs() <= edge)
    }) {
        return Err(WorldError::invalid(
            mpath,
            format!("paths.paths[{k}].points"),
            format!("{q:?} is not a finite point on the map (|x|, |y| <= {half})"),
        ));
    }
    Ok(())
}

/// The clearance is a length in [0, 20] full-scale metres, like the generator's.
pub fn check_clearance(mpath: &Path, clearance: f64, scale: f64) -> Result<()> {
    let top = 20.0 * scale;
    if !(clearance.is_finite() && clearance >= 0.0 && clearance <= top * (1.0 + REL_TOL)) {
        return Err(WorldError::invalid(
            mpath,
            "paths.clearance",
            format!("{clearance} m is outside [0, {top}] (0 to 20 m at full scale)"),
        ));
    }
    Ok(())
}
