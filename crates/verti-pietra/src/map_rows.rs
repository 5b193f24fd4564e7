//! One row of a CVaR map, many footprints at a time: the fast path of [`CvarMap::build`].
//!
//! It computes what [`footprint_cvar`] computes for every cell and heading of the row, with the
//! same arithmetic in the same order, so the values are bit-identical (tested in `cvar_map`):
//! * each heading's sines, cosines and offset products are computed once per row, not once per
//!   wheel and patch point of each footprint;
//! * the patches of up to [`CHUNK`] cells of one heading go through each network together,
//!   as matrix-matrix products ([`crate::batch_mlp`]);
//! * the tail after the networks (softmaxes, flow density, posterior, CVaRs) runs four
//!   footprints side by side ([`crate::model_lanes`]);
//! * buffers live in one scratch per row, nothing is allocated per footprint.
//!
//! [`CvarMap::build`]: crate::cvar_map::CvarMap::build
//! [`footprint_cvar`]: crate::cvar_map::footprint_cvar

use crate::batch_mlp::BatchScratch;
use crate::bins::{B, PARAMS, Pmf};
use crate::dataset::{
    FEATURES, PATCH_CELL, PATCH_LENGTH, PATCH_WIDTH, SLOPE_BASE, height_at, height_on_grid,
};
use crate::lanes::{LANES, Lanes};
use crate::map_spec::{MapSpec, Region, Source, YAWS, pmf_cvars, yaw_of};
use crate::model::TravModel;
use crate::model_lanes::{LaneInput, finish_cvars};
use crate::prior::{Footprint, physics_prior};
use verti_world::Heightfield;

/// Cells of one heading whose patches go through the networks together: their activations
/// (at most 84 inputs each) stay in the first-level cache.
const CHUNK: usize = 32;

/// What a heading contributes to every footprint's coordinates: the products `forward · cos`,
/// `left · sin`, … of [`crate::dataset::footprint`] and [`crate::dataset::footprint_patch`],
/// which do not depend on the cell.
struct Heading {
    /// Per wheel: for the wheel and for the points half a slope base ahead and behind it,
    /// (forward · cos, left · sin, forward · sin, left · cos).
    wheel: [[f64; 4]; 4],
    ahead: [f64; 4],
    behind: [f64; 4],
    /// Patch row i: f_i · fx, added to the cell's grid column first.
    col_f: [f64; PATCH_LENGTH],
    /// Patch column j: l_j · lx, added second.
    col_l: [f64; PATCH_WIDTH],
    /// Patch point (i, j): f_i · fy + l_j · ly, subtracted from the cell's grid row.
    row_fl: [f64; FEATURES],
    /// `col_f` and `col_l` of each patch point, for the four-lane lookups.
    point_f: [f64; FEATURES],
    point_l: [f64; FEATURES],
}

impl Heading {
    fn new(spec: &MapSpec, terrain: &Heightfield, yaw: f64) -> Heading {
        let (s, c) = yaw.sin_cos();
        let products = |forward: f64, left: f64| [forward * c, left * s, forward * s, left * c];
        let half_l = 0.5 * (PATCH_LENGTH - 1) as f64;
        let half_w = 0.5 * (PATCH_WIDTH - 1) as f64;
        let k = PATCH_CELL / terrain.cell();
        let (fx, fy) = (c * k, s * k);
        let (lx, ly) = (-s * k, c * k);
        let col_f: [f64; PATCH_LENGTH] = std::array::from_fn(|i| (half_l - i as f64) * fx);
        let col_l: [f64; PATCH_WIDTH] = std::array::from_fn(|j| (half_w - j as f64) * lx);
        Heading {
            point_f: std::array::from_fn(|p| col_f[p / PATCH_WIDTH]),
            point_l: std::array::from_fn(|p| col_l[p % PATCH_WIDTH]),
            col_f,
            col_l,
            wheel: spec.layout.wheels.map(|w| products(w[0], w[1])),
            ahead: products(0.5 * SLOPE_BASE, 0.0),
            behind: products(-0.5 * SLOPE_BASE, 0.0),
            row_fl: std::array::from_fn(|p| {
                let (f, l) = (
                    half_l - (p / PATCH_WIDTH) as f64,
                    half_w - (p % PATCH_WIDTH) as f64,
                );
                f * fy + l * ly
            }),
        }
    }
}

/// `offset` of [`crate::dataset`] with the heading's products: x + f·cos − l·sin,
/// y + f·sin + l·cos.
#[inline(always)]
fn offset(x: f64, y: f64, p: &[f64; 4]) -> (f64, f64) {
    (x + p[0] - p[1], y + p[2] + p[3])
}

/// [`crate::dataset::footprint`] at (x, y) with the heading's products.
#[inline(always)]
fn footprint(terrain: &Heightfield, spec: &MapSpec, h: &Heading, x: f64, y: f64) -> Footprint {
    let mut heights = [0.0; 4];
    let mut slopes = [0.0; 4];
    let mut friction = [crate::prior::DIRT_FRICTION; 4];
    for (k, w) in h.wheel.iter().enumerate() {
        let (wx, wy) = offset(x, y, w);
        heights[k] = height_at(terrain, wx, wy);
        if spec.surface.is_some() {
            friction[k] = spec.friction_at(wx, wy);
        }
        let (ax, ay) = offset(wx, wy, &h.ahead);
        let (bx, by) = offset(wx, wy, &h.behind);
        slopes[k] = ((height_at(terrain, ax, ay) - height_at(terrain, bx, by)) / SLOPE_BASE).atan();
    }
    Footprint {
        heights,
        slopes,
        track: spec.layout.track,
        wheelbase: spec.layout.wheelbase,
        vegetation: [0.0; 4],
        veg_fraction: 0.0,
        friction,
    }
}

/// [`crate::dataset::footprint_patch`]'s features (not its unevenness) with the heading's
/// products.
#[inline(always)]
fn patch(terrain: &Heightfield, h: &Heading, x: f64, y: f64, out: &mut [f32]) {
    let (gc0, gr0) = terrain.grid_coords(x, y);
    let mut z = [0.0f64; FEATURES];
    for (i, cf) in h.col_f.iter().enumerate() {
        let gci = gc0 + cf;
        for (j, cl) in h.col_l.iter().enumerate() {
            let p = i * PATCH_WIDTH + j;
            z[p] = height_on_grid(terrain, gci + cl, gr0 - h.row_fl[p]);
        }
    }
    let mean = z.iter().sum::<f64>() / FEATURES as f64;
    for (o, v) in out.iter_mut().zip(&z) {
        *o = (v - mean) as f32;
    }
}

/// The features of the patches at (`xs[j]`, y) into `out[j * FEATURES..]`.
#[inline(always)]
fn patches(terrain: &Heightfield, h: &Heading, xs: &[f64], y: f64, out: &mut [f32], avx2: bool) {
    #[cfg(target_arch = "x86_64")]
    if avx2 && terrain.size() < 1 << 30 {
        let mut groups = out[..xs.len().div_ceil(4) * 4 * FEATURES].chunks_exact_mut(4 * FEATURES);
        for (j, group) in groups.by_ref().enumerate() {
            let (a, rest) = group.split_at_mut(FEATURES);
            let (b, rest) = rest.split_at_mut(FEATURES);
            let (c, d) = rest.split_at_mut(FEATURES);
            // a last group of fewer than four cells repeats its last cell in the spare lanes
            let gc: [f64; 4] = std::array::from_fn(|k| {
                terrain.grid_coords(xs[(4 * j + k).min(xs.len() - 1)], y).0
            });
            let gr0 = terrain.grid_coords(xs[0], y).1;
            // SAFETY: `avx2` is true only on a CPU with AVX2; the size is checked above.
            unsafe {
                crate::map_simd::patches4(
                    terrain,
                    gc,
                    gr0,
                    &h.point_f,
                    &h.point_l,
                    &h.row_fl,
                    [a, b, c, d],
                )
            };
        }
        return;
    }
    let _ = avx2;
    for (j, x) in xs.iter().enumerate() {
        patch(terrain, h, *x, y, &mut out[j * FEATURES..][..FEATURES]);
    }
}

/// Buffers of one row.
#[derive(Default)]
struct Scratch {
    features: Vec<f32>,
    mlp: BatchScratch,
    z: Vec<f32>,
    logits: Vec<[[f32; B]; PARAMS]>,
    scale: Vec<[f32; PARAMS]>,
    flow: Vec<Lanes>,
    one: Option<crate::model::TravScratch>,
}

/// The row `r` of `region`, in [`crate::cvar_map`]'s order (columns, then headings).
pub(crate) fn row(
    terrain: &Heightfield,
    spec: &MapSpec,
    source: Source,
    region: Region,
    r: usize,
) -> (Vec<[f64; PARAMS]>, Vec<bool>) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { row_avx2(terrain, spec, source, region, r) };
    }
    row_body(terrain, spec, source, region, r, false)
}

/// [`row`] compiled for AVX2 (rounding and conversions in one instruction, wider moves); the
/// arithmetic is the same IEEE operations in the same order, so the same values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn row_avx2(
    terrain: &Heightfield,
    spec: &MapSpec,
    source: Source,
    region: Region,
    r: usize,
) -> (Vec<[f64; PARAMS]>, Vec<bool>) {
    row_body(terrain, spec, source, region, r, true)
}

#[inline(always)]
fn row_body(
    terrain: &Heightfield,
    spec: &MapSpec,
    source: Source,
    region: Region,
    r: usize,
    avx2: bool,
) -> (Vec<[f64; PARAMS]>, Vec<bool>) {
    let mut vals = vec![[0.0; PARAMS]; region.cols * YAWS];
    let mut flags = vec![false; region.cols * YAWS];
    let mut s = Scratch::default();
    let y = region.y0 + r as f64 * region.cell;
    let mut physics = [[[0.0; B]; PARAMS]; CHUNK];
    for k in 0..YAWS {
        let h = Heading::new(spec, terrain, yaw_of(k));
        for c0 in (0..region.cols).step_by(CHUNK) {
            let n = (region.cols - c0).min(CHUNK);
            let xs: [f64; CHUNK] =
                std::array::from_fn(|j| region.x0 + (c0 + j) as f64 * region.cell);
            for (j, p) in physics[..n].iter_mut().enumerate() {
                *p = physics_prior(
                    &footprint(terrain, spec, &h, xs[j], y),
                    &spec.prior,
                    &spec.bins,
                );
            }
            let out = |j: usize| (c0 + j) * YAWS + k;
            match source {
                Source::Physics => {
                    for (j, p) in physics[..n].iter().enumerate() {
                        vals[out(j)] = pmf_cvars(p, spec);
                    }
                }
                Source::Model(m) => {
                    s.features.resize((CHUNK + 3) * FEATURES, 0.0);
                    patches(terrain, &h, &xs[..n], y, &mut s.features, avx2);
                    model_chunk(
                        m,
                        &physics[..n],
                        &mut s,
                        |j, v, o| {
                            vals[out(j)] = v;
                            flags[out(j)] = o;
                        },
                        spec,
                    );
                }
            }
        }
    }
    (vals, flags)
}

/// The model's CVaRs and OOD flags of the `physics.len()` footprints whose features are in
/// `s.features`, handed to `put(index, cvars, ood)`. Inlined into the row, so that an AVX2
/// row runs the lanes of [`finish_cvars`] in 256-bit vectors.
#[inline(always)]
fn model_chunk(
    m: &TravModel,
    physics: &[[Pmf; PARAMS]],
    s: &mut Scratch,
    mut put: impl FnMut(usize, [f64; PARAMS], bool),
    spec: &MapSpec,
) {
    let n = physics.len();
    let Some(nets) = m.batch() else {
        // a network the batch kernel does not run: one footprint at a time
        let one = s.one.get_or_insert_with(|| m.scratch());
        for (j, p) in physics.iter().enumerate() {
            let pred = m.predict(&s.features[j * FEATURES..][..FEATURES], p, one);
            put(
                j,
                pmf_cvars(&pred.pmf, spec),
                pred.log_density < m.card.ood_log_density,
            );
        }
        return;
    };
    let latent = nets.encoder.outputs();
    let (z, zs) = nets.encoder.forward(&s.features, FEATURES, n, &mut s.mlp);
    s.z.clear();
    for j in 0..n {
        s.z.extend_from_slice(&z[j * zs..][..latent]);
    }
    s.logits.resize(n, [[0.0; B]; PARAMS]);
    for (k, dec) in nets.decoders.iter().enumerate() {
        let (l, ls) = dec.forward(&s.z, latent, n, &mut s.mlp);
        for j in 0..n {
            s.logits[j][k].copy_from_slice(&l[j * ls..][..B]);
        }
    }
    s.scale.resize(n, [0.0; PARAMS]);
    if m.card.evidential && m.card.scales_evidence {
        let (l, ls) = nets.scaler.forward(&s.z, latent, n, &mut s.mlp);
        for j in 0..n {
            s.scale[j].copy_from_slice(&l[j * ls..][..PARAMS]);
        }
    }
    for j0 in (0..n).step_by(LANES) {
        // a last group of fewer than four repeats its last footprint in the spare lanes
        let lane = |l: usize| (j0 + l).min(n - 1);
        let input = std::array::from_fn(|l| LaneInput {
            z: &s.z[lane(l) * latent..][..latent],
            logits: &s.logits[lane(l)],
            scale: &s.scale[lane(l)],
            physics: &physics[lane(l)],
        });
        let (cvars, log_density) = finish_cvars(m, input, &spec.bins, spec.alpha, &mut s.flow);
        for l in 0..LANES.min(n - j0) {
            put(j0 + l, cvars[l], log_density[l] < m.card.ood_log_density);
        }
    }
}
