//! What a system sees: ground-truth vehicle state, the goal and global path, and robot-centred,
//! heading-aligned crops of elevation, semantic class and obstacle occupancy (paper §III-G.4).
//!
//! Crops are computed only when a system asks for them, so a system that needs no map pays
//! nothing for maps.
//!
//! An observation made by a running [`Trial`](crate::Trial) also carries the trial itself,
//! reachable through [`Observation::trial`]. That is *privileged*: a system that uses it plans
//! with the true simulator, which no deployable system has. Only oracle-type systems (the
//! `oracle` of verti-systems, an expert demonstrator for datasets) may use it; every system of
//! the paper sees the fields above only. The observation holds it as an opaque view (the seam
//! of `crate::privileged`), so this module does not depend on the trial (which depends on it):
//! `Observation::with_trial` and `Observation::trial` are defined in `trial`.

use crate::features::FeatureSource;
use crate::perception::Sensing;
use crate::privileged::PrivilegedView;
use verti_core::Vec3;
use verti_sim::Controls;
use verti_world::World;

/// Size and resolution of a square crop centred on the vehicle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CropSpec {
    /// Cells per side.
    pub size: usize,
    /// Metres per cell.
    pub resolution: f64,
}

/// A heading-aligned crop: row 0 is farthest ahead of the vehicle, column 0 farthest to its
/// left; the vehicle is at the centre. Row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Crop<T> {
    pub spec: CropSpec,
    pub data: Vec<T>,
}

impl<T: Copy> Crop<T> {
    pub fn get(&self, row: usize, col: usize) -> T {
        self.data[row * self.spec.size + col]
    }
}

/// The chassis pose (defined in the bottom-layer `crate::pose`, which every module that
/// speaks of poses imports; re-exported here, where it has always been reachable).
pub use crate::pose::Pose6;

/// One observation. Borrowed from the episode; valid during one `act` call.
pub struct Observation<'a> {
    world: &'a World,
    /// Simulated time since the start of the trial, seconds.
    pub time: f64,
    pub pose: Pose6,
    /// Linear velocity in the body frame (x forward, y left, z up), m/s.
    pub velocity_body: Vec3,
    /// Angular velocity in the body frame, rad/s.
    pub angular_velocity_body: Vec3,
    /// Forward speed (body x), m/s.
    pub forward_speed: f64,
    /// Driver inputs applied in the latest inner step (idle before the first step).
    pub controls: Controls,
    pub goal: [f64; 2],
    pub global_path: &'a [[f64; 2]],
    /// Length scale of the world.
    pub world_scale: f64,
    vehicle: FeatureSource,
    /// The trial observed (privileged; see [`Observation::trial`]), type-erased so that this
    /// module need not name the trial (`crate::privileged`).
    privileged: Option<PrivilegedView<'a>>,
    /// Range limit and latency of map reads under perception noise (None: ideal sensing).
    sensing: Option<Sensing>,
}

impl<'a> Observation<'a> {
    /// An observation of `world` with the vehicle as `vehicle` describes it (inside a trial,
    /// [`crate::Trial::observation`] makes it; tools and tests build their own).
    pub fn new(
        world: &'a World,
        vehicle: FeatureSource,
        goal: [f64; 2],
        global_path: &'a [[f64; 2]],
    ) -> Self {
        Observation {
            world,
            time: vehicle.time,
            pose: vehicle.pose,
            velocity_body: vehicle.velocity_body,
            angular_velocity_body: vehicle.angular_velocity_body,
            forward_speed: vehicle.forward_speed,
            controls: vehicle.controls,
            goal,
            global_path,
            world_scale: world.meta.scale,
            vehicle,
            privileged: None,
            sensing: None,
        }
    }

    /// This observation with map reads limited and displaced as `sensing` says (perception
    /// noise; [`crate::perception`]).
    pub fn with_sensing(mut self, sensing: Sensing) -> Self {
        self.sensing = Some(sensing);
        self
    }

    /// How the map is sensed (None: every cell, as it is).
    pub fn sensing(&self) -> Option<&Sensing> {
        self.sensing.as_ref()
    }

    /// This observation with the privileged view `view` (the running trial it describes;
    /// `Observation::with_trial` in `trial` sets it).
    pub(crate) fn with_privileged(mut self, view: PrivilegedView<'a>) -> Self {
        self.privileged = Some(view);
        self
    }

    /// This observation without privileged access (what a system would see outside a trial).
    pub fn without_trial(mut self) -> Self {
        self.privileged = None;
        self
    }

    /// The privileged view, if this observation carries one (`Observation::trial` in `trial`
    /// reads it back as the trial).
    pub(crate) fn privileged(&self) -> Option<PrivilegedView<'a>> {
        self.privileged
    }

    /// The vehicle's state as named features (the schema of [`crate::features`]).
    pub fn features(&self) -> &FeatureSource {
        &self.vehicle
    }

    /// The world observed (ground truth).
    pub fn world(&self) -> &'a World {
        self.world
    }

    /// World (x, y) of the centre of crop cell (row, col).
    pub fn crop_cell_xy(&self, spec: CropSpec, row: usize, col: usize) -> (f64, f64) {
        let half = 0.5 * (spec.size as f64 - 1.0);
        let ahead = (half - row as f64) * spec.resolution;
        let left = (half - col as f64) * spec.resolution;
        let (s, c) = self.pose.yaw.sin_cos();
        (
            self.pose.x + ahead * c - left * s,
            self.pose.y + ahead * s + left * c,
        )
    }

    fn crop<T>(&self, spec: CropSpec, f: impl Fn(f64, f64) -> T) -> Crop<T> {
        let mut data = Vec::with_capacity(spec.size * spec.size);
        for r in 0..spec.size {
            for c in 0..spec.size {
                let (x, y) = self.crop_cell_xy(spec, r, c);
                data.push(f(x, y));
            }
        }
        Crop { spec, data }
    }

    /// Terrain height (m, undeformed) under each cell.
    pub fn elevation_crop(&self, spec: CropSpec) -> Crop<f64> {
        self.crop(spec, |x, y| self.elevation_at(x, y))
    }

    /// Semantic class id (Verti-Bench label ids 0..9) under each cell; out of sensing range,
    /// the class under the vehicle.
    pub fn semantic_crop(&self, spec: CropSpec) -> Crop<u8> {
        self.crop(spec, |x, y| {
            let (x, y) = self.sensed(x, y).unwrap_or_else(|| self.vehicle_xy());
            self.world.patches.at(x, y).class.id()
        })
    }

    /// 1 where an obstacle footprint covers the cell centre, else 0. Off-map cells read 1 so
    /// planners keep to the map.
    pub fn occupancy_crop(&self, spec: CropSpec) -> Crop<u8> {
        // reads displaced by a perception latency land this much farther away
        let shift = self.sensing.map_or(0.0, |s| s.shift[0].hypot(s.shift[1]));
        let reach = 0.75 * spec.size as f64 * spec.resolution + shift;
        let near: Vec<&verti_world::Obstacle> = self
            .world
            .obstacles
            .iter()
            .filter(|o| {
                let p = o.position();
                ((p.x - self.pose.x).powi(2) + (p.y - self.pose.y).powi(2)).sqrt()
                    < reach + o.radius_xy()
            })
            .collect();
        // the bounding-circle test rejects almost every (cell, obstacle) pair before the
        // polygon test, which keeps large crops cheap enough for a 20 Hz planner
        self.crop(spec, |x, y| {
            let off_map = !self.world.terrain.contains(x, y);
            // under perception noise: nothing is known beyond range, and reads lag by the latency
            let Some((x, y)) = self.sensed(x, y) else {
                return u8::from(off_map);
            };
            u8::from(
                off_map
                    || near.iter().any(|o| {
                        let p = o.position();
                        let r = o.radius_xy();
                        (p.x - x).powi(2) + (p.y - y).powi(2) <= r * r
                            && o.footprint_distance(x, y) <= 0.0
                    }),
            )
        })
    }

    /// Undeformed terrain height at a world point (ground truth, as the paper's systems get;
    /// under perception noise, the perceived map within sensing range, level ground beyond).
    pub fn elevation_at(&self, x: f64, y: f64) -> f64 {
        // beyond sensing range: level ground at the vehicle
        self.sensed(x, y).map_or_else(
            || self.sensing.map_or(0.0, |s| s.ground),
            |(x, y)| self.world.terrain.height_at(x, y),
        )
    }

    /// Horizontal distance from (x, y) to the nearest obstacle footprint (negative inside);
    /// under perception noise, infinite beyond sensing range.
    pub fn obstacle_distance(&self, x: f64, y: f64) -> f64 {
        self.sensed(x, y)
            .map_or(f64::INFINITY, |(x, y)| self.world.obstacle_distance(x, y))
    }

    /// Where a map read at (x, y) lands: the point itself with ideal sensing; under perception
    /// noise the point displaced by the latency shift, or None beyond sensing range.
    #[inline]
    fn sensed(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        match &self.sensing {
            None => Some((x, y)),
            Some(s) => s.sees(x, y).then(|| s.lookup(x, y)),
        }
    }

    /// Where reads beyond sensing range look: the vehicle's true place (only sensing puts a
    /// point out of range; without it, the observed pose).
    fn vehicle_xy(&self) -> (f64, f64) {
        self.sensing
            .map_or((self.pose.x, self.pose.y), |s| (s.centre[0], s.centre[1]))
    }

    /// Half of the map's side length (m): the map spans [-h, h] in x and y.
    pub fn map_half_extent(&self) -> f64 {
        self.world.terrain.half_extent()
    }
}

/// An observation of a vehicle standing at `xy` with heading `yaw` (for tests and benchmarks of
/// systems outside an episode).
pub fn test_observation<'a>(
    world: &'a World,
    xy: [f64; 2],
    yaw: f64,
    goal: [f64; 2],
    path: &'a [[f64; 2]],
) -> Observation<'a> {
    let z = world.terrain.height_at(xy[0], xy[1]);
    let pose = Pose6 {
        x: xy[0],
        y: xy[1],
        z,
        roll: 0.0,
        pitch: 0.0,
        yaw,
    };
    let vehicle = FeatureSource::at_rest(pose);
    Observation::new(world, vehicle, goal, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use verti_sim::testing;

    #[test]
    fn crops_are_heading_aligned() {
        // a plane rising to the east: z = 0.1 x
        let world = testing::plane_world(1.0, 0.1f64.atan(), 0.0, 0.8);
        let spec = CropSpec {
            size: 5,
            resolution: 1.0,
        };
        // facing east: row 0 is 2 m ahead (x = 2), row 4 is 2 m behind
        let crop = test_observation(&world, [0.0, 0.0], 0.0, [10.0, 0.0], &[]).elevation_crop(spec);
        let here = crop.get(2, 2);
        assert!(
            (crop.get(0, 2) - here - 0.2).abs() < 1e-9
                && (crop.get(4, 2) - here + 0.2).abs() < 1e-9
        );
        // facing north: the robot's left is west, so column 0 is lower on this east-rising plane
        let north = std::f64::consts::FRAC_PI_2;
        let crop =
            test_observation(&world, [0.0, 0.0], north, [10.0, 0.0], &[]).elevation_crop(spec);
        let here = crop.get(2, 2);
        assert!(
            (crop.get(2, 0) - here + 0.2).abs() < 1e-9,
            "column 0 is the robot's left = west"
        );
        assert!((crop.get(2, 4) - here - 0.2).abs() < 1e-9);
    }

    #[test]
    fn sensing_limits_what_the_crops_show() {
        // a plane rising to the east, z = 0.1 x; the vehicle at the origin facing east
        let world = testing::plane_world(1.0, 0.1f64.atan(), 0.0, 0.8);
        let spec = CropSpec {
            size: 41,
            resolution: 1.0,
        };
        let obs = || test_observation(&world, [0.0, 0.0], 0.0, [10.0, 0.0], &[]);
        let sensing = Sensing {
            centre: [0.0, 0.0],
            range: 10.0,
            ground: 0.0,
            shift: [2.0, 0.0],
        };
        let plain = obs().elevation_crop(spec);
        let seen = obs().with_sensing(sensing).elevation_crop(spec);
        // row 0 is 20 m ahead: beyond range, level ground at the vehicle's height
        assert_eq!(seen.get(0, 20), 0.0);
        assert!((plain.get(0, 20) - 2.0).abs() < 1e-9);
        // 5 m ahead (row 15) is in range, read 2 m behind where it is (the latency shift)
        assert!(
            (seen.get(15, 20) - 0.3).abs() < 1e-9,
            "{}",
            seen.get(15, 20)
        );
        assert!((obs().with_sensing(sensing).elevation_at(5.0, 0.0) - 0.3).abs() < 1e-9);
        // beyond range nothing is an obstacle, but the map's edge still is
        let occ = obs().with_sensing(sensing).occupancy_crop(spec);
        assert_eq!(occ.get(0, 20), 0);
        assert_eq!(
            obs().with_sensing(sensing).obstacle_distance(50.0, 0.0),
            f64::INFINITY
        );
        let far = CropSpec {
            size: 9,
            resolution: 100.0,
        };
        let edge = obs().with_sensing(sensing).occupancy_crop(far);
        assert_eq!(
            edge.get(0, 4),
            1,
            "off the map reads occupied even out of range"
        );
    }
}
