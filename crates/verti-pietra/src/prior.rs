//! The physics prior of PIETRA §IV-C (eqs. 15–18, spec §A.5): a traversability PMF per parameter
//! computed from the terrain under the four wheels, with no learning.
//!
//! It is the prior p_phys in the Dirichlet posterior update (eq. 9), so in out-of-distribution
//! terrain, where the learned evidence vanishes, the planner falls back to it; it is also the
//! target of the physics term of the UPI loss (eq. 14).
//!
//! Wheel order is the paper's 1..4 shifted to 0..3: 0 = front-left, 1 = rear-left,
//! 2 = rear-right, 3 = front-right.

use serde::{Deserialize, Serialize};

use crate::bins::{B, Bins, PARAMS, Pmf, uniform};

/// Wheel pairs whose height difference gives the roll (W^{ψ3}): the front pair and the rear pair,
/// each `track` apart. Two pairs, because the terrain contact points are uncertain (Fig. 4c).
pub const ROLL_PAIRS: [(usize, usize); 2] = [(0, 3), (1, 2)];

/// Wheel pairs whose height difference gives the pitch (W^{ψ4}): the left pair and the right
/// pair, each `wheelbase` apart (Fig. 4d).
pub const PITCH_PAIRS: [(usize, usize); 2] = [(0, 1), (3, 2)];

/// What the prior needs to know about the terrain under the robot at one pose; the dataset and
/// the map builder extract it from the height map, the semantics and the robot geometry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Footprint {
    /// Terrain height under each wheel (m), for the roll and pitch estimates of eq. 17.
    pub heights: [f64; 4],
    /// Terrain slope along the robot heading under each wheel (rad). The sign is ignored: uphill
    /// and downhill both reduce traction (eq. 15).
    pub slopes: [f64; 4],
    /// Left–right wheel distance (m): the d_ij of the roll pairs.
    pub track: f64,
    /// Front–rear wheel distance (m): the d_ij of the pitch pairs.
    pub wheelbase: f64,
    /// Vegetation height under each wheel (m), 0 on dirt, for the vegetation traction of eq. 16.
    pub vegetation: [f64; 4],
    /// Fraction r_veg ∈ [0, 1] of vegetation in the footprint; r_dirt = 1 − r_veg (eq. 18).
    pub veg_fraction: f64,
    /// Ground friction under each wheel (Coulomb μ of rigid ground, tan φ of soil). The paper's
    /// maps are all dirt ([`DIRT_FRICTION`]); verti's ten classes scale the slope limits by it
    /// (see [`slope_limit`]).
    #[serde(default = "dirt_everywhere")]
    pub friction: [f64; 4],
}

/// Friction of the paper's dirt (verti's dirt class mean): the ground the slope limits s_max
/// were measured on.
pub const DIRT_FRICTION: f64 = 0.6;

fn dirt_everywhere() -> [f64; 4] {
    [DIRT_FRICTION; 4]
}

/// The slope limit of eq. 15 on ground of friction `mu`: `limit` (measured on dirt) scaled by
/// atan(μ) / atan(μ_dirt), because the steepest slope a wheel can climb before it slides grows
/// as atan(μ) (the friction angle). On dirt it is `limit` exactly; on grass (μ 0.36) a 30°
/// limit becomes 19.2°, on concrete (0.85) 39.3°. A NaN or non-positive μ gives 0: no traction.
#[inline(always)]
pub fn slope_limit(limit: f64, mu: f64) -> f64 {
    if mu == DIRT_FRICTION {
        return limit;
    }
    if mu.is_nan() || mu <= 0.0 {
        return 0.0;
    }
    limit * (mu.atan() / DIRT_FRICTION.atan())
}

/// Constants of the prior. The defaults are the paper's: s_max = 30° (linear) and 15° (angular)
/// from the simulation study, h_max = 0.2 m from the hardware study, and w_unif = 0.2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PriorConfig {
    /// Slope (rad) at which the linear traction prior reaches 0 (s_max of eq. 15 for ψ1).
    pub max_slope_linear: f64,
    /// Slope (rad) at which the angular traction prior reaches 0 (s_max of eq. 15 for ψ2);
    /// smaller than the linear one because turning on a slope loses traction sooner.
    pub max_slope_angular: f64,
    /// Vegetation height (m) at which both traction priors reach 0 (h_max of eq. 16).
    pub max_vegetation: f64,
    /// Weight of the uniform PMF mixed in (w_unif of eq. 18), so the prior is never certain.
    pub w_uniform: f64,
}

impl Default for PriorConfig {
    fn default() -> Self {
        PriorConfig {
            max_slope_linear: 30f64.to_radians(),
            max_slope_angular: 15f64.to_radians(),
            max_vegetation: 0.2,
            w_uniform: 0.2,
        }
    }
}

/// `x` clipped to [0, 1], with NaN mapped to `nan_as`, so every caller states its NaN policy.
#[inline(always)]
fn unit(x: f64, nan_as: f64) -> f64 {
    if x.is_nan() {
        nan_as
    } else {
        x.clamp(0.0, 1.0)
    }
}

/// One-hot traction PMFs of four wheels, ¼ each, from a per-wheel "how far to the limit" value.
/// A NaN traction (bad measurement, or a non-positive limit) is taken as 0, the pessimistic end.
#[inline(always)]
fn wheel_traction(quantity: &[f64; 4], limits: &[f64; 4], bins: &Bins) -> Pmf {
    let mut p = [0.0; B];
    for (&q, &limit) in quantity.iter().zip(limits) {
        let t = unit((limit - q) / limit, 0.0);
        p[bins.index(t)] += 0.25;
    }
    p
}

/// Dirt traction prior of eq. 15: each wheel contributes ¼ on the bin of
/// clip((s_max − |s_i|)/s_max, 0, 1), i.e. traction falls linearly with the slope along the
/// heading. NaN slopes, or s_max ≤ 0, give traction 0 (the pessimistic end).
#[inline(always)]
pub fn dirt_traction(slopes: &[f64; 4], max_slope: f64, bins: &Bins) -> Pmf {
    wheel_traction(&slopes.map(f64::abs), &[max_slope; 4], bins)
}

/// Eq. 15 on ground of any class: each wheel's slope limit is s_max scaled by its ground's
/// friction ([`slope_limit`]). With dirt under every wheel it is [`dirt_traction`], bit for bit.
#[inline(always)]
pub fn ground_traction(slopes: &[f64; 4], max_slope: f64, friction: &[f64; 4], bins: &Bins) -> Pmf {
    wheel_traction(
        &slopes.map(f64::abs),
        &friction.map(|mu| slope_limit(max_slope, mu)),
        bins,
    )
}

/// Vegetation traction prior of eq. 16: each wheel contributes ¼ on the bin of
/// clip((h_max − h_i)/h_max, 0, 1), since taller vegetation slows the robot more. NaN heights,
/// or h_max ≤ 0, give traction 0.
#[inline(always)]
pub fn vegetation_traction(vegetation: &[f64; 4], max_height: f64, bins: &Bins) -> Pmf {
    wheel_traction(vegetation, &[max_height; 4], bins)
}

/// Roll or pitch prior of eq. 17: each wheel pair contributes ½ on the bin of
/// |atan((h_i − h_j)/d)| (absolute, since ψ3, ψ4 ≥ 0). A NaN angle (NaN height, or 0/0 with
/// d = 0) goes to the last bin: unlike traction, the pessimistic end of attitude is the top.
#[inline(always)]
pub fn attitude_prior(
    heights: &[f64; 4],
    pairs: &[(usize, usize); 2],
    distance: f64,
    bins: &Bins,
) -> Pmf {
    let mut p = [0.0; B];
    for &(i, j) in pairs {
        let angle = ((heights[i] - heights[j]) / distance).atan().abs();
        let k = if angle.is_nan() {
            B - 1
        } else {
            bins.index(angle)
        };
        p[k] += 0.5;
    }
    p
}

/// The physics prior p_phys of eq. 18 for ψ1..ψ4: w_unif·uniform + (1 − w_unif)·Σ_s r_s·p_s,
/// with p_dirt from eqs. 15/17 and p_veg from eqs. 16/17 (roll and pitch use eq. 17 for both
/// semantics, so they do not depend on r_s). `bins` are the bins of ψ1..ψ4
/// ([`crate::bins::param_bins`]).
///
/// Every output sums to 1 whatever the input: `veg_fraction` and `w_uniform` are clipped to
/// [0, 1]; a NaN `veg_fraction` counts as 0 (dirt) and a NaN `w_uniform` as 1 (all uniform).
#[inline(always)]
pub fn physics_prior(fp: &Footprint, cfg: &PriorConfig, bins: &[Bins; PARAMS]) -> [Pmf; PARAMS] {
    let r_veg = unit(fp.veg_fraction, 0.0);
    let r_dirt = 1.0 - r_veg;
    let w = unit(cfg.w_uniform, 1.0);
    let limits = [cfg.max_slope_linear, cfg.max_slope_angular];
    let semantic: [Pmf; PARAMS] = std::array::from_fn(|k| match k {
        0 | 1 => {
            let dirt = ground_traction(&fp.slopes, limits[k], &fp.friction, &bins[k]);
            let veg = vegetation_traction(&fp.vegetation, cfg.max_vegetation, &bins[k]);
            std::array::from_fn(|b| r_dirt * dirt[b] + r_veg * veg[b])
        }
        2 => attitude_prior(&fp.heights, &ROLL_PAIRS, fp.track, &bins[k]),
        _ => attitude_prior(&fp.heights, &PITCH_PAIRS, fp.wheelbase, &bins[k]),
    });
    let u = uniform();
    semantic.map(|p| std::array::from_fn(|b| w * u[b] + (1.0 - w) * p[b]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bins::param_bins;
    use verti_core::Rng;

    const TRACK: f64 = 1.8;
    const WHEELBASE: f64 = 3.4;

    /// Footprint of a robot on the plane z = x·tan(pitch) + y·tan(roll) (x forward, y left),
    /// with wheels at (±wheelbase/2, ±track/2).
    fn on_plane(roll: f64, pitch: f64) -> Footprint {
        let pos = [
            (WHEELBASE / 2.0, TRACK / 2.0),
            (-WHEELBASE / 2.0, TRACK / 2.0),
            (-WHEELBASE / 2.0, -TRACK / 2.0),
            (WHEELBASE / 2.0, -TRACK / 2.0),
        ];
        Footprint {
            heights: pos.map(|(x, y)| x * pitch.tan() + y * roll.tan()),
            slopes: [pitch; 4],
            track: TRACK,
            wheelbase: WHEELBASE,
            vegetation: [0.0; 4],
            veg_fraction: 0.0,
            friction: [DIRT_FRICTION; 4],
        }
    }

    fn peak(p: &Pmf, k: usize, w: f64) {
        let other = w / B as f64;
        for (b, &x) in p.iter().enumerate() {
            let want = if b == k { 1.0 - w + other } else { other };
            assert!((x - want).abs() < 1e-12, "bin {b}: {x} vs {want} in {p:?}");
        }
    }

    #[test]
    fn flat_ground() {
        let cfg = PriorConfig::default();
        let p = physics_prior(&on_plane(0.0, 0.0), &cfg, &param_bins());
        peak(&p[0], B - 1, 0.2);
        peak(&p[1], B - 1, 0.2);
        peak(&p[2], 0, 0.2);
        peak(&p[3], 0, 0.2);
        // Hand value: (1 − 0.2) + 0.2/12.
        assert!((p[0][B - 1] - (0.8 + 0.2 / 12.0)).abs() < 1e-15);
    }

    #[test]
    fn sideways_tilt_gives_roll_only() {
        let cfg = PriorConfig::default();
        let roll = 20f64.to_radians();
        let p = physics_prior(&on_plane(roll, 0.0), &cfg, &param_bins());
        // 20° / 45° · 12 = 5.33 → bin 5.
        peak(&p[2], 5, 0.2);
        peak(&p[3], 0, 0.2);
        peak(&p[0], B - 1, 0.2);
        // Tilted the other way: same |roll|.
        let q = physics_prior(&on_plane(-roll, 0.0), &cfg, &param_bins());
        assert_eq!(p[2], q[2]);
    }

    #[test]
    fn forward_tilt_gives_pitch_and_traction() {
        let cfg = PriorConfig::default();
        let bins = param_bins();
        // 15° along the heading: linear (30 − 15)/30 = 0.5 → bin 6; angular (15 − 15)/15 = 0.
        let p = physics_prior(&on_plane(0.0, 15f64.to_radians()), &cfg, &bins);
        assert_eq!(bins[0].index(0.5), 6);
        peak(&p[0], 6, 0.2);
        peak(&p[1], 0, 0.2);
        peak(&p[2], 0, 0.2);
        // −12° (downhill): linear 0.6 → bin 7, angular 0.2 → bin 2, pitch 3.2 → bin 3.
        let p = physics_prior(&on_plane(0.0, -12f64.to_radians()), &cfg, &bins);
        peak(&p[0], 7, 0.2);
        peak(&p[1], 2, 0.2);
        peak(&p[3], 3, 0.2);
    }

    #[test]
    fn wheels_split_the_mass() {
        let cfg = PriorConfig {
            w_uniform: 0.0,
            ..PriorConfig::default()
        };
        let mut fp = on_plane(0.0, 0.0);
        // Slopes 0°, 6°, 17°, 40°: linear traction 1, 0.8, 0.433, 0 → bins 11, 9, 5, 0.
        fp.slopes = [0.0, 6.0, -17.0, 40.0].map(f64::to_radians);
        // Front wheels raised 0.5 m: pitch atan(0.5/3.4) = 8.37° → bin 2 for both pairs.
        fp.heights = [0.5, 0.0, 0.0, 0.5];
        let p = physics_prior(&fp, &cfg, &param_bins());
        for k in [11, 9, 5, 0] {
            assert!((p[0][k] - 0.25).abs() < 1e-15, "bin {k}: {:?}", p[0]);
        }
        assert!((p[3][2] - 1.0).abs() < 1e-15);
        assert!((p[2][0] - 1.0).abs() < 1e-15);
        // Only the front pair is tilted sideways: ½ on the roll bin, ½ on 0.
        fp.heights = [0.3, 0.0, 0.0, 0.0];
        let p = physics_prior(&fp, &cfg, &param_bins());
        let k = param_bins()[2].index((0.3 / TRACK).atan());
        assert_eq!(k, 2); // atan(0.3/1.8) = 9.46° → bin 2
        assert!((p[2][k] - 0.5).abs() < 1e-15 && (p[2][0] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn vegetation_traction_and_mixture() {
        let cfg = PriorConfig::default();
        let mut fp = on_plane(0.0, 0.0);
        fp.vegetation = [0.5; 4];
        fp.veg_fraction = 1.0;
        let p = physics_prior(&fp, &cfg, &param_bins());
        peak(&p[0], 0, 0.2);
        peak(&p[1], 0, 0.2);
        peak(&p[2], 0, 0.2);
        // Half vegetation of height 0.06 m (traction 0.7 → bin 8), half flat dirt (bin 11).
        fp.vegetation = [0.06; 4];
        fp.veg_fraction = 0.5;
        let p = physics_prior(&fp, &cfg, &param_bins());
        let u = 0.2 / B as f64;
        assert!((p[0][8] - (0.4 + u)).abs() < 1e-15);
        assert!((p[0][11] - (0.4 + u)).abs() < 1e-15);
    }

    #[test]
    fn friction_scales_the_slope_limit() {
        let cfg = PriorConfig::default();
        let bins = param_bins();
        // 15° uphill: dirt keeps (30 − 15)/30 = 0.5 of its traction (bin 6 of 12)
        let mut fp = on_plane(0.0, 15f64.to_radians());
        let dirt = physics_prior(&fp, &cfg, &bins);
        peak(&dirt[0], 6, 0.2);
        // grass (μ 0.36): the limit is 30° · atan 0.36 / atan 0.6 = 19.19°, so 0.218 (bin 2)
        fp.friction = [0.36; 4];
        let limit = slope_limit(30f64.to_radians(), 0.36).to_degrees();
        assert!((limit - 30.0 * 0.36f64.atan() / 0.6f64.atan()).abs() < 1e-12);
        assert!((limit - 19.19).abs() < 0.01, "{limit}");
        let grass = physics_prior(&fp, &cfg, &bins);
        peak(&grass[0], 2, 0.2);
        // concrete (μ 0.85): 39.3°, so 0.618 (bin 7); attitude does not depend on the ground
        fp.friction = [0.85; 4];
        let concrete = physics_prior(&fp, &cfg, &bins);
        peak(&concrete[0], 7, 0.2);
        assert_eq!(concrete[3], dirt[3]);
        // dirt under every wheel is the paper's prior, bit for bit
        fp.friction = [DIRT_FRICTION; 4];
        assert_eq!(physics_prior(&fp, &cfg, &bins), dirt);
        assert_eq!(slope_limit(0.5, f64::NAN), 0.0);
    }

    #[test]
    fn always_a_pmf() {
        let mut rng = Rng::new(21);
        let bins = param_bins();
        let check = |fp: &Footprint, cfg: &PriorConfig| {
            for p in physics_prior(fp, cfg, &bins) {
                assert!(p.iter().all(|x| x.is_finite() && *x >= 0.0));
                assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{p:?}");
            }
        };
        for _ in 0..200 {
            let fp = Footprint {
                heights: std::array::from_fn(|_| rng.range(-2.0, 2.0)),
                slopes: std::array::from_fn(|_| rng.range(-1.5, 1.5)),
                track: rng.range(0.2, 2.0),
                wheelbase: rng.range(0.3, 4.0),
                vegetation: std::array::from_fn(|_| rng.range(0.0, 0.4)),
                veg_fraction: rng.range(-0.2, 1.2),
                friction: std::array::from_fn(|_| rng.range(-0.1, 1.0)),
            };
            let cfg = PriorConfig {
                w_uniform: rng.range(-0.5, 1.5),
                ..PriorConfig::default()
            };
            check(&fp, &cfg);
        }
        // Garbage in: still a PMF, with the pessimistic NaN policies.
        let nan = Footprint {
            heights: [f64::NAN; 4],
            slopes: [f64::NAN; 4],
            track: 0.0,
            wheelbase: f64::NAN,
            vegetation: [f64::NAN; 4],
            veg_fraction: f64::NAN,
            friction: [f64::NAN; 4],
        };
        let cfg = PriorConfig {
            max_slope_linear: 0.0,
            w_uniform: 0.0,
            ..PriorConfig::default()
        };
        check(&nan, &cfg);
        let p = physics_prior(&nan, &cfg, &bins);
        assert_eq!(p[0][0], 1.0);
        assert_eq!(p[2][B - 1], 1.0);
        let cfg_nan_w = PriorConfig {
            w_uniform: f64::NAN,
            ..PriorConfig::default()
        };
        check(&nan, &cfg_nan_w);
        assert_eq!(physics_prior(&nan, &cfg_nan_w, &bins)[1], uniform());
    }

    #[test]
    fn config_serde_defaults() {
        let cfg: PriorConfig = serde_json::from_str(r#"{"w_uniform": 0.5}"#).unwrap();
        assert_eq!(cfg.w_uniform, 0.5);
        assert_eq!(cfg.max_vegetation, 0.2);
        assert!((cfg.max_slope_angular.to_degrees() - 15.0).abs() < 1e-12);
    }
}
