//! Terrain shading: per-vertex hillshade and relative height, sampled bilinearly per pixel.

use verti_world::World;

/// Sun elevation of the hillshade; the sun is in the north-west.
const SUN_ELEVATION_DEG: f64 = 40.0;
/// The hillshade exaggerates heights so the 90th-percentile slope reads like this gradient
/// (about 35 degrees); low-relief worlds would otherwise look flat.
const TARGET_GRADIENT: f64 = 0.7;

/// Per-vertex hillshade brightness factor (about 1 on flat ground) and height in 0..1 of the
/// world's range.
pub(super) fn shade_and_height(world: &World) -> (Vec<f64>, Vec<f64>, f64) {
    let hf = &world.terrain;
    let n = hf.size();
    let cell = hf.cell();
    let h = hf.heights();
    let at = |r: usize, c: usize| h[r * n + c];
    let mut grads = Vec::with_capacity(n * n);
    for r in 0..n {
        for c in 0..n {
            // Central differences, one-sided at the border.
            let (c0, c1) = (c.saturating_sub(1), (c + 1).min(n - 1));
            let (r0, r1) = (r.saturating_sub(1), (r + 1).min(n - 1));
            let gx = (at(r, c1) - at(r, c0)) / ((c1 - c0) as f64 * cell);
            // Row 0 is north: +y is towards smaller rows.
            let gy = (at(r0, c) - at(r1, c)) / ((r1 - r0) as f64 * cell);
            grads.push((gx, gy));
        }
    }
    let mut mags: Vec<f64> = grads
        .iter()
        .map(|g| g.0.hypot(g.1))
        .filter(|m| m.is_finite())
        .collect();
    mags.sort_by(f64::total_cmp);
    let p90 = mags.get(mags.len() * 9 / 10).copied().unwrap_or(0.0);
    let exaggeration = if p90 > 1e-9 {
        (TARGET_GRADIENT / p90).clamp(1.0, 200.0)
    } else {
        1.0
    };
    let (se, ce) = (
        SUN_ELEVATION_DEG.to_radians().sin(),
        SUN_ELEVATION_DEG.to_radians().cos(),
    );
    // Unit vector towards the sun: north-west and up.
    let light = (
        -ce * std::f64::consts::FRAC_1_SQRT_2,
        ce * std::f64::consts::FRAC_1_SQRT_2,
        se,
    );
    let shade = grads
        .iter()
        .map(|&(gx, gy)| {
            let (nx, ny, nz) = (-exaggeration * gx, -exaggeration * gy, 1.0);
            let len = (nx * nx + ny * ny + nz * nz).sqrt();
            let lambert = (nx * light.0 + ny * light.1 + nz * light.2) / len;
            if lambert.is_finite() {
                (1.0 + 1.25 * (lambert - se)).clamp(0.3, 1.4)
            } else {
                1.0
            }
        })
        .collect();
    let (lo, hi) = (hf.min_height(), hf.max_height());
    let relief = hi - lo;
    let height = h
        .iter()
        .map(|&v| {
            if relief > 0.0 && relief.is_finite() {
                ((v - lo) / relief).clamp(0.0, 1.0)
            } else {
                0.5
            }
        })
        .collect();
    (shade, height, exaggeration)
}

/// Bilinear sample of a per-vertex grid at continuous (col, row), clamped to the grid.
pub(super) fn bilinear(grid: &[f64], n: usize, gc: f64, gr: f64) -> f64 {
    let m = (n - 1) as f64;
    let (gc, gr) = (gc.clamp(0.0, m), gr.clamp(0.0, m));
    let (c0, r0) = (
        (gc.floor() as usize).min(n - 2),
        (gr.floor() as usize).min(n - 2),
    );
    let (u, v) = (gc - c0 as f64, gr - r0 as f64);
    let g = |r: usize, c: usize| grid[r * n + c];
    (1.0 - v) * ((1.0 - u) * g(r0, c0) + u * g(r0, c0 + 1))
        + v * ((1.0 - u) * g(r0 + 1, c0) + u * g(r0 + 1, c0 + 1))
}
