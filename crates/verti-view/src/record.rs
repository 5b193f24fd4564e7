//! What a 3-D recording holds, and how a trial is recorded.

use serde::{Deserialize, Serialize};
use std::sync::Arc;
use verti_bench::{EpisodeConfig, MobilitySystem, Trial, TrialResult, run_episode_watched};
use verti_core::Vec3;
use verti_sim::VehicleSpec;
use verti_world::{ObstacleShape, World};

/// Sides of the polygon a tree trunk is drawn as.
const TREE_SIDES: usize = 10;

/// Rounds to 4 decimals: millimetres and tenths of a milliradian are plenty for a picture,
/// and the page stays a few hundred kilobytes.
fn r4(x: f64) -> f32 {
    ((x * 1e4).round() / 1e4) as f32
}

/// One sample of the scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Frame {
    /// Trial time, s.
    pub t: f32,
    /// Collision-box centre (world) and chassis orientation quaternion (w, x, y, z).
    pub body: [f32; 7],
    /// Per wheel: centre (world x, y, z), road-wheel steer angle (rad), suspension compression
    /// (m, positive = pushed up), soil sinkage under it (m).
    pub wheels: Vec<[f32; 6]>,
    /// Forward speed (m/s), roll and pitch (degrees), throttle − brake and steering (−1..1).
    pub speed: f32,
    pub roll: f32,
    pub pitch: f32,
    pub throttle: f32,
    pub steering: f32,
}

/// An obstacle as a vertical prism: a ground polygon extruded from `z0` to `z1`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Prism {
    pub polygon: Vec<[f32; 2]>,
    pub z0: f32,
    pub z1: f32,
    pub tree: bool,
}

/// Everything the viewer draws.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Recording {
    pub title: String,
    /// Heightfield: vertices per side, cell size (m), row-major heights (row 0 = north).
    pub n: usize,
    pub cell: f32,
    pub heights: Vec<f32>,
    /// Per-vertex colour of the terrain class, RGB 0..255.
    pub colors: Vec<[u8; 3]>,
    pub obstacles: Vec<Prism>,
    pub path: Vec<[f32; 3]>,
    pub start: [f32; 3],
    pub goal: [f32; 3],
    /// Success radius around the goal (m).
    pub goal_radius: f32,
    /// Chassis collision box size (m) and wheel radius and width (m), per wheel.
    pub body_size: [f32; 3],
    pub wheel_size: Vec<[f32; 2]>,
    pub frames: Vec<Frame>,
    /// The trial's outcome and result line.
    pub outcome: String,
    pub result: serde_json::Value,
    /// Set on a live page: it asks its server for new frames and sends the keys held.
    #[serde(default)]
    pub live: bool,
}

/// The scene now: body, wheels and commands of `trial`.
pub fn frame(trial: &Trial) -> Frame {
    let (sim, state) = (trial.sim(), trial.state());
    let spec = sim.spec();
    let [bx, by, bz] = spec.chassis.collision_box.center;
    let box_centre = sim.point_world(state, Vec3::new(bx, by, bz));
    let q = state.orientation();
    let world = trial.world();
    let wheels = sim
        .wheel_centers(state)
        .iter()
        .zip(state.wheels())
        .map(|(c, w)| {
            let ground = world.terrain.height_at(c.x, c.y);
            let sinkage = (ground - sim.ground_height_at(state, c.x, c.y)).max(0.0);
            [
                r4(c.x),
                r4(c.y),
                r4(c.z),
                r4(w.steer_angle),
                r4(w.compression),
                r4(sinkage),
            ]
        })
        .collect();
    let pose = trial.pose();
    let controls = trial.controls();
    Frame {
        t: r4(trial.time()),
        body: [
            r4(box_centre.x),
            r4(box_centre.y),
            r4(box_centre.z),
            r4(q.w),
            r4(q.x),
            r4(q.y),
            r4(q.z),
        ],
        wheels,
        speed: r4(state.forward_speed()),
        roll: r4(pose.roll.to_degrees()),
        pitch: r4(pose.pitch.to_degrees()),
        throttle: r4(controls.throttle - controls.brake),
        steering: r4(controls.steering),
    }
}

fn scene(world: &World, pair: u32, cfg: &EpisodeConfig) -> Recording {
    let t = &world.terrain;
    let n = t.size();
    let mut colors = Vec::with_capacity(n * n);
    for r in 0..n {
        for c in 0..n {
            let (x, y) = t.vertex_xy(r, c);
            let rgb = verti_render::palette::class_color(world.patches.at(x, y).class);
            colors.push(rgb.0);
        }
    }
    let obstacles = world
        .obstacles
        .iter()
        .map(|o| {
            let p = o.position();
            let (z0, z1) = o.z_range();
            let polygon: Vec<[f32; 2]> = match o.shape() {
                ObstacleShape::Tree { radius, .. } => (0..TREE_SIDES)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / TREE_SIDES as f64;
                        [r4(p.x + radius * a.cos()), r4(p.y + radius * a.sin())]
                    })
                    .collect(),
                ObstacleShape::Rock { .. } => {
                    o.footprint().iter().map(|q| [r4(q[0]), r4(q[1])]).collect()
                }
            };
            Prism {
                polygon,
                z0: r4(z0.min(t.height_at(p.x, p.y))),
                z1: r4(z1),
                tree: !o.is_rock(),
            }
        })
        .collect();
    let index = world.tasks.iter().position(|k| k.pair == pair);
    let task = index.map(|i| world.tasks[i]);
    let lift = 0.3 * world.meta.scale;
    let on_ground = |x: f64, y: f64, up: f64| [r4(x), r4(y), r4(t.height_at(x, y) + up)];
    Recording {
        title: String::new(),
        n,
        cell: r4(t.cell()),
        heights: t.heights().iter().map(|&h| r4(h)).collect(),
        colors,
        obstacles,
        path: index
            .and_then(|i| world.paths.get(i))
            .map(|p| {
                p.points
                    .iter()
                    .map(|q| on_ground(q[0], q[1], lift))
                    .collect()
            })
            .unwrap_or_default(),
        start: task.map_or([0.0; 3], |k| on_ground(k.start[0], k.start[1], 0.0)),
        goal: task.map_or([0.0; 3], |k| on_ground(k.goal[0], k.goal[1], 0.0)),
        goal_radius: r4(cfg.success_radius * world.meta.scale),
        body_size: [0.0; 3],
        wheel_size: Vec::new(),
        frames: Vec::new(),
        outcome: String::new(),
        result: serde_json::Value::Null,
        live: false,
    }
}

impl Recording {
    /// The still scene of task `pair` of `world` driven by `spec`, with no frames yet.
    pub fn start(world: &World, spec: &VehicleSpec, pair: u32, cfg: &EpisodeConfig) -> Recording {
        let mut rec = scene(world, pair, cfg);
        let b = spec.chassis.collision_box.size;
        rec.body_size = [r4(b[0]), r4(b[1]), r4(b[2])];
        rec.wheel_size = spec
            .axles
            .iter()
            .flat_map(|a| {
                let w = [r4(a.wheel.radius), r4(a.wheel.width)];
                [w, w]
            })
            .collect();
        rec.title = format!("{} on {} pair {pair}", spec.name, world.meta.name);
        rec
    }

    /// Records how the trial ended.
    pub fn finish(&mut self, result: &TrialResult) {
        self.outcome = result.outcome.name().to_string();
        self.title = format!(
            "{} on task {} ({}, {} elevation, {}, {} obstacles): {}",
            result.system,
            result.task,
            result.world_name,
            format!("{:?}", result.level).to_lowercase(),
            format!("{:?}", result.terrain_type).to_lowercase(),
            format!("{:?}", result.density).to_lowercase(),
            self.outcome
        );
        self.result = serde_json::to_value(result).unwrap_or_default();
    }
}

/// Drives `system` through task `pair` of `world` with the benchmark's episode loop, sampling
/// the scene at the start and after every control period. Returns the recording and the
/// trial's result (the same as `run_episode`'s for the same settings, but the wall time).
pub fn record_trial(
    world: &Arc<World>,
    spec: &VehicleSpec,
    pair: u32,
    system: &mut dyn MobilitySystem,
    cfg: &EpisodeConfig,
) -> (Recording, TrialResult) {
    let mut rec = Recording::start(world, spec, pair, cfg);
    let mut frames = Vec::new();
    let result = run_episode_watched(world, spec, pair, system, cfg, None, &mut |trial| {
        frames.push(frame(trial));
    });
    rec.frames = frames;
    rec.finish(&result);
    (rec, result)
}
