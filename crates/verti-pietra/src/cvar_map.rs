//! CVaR maps (paper §IV-D, §V-D): for every cell of a grid and each of 13 headings, the
//! footprint a vehicle centred there would stand on, its traversability PMFs (a trained model's
//! expected PMF, or the physics prior alone), reduced to the risk-aware values the planner
//! reads: the left-tail CVaR_α of linear and angular traction and the right-tail CVaR_α of
//! |roll| and |pitch|. Stored as a [4, 13, rows, cols] array, plus an OOD mask where the
//! model's latent density is below the lowest it gave a training sample.

use crate::bins::{PARAMS, Pmf};
use crate::dataset::{FEATURES, footprint, footprint_patch};
// the grid, yaw bins, source and spec live in `map_spec` (shared with `map_rows`, which
// `CvarMap::build` calls); `cvar_map::` stays their public path
use crate::map_spec::pmf_cvars;
pub use crate::map_spec::{MapSpec, Region, Source, YAWS, yaw_bin, yaw_of};
use crate::prior::physics_prior;
use rayon::prelude::*;
use verti_world::Heightfield;

/// The risk-aware traversability of a region.
#[derive(Clone, Debug, PartialEq)]
pub struct CvarMap {
    pub region: Region,
    pub alpha: f64,
    /// \[param\]\[yaw\]\[row\]\[col\]: CVaR← of ψ1, ψ2 (traction, [0, 1]) and CVaR→ of ψ3, ψ4 (rad).
    pub values: Vec<f32>,
    /// \[yaw\]\[row\]\[col\]: latent density below the model's lowest training density.
    pub ood: Vec<bool>,
}

/// The CVaR values and OOD flag of one footprint.
pub fn footprint_cvar(
    terrain: &Heightfield,
    spec: &MapSpec,
    source: Source,
    x: f64,
    y: f64,
    yaw: f64,
    scratch: &mut (Vec<f32>, Option<crate::model::TravScratch>),
) -> ([f64; PARAMS], bool) {
    let mut fp = footprint(terrain, &spec.layout, x, y, yaw);
    if spec.surface.is_some() {
        for (k, w) in spec.layout.wheels.iter().enumerate() {
            let (wx, wy) = crate::dataset::offset(x, y, yaw, w[0], w[1]);
            fp.friction[k] = spec.friction_at(wx, wy);
        }
    }
    let physics = physics_prior(&fp, &spec.prior, &spec.bins);
    let (pmf, ood): ([Pmf; PARAMS], bool) = match source {
        Source::Physics => (physics, false),
        Source::Model(m) => {
            scratch.0.resize(FEATURES, 0.0);
            footprint_patch(terrain, x, y, yaw, &mut scratch.0);
            let s = scratch.1.get_or_insert_with(|| m.scratch());
            let p = m.predict(&scratch.0, &physics, s);
            (p.pmf, p.log_density < m.card.ood_log_density)
        }
    };
    (pmf_cvars(&pmf, spec), ood)
}

impl CvarMap {
    /// Computes the map of `region` (rows in parallel; the result does not depend on the
    /// thread count). Many footprints at a time; the values are those of [`footprint_cvar`],
    /// bit for bit.
    pub fn build(terrain: &Heightfield, spec: &MapSpec, source: Source, region: Region) -> CvarMap {
        Self::assemble(spec, region, |r| {
            crate::map_rows::row(terrain, spec, source, region, r)
        })
    }

    /// The same map computed one footprint at a time by [`footprint_cvar`]: the reference the
    /// fast path is tested against.
    pub fn build_reference(
        terrain: &Heightfield,
        spec: &MapSpec,
        source: Source,
        region: Region,
    ) -> CvarMap {
        Self::assemble(spec, region, |r| {
            Self::row(terrain, spec, source, region, r)
        })
    }

    /// Rows (columns then headings, as [`CvarMap::row`] orders them) into the map's layout.
    fn assemble(
        spec: &MapSpec,
        region: Region,
        row: impl Fn(usize) -> (Vec<[f64; PARAMS]>, Vec<bool>) + Sync + Send,
    ) -> CvarMap {
        let plane = region.cells();
        let rows: Vec<(Vec<[f64; PARAMS]>, Vec<bool>)> =
            (0..region.rows).into_par_iter().map(row).collect();
        let mut values = vec![0.0f32; PARAMS * YAWS * plane];
        let mut ood = vec![false; YAWS * plane];
        for (r, (vals, flags)) in rows.into_iter().enumerate() {
            for c in 0..region.cols {
                for k in 0..YAWS {
                    let i = c * YAWS + k;
                    for (p, v) in vals[i].iter().enumerate() {
                        values[(p * YAWS + k) * plane + r * region.cols + c] = *v as f32;
                    }
                    ood[k * plane + r * region.cols + c] = flags[i];
                }
            }
        }
        CvarMap {
            region,
            alpha: spec.alpha,
            values,
            ood,
        }
    }

    /// The same on the calling thread only (what "one core" means in the speed benchmark).
    pub fn build_serial(
        terrain: &Heightfield,
        spec: &MapSpec,
        source: Source,
        region: Region,
    ) -> CvarMap {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a one-thread pool")
            .install(|| Self::build(terrain, spec, source, region))
    }

    fn row(
        terrain: &Heightfield,
        spec: &MapSpec,
        source: Source,
        region: Region,
        r: usize,
    ) -> (Vec<[f64; PARAMS]>, Vec<bool>) {
        let mut scratch = (Vec::new(), None);
        let mut vals = Vec::with_capacity(region.cols * YAWS);
        let mut flags = Vec::with_capacity(region.cols * YAWS);
        let y = region.y0 + r as f64 * region.cell;
        for c in 0..region.cols {
            let x = region.x0 + c as f64 * region.cell;
            for k in 0..YAWS {
                let (v, o) = footprint_cvar(terrain, spec, source, x, y, yaw_of(k), &mut scratch);
                vals.push(v);
                flags.push(o);
            }
        }
        (vals, flags)
    }

    /// Nearest cell of (x, y), if on the map.
    #[inline]
    fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        let g = &self.region;
        let c = ((x - g.x0) / g.cell).round();
        let r = ((y - g.y0) / g.cell).round();
        if c < 0.0 || r < 0.0 || c >= g.cols as f64 || r >= g.rows as f64 {
            return None;
        }
        Some(r as usize * g.cols + c as usize)
    }

    /// CVaR values at (x, y) heading `yaw` (nearest cell and yaw bin); `None` off the map.
    #[inline]
    pub fn at(&self, x: f64, y: f64, yaw: f64) -> Option<[f32; PARAMS]> {
        let i = self.cell_of(x, y)?;
        let k = yaw_bin(yaw);
        let plane = self.region.cells();
        Some(std::array::from_fn(|p| {
            self.values[(p * YAWS + k) * plane + i]
        }))
    }

    /// Whether (x, y) heading `yaw` is out of the model's training distribution.
    #[inline]
    pub fn is_ood(&self, x: f64, y: f64, yaw: f64) -> bool {
        self.cell_of(x, y)
            .is_some_and(|i| self.ood[yaw_bin(yaw) * self.region.cells() + i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bins::param_bins;
    use crate::dataset::WheelLayout;
    use crate::prior::PriorConfig;

    fn spec(alpha: f64) -> MapSpec {
        MapSpec {
            layout: WheelLayout {
                wheels: [[1.7, 0.9], [-1.7, 0.9], [-1.7, -0.9], [1.7, -0.9]],
                track: 1.8,
                wheelbase: 3.4,
            },
            prior: PriorConfig::default(),
            bins: param_bins(),
            alpha,
            surface: None,
        }
    }

    #[test]
    fn yaw_bins_round_trip() {
        for k in 0..YAWS - 1 {
            assert_eq!(yaw_bin(yaw_of(k)), k);
        }
        assert_eq!(yaw_bin(std::f64::consts::PI), 0);
        assert_eq!(yaw_bin(0.2), 6);
    }

    #[test]
    fn a_ramp_has_less_traction_climbing_than_across() {
        // a 15° ramp rising towards +x
        let n = 81;
        let s = 15f64.to_radians().tan();
        let h: Vec<f64> = (0..n * n)
            .map(|i| s * ((i % n) as f64 - 40.0) * 0.5)
            .collect();
        let t = Heightfield::new(n, 0.5, h);
        let m = CvarMap::build(
            &t,
            &spec(0.5),
            Source::Physics,
            Region::around(0.0, 0.0, 1.0, 5, 5),
        );
        let up = m.at(0.0, 0.0, 0.0).unwrap();
        let across = m.at(0.0, 0.0, std::f64::consts::FRAC_PI_2).unwrap();
        assert!(up[0] < across[0], "climbing {up:?} vs across {across:?}");
        assert!(
            up[3] > across[3],
            "pitch climbing {} vs across {}",
            up[3],
            across[3]
        );
        assert!(
            across[2] > up[2],
            "roll across {} vs climbing {}",
            across[2],
            up[2]
        );
        assert!(m.at(100.0, 0.0, 0.0).is_none());
        // a lower α is more pessimistic
        let m2 = CvarMap::build(
            &t,
            &spec(0.1),
            Source::Physics,
            Region::around(0.0, 0.0, 1.0, 5, 5),
        );
        assert!(m2.at(0.0, 0.0, 0.0).unwrap()[0] <= up[0]);
        // parallel and serial builds agree
        assert_eq!(
            m2,
            CvarMap::build_serial(
                &t,
                &spec(0.1),
                Source::Physics,
                Region::around(0.0, 0.0, 1.0, 5, 5)
            )
        );
    }

    #[test]
    fn fast_build_equals_one_footprint_at_a_time_bit_for_bit() {
        // a rough test map, the shipped model, the three baselines of Fig. 7 (no evidence
        // scaling, uniform prior, no flow) and the prior alone; 37 columns: a whole chunk of
        // the batch path, a part chunk with a part group of lanes, and footprints reaching
        // past the map's edge
        let model = crate::shipped::pietra_v1().unwrap();
        let models = ["evora-v1", "pi-v1", "vanilla-v1"].map(|name| {
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
            crate::model::TravModel::load(&dir.join(format!("{name}.yaml"))).unwrap()
        });
        let mut sources = vec![Source::Model(&model), Source::Physics];
        sources.extend(models.iter().map(Source::Model));
        let world = &crate::maps::split_maps(crate::maps::Split::Test)[0];
        let t = &world.terrain;
        let half = t.half_extent();
        for (region, alpha) in [
            (Region::around(0.0, 0.0, 0.5, 37, 6), 0.5),
            (Region::around(half - 4.0, 3.0 - half, 0.39, 37, 4), 0.2),
        ] {
            let spec = spec(alpha);
            for &source in &sources {
                let fast = CvarMap::build(t, &spec, source, region);
                let slow = CvarMap::build_reference(t, &spec, source, region);
                assert_eq!(fast.ood, slow.ood);
                let bits = |m: &CvarMap| m.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&slow));
                // and before the f32 store: the f64 values of one row
                let r = 1;
                let fast_row = crate::map_rows::row(t, &spec, source, region, r);
                let slow_row = CvarMap::row(t, &spec, source, region, r);
                let bits64 = |v: &[[f64; PARAMS]]| {
                    v.iter()
                        .flat_map(|a| a.map(f64::to_bits))
                        .collect::<Vec<_>>()
                };
                assert_eq!(bits64(&fast_row.0), bits64(&slow_row.0));
            }
        }
    }

    /// A grid of 16 x 16 patches whose classes cycle through all ten, each with its class's
    /// physics.
    fn all_classes(cell: f64) -> std::sync::Arc<verti_world::PatchGrid> {
        use verti_world::{Patch, Surface, TerrainClass};
        let patches = (0..256)
            .map(|i| {
                let class = TerrainClass::from_id(i % 10).unwrap();
                let surface = match (class.friction_distribution(), class.soil()) {
                    (Some((mu, _)), _) => Surface::Rigid {
                        friction: mu,
                        restitution: 0.0,
                    },
                    (None, Some(soil)) => Surface::Deformable { soil },
                    (None, None) => unreachable!("every class is rigid or soil"),
                };
                Patch { class, surface }
            })
            .collect();
        std::sync::Arc::new(verti_world::PatchGrid::new(patches, cell))
    }

    #[test]
    fn semantics_follow_friction_and_the_fast_path_matches() {
        // on a 15° ramp, grass everywhere leaves less traction uphill than dirt, concrete more
        let n = 81;
        let slope = 15f64.to_radians().tan();
        let h: Vec<f64> = (0..n * n)
            .map(|i| slope * ((i % n) as f64 - 40.0) * 0.5)
            .collect();
        let ramp = Heightfield::new(n, 0.5, h);
        let uniform = |class: i64| {
            use verti_world::{Patch, Surface, TerrainClass};
            let class = TerrainClass::from_id(class).unwrap();
            let friction = class.friction_distribution().unwrap().0;
            let patch = Patch {
                class,
                surface: Surface::Rigid {
                    friction,
                    restitution: 0.0,
                },
            };
            std::sync::Arc::new(verti_world::PatchGrid::new(vec![patch; 256], 0.5))
        };
        let region = Region::around(0.0, 0.0, 1.0, 5, 5);
        let traction_up = |surface| {
            let spec = MapSpec {
                surface,
                ..spec(0.5)
            };
            CvarMap::build(&ramp, &spec, Source::Physics, region)
                .at(0.0, 0.0, 0.0)
                .unwrap()[0]
        };
        let dirt = traction_up(None);
        let (grass, concrete) = (traction_up(Some(uniform(3))), traction_up(Some(uniform(1))));
        assert!(grass < dirt && dirt < concrete, "{grass} {dirt} {concrete}");
        // dirt classes read as the paper's prior, bit for bit
        assert_eq!(traction_up(Some(uniform(2))).to_bits(), dirt.to_bits());

        // the batched path reads the classes as the one-footprint path does, bit for bit
        let model = crate::shipped::pietra_v1().unwrap();
        let world = &crate::maps::split_maps(crate::maps::Split::Test)[0];
        let t = &world.terrain;
        let sem = MapSpec {
            surface: Some(all_classes(t.cell())),
            ..spec(0.5)
        };
        let region = Region::around(0.0, 0.0, 0.5, 37, 4);
        for source in [Source::Model(&model), Source::Physics] {
            let fast = CvarMap::build(t, &sem, source, region);
            let slow = CvarMap::build_reference(t, &sem, source, region);
            let bits = |m: &CvarMap| m.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast), bits(&slow));
            // and the classes changed the map
            let plain = CvarMap::build(t, &spec(0.5), source, region);
            assert_ne!(bits(&fast), bits(&plain));
        }
    }
}
