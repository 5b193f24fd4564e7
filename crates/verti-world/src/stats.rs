//! Statistics of world sets, for `verti world stats`: what a set is made of (elevation levels,
//! terrain types, obstacle densities), how its elevation is distributed per level (the paper's
//! Fig. 2 bottom), its semantic classes and friction samples (Fig. 3), its obstacles and the
//! spacing rules they obey (§III-D), and its global paths.
//!
//! Everything is plain data with stable snake_case field names so the JSON output can be
//! compared across versions; [`fmt::Display`] gives the compact text report.

use crate::surface::{Surface, TerrainClass};
use crate::world::{ElevationLevel, MAX_RELIEF_FULL_SCALE, ObstacleDensity, TerrainType, World};
use serde::Serialize;
use std::fmt;

/// Histogram bin width at full scale, metres (multiplied by the set's scale).
pub const HISTOGRAM_BIN_WIDTH: f64 = 0.1;
/// Histogram range at full scale, metres: the highest level's ceiling.
pub const HISTOGRAM_RANGE: f64 = MAX_RELIEF_FULL_SCALE;

/// Statistics of a whole set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetStats {
    pub worlds: usize,
    pub tasks: usize,
    /// Length scale of the set (the largest world scale when worlds disagree, so the
    /// histograms cover every world).
    pub scale: f64,
    /// True when not every world has the same scale.
    pub mixed_scales: bool,
    pub composition: Composition,
    /// One entry per elevation level, in the order low, mid, high (levels without worlds
    /// included, with zero counts).
    pub elevation: Vec<LevelElevation>,
    /// One entry per terrain class, in Verti-Bench label order (classes never used included).
    pub classes: Vec<ClassStats>,
    pub obstacles: ObstacleStats,
    pub paths: PathStats,
}

/// A count under a name.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct NamedCount {
    pub name: String,
    pub count: usize,
}

/// How many worlds of each kind the set holds.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Composition {
    /// low, mid, high.
    pub by_level: Vec<NamedCount>,
    /// rigid, deformable, mixed.
    pub by_terrain_type: Vec<NamedCount>,
    /// sparse, medium, dense.
    pub by_density: Vec<NamedCount>,
    /// World counts per (level, terrain type), one row per level.
    pub level_by_type: Vec<LevelTypeRow>,
}

/// One row of the level x terrain type table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LevelTypeRow {
    pub level: String,
    pub rigid: usize,
    pub deformable: usize,
    pub mixed: usize,
}

/// count / mean / population standard deviation / min / max of a sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub count: usize,
    pub mean: f64,
    pub std: f64,
    pub min: f64,
    pub max: f64,
}

impl Summary {
    /// Summarises the finite values; `None` when there are none.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Summary> {
        let mut count = 0usize;
        let (mut sum, mut min, mut max) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
        let mut kept = Vec::new();
        for v in values.into_iter().filter(|v| v.is_finite()) {
            count += 1;
            sum += v;
            min = min.min(v);
            max = max.max(v);
            kept.push(v);
        }
        if count == 0 {
            return None;
        }
        let mean = sum / count as f64;
        // Two passes: the variance of friction samples (~0.6 ± 0.1) would lose digits with the
        // one-pass sum-of-squares formula.
        let var = kept.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / count as f64;
        Some(Summary {
            count,
            mean,
            std: var.sqrt(),
            min,
            max,
        })
    }
}

/// Elevation of the worlds of one level: a histogram of every vertex height plus per-world
/// shape figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelElevation {
    pub level: String,
    pub worlds: usize,
    /// The level's ceiling at the set's scale, metres (4.8 / 9.6 / 16 m at full scale).
    pub ceiling: f64,
    /// Left edge of bin 0, metres (always 0).
    pub bin_start: f64,
    /// Bin width, metres (0.1 m times the scale).
    pub bin_width: f64,
    /// Vertex counts per bin; bins cover [0, 16 m · scale).
    pub counts: Vec<u64>,
    /// `counts` divided by the number of vertices of the level (sums to 1 minus the
    /// out-of-range share; all zero without worlds).
    pub frequency: Vec<f64>,
    /// Vertices below 0 m or at/above the histogram's top edge.
    pub below_range: u64,
    pub above_range: u64,
    /// Mean and standard deviation of all vertex heights of the level, metres.
    pub mean: Option<f64>,
    pub std: Option<f64>,
    /// Per-world relief (max - min height), metres.
    pub relief: Option<Summary>,
    /// Per-world standard deviation of height, metres.
    pub world_std: Option<Summary>,
}

/// Patch counts and friction samples of one terrain class.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassStats {
    pub class: String,
    pub deformable: bool,
    pub patches: usize,
    /// Share of all patches of the set.
    pub share: f64,
    /// Worlds with at least one patch of the class.
    pub worlds: usize,
    /// Coulomb friction of the class's rigid patches (`None` for soils or unused classes).
    pub friction: Option<Summary>,
}

/// Smallest distance of some kind and the world that has it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MinDistance {
    pub metres: f64,
    pub world: String,
}

/// Obstacle counts and spacing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObstacleStats {
    pub rocks: usize,
    pub trees: usize,
    /// Obstacles per world (rocks + trees).
    pub per_world: Option<Summary>,
    /// Horizontal footprint radius of rocks, metres.
    pub rock_radius: Option<Summary>,
    /// Closest pair of obstacle centres within one world (horizontal), metres.
    pub min_obstacle_spacing: Option<MinDistance>,
    /// Closest obstacle centre to any start or goal, metres.
    pub min_task_spacing: Option<MinDistance>,
}

/// Global path figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PathStats {
    /// Tasks that have a path (at least two waypoints).
    pub planned: usize,
    /// Tasks without a path (no path stored, or fewer than two waypoints).
    pub missing: usize,
    /// Path length, metres.
    pub length: Option<Summary>,
    /// Path length over the straight start-goal distance (1 = straight line).
    pub straight_ratio: Option<Summary>,
    /// Waypoints per path.
    pub waypoints: Option<Summary>,
}

fn counts_by<T: Copy + PartialEq>(
    worlds: &[World],
    all: &[T],
    key: impl Fn(&World) -> T,
    name: impl Fn(T) -> &'static str,
) -> Vec<NamedCount> {
    all.iter()
        .map(|&v| NamedCount {
            name: name(v).to_string(),
            count: worlds.iter().filter(|w| key(w) == v).count(),
        })
        .collect()
}

fn composition(worlds: &[World]) -> Composition {
    let level_by_type = ElevationLevel::ALL
        .iter()
        .map(|&l| {
            let n = |t: TerrainType| {
                worlds
                    .iter()
                    .filter(|w| w.meta.level == l && w.meta.terrain_type == t)
                    .count()
            };
            LevelTypeRow {
                level: l.name().to_string(),
                rigid: n(TerrainType::Rigid),
                deformable: n(TerrainType::Deformable),
                mixed: n(TerrainType::Mixed),
            }
        })
        .collect();
    Composition {
        by_level: counts_by(
            worlds,
            &ElevationLevel::ALL,
            |w| w.meta.level,
            ElevationLevel::name,
        ),
        by_terrain_type: counts_by(
            worlds,
            &TerrainType::ALL,
            |w| w.meta.terrain_type,
            TerrainType::name,
        ),
        by_density: counts_by(
            worlds,
            &ObstacleDensity::ALL,
            |w| w.meta.density,
            ObstacleDensity::name,
        ),
        level_by_type,
    }
}

fn level_elevation(worlds: &[World], level: ElevationLevel, scale: f64) -> LevelElevation {
    let bin_width = HISTOGRAM_BIN_WIDTH * scale;
    let bins = (HISTOGRAM_RANGE / HISTOGRAM_BIN_WIDTH).round() as usize;
    let top = bins as f64 * bin_width;
    let mut counts = vec![0u64; bins];
    let (mut below, mut above) = (0u64, 0u64);
    let (mut n, mut sum, mut sum_sq) = (0u64, 0.0f64, 0.0f64);
    let mut reliefs = Vec::new();
    let mut stds = Vec::new();
    let mine: Vec<&World> = worlds.iter().filter(|w| w.meta.level == level).collect();
    for w in &mine {
        let h = w.terrain.heights();
        // Not `elevation::shape_stats`: its autocorrelation lags need at least 9 vertices per
        // side, and any valid heightfield (2x2 and up) must work here.
        let len = h.len() as f64;
        let m = h.iter().sum::<f64>() / len;
        reliefs.push(w.terrain.max_height() - w.terrain.min_height());
        stds.push((h.iter().map(|v| (v - m).powi(2)).sum::<f64>() / len).sqrt());
        for &v in h {
            n += 1;
            sum += v;
            sum_sq += v * v;
            if v < 0.0 || !v.is_finite() {
                below += 1;
            } else if v >= top {
                above += 1;
            } else {
                // v < top guarantees the index is below `bins`; min() guards rounding.
                counts[((v / bin_width) as usize).min(bins - 1)] += 1;
            }
        }
    }
    let frequency = counts
        .iter()
        .map(|&c| if n > 0 { c as f64 / n as f64 } else { 0.0 })
        .collect();
    let mean = (n > 0).then(|| sum / n as f64);
    // Heights are at most tens of metres, so the one-pass variance keeps plenty of digits.
    let std = mean.map(|m| (sum_sq / n as f64 - m * m).max(0.0).sqrt());
    LevelElevation {
        level: level.name().to_string(),
        worlds: mine.len(),
        ceiling: level.max_height() * scale,
        bin_start: 0.0,
        bin_width,
        counts,
        frequency,
        below_range: below,
        above_range: above,
        mean,
        std,
        relief: Summary::of(reliefs),
        world_std: Summary::of(stds),
    }
}

fn class_stats(worlds: &[World]) -> Vec<ClassStats> {
    let total: usize = worlds.iter().map(|w| w.patches.patches().len()).sum();
    TerrainClass::ALL
        .iter()
        .map(|&class| {
            let mut patches = 0usize;
            let mut in_worlds = 0usize;
            let mut friction = Vec::new();
            for w in worlds {
                let before = patches;
                for p in w.patches.patches().iter().filter(|p| p.class == class) {
                    patches += 1;
                    if let Surface::Rigid { friction: f, .. } = p.surface {
                        friction.push(f);
                    }
                }
                if patches > before {
                    in_worlds += 1;
                }
            }
            ClassStats {
                class: class.name().to_string(),
                deformable: class.is_deformable(),
                patches,
                share: if total > 0 {
                    patches as f64 / total as f64
                } else {
                    0.0
                },
                worlds: in_worlds,
                friction: Summary::of(friction),
            }
        })
        .collect()
}

fn keep_min(slot: &mut Option<MinDistance>, metres: f64, world: &World) {
    if metres.is_finite() && slot.as_ref().is_none_or(|m| metres < m.metres) {
        *slot = Some(MinDistance {
            metres,
            world: world.meta.name.clone(),
        });
    }
}

fn obstacle_stats(worlds: &[World]) -> ObstacleStats {
    let mut min_obstacle_spacing = None;
    let mut min_task_spacing = None;
    let mut rock_radius = Vec::new();
    for w in worlds {
        let centres: Vec<(f64, f64)> = w
            .obstacles
            .iter()
            .map(|o| (o.position().x, o.position().y))
            .collect();
        rock_radius.extend(
            w.obstacles
                .iter()
                .filter(|o| o.is_rock())
                .map(|o| o.radius_xy()),
        );
        for (i, a) in centres.iter().enumerate() {
            for b in &centres[i + 1..] {
                keep_min(&mut min_obstacle_spacing, (a.0 - b.0).hypot(a.1 - b.1), w);
            }
            for t in &w.tasks {
                for p in [t.start, t.goal] {
                    keep_min(&mut min_task_spacing, (a.0 - p[0]).hypot(a.1 - p[1]), w);
                }
            }
        }
    }
    ObstacleStats {
        rocks: worlds
            .iter()
            .map(|w| w.obstacles.iter().filter(|o| o.is_rock()).count())
            .sum(),
        trees: worlds
            .iter()
            .map(|w| w.obstacles.iter().filter(|o| !o.is_rock()).count())
            .sum(),
        per_world: Summary::of(worlds.iter().map(|w| w.obstacles.len() as f64)),
        rock_radius: Summary::of(rock_radius),
        min_obstacle_spacing,
        min_task_spacing,
    }
}

fn path_stats(worlds: &[World]) -> PathStats {
    let (mut lengths, mut ratios, mut waypoints) = (Vec::new(), Vec::new(), Vec::new());
    let mut missing = 0usize;
    for w in worlds {
        for (i, t) in w.tasks.iter().enumerate() {
            match w.paths.get(i).filter(|p| p.points.len() >= 2) {
                Some(p) => {
                    let len = p.length();
                    lengths.push(len);
                    waypoints.push(p.points.len() as f64);
                    let d = t.distance();
                    if d > 0.0 {
                        ratios.push(len / d);
                    }
                }
                None => missing += 1,
            }
        }
    }
    PathStats {
        planned: lengths.len(),
        missing,
        length: Summary::of(lengths),
        straight_ratio: Summary::of(ratios),
        waypoints: Summary::of(waypoints),
    }
}

/// Computes the statistics of a set of worlds (any number, including none).
pub fn set_stats(worlds: &[World]) -> SetStats {
    let scales: Vec<f64> = worlds
        .iter()
        .map(|w| w.meta.scale)
        .filter(|s| s.is_finite() && *s > 0.0)
        .collect();
    let scale = scales.iter().copied().fold(f64::NAN, f64::max);
    let scale = if scale.is_finite() { scale } else { 1.0 };
    let mixed_scales = scales.iter().any(|s| (s - scale).abs() > 1e-12 * scale);
    SetStats {
        worlds: worlds.len(),
        tasks: worlds.iter().map(|w| w.tasks.len()).sum(),
        scale,
        mixed_scales,
        composition: composition(worlds),
        elevation: ElevationLevel::ALL
            .iter()
            .map(|&l| level_elevation(worlds, l, scale))
            .collect(),
        classes: class_stats(worlds),
        obstacles: obstacle_stats(worlds),
        paths: path_stats(worlds),
    }
}

/// `value` with `digits` decimals, or `-` when absent.
fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"))
}

fn percent(part: usize, whole: usize) -> String {
    if whole == 0 {
        "-".to_string()
    } else {
        format!("{:.0}%", 100.0 * part as f64 / whole as f64)
    }
}

impl fmt::Display for SetStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.composition;
        writeln!(
            f,
            "worlds {}   tasks {}   scale {}{}",
            self.worlds,
            self.tasks,
            self.scale,
            if self.mixed_scales {
                " (mixed; largest shown)"
            } else {
                ""
            }
        )?;

        writeln!(f, "\ncomposition")?;
        for (title, rows) in [
            ("level", &c.by_level),
            ("terrain type", &c.by_terrain_type),
            ("density", &c.by_density),
        ] {
            let cells: Vec<String> = rows
                .iter()
                .map(|r| {
                    format!(
                        "{:<20}",
                        format!("{} {} ({})", r.name, r.count, percent(r.count, self.worlds))
                    )
                })
                .collect();
            writeln!(f, "  {title:<13} {}", cells.join(" ").trim_end())?;
        }
        writeln!(
            f,
            "  {:<13} {:>10} {:>10} {:>10} {:>10}",
            "level\\type", "rigid", "deformable", "mixed", "total"
        )?;
        for r in &c.level_by_type {
            writeln!(
                f,
                "  {:<13} {:>10} {:>10} {:>10} {:>10}",
                r.level,
                r.rigid,
                r.deformable,
                r.mixed,
                r.rigid + r.deformable + r.mixed
            )?;
        }

        writeln!(
            f,
            "\nelevation (metres; histogram {} bins of {} m)",
            self.elevation.first().map_or(0, |e| e.counts.len()),
            self.elevation.first().map_or(0.0, |e| e.bin_width)
        )?;
        writeln!(
            f,
            "  {:<6} {:>6} {:>8} {:>7} {:>7} {:>20} {:>9}",
            "level", "worlds", "ceiling", "mean", "std", "relief mean [min,max]", "world std"
        )?;
        for e in &self.elevation {
            let relief = e.relief.map_or_else(
                || "-".to_string(),
                |r| format!("{:.2} [{:.2},{:.2}]", r.mean, r.min, r.max),
            );
            writeln!(
                f,
                "  {:<6} {:>6} {:>8.2} {:>7} {:>7} {:>20} {:>9}",
                e.level,
                e.worlds,
                e.ceiling,
                opt(e.mean, 2),
                opt(e.std, 2),
                relief,
                opt(e.world_std.map(|s| s.mean), 2)
            )?;
        }

        writeln!(f, "\nterrain classes")?;
        writeln!(
            f,
            "  {:<9} {:<10} {:>7} {:>6} {:>6} {:>8} {:>7} {:>6} {:>6}",
            "class", "kind", "patches", "share", "worlds", "friction", "std", "min", "max"
        )?;
        for k in &self.classes {
            let fr = k.friction;
            writeln!(
                f,
                "  {:<9} {:<10} {:>7} {:>5.1}% {:>6} {:>8} {:>7} {:>6} {:>6}",
                k.class,
                if k.deformable { "deformable" } else { "rigid" },
                k.patches,
                100.0 * k.share,
                k.worlds,
                opt(fr.map(|s| s.mean), 3),
                opt(fr.map(|s| s.std), 3),
                opt(fr.map(|s| s.min), 2),
                opt(fr.map(|s| s.max), 2),
            )?;
        }

        let o = &self.obstacles;
        writeln!(f, "\nobstacles")?;
        writeln!(
            f,
            "  rocks {}   trees {}   per world {} [{}, {}]",
            o.rocks,
            o.trees,
            opt(o.per_world.map(|s| s.mean), 1),
            opt(o.per_world.map(|s| s.min), 0),
            opt(o.per_world.map(|s| s.max), 0)
        )?;
        writeln!(
            f,
            "  rock footprint radius {} m [{}, {}]",
            opt(o.rock_radius.map(|s| s.mean), 2),
            opt(o.rock_radius.map(|s| s.min), 2),
            opt(o.rock_radius.map(|s| s.max), 2)
        )?;
        for (what, m) in [
            ("obstacle-obstacle", &o.min_obstacle_spacing),
            ("obstacle-start/goal", &o.min_task_spacing),
        ] {
            match m {
                Some(m) => writeln!(
                    f,
                    "  min centre distance {what:<20} {:>7.2} m  ({})",
                    m.metres, m.world
                )?,
                None => writeln!(f, "  min centre distance {what:<20} {:>7}", "-")?,
            }
        }

        let p = &self.paths;
        writeln!(f, "\nglobal paths")?;
        writeln!(f, "  planned {}   missing {}", p.planned, p.missing)?;
        writeln!(
            f,
            "  length {} m (std {}, [{}, {}])   length / straight line {} (max {})   waypoints {}",
            opt(p.length.map(|s| s.mean), 1),
            opt(p.length.map(|s| s.std), 1),
            opt(p.length.map(|s| s.min), 1),
            opt(p.length.map(|s| s.max), 1),
            opt(p.straight_ratio.map(|s| s.mean), 3),
            opt(p.straight_ratio.map(|s| s.max), 3),
            opt(p.waypoints.map(|s| s.mean), 1)
        )?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{SetConfig, generate_set};
    use crate::heightfield::Heightfield;
    use crate::obstacle::{Obstacle, box_faces};
    use crate::surface::{Patch, PatchGrid, RIGID_RESTITUTION, SoilParams};
    use crate::world::{GlobalPath, Task, WorldMeta, WorldSource};
    use verti_core::Vec3;

    /// A 3x3-vertex world (cell 1 m) whose heights, classes, obstacles and paths are all chosen
    /// by hand so every statistic can be checked exactly.
    fn tiny(name: &str, level: ElevationLevel, ty: TerrainType, heights: Vec<f64>) -> World {
        let rigid = |class, friction| Patch {
            class,
            surface: Surface::Rigid {
                friction,
                restitution: RIGID_RESTITUTION,
            },
        };
        let mut patches = vec![rigid(TerrainClass::Grass, 0.3); 256];
        patches[0] = rigid(TerrainClass::Grass, 0.5);
        patches[1] = Patch {
            class: TerrainClass::Snow,
            surface: Surface::Deformable {
                soil: SoilParams::SOFT,
            },
        };
        World {
            meta: WorldMeta {
                name: name.to_string(),
                index: 1,
                source: WorldSource::Generated {
                    set_seed: 0,
                    generator: "hand".into(),
                },
                level,
                terrain_type: ty,
                density: ObstacleDensity::Sparse,
                scale: 1.0,
                max_height: level.max_height(),
            },
            terrain: Heightfield::new(3, 1.0, heights),
            patches: PatchGrid::new(patches, 1.0),
            obstacles: vec![
                Obstacle::rock(
                    box_faces(Vec3::new(2.0, 2.0, 1.0)),
                    1.0,
                    Vec3::new(0.0, 0.0, 0.5),
                    0.0,
                )
                .unwrap(),
                Obstacle::tree(0.2, 3.0, Vec3::new(3.0, 4.0, 1.5)).unwrap(),
            ],
            tasks: vec![
                Task {
                    pair: 0,
                    start: [-10.0, 0.0],
                    goal: [10.0, 0.0],
                },
                Task {
                    pair: 1,
                    start: [0.0, -10.0],
                    goal: [0.0, 10.0],
                },
            ],
            // pair 0: a detour of length 2·sqrt(10² + 5²); pair 1: no path
            paths: vec![
                GlobalPath {
                    points: vec![[-10.0, 0.0], [0.0, 5.0], [10.0, 0.0]],
                },
                GlobalPath { points: vec![] },
            ],
            path_clearance: 1.0,
        }
    }

    #[test]
    fn hand_built_set_is_counted_exactly() {
        let a = tiny(
            "a",
            ElevationLevel::Low,
            TerrainType::Rigid,
            vec![0.02, 0.05, 0.08, 0.12, 0.18, 0.23, 0.26, 0.29, 0.35],
        );
        let b = tiny("b", ElevationLevel::High, TerrainType::Mixed, vec![1.05; 9]);
        let s = set_stats(&[a, b]);
        assert_eq!(
            (s.worlds, s.tasks, s.scale, s.mixed_scales),
            (2, 4, 1.0, false)
        );
        assert_eq!(
            s.composition
                .by_level
                .iter()
                .map(|c| c.count)
                .collect::<Vec<_>>(),
            vec![1, 0, 1]
        );
        assert_eq!(
            s.composition
                .by_terrain_type
                .iter()
                .map(|c| c.count)
                .collect::<Vec<_>>(),
            vec![1, 0, 1]
        );
        assert_eq!(s.composition.by_density[0].count, 2);
        assert_eq!(
            s.composition.level_by_type[2],
            LevelTypeRow {
                level: "high".into(),
                rigid: 0,
                deformable: 0,
                mixed: 1
            }
        );

        // Low: 0.1 m bins -> 0.02,0.05,0.08 | 0.12,0.18 | 0.23,0.26,0.29 | 0.35 (values kept off
        // the bin edges, where floating-point division could go either way).
        let low = &s.elevation[0];
        assert_eq!(low.counts.len(), 160);
        assert_eq!(&low.counts[..4], &[3, 2, 3, 1]);
        assert!((low.frequency.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((low.mean.unwrap() - 1.58 / 9.0).abs() < 1e-12);
        assert!((low.relief.unwrap().mean - 0.33).abs() < 1e-12);
        // High: a flat world at 1.05 m, bin 10; no relief.
        let high = &s.elevation[2];
        assert_eq!(high.counts[10], 9);
        assert_eq!(high.relief.unwrap().max, 0.0);
        assert_eq!((high.ceiling, high.worlds), (16.0, 1));
        // Mid: no worlds, all empty but well-formed.
        assert_eq!((s.elevation[1].worlds, s.elevation[1].mean), (0, None));
        assert!(s.elevation[1].frequency.iter().all(|&f| f == 0.0));

        let grass = &s.classes[TerrainClass::Grass.id() as usize];
        assert_eq!((grass.patches, grass.worlds), (2 * 255, 2));
        let fr = grass.friction.unwrap();
        assert_eq!((fr.count, fr.min, fr.max), (510, 0.3, 0.5));
        let snow = &s.classes[TerrainClass::Snow.id() as usize];
        assert_eq!(
            (snow.patches, snow.deformable, snow.friction),
            (2, true, None)
        );
        assert_eq!(s.classes[TerrainClass::Mud.id() as usize].patches, 0);
        assert!((s.classes.iter().map(|c| c.share).sum::<f64>() - 1.0).abs() < 1e-12);

        assert_eq!((s.obstacles.rocks, s.obstacles.trees), (2, 2));
        let spacing = s.obstacles.min_obstacle_spacing.as_ref().unwrap();
        assert!((spacing.metres - 5.0).abs() < 1e-12 && spacing.world == "a");
        // the rock at the origin is 10 m from every start and goal; the tree at (3, 4) is
        // closest to the goal (0, 10)
        assert!(
            (s.obstacles.min_task_spacing.as_ref().unwrap().metres - 3f64.hypot(6.0)).abs() < 1e-12
        );

        assert_eq!((s.paths.planned, s.paths.missing), (2, 2));
        let expected = 2.0 * 10f64.hypot(5.0);
        assert!((s.paths.length.unwrap().mean - expected).abs() < 1e-12);
        assert!((s.paths.straight_ratio.unwrap().mean - expected / 20.0).abs() < 1e-12);

        // The report mentions every section and the JSON keeps its field names.
        let text = s.to_string();
        for needle in [
            "composition",
            "elevation",
            "terrain classes",
            "obstacles",
            "global paths",
            "snow",
        ] {
            assert!(text.contains(needle), "{needle} missing from\n{text}");
        }
        let json = serde_json_like(&s);
        assert!(json.contains("level_by_type") && json.contains("min_task_spacing"));
    }

    /// Serialises through serde's data model without a JSON crate (verti-world does not depend
    /// on one): the derived `Serialize` must at least expose the field names.
    fn serde_json_like(s: &SetStats) -> String {
        serde_norway::to_string(s).unwrap()
    }

    #[test]
    fn empty_set_has_no_figures_and_does_not_panic() {
        let s = set_stats(&[]);
        assert_eq!((s.worlds, s.tasks, s.paths.planned), (0, 0, 0));
        assert!(s.obstacles.min_obstacle_spacing.is_none());
        assert!(s.classes.iter().all(|c| c.share == 0.0));
        assert!(!s.to_string().is_empty());
    }

    #[test]
    fn scaled_worlds_scale_the_bins() {
        let mut w = tiny(
            "s",
            ElevationLevel::Mid,
            TerrainType::Rigid,
            vec![
                0.002, 0.005, 0.008, 0.012, 0.018, 0.023, 0.026, 0.029, 0.035,
            ],
        );
        w.meta.scale = 0.1;
        let s = set_stats(&[w]);
        let mid = &s.elevation[1];
        assert!((mid.bin_width - 0.01).abs() < 1e-15 && (mid.ceiling - 0.96).abs() < 1e-12);
        assert_eq!(&mid.counts[..4], &[3, 2, 3, 1]);
    }

    /// A small generated set obeys the generator's rules as seen through the statistics.
    #[test]
    fn generated_set_statistics_follow_the_generator() {
        let worlds = generate_set(
            &SetConfig {
                count: 6,
                ..Default::default()
            },
            &|| {},
        )
        .unwrap();
        let s = set_stats(&worlds);
        assert_eq!((s.worlds, s.tasks), (6, 60));
        assert_eq!(
            s.composition
                .by_level
                .iter()
                .map(|c| c.count)
                .sum::<usize>(),
            6
        );
        for e in &s.elevation {
            // heights stay within the level's ceiling, so nothing falls outside the histogram
            assert_eq!((e.below_range, e.above_range), (0, 0));
            if let Some(r) = e.relief {
                assert!(r.max <= e.ceiling + 1e-9, "{e:?}");
            }
        }
        for c in s.classes.iter().filter(|c| !c.deformable) {
            if let Some(fr) = c.friction {
                assert!(fr.min >= 0.1 && fr.max <= 1.0);
            }
        }
        let per_world: usize = worlds.iter().map(|w| w.obstacles.len()).sum();
        assert_eq!(s.obstacles.rocks + s.obstacles.trees, per_world);
        assert_eq!(s.paths.planned + s.paths.missing, 60);
        if let Some(r) = s.paths.straight_ratio {
            assert!(
                r.min >= 1.0 - 1e-9,
                "a path is never shorter than the straight line"
            );
        }
    }
}
