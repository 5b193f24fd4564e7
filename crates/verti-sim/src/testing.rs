//! Programmatic worlds for tests and benchmarks: flat, tilted, bumpy, a rock ahead, soil, and
//! rough worlds with dense obstacles. All are 129x129-vertex maps with 1 m cells at full scale
//! (Verti-Bench's layout), every length multiplied by `scale`.

use verti_core::{Rng, Vec3};
use verti_world::obstacle::box_faces;
use verti_world::surface::{PATCHES_PER_SIDE, RIGID_RESTITUTION};
use verti_world::{
    ElevationLevel, Heightfield, Obstacle, ObstacleDensity, Patch, PatchGrid, SoilParams, Surface,
    TerrainClass, TerrainType, World, WorldMeta, WorldSource,
};

/// Vertices per side of every test world.
pub const TEST_WORLD_VERTICES: usize = 129;

/// A rigid patch of the given friction.
pub fn rigid_patch(friction: f64) -> Patch {
    Patch {
        class: TerrainClass::Concrete,
        surface: Surface::Rigid {
            friction,
            restitution: RIGID_RESTITUTION,
        },
    }
}

/// A deformable patch of the given soil.
pub fn soil_patch(soil: SoilParams) -> Patch {
    let class = if soil == SoilParams::SOFT {
        TerrainClass::Snow
    } else if soil == SoilParams::HARD {
        TerrainClass::Sand
    } else {
        TerrainClass::Mud
    };
    Patch {
        class,
        surface: Surface::Deformable { soil },
    }
}

/// Builds a world from a height function of world (x, y), uniform patches and obstacles.
pub fn world_from_fn(
    name: &str,
    scale: f64,
    height: impl Fn(f64, f64) -> f64,
    patches: Vec<Patch>,
    obstacles: Vec<Obstacle>,
) -> World {
    let n = TEST_WORLD_VERTICES;
    let cell = scale;
    let half = 0.5 * (n - 1) as f64;
    let mut heights = Vec::with_capacity(n * n);
    for r in 0..n {
        for c in 0..n {
            heights.push(height((c as f64 - half) * cell, (half - r as f64) * cell));
        }
    }
    let terrain = Heightfield::new(n, cell, heights);
    let max_height = terrain.max_height().max(0.0);
    let has_soil = patches.iter().any(|p| p.surface.is_deformable());
    let all_soil = patches.iter().all(|p| p.surface.is_deformable());
    let terrain_type = if all_soil {
        TerrainType::Deformable
    } else if has_soil {
        TerrainType::Mixed
    } else {
        TerrainType::Rigid
    };
    World {
        meta: WorldMeta {
            name: format!("test/{name}"),
            index: 0,
            source: WorldSource::Generated {
                set_seed: 0,
                generator: "test".into(),
            },
            level: ElevationLevel::Low,
            terrain_type,
            density: ObstacleDensity::Sparse,
            scale,
            max_height,
        },
        terrain,
        patches: PatchGrid::new(patches, cell),
        obstacles,
        tasks: Vec::new(),
        paths: Vec::new(),
        path_clearance: 0.0,
    }
}

fn uniform(p: Patch) -> Vec<Patch> {
    vec![p; PATCHES_PER_SIDE * PATCHES_PER_SIDE]
}

/// Flat rigid ground at z = 0.
pub fn flat_world(scale: f64, friction: f64) -> World {
    world_from_fn(
        "flat",
        scale,
        |_, _| 0.0,
        uniform(rigid_patch(friction)),
        Vec::new(),
    )
}

/// A rigid plane rising at `slope_x` radians toward +x and `slope_y` toward +y.
pub fn plane_world(scale: f64, slope_x: f64, slope_y: f64, friction: f64) -> World {
    let (tx, ty) = (slope_x.tan(), slope_y.tan());
    world_from_fn(
        "plane",
        scale,
        move |x, y| tx * x + ty * y,
        uniform(rigid_patch(friction)),
        Vec::new(),
    )
}

/// A plane of soil rising at `slope_x` radians toward +x.
pub fn soil_world(scale: f64, soil: SoilParams, slope_x: f64) -> World {
    let t = slope_x.tan();
    world_from_fn(
        "soil",
        scale,
        move |x, _| t * x,
        uniform(soil_patch(soil)),
        Vec::new(),
    )
}

/// Flat ground at z = 0: soil west of x = 0 (patch columns 0-7), rigid ground of `friction`
/// east of it: a straight edge between rigid ground and soil along the y axis.
pub fn half_soil_world(scale: f64, soil: SoilParams, friction: f64) -> World {
    let patches = (0..PATCHES_PER_SIDE * PATCHES_PER_SIDE)
        .map(|k| {
            if k % PATCHES_PER_SIDE < PATCHES_PER_SIDE / 2 {
                soil_patch(soil)
            } else {
                rigid_patch(friction)
            }
        })
        .collect();
    world_from_fn("half-soil", scale, |_, _| 0.0, patches, Vec::new())
}

/// Rolling bumps: sum of two sines of the given amplitude and wavelength (at full scale).
pub fn bumpy_world(scale: f64, amplitude: f64, wavelength: f64, friction: f64) -> World {
    let k = std::f64::consts::TAU / (wavelength * scale);
    let a = amplitude * scale;
    world_from_fn(
        "bumpy",
        scale,
        move |x, y| {
            a * (0.5 * (k * x).sin() + 0.5 * (0.73 * k * y + 0.4).sin() * (0.61 * k * x).cos())
        },
        uniform(rigid_patch(friction)),
        Vec::new(),
    )
}

/// Flat rigid ground with one ridge: the row of vertices at x = `ridge_x` (world units, a
/// multiple of the cell, `scale`) raised by `height` (world units), a tent one cell wide on
/// each side running along y: the thinnest ridge a height map can hold.
pub fn ridge_world(scale: f64, friction: f64, ridge_x: f64, height: f64) -> World {
    world_from_fn(
        "ridge",
        scale,
        move |x, _| {
            if (x - ridge_x).abs() < 0.5 * scale {
                height
            } else {
                0.0
            }
        },
        uniform(rigid_patch(friction)),
        Vec::new(),
    )
}

/// Flat ground with one box rock of full size `size` (world units, already scaled) whose
/// near face is at x = `front_x`, centred on y = 0, sitting on the ground.
pub fn rock_world(scale: f64, friction: f64, front_x: f64, size: Vec3) -> World {
    let rock = Obstacle::rock(
        box_faces(size),
        1.0,
        Vec3::new(front_x + 0.5 * size.x, 0.0, 0.5 * size.z),
        0.0,
    )
    .expect("a box is a valid rock");
    world_from_fn(
        "rock",
        scale,
        |_, _| 0.0,
        uniform(rigid_patch(friction)),
        vec![rock],
    )
}

/// Flat ground with one box rock of full size `size` (world units) centred on `centre` (x, y),
/// sitting on the ground, turned by `yaw` \[rad\] about the vertical.
pub fn yawed_rock_world(
    scale: f64,
    friction: f64,
    centre: (f64, f64),
    size: Vec3,
    yaw: f64,
) -> World {
    let rock = Obstacle::rock(
        box_faces(size),
        1.0,
        Vec3::new(centre.0, centre.1, 0.5 * size.z),
        yaw,
    )
    .expect("a box is a valid rock");
    world_from_fn(
        "yawed-rock",
        scale,
        |_, _| 0.0,
        uniform(rigid_patch(friction)),
        vec![rock],
    )
}

/// Flat ground with one tree (vertical cylinder of the given radius and height, world units)
/// centred at (x, 0).
pub fn tree_world(scale: f64, friction: f64, x: f64, radius: f64, height: f64) -> World {
    let tree =
        Obstacle::tree(radius, height, Vec3::new(x, 0.0, 0.5 * height)).expect("a valid tree");
    world_from_fn(
        "tree",
        scale,
        |_, _| 0.0,
        uniform(rigid_patch(friction)),
        vec![tree],
    )
}

/// Terrain kinds for [`rough_world`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoughSurface {
    Rigid,
    Soil,
    Mixed,
}

/// A rough, high-relief world with dense obstacles like Verti-Bench's hardest ones: smooth
/// random hills (up to `relief` metres at full scale), 40 rocks and 3 trees kept out of a
/// 12 m (scaled) clearing around the origin so vehicles can start there.
pub fn rough_world(scale: f64, seed: u64, relief: f64, surface: RoughSurface) -> World {
    let mut rng = Rng::derive(seed, "verti-sim rough world", 0);
    let waves: Vec<(f64, f64, f64, f64)> = (0..8)
        .map(|k| {
            let wl = 20.0 + 60.0 * rng.uniform() / (1.0 + k as f64 * 0.3);
            let dir = rng.range(0.0, std::f64::consts::TAU);
            (
                std::f64::consts::TAU / (wl * scale),
                dir,
                rng.range(0.0, std::f64::consts::TAU),
                rng.range(0.3, 1.0),
            )
        })
        .collect();
    let total: f64 = waves.iter().map(|w| w.3).sum();
    let amp = 0.5 * relief * scale / total;
    let height = move |x: f64, y: f64| {
        waves
            .iter()
            .map(|&(k, dir, ph, a)| a * (k * (x * dir.cos() + y * dir.sin()) + ph).sin())
            .sum::<f64>()
            * amp
            + 0.5 * relief * scale
    };
    let mut patches = Vec::with_capacity(256);
    for i in 0..256 {
        let friction = rng.range(0.4, 0.95);
        let soil = match rng.below(3) {
            0 => SoilParams::SOFT,
            1 => SoilParams::MID,
            _ => SoilParams::HARD,
        };
        patches.push(match surface {
            RoughSurface::Rigid => rigid_patch(friction),
            RoughSurface::Soil => soil_patch(soil),
            RoughSurface::Mixed => {
                if (i / 16 + i % 16) % 2 == 0 {
                    rigid_patch(friction)
                } else {
                    soil_patch(soil)
                }
            }
        });
    }
    let mut obstacles = Vec::new();
    let half = 0.5 * (TEST_WORLD_VERTICES - 1) as f64 * scale;
    let clearing = 12.0 * scale;
    let mut tries = 0;
    while obstacles.len() < 43 && tries < 10_000 {
        tries += 1;
        let x = rng.range(-half * 0.9, half * 0.9);
        let y = rng.range(-half * 0.9, half * 0.9);
        if x.hypot(y) < clearing {
            continue;
        }
        let z = height(x, y);
        if obstacles.len() < 40 {
            let s = rng.range(0.7, 1.2) * scale;
            let size = Vec3::new(
                4.4 * s * rng.range(0.4, 1.0),
                4.4 * s * rng.range(0.4, 1.0),
                3.8 * s * rng.range(0.3, 0.8),
            );
            let yaw = rng.range(0.0, std::f64::consts::PI);
            if let Ok(o) =
                Obstacle::rock(box_faces(size), s, Vec3::new(x, y, z + 0.3 * size.z), yaw)
            {
                obstacles.push(o);
            }
        } else if let Ok(o) =
            Obstacle::tree(0.3 * scale, 5.0 * scale, Vec3::new(x, y, z + 2.5 * scale))
        {
            obstacles.push(o);
        }
    }
    let name = match surface {
        RoughSurface::Rigid => "rough-rigid",
        RoughSurface::Soil => "rough-soil",
        RoughSurface::Mixed => "rough-mixed",
    };
    let mut w = world_from_fn(name, scale, height, patches, obstacles);
    w.meta.level = ElevationLevel::High;
    w.meta.density = ObstacleDensity::Dense;
    w
}

/// A tilt table you drive along: the ground rises toward +y with a cross slope that grows
/// linearly along x, `start_deg` at x = 0 and `deg_per_m` more per metre (world-scaled).
pub fn twisting_slope_world(scale: f64, start_deg: f64, deg_per_m: f64, friction: f64) -> World {
    world_from_fn(
        "twisting-slope",
        scale,
        move |x, y| {
            y * (start_deg + deg_per_m * x / scale)
                .clamp(0.0, 85.0)
                .to_radians()
                .tan()
        },
        uniform(rigid_patch(friction)),
        Vec::new(),
    )
}
