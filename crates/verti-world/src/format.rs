//! The versioned on-disk world format.
//!
//! A world is a directory:
//!
//! ```text
//! world-042/
//!   world.yaml      manifest: metadata, grid, soils, 256 patches, obstacles, tasks, paths
//!   elevation.npy   float32 (129, 129) heights in metres, row 0 = north, column 0 = west
//!   labels.npy      int32   (129, 129) class ids (Verti-Bench label ids), derived from the patches
//! ```
//!
//! A world set is a directory of world directories plus `set.yaml` (name and member list).
//! Loading validates everything and reports the file, the field and the problem.

use crate::checks;
use crate::error::{Result, WorldError};
use crate::heightfield::Heightfield;
use crate::npy;
use crate::obstacle::{Face, Obstacle, ObstacleShape};
use crate::surface::{PATCHES_PER_SIDE, Patch, PatchGrid, SoilParams, Surface, TerrainClass};
use crate::world::{
    ElevationLevel, GlobalPath, ObstacleDensity, PAIRS_PER_WORLD, Task, TerrainType, World,
    WorldMeta, WorldSource,
};
use crate::yaml::{YamlLimits, read_yaml_bounded};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use verti_core::Vec3;

pub const FORMAT_NAME: &str = "verti-world";
pub const FORMAT_VERSION: u32 = 1;
pub const MANIFEST: &str = "world.yaml";
pub const ELEVATION: &str = "elevation.npy";
pub const LABELS: &str = "labels.npy";
pub const SET_MANIFEST: &str = "set.yaml";
/// Most obstacles a world may have: generated and imported worlds have at most 43, and each
/// rock costs the loader up to a few hundred thousand operations.
pub const MAX_OBSTACLES: usize = 1000;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    format: String,
    version: u32,
    name: String,
    index: u32,
    source: WorldSource,
    level: ElevationLevel,
    terrain_type: TerrainType,
    density: ObstacleDensity,
    scale: f64,
    max_height: f64,
    grid: GridSpec,
    /// Soil parameter sets referenced by deformable patches.
    soils: BTreeMap<String, SoilParams>,
    /// 256 patches, row-major from the north-west corner.
    patches: Vec<PatchSpec>,
    obstacles: Vec<ObstacleSpec>,
    tasks: Vec<Task>,
    paths: PathsSpec,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct GridSpec {
    size: usize,
    cell: f64,
    elevation: String,
    labels: String,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PatchSpec {
    row: usize,
    col: usize,
    class: TerrainClass,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    friction: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    restitution: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    soil: Option<String>,
}

#[derive(Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
enum ObstacleSpec {
    Rock {
        position: [f64; 3],
        yaw: f64,
        scale: f64,
        /// Bounding planes in the rock frame: [nx, ny, nz, offset] with n·p <= offset inside.
        faces: Vec<[f64; 4]>,
    },
    Tree {
        position: [f64; 3],
        radius: f64,
        height: f64,
    },
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PathsSpec {
    clearance: f64,
    paths: Vec<PathSpec>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PathSpec {
    pair: u32,
    points: Vec<[f64; 2]>,
}

/// Name under which a soil parameter set is stored.
fn soil_name(soil: &SoilParams) -> String {
    if *soil == SoilParams::SOFT {
        "soft".into()
    } else if *soil == SoilParams::MID {
        "mid".into()
    } else if *soil == SoilParams::HARD {
        "hard".into()
    } else {
        format!(
            "custom-{:016x}",
            soil.bekker_kphi.to_bits() ^ soil.elastic_k.to_bits().rotate_left(7)
        )
    }
}

/// Writes a world directory (created if missing). Output is byte-identical for equal worlds.
pub fn save_world(world: &World, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| WorldError::io(dir, e))?;
    let n = world.terrain.size();
    let heights: Vec<f32> = world.terrain.heights().iter().map(|&h| h as f32).collect();
    npy::write_f32(&dir.join(ELEVATION), n, n, &heights)?;
    let labels: Vec<i32> = world.labels().into_iter().map(i32::from).collect();
    npy::write_i32(&dir.join(LABELS), n, n, &labels)?;

    let mut soils = BTreeMap::new();
    let mut patches = Vec::with_capacity(world.patches.patches().len());
    for (k, p) in world.patches.patches().iter().enumerate() {
        let (row, col) = (k / PATCHES_PER_SIDE, k % PATCHES_PER_SIDE);
        patches.push(match p.surface {
            Surface::Rigid {
                friction,
                restitution,
            } => PatchSpec {
                row,
                col,
                class: p.class,
                friction: Some(friction),
                restitution: Some(restitution),
                soil: None,
            },
            Surface::Deformable { soil } => {
                let name = soil_name(&soil);
                soils.insert(name.clone(), soil);
                PatchSpec {
                    row,
                    col,
                    class: p.class,
                    friction: None,
                    restitution: None,
                    soil: Some(name),
                }
            }
        });
    }
    let obstacles = world
        .obstacles
        .iter()
        .map(|o| {
            let p = o.position();
            match o.shape() {
                ObstacleShape::Rock { faces, scale } => ObstacleSpec::Rock {
                    position: p.to_array(),
                    yaw: o.yaw(),
                    scale: *scale,
                    faces: faces
                        .iter()
                        .map(|f| [f.normal.x, f.normal.y, f.normal.z, f.offset])
                        .collect(),
                },
                ObstacleShape::Tree { radius, height } => ObstacleSpec::Tree {
                    position: p.to_array(),
                    radius: *radius,
                    height: *height,
                },
            }
        })
        .collect();
    let manifest = Manifest {
        format: FORMAT_NAME.into(),
        version: FORMAT_VERSION,
        name: world.meta.name.clone(),
        index: world.meta.index,
        source: world.meta.source.clone(),
        level: world.meta.level,
        terrain_type: world.meta.terrain_type,
        density: world.meta.density,
        scale: world.meta.scale,
        max_height: world.meta.max_height,
        grid: GridSpec {
            size: n,
            cell: world.terrain.cell(),
            elevation: ELEVATION.into(),
            labels: LABELS.into(),
        },
        soils,
        patches,
        obstacles,
        tasks: world.tasks.clone(),
        paths: PathsSpec {
            clearance: world.path_clearance,
            paths: world
                .paths
                .iter()
                .zip(&world.tasks)
                .map(|(p, t)| PathSpec {
                    pair: t.pair,
                    points: p.points.clone(),
                })
                .collect(),
        },
    };
    let text = crate::yaml::to_yaml(&manifest).map_err(|e| {
        WorldError::invalid(
            dir.join(MANIFEST),
            "manifest",
            format!("cannot serialise: {e}"),
        )
    })?;
    let header = "# verti world manifest (format verti-world v1). Heights: elevation.npy; labels: labels.npy.\n";
    std::fs::write(dir.join(MANIFEST), format!("{header}{text}"))
        .map_err(|e| WorldError::io(dir.join(MANIFEST), e))
}

fn finite(path: &Path, field: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(WorldError::invalid(
            path,
            field,
            format!("{v} is not a finite number"),
        ))
    }
}

/// Loads and validates a world directory (or a path to its `world.yaml`).
pub fn load_world(path: &Path) -> Result<World> {
    let (dir, mpath): (PathBuf, PathBuf) = if path.is_dir() {
        (path.to_path_buf(), path.join(MANIFEST))
    } else {
        // a file, or a path that cannot be read: the reader says which (missing, a link loop...)
        (
            path.parent().map(Path::to_path_buf).unwrap_or_default(),
            path.to_path_buf(),
        )
    };
    let text = read_yaml_bounded(&mpath, &YamlLimits::DEFAULT, "the world manifest")?;
    let m: Manifest = serde_norway::from_str(&text).map_err(|e| {
        let msg = e.to_string();
        let field = msg
            .split(':')
            .next()
            .unwrap_or("manifest")
            .trim()
            .to_string();
        // serde names the field first (`patches[3].friction: ...`); other messages
        // (a syntax error) have no field, and their first words are not one
        let is_path = !field.is_empty()
            && field.len() < 60
            && field
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_.[]".contains(c));
        WorldError::invalid(&mpath, if is_path { field } else { "manifest".into() }, msg)
    })?;
    if m.format != FORMAT_NAME {
        return Err(WorldError::invalid(
            &mpath,
            "format",
            format!("expected `{FORMAT_NAME}`, found `{}`", m.format),
        ));
    }
    if m.version != FORMAT_VERSION {
        return Err(WorldError::invalid(
            &mpath,
            "version",
            format!(
                "this verti reads version {FORMAT_VERSION}, the file is version {}",
                m.version
            ),
        ));
    }
    if m.index == 0 {
        return Err(WorldError::invalid(
            &mpath,
            "index",
            "world indices start at 1",
        ));
    }
    crate::scale::check_scale(m.scale)
        .map_err(|e| WorldError::invalid(&mpath, "scale", e.to_string()))?;
    let max_height = finite(&mpath, "max_height", m.max_height)?;
    if max_height <= 0.0 {
        return Err(WorldError::invalid(
            &mpath,
            "max_height",
            "must be positive",
        ));
    }
    checks::check_level(&mpath, m.level, max_height, m.scale)?;
    let n = m.grid.size;
    checks::check_grid_size(&mpath, n)?;
    let cell = finite(&mpath, "grid.cell", m.grid.cell)?;
    checks::check_cell(&mpath, cell, m.scale)?;

    // elevation
    let epath = dir.join(&m.grid.elevation);
    let elev = npy::read_array2(&epath)?;
    if (elev.rows, elev.cols) != (n, n) {
        return Err(WorldError::invalid(
            &epath,
            "shape",
            format!(
                "expected ({n}, {n}) to match grid.size, found ({}, {})",
                elev.rows, elev.cols
            ),
        ));
    }
    checks::check_heights(&epath, &elev.data, n, max_height)?;
    let ground = elev
        .data
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
            (lo.min(h), hi.max(h))
        });

    // patches
    if m.patches.len() != PATCHES_PER_SIDE * PATCHES_PER_SIDE {
        return Err(WorldError::invalid(
            &mpath,
            "patches",
            format!("expected 256 patches, found {}", m.patches.len()),
        ));
    }
    for (name, soil) in &m.soils {
        soil.validate()
            .map_err(|e| WorldError::invalid(&mpath, format!("soils.{name}"), e))?;
    }
    let mut patches = Vec::with_capacity(256);
    for (k, p) in m.patches.iter().enumerate() {
        let field = |f: &str| format!("patches[{k}].{f}");
        if (p.row, p.col) != (k / PATCHES_PER_SIDE, k % PATCHES_PER_SIDE) {
            return Err(WorldError::invalid(
                &mpath,
                field("row/col"),
                format!(
                    "patch {k} must be row {}, col {} (row-major order), found ({}, {})",
                    k / 16,
                    k % 16,
                    p.row,
                    p.col
                ),
            ));
        }
        let surface = if p.class.is_deformable() {
            let name = p.soil.as_ref().ok_or_else(|| {
                WorldError::invalid(
                    &mpath,
                    field("soil"),
                    format!("deformable class {} needs a soil", p.class),
                )
            })?;
            let soil = m.soils.get(name).ok_or_else(|| {
                WorldError::invalid(
                    &mpath,
                    field("soil"),
                    format!("unknown soil `{name}` (not in `soils`)"),
                )
            })?;
            if p.friction.is_some() {
                return Err(WorldError::invalid(
                    &mpath,
                    field("friction"),
                    format!("deformable class {} takes a soil, not a friction", p.class),
                ));
            }
            Surface::Deformable { soil: *soil }
        } else {
            let friction = p.friction.ok_or_else(|| {
                WorldError::invalid(
                    &mpath,
                    field("friction"),
                    format!("rigid class {} needs a friction", p.class),
                )
            })?;
            if !(friction.is_finite() && (0.0..=2.0).contains(&friction)) {
                return Err(WorldError::invalid(
                    &mpath,
                    field("friction"),
                    format!("{friction} is outside [0, 2]"),
                ));
            }
            let restitution = p.restitution.unwrap_or(crate::surface::RIGID_RESTITUTION);
            if !(restitution.is_finite() && (0.0..=1.0).contains(&restitution)) {
                return Err(WorldError::invalid(
                    &mpath,
                    field("restitution"),
                    format!("{restitution} is outside [0, 1]"),
                ));
            }
            if p.soil.is_some() {
                return Err(WorldError::invalid(
                    &mpath,
                    field("soil"),
                    format!("rigid class {} cannot have a soil", p.class),
                ));
            }
            Surface::Rigid {
                friction,
                restitution,
            }
        };
        patches.push(Patch {
            class: p.class,
            surface,
        });
    }
    let patches = PatchGrid::new(patches, cell);

    // labels must agree with the patches
    let lpath = dir.join(&m.grid.labels);
    let labels = npy::read_array2(&lpath)?;
    if (labels.rows, labels.cols) != (n, n) {
        return Err(WorldError::invalid(
            &lpath,
            "shape",
            format!(
                "expected ({n}, {n}), found ({}, {})",
                labels.rows, labels.cols
            ),
        ));
    }
    let expected = patches.label_grid(n);
    if let Some(i) = labels
        .data
        .iter()
        .zip(&expected)
        .position(|(a, b)| *a != f64::from(*b))
    {
        return Err(WorldError::invalid(
            &lpath,
            "data",
            format!(
                "label {} at row {}, column {} disagrees with the manifest's patch class {}",
                labels.data[i],
                i / n,
                i % n,
                expected[i]
            ),
        ));
    }

    // obstacles
    let half = 0.5 * (n - 1) as f64 * cell;
    if m.obstacles.len() > MAX_OBSTACLES {
        return Err(WorldError::invalid(
            &mpath,
            "obstacles",
            format!(
                "{} obstacles; a world may have at most {MAX_OBSTACLES} (dense worlds have 43)",
                m.obstacles.len()
            ),
        ));
    }
    let mut obstacles = Vec::with_capacity(m.obstacles.len());
    for (k, o) in m.obstacles.iter().enumerate() {
        let built = match o {
            ObstacleSpec::Rock {
                position,
                yaw,
                scale,
                faces,
            } => {
                let faces: Vec<Face> = faces
                    .iter()
                    .map(|f| Face {
                        normal: Vec3::new(f[0], f[1], f[2]),
                        offset: f[3],
                    })
                    .collect();
                Obstacle::rock(
                    faces,
                    *scale,
                    Vec3::new(position[0], position[1], position[2]),
                    *yaw,
                )
            }
            ObstacleSpec::Tree {
                position,
                radius,
                height,
            } => Obstacle::tree(
                *radius,
                *height,
                Vec3::new(position[0], position[1], position[2]),
            ),
        };
        let built = built.map_err(|e| WorldError::invalid(&mpath, format!("obstacles[{k}]"), e))?;
        checks::check_obstacle(&mpath, k, &built, half, ground)?;
        obstacles.push(built);
    }

    // tasks and paths
    let mut seen_pairs = std::collections::BTreeSet::new();
    for (k, t) in m.tasks.iter().enumerate() {
        for (what, p) in [("start", t.start), ("goal", t.goal)] {
            if !(p[0].is_finite() && p[1].is_finite() && p[0].abs() <= half && p[1].abs() <= half) {
                return Err(WorldError::invalid(
                    &mpath,
                    format!("tasks[{k}].{what}"),
                    format!("{p:?} is not a finite point on the map (|x|, |y| <= {half})"),
                ));
            }
        }
        // task numbers are (world - 1) * 10 + pair + 1: a pair of 10 or more would take
        // another world's number
        if t.pair >= PAIRS_PER_WORLD {
            return Err(WorldError::invalid(
                &mpath,
                format!("tasks[{k}].pair"),
                format!(
                    "{} is not a pair number 0..={}",
                    t.pair,
                    PAIRS_PER_WORLD - 1
                ),
            ));
        }
        if !seen_pairs.insert(t.pair) {
            return Err(WorldError::invalid(
                &mpath,
                format!("tasks[{k}].pair"),
                format!("pair {} appears twice", t.pair),
            ));
        }
    }
    if m.paths.paths.len() != m.tasks.len() {
        return Err(WorldError::invalid(
            &mpath,
            "paths.paths",
            format!(
                "expected one path per task ({}), found {}",
                m.tasks.len(),
                m.paths.paths.len()
            ),
        ));
    }
    let clearance = m.paths.clearance;
    checks::check_clearance(&mpath, clearance, m.scale)?;
    let mut paths = Vec::with_capacity(m.tasks.len());
    for (k, (p, t)) in m.paths.paths.iter().zip(&m.tasks).enumerate() {
        if p.pair != t.pair {
            return Err(WorldError::invalid(
                &mpath,
                format!("paths.paths[{k}].pair"),
                format!(
                    "expected pair {} (same order as tasks), found {}",
                    t.pair, p.pair
                ),
            ));
        }
        checks::check_path_points(&mpath, k, &p.points, half)?;
        paths.push(GlobalPath {
            points: p.points.clone(),
        });
    }

    Ok(World {
        meta: WorldMeta {
            name: m.name,
            index: m.index,
            source: m.source,
            level: m.level,
            terrain_type: m.terrain_type,
            density: m.density,
            scale: m.scale,
            max_height,
        },
        terrain: Heightfield::new(n, cell, elev.data),
        patches,
        obstacles,
        tasks: m.tasks,
        paths,
        path_clearance: clearance,
    })
}

/// Manifest of a world set directory.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SetManifest {
    pub format: String,
    pub version: u32,
    pub name: String,
    /// Generator seed (absent for imported sets).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    pub scale: f64,
    /// World directory names relative to the set directory, in world-index order.
    pub worlds: Vec<String>,
}

/// Directory name of world `index` inside a set.
pub fn world_dir_name(index: u32) -> String {
    format!("world-{index:03}")
}

/// Writes a whole set: one directory per world plus `set.yaml`.
pub fn save_set(
    worlds: &[World],
    name: &str,
    seed: Option<u64>,
    dir: &Path,
    progress: &(dyn Fn() + Sync),
) -> Result<()> {
    use rayon::prelude::*;
    std::fs::create_dir_all(dir).map_err(|e| WorldError::io(dir, e))?;
    worlds.par_iter().try_for_each(|w| {
        let r = save_world(w, &dir.join(world_dir_name(w.meta.index)));
        progress();
        r
    })?;
    let manifest = SetManifest {
        format: "verti-world-set".into(),
        version: FORMAT_VERSION,
        name: name.into(),
        seed,
        scale: worlds.first().map(|w| w.meta.scale).unwrap_or(1.0),
        worlds: worlds
            .iter()
            .map(|w| world_dir_name(w.meta.index))
            .collect(),
    };
    let text = crate::yaml::to_yaml(&manifest)
        .map_err(|e| WorldError::invalid(dir.join(SET_MANIFEST), "manifest", e.to_string()))?;
    std::fs::write(dir.join(SET_MANIFEST), text)
        .map_err(|e| WorldError::io(dir.join(SET_MANIFEST), e))
}

/// Reads a set manifest.
pub fn read_set_manifest(dir: &Path) -> Result<SetManifest> {
    let p = dir.join(SET_MANIFEST);
    let text = read_yaml_bounded(&p, &YamlLimits::DEFAULT, "the set manifest")?;
    let m: SetManifest = serde_norway::from_str(&text)
        .map_err(|e| WorldError::invalid(&p, "manifest", e.to_string()))?;
    if m.format != "verti-world-set" {
        return Err(WorldError::invalid(
            &p,
            "format",
            format!("expected `verti-world-set`, found `{}`", m.format),
        ));
    }
    if m.version != FORMAT_VERSION {
        return Err(WorldError::invalid(
            &p,
            "version",
            format!(
                "this verti reads version {FORMAT_VERSION}, the file is version {}",
                m.version
            ),
        ));
    }
    Ok(m)
}

/// Loads every world of a set directory, in order, in parallel.
pub fn load_set(dir: &Path) -> Result<(SetManifest, Vec<World>)> {
    use rayon::prelude::*;
    let m = read_set_manifest(dir)?;
    let manifest = dir.join(SET_MANIFEST);
    // task numbers come from world indices: a world listed twice, or two worlds sharing an
    // index, would give two trials one number (and `world stats` would count them twice)
    let mut listed = std::collections::HashSet::new();
    for w in &m.worlds {
        if !listed.insert(w.as_str()) {
            return Err(WorldError::invalid(
                &manifest,
                "worlds",
                format!("`{w}` is listed twice"),
            ));
        }
    }
    let worlds = m
        .worlds
        .par_iter()
        .map(|w| load_world(&dir.join(w)))
        .collect::<Result<Vec<_>>>()?;
    let mut by_index = std::collections::HashMap::new();
    for (name, w) in m.worlds.iter().zip(&worlds) {
        if let Some(first) = by_index.insert(w.meta.index, name) {
            return Err(WorldError::invalid(
                &manifest,
                "worlds",
                format!(
                    "`{first}` and `{name}` both have index {}: their task numbers would collide",
                    w.meta.index
                ),
            ));
        }
    }
    Ok((m, worlds))
}
