//! Import of original Verti-Bench worlds (reference spec §1, §2).
//!
//! Inputs: `configN_LEVEL.yaml` (levels, obstacles, start/goal pairs, 256 patch records with
//! frictions), the 129x129 8-bit heightmap `worldN.bmp` (height = grey/255 · max_height,
//! 1 m pixels, row 0 = north) and optionally `labelsN_LEVEL.npy` (int32 class ids), which is
//! cross-checked against the patch records.
//!
//! Decisions (see the README): pixel (r, c) becomes vertex (r, c) of our heightfield, i.e.
//! x = c − 64, y = 64 − r, exactly where Chrono puts the physical terrain. Deformable patches
//! get the soil of their *label* (the reference simulates alphabetical bands instead, spec §8
//! item 4; we do not copy that). Obstacles keep the reference collision geometry (rock boxes
//! 4.4s x 4.4s x 3.8s, 1 x 1 x 5 m trees as cylinders) at the stored (x, y), but are seated on
//! the ground instead of at the stored z, which the reference read at the wrong place (spec §8
//! item 2) so that rocks float or sink by up to 2.7 m.

use crate::error::{Result, WorldError};
use crate::generate::plan_paths;
use crate::heightfield::Heightfield;
use crate::npy;
use crate::obstacle::{Obstacle, box_faces};
use crate::paths::DEFAULT_CLEARANCE;
use crate::surface::{
    PATCHES_PER_SIDE, Patch, PatchGrid, RIGID_RESTITUTION, Surface, TerrainClass,
};
use crate::world::{
    ElevationLevel, ObstacleDensity, PAIRS_PER_WORLD, Task, TerrainType, World, WorldMeta,
    WorldSource,
};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use verti_core::Vec3;

/// Size of the Verti-Bench BMPs.
pub const VB_GRID: usize = 129;
/// Reference rock collision box per unit scale, metres.
pub const VB_ROCK_BOX: [f64; 3] = [4.4, 4.4, 3.8];
/// Reference tree box, metres (we use a cylinder of this width and height).
pub const VB_TREE_BOX: [f64; 3] = [1.0, 1.0, 5.0];
const BURY: f64 = 0.3;

#[derive(Deserialize)]
struct VbConfig {
    terrain: VbTerrain,
    terrain_type: String,
    obstacle_density: String,
    #[serde(default)]
    obstacles: Option<VbObstacles>,
    positions: Vec<VbPair>,
    textures: Vec<VbTexture>,
}

#[derive(Deserialize)]
struct VbTerrain {
    difficulty: String,
    max_height: f64,
    #[serde(default)]
    min_height: f64,
}

#[derive(Deserialize, Default)]
struct VbObstacles {
    #[serde(default)]
    rocks: Vec<VbRock>,
    #[serde(default)]
    trees: Vec<VbTree>,
}

#[derive(Deserialize, Clone, Copy)]
pub struct VbPoint {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

#[derive(Deserialize)]
struct VbRock {
    position: VbPoint,
    scale: f64,
}

#[derive(Deserialize)]
struct VbTree {
    position: VbPoint,
}

#[derive(Deserialize)]
struct VbPair {
    start: Vec<f64>,
    goal: Vec<f64>,
}

#[derive(Deserialize)]
struct VbTexture {
    index: [usize; 2],
    is_deformable: bool,
    terrain_type: String,
    #[serde(default)]
    friction: Option<f64>,
    #[serde(default)]
    restitution: Option<f64>,
}

/// Options for an import.
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// Length scale applied to the imported world (1 = the original full-scale world).
    pub scale: f64,
    /// Path clearance at full scale, metres.
    pub clearance: f64,
    /// World index; by default parsed from the config file name (`config12_high.yaml` → 12).
    pub index: Option<u32>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            scale: 1.0,
            clearance: DEFAULT_CLEARANCE,
            index: None,
        }
    }
}

/// Obstacle positions exactly as stored in a Verti-Bench config.
pub struct VbObstaclePositions {
    /// (position, scale) of every rock.
    pub rocks: Vec<(VbPoint, f64)>,
    pub trees: Vec<VbPoint>,
}

/// The obstacle positions as stored in a config (for checks against the reference data).
pub fn read_vb_obstacle_positions(config: &Path) -> Result<VbObstaclePositions> {
    let cfg = read_config(config)?;
    let obs = cfg.obstacles.unwrap_or_default();
    Ok(VbObstaclePositions {
        rocks: obs.rocks.iter().map(|r| (r.position, r.scale)).collect(),
        trees: obs.trees.iter().map(|t| t.position).collect(),
    })
}

fn read_config(path: &Path) -> Result<VbConfig> {
    let text = crate::yaml::read_yaml_bounded(
        path,
        &crate::yaml::YamlLimits::DEFAULT,
        "a Verti-Bench config",
    )?;
    serde_norway::from_str(&text).map_err(|e| WorldError::invalid(path, "yaml", e.to_string()))
}

/// Largest heightmap read: a 129 x 129 BMP is 18 KiB even at 32 bits per pixel.
const MAX_BMP_BYTES: u64 = 1 << 20;

/// Checks what a BMP header says before the image is decoded: a size of at most 4097 pixels
/// per side, and a pixel format that holds 8-bit grey levels exactly. 16-bit BMPs (5 or 6 bits
/// per channel) do not: the decoder stretched them to 8 bits, so grey levels came out up to
/// 6 steps off (0.38 m at 16 m) without a word; so do bit-field masks wider or narrower than 8
/// bits.
fn check_bmp_header(path: &Path, b: &[u8]) -> Result<()> {
    let u16_at = |i: usize| b.get(i..i + 2).map(|s| u16::from_le_bytes([s[0], s[1]]));
    let u32_at = |i: usize| {
        b.get(i..i + 4)
            .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    };
    let bad = |p: String| WorldError::invalid(path, "bmp", format!("not a usable BMP: {p}"));
    if !b.starts_with(b"BM") {
        return Err(bad("not a BMP file (no `BM` signature)".into()));
    }
    let header = u32_at(14).ok_or_else(|| bad("truncated header".into()))?;
    let (w, h, bpp, compression) = if header == 12 {
        let w = u16_at(18).unwrap_or(0);
        let h = u16_at(20).unwrap_or(0);
        (i64::from(w), i64::from(h), u16_at(24), Some(0))
    } else {
        let w = u32_at(18).map_or(0, |v| i64::from(v as i32));
        let h = u32_at(22).map_or(0, |v| i64::from(v as i32));
        (w, h, u16_at(28), u32_at(30))
    };
    let (Some(bpp), Some(compression)) = (bpp, compression) else {
        return Err(bad("truncated header".into()));
    };
    if !(1..=4097).contains(&w) || !(1..=4097).contains(&h.abs()) {
        return Err(bad(format!(
            "header says {w}x{} pixels; a heightmap is at most 4097x4097",
            h.abs()
        )));
    }
    if bpp == 16 {
        return Err(bad(
            "16-bit BMP: 5-6 bits per channel cannot hold the 256 grey levels of a heightmap exactly (heights would be off by up to 6 grey steps); save it as an 8-bit grey or a 24-bit BMP".into(),
        ));
    }
    // BI_BITFIELDS / BI_ALPHABITFIELDS: colour masks follow the 40-byte info header
    if matches!(compression, 3 | 6) && bpp == 32 {
        for (k, name) in ["red", "green", "blue"].iter().enumerate() {
            let mask = u32_at(54 + 4 * k).unwrap_or(0);
            if mask.count_ones() != 8 {
                return Err(bad(format!(
                    "32-bit BMP with a {}-bit {name} channel: only 8-bit channels hold grey levels exactly",
                    mask.count_ones()
                )));
            }
        }
    }
    Ok(())
}

/// Reads an 8-bit grey BMP (palettised or RGB with equal channels) into grey levels.
pub fn read_grey_bmp(path: &Path) -> Result<(usize, usize, Vec<u8>)> {
    let bytes = crate::input::read_capped(path, MAX_BMP_BYTES, "a heightmap BMP")?;
    check_bmp_header(path, &bytes)?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Bmp)
        .map_err(|e| WorldError::invalid(path, "bmp", format!("not a readable BMP: {e}")))?;
    let rgb = img.to_rgb8();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    let mut grey = Vec::with_capacity(w * h);
    for p in rgb.pixels() {
        if p[0] != p[1] || p[1] != p[2] {
            return Err(WorldError::invalid(
                path,
                "pixels",
                "expected a grey-scale heightmap, found colour pixels",
            ));
        }
        grey.push(p[0]);
    }
    Ok((h, w, grey))
}

/// Checks every pixel of a Verti-Bench label grid against the patches. Pixel (r, c) holds the
/// class of patch (min(r / 8, 15), min(c / 8, 15)) (the shared borders carry the later patch's
/// label). The one known exception (spec §1.5): in mixed worlds, pixels of the map's last row
/// or column may keep the deformable label a patch had before it was converted to rigid; they
/// are accepted when they hold a deformable class. Every other disagreement, and any value that
/// is not a class id, is refused with its position.
fn check_vb_labels(
    lpath: &Path,
    data: &[f64],
    patches: &PatchGrid,
    terrain_type: TerrainType,
    config: &Path,
) -> Result<()> {
    let last = VB_GRID - 1;
    for (k, &v) in data.iter().enumerate() {
        let (r, c) = (k / VB_GRID, k % VB_GRID);
        let (i, j) = ((r / 8).min(15), (c / 8).min(15));
        let class = patches.get(i, j).class;
        if v == f64::from(class.id()) {
            continue;
        }
        let label = (v.fract() == 0.0)
            .then(|| TerrainClass::from_id(v as i64))
            .flatten();
        let Some(label) = label else {
            return Err(WorldError::invalid(
                lpath,
                format!("label at row {r}, column {c}"),
                format!("{v} is not a class id (0..=9)"),
            ));
        };
        let edge_quirk =
            terrain_type == TerrainType::Mixed && (r == last || c == last) && label.is_deformable();
        if !edge_quirk {
            return Err(WorldError::invalid(
                lpath,
                format!("label at row {r}, column {c}"),
                format!(
                    "{v} ({label}) disagrees with patch [{i}, {j}] = {class} ({}) in {}",
                    class.id(),
                    config.display()
                ),
            ));
        }
    }
    Ok(())
}

/// World id from a Verti-Bench config name: `config12_high.yaml` → 12.
pub fn index_from_config_name(path: &Path) -> Option<u32> {
    let stem = path.file_stem()?.to_str()?;
    let rest = stem.strip_prefix("config")?;
    rest.split('_').next()?.parse().ok()
}

/// Imports one Verti-Bench world.
pub fn import_vb(
    config: &Path,
    heightmap: &Path,
    labels: Option<&Path>,
    options: &ImportOptions,
) -> Result<World> {
    crate::scale::check_scale(options.scale)?;
    // the same range as generation: a non-finite clearance would write a world that cannot be
    // loaded back
    if !(options.clearance.is_finite() && (0.0..=20.0).contains(&options.clearance)) {
        return Err(WorldError::Argument(format!(
            "clearance {} m is out of range: it must be in [0, 20] (full-scale metres)",
            options.clearance
        )));
    }
    let cfg = read_config(config)?;
    let s = options.scale;
    let level = ElevationLevel::from_name(&cfg.terrain.difficulty).ok_or_else(|| {
        WorldError::invalid(
            config,
            "terrain.difficulty",
            format!("`{}` is not low, mid or high", cfg.terrain.difficulty),
        )
    })?;
    if !(cfg.terrain.max_height.is_finite() && cfg.terrain.max_height > 0.0) {
        return Err(WorldError::invalid(
            config,
            "terrain.max_height",
            format!("{} must be a positive number", cfg.terrain.max_height),
        ));
    }
    // every Verti-Bench world's max_height is its difficulty's ceiling (4.8, 9.6 or 16 m)
    crate::checks::check_level(config, level, cfg.terrain.max_height, 1.0).map_err(|_| {
        WorldError::invalid(
            config,
            "terrain.max_height",
            format!(
                "{} m contradicts difficulty `{}`, whose worlds have max_height {} m",
                cfg.terrain.max_height,
                cfg.terrain.difficulty,
                level.max_height()
            ),
        )
    })?;
    if cfg.terrain.min_height != 0.0 {
        return Err(WorldError::invalid(
            config,
            "terrain.min_height",
            format!(
                "{} is not supported (Verti-Bench worlds use 0)",
                cfg.terrain.min_height
            ),
        ));
    }
    let terrain_type = TerrainType::from_name(&cfg.terrain_type).ok_or_else(|| {
        WorldError::invalid(
            config,
            "terrain_type",
            format!("`{}` is not rigid, deformable or mixed", cfg.terrain_type),
        )
    })?;
    let density = ObstacleDensity::from_name(&cfg.obstacle_density).ok_or_else(|| {
        WorldError::invalid(
            config,
            "obstacle_density",
            format!("`{}` is not sparse, medium or dense", cfg.obstacle_density),
        )
    })?;

    // elevation
    let (rows, cols, grey) = read_grey_bmp(heightmap)?;
    if (rows, cols) != (VB_GRID, VB_GRID) {
        return Err(WorldError::invalid(
            heightmap,
            "size",
            format!("expected 129x129 pixels, found {cols}x{rows}"),
        ));
    }
    let max_height = cfg.terrain.max_height * s;
    let heights: Vec<f64> = grey
        .iter()
        .map(|&g| f64::from((f64::from(g) / 255.0 * max_height) as f32))
        .collect();
    let terrain = Heightfield::new(VB_GRID, s, heights);

    // patches
    if cfg.textures.len() != PATCHES_PER_SIDE * PATCHES_PER_SIDE {
        return Err(WorldError::invalid(
            config,
            "textures",
            format!("expected 256 patch records, found {}", cfg.textures.len()),
        ));
    }
    let mut slots: Vec<Option<Patch>> = vec![None; 256];
    for (k, t) in cfg.textures.iter().enumerate() {
        let field = |f: &str| format!("textures[{k}].{f}");
        let [i, j] = t.index;
        if i >= PATCHES_PER_SIDE || j >= PATCHES_PER_SIDE {
            return Err(WorldError::invalid(
                config,
                field("index"),
                format!("[{i}, {j}] is outside the 16x16 grid"),
            ));
        }
        let class = TerrainClass::from_name(&t.terrain_type).ok_or_else(|| {
            WorldError::invalid(
                config,
                field("terrain_type"),
                format!("unknown class `{}`", t.terrain_type),
            )
        })?;
        if class.is_deformable() != t.is_deformable {
            return Err(WorldError::invalid(
                config,
                field("is_deformable"),
                format!("{} does not match class {class}", t.is_deformable),
            ));
        }
        let surface = if let Some(soil) = class.soil() {
            Surface::Deformable { soil }
        } else {
            let friction = t.friction.ok_or_else(|| {
                WorldError::invalid(
                    config,
                    field("friction"),
                    format!("rigid patch ({class}) has no friction"),
                )
            })?;
            if !(friction.is_finite() && (0.0..=2.0).contains(&friction)) {
                return Err(WorldError::invalid(
                    config,
                    field("friction"),
                    format!("{friction} is outside [0, 2]"),
                ));
            }
            Surface::Rigid {
                friction,
                restitution: t.restitution.unwrap_or(RIGID_RESTITUTION),
            }
        };
        let slot = &mut slots[i * PATCHES_PER_SIDE + j];
        if slot.is_some() {
            return Err(WorldError::invalid(
                config,
                field("index"),
                format!("patch [{i}, {j}] appears twice"),
            ));
        }
        *slot = Some(Patch { class, surface });
    }
    let patches: Vec<Patch> = slots
        .into_iter()
        .map(|p| p.expect("256 distinct indices fill the grid"))
        .collect();
    let patches = PatchGrid::new(patches, s);

    if let Some(lpath) = labels {
        let arr = npy::read_array2(lpath)?;
        if (arr.rows, arr.cols) != (VB_GRID, VB_GRID) {
            return Err(WorldError::invalid(
                lpath,
                "shape",
                format!("expected (129, 129), found ({}, {})", arr.rows, arr.cols),
            ));
        }
        check_vb_labels(lpath, &arr.data, &patches, terrain_type, config)?;
    }

    // obstacles: reference geometry, seated on the ground
    let obs = cfg.obstacles.unwrap_or_default();
    let (want_rocks, want_trees) = density.counts();
    if obs.rocks.len() != want_rocks || obs.trees.len() != want_trees {
        return Err(WorldError::invalid(
            config,
            "obstacles",
            format!(
                "{density} density means {want_rocks} rocks and {want_trees} trees, found {} and {}",
                obs.rocks.len(),
                obs.trees.len()
            ),
        ));
    }
    let mut obstacles = Vec::with_capacity(obs.rocks.len() + obs.trees.len());
    for (k, r) in obs.rocks.iter().enumerate() {
        let p = r.position;
        if !(p.x.is_finite() && p.y.is_finite() && r.scale.is_finite() && r.scale > 0.0) {
            return Err(WorldError::invalid(
                config,
                format!("obstacles.rocks[{k}]"),
                "position and scale must be finite, scale > 0",
            ));
        }
        let size = Vec3::new(
            VB_ROCK_BOX[0] * r.scale * s,
            VB_ROCK_BOX[1] * r.scale * s,
            VB_ROCK_BOX[2] * r.scale * s,
        );
        let (x, y) = (p.x * s, p.y * s);
        let (ground, _) = terrain.range_in_box(
            x - 0.5 * size.x,
            y - 0.5 * size.y,
            x + 0.5 * size.x,
            y + 0.5 * size.y,
        );
        let z = ground - BURY * s + 0.5 * size.z;
        obstacles.push(
            Obstacle::rock(box_faces(size), r.scale, Vec3::new(x, y, z), 0.0)
                .map_err(|e| WorldError::invalid(config, format!("obstacles.rocks[{k}]"), e))?,
        );
    }
    for (k, t) in obs.trees.iter().enumerate() {
        let p = t.position;
        if !(p.x.is_finite() && p.y.is_finite()) {
            return Err(WorldError::invalid(
                config,
                format!("obstacles.trees[{k}]"),
                "position must be finite",
            ));
        }
        let (x, y) = (p.x * s, p.y * s);
        let r = 0.5 * VB_TREE_BOX[0] * s;
        let (ground, _) = terrain.range_in_box(x - r, y - r, x + r, y + r);
        let h = VB_TREE_BOX[2] * s + BURY * s;
        obstacles.push(
            Obstacle::tree(r, h, Vec3::new(x, y, ground - BURY * s + 0.5 * h))
                .map_err(|e| WorldError::invalid(config, format!("obstacles.trees[{k}]"), e))?,
        );
    }

    // tasks
    let half = terrain.half_extent();
    let mut tasks = Vec::with_capacity(cfg.positions.len());
    for (k, pair) in cfg.positions.iter().enumerate() {
        let get = |v: &Vec<f64>, what: &str| -> Result<[f64; 2]> {
            if v.len() < 2 || !v[0].is_finite() || !v[1].is_finite() {
                return Err(WorldError::invalid(
                    config,
                    format!("positions[{k}].{what}"),
                    "needs finite [x, y, z]",
                ));
            }
            let p = [v[0] * s, v[1] * s];
            if p[0].abs() > half || p[1].abs() > half {
                return Err(WorldError::invalid(
                    config,
                    format!("positions[{k}].{what}"),
                    format!("{p:?} is off the map"),
                ));
            }
            Ok(p)
        };
        tasks.push(Task {
            pair: k as u32,
            start: get(&pair.start, "start")?,
            goal: get(&pair.goal, "goal")?,
        });
    }
    if tasks.len() > PAIRS_PER_WORLD as usize {
        return Err(WorldError::invalid(
            config,
            "positions",
            format!(
                "{} start/goal pairs; a world has at most {PAIRS_PER_WORLD} (task numbers are (world - 1) * 10 + pair + 1)",
                tasks.len()
            ),
        ));
    }
    if tasks.is_empty() {
        return Err(WorldError::invalid(
            config,
            "positions",
            "no start/goal pairs",
        ));
    }

    let clearance = options.clearance * s;
    let paths = plan_paths(&obstacles, &terrain, &tasks, clearance);
    let index = options
        .index
        .or_else(|| index_from_config_name(config))
        .unwrap_or(1);
    let stem = config
        .file_stem()
        .and_then(|x| x.to_str())
        .unwrap_or("world")
        .to_string();
    Ok(World {
        meta: WorldMeta {
            name: format!("vb/{stem}"),
            index,
            source: WorldSource::VertiBench {
                config: file_name(config),
                heightmap: file_name(heightmap),
            },
            level,
            terrain_type,
            density,
            scale: s,
            max_height,
        },
        terrain,
        patches,
        obstacles,
        tasks,
        paths,
        path_clearance: clearance,
    })
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default()
        .to_string()
}

/// One world's files found in a Verti-Bench folder.
#[derive(Clone, Debug, PartialEq)]
pub struct VbWorldFiles {
    pub config: PathBuf,
    pub heightmap: PathBuf,
    pub labels: Option<PathBuf>,
    pub index: u32,
}

/// Finds every `configN_LEVEL.yaml` in a folder with its heightmap (`worldN.bmp` next to it, or
/// the reference layout `../../Worlds/N.bmp`) and labels (`labelsN_LEVEL.npy`), sorted by N.
pub fn scan_vb_dir(dir: &Path) -> Result<Vec<VbWorldFiles>> {
    let entries = std::fs::read_dir(dir).map_err(|e| WorldError::io(dir, e))?;
    let mut out = Vec::new();
    for e in entries {
        let e = e.map_err(|e| WorldError::io(dir, e))?;
        let path = e.path();
        let name = file_name(&path);
        if !(name.starts_with("config") && name.ends_with(".yaml")) {
            continue;
        }
        let Some(index) = index_from_config_name(&path) else {
            continue;
        };
        let level = name
            .trim_end_matches(".yaml")
            .split('_')
            .nth(1)
            .unwrap_or("");
        let candidates = [
            dir.join(format!("world{index}.bmp")),
            dir.join(format!("{index}.bmp")),
            dir.join("../../Worlds").join(format!("{index}.bmp")),
        ];
        let heightmap = candidates.iter().find(|p| p.exists()).cloned().ok_or_else(|| {
            WorldError::invalid(&path, "heightmap", format!("no heightmap found for world {index} (looked for world{index}.bmp, {index}.bmp, ../../Worlds/{index}.bmp)"))
        })?;
        let labels = Some(dir.join(format!("labels{index}_{level}.npy"))).filter(|p| p.exists());
        out.push(VbWorldFiles {
            config: path,
            heightmap,
            labels,
            index,
        });
    }
    out.sort_by_key(|f| f.index);
    if out.is_empty() {
        return Err(WorldError::Argument(format!(
            "{}: no Verti-Bench configs (configN_LEVEL.yaml) found",
            dir.display()
        )));
    }
    Ok(out)
}
