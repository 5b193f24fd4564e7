//! Perception noise (the paper's stated future work, §VI): a seeded model of what a real robot's
//! state estimator, elevation mapper, terrain classifier and obstacle detector get wrong,
//! applied to what systems observe and never to the physics or the rules.
//!
//! * [`model`]: the model's parameters, the `none`/`low`/`medium`/`high` presets, YAML files.
//! * [`map`]: the perceived world, built once per trial: per-vertex height error, in-painted
//!   holes, confused terrain classes (with the physics a planner would assume for the class it
//!   sees), missed and phantom obstacles.
//! * [`Perception`] (here): the per-trial state: the perceived world, and the estimator's
//!   error — white noise redrawn every control period plus a random-walk drift of position and
//!   heading. Range limit and registration latency act where systems read the map through the
//!   observation ([`Sensing`]).
//!
//! Every draw comes from the run seed and the task, so a noisy run is as reproducible as a
//! clean one, on any number of threads; a trial's branches carry the same noise state.

pub mod map;
pub mod model;

pub use model::{PRESETS, PerceptionModel};

use crate::features::FeatureSource;
use crate::pose::Pose6;
use std::sync::Arc;
use verti_core::Vec3;
use verti_core::rng::Rng;
use verti_world::World;

/// How the map is sensed from where the vehicle is: cells beyond `range` of the vehicle are
/// unknown (level ground at the vehicle's height, no class change, no obstacles), and lookups
/// are displaced by `shift`, the distance travelled during the registration latency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensing {
    /// True vehicle position (the sensor is on the vehicle, wherever the estimate puts it).
    pub centre: [f64; 2],
    /// Sensing radius, m (infinite when unlimited).
    pub range: f64,
    /// Height unknown cells read as: the perceived ground under the vehicle.
    pub ground: f64,
    /// World-frame displacement of every map lookup, m.
    pub shift: [f64; 2],
}

impl Sensing {
    /// Whether (x, y) is within range.
    pub fn sees(&self, x: f64, y: f64) -> bool {
        (x - self.centre[0]).hypot(y - self.centre[1]) <= self.range
    }
    /// Where a lookup at (x, y) lands in the perceived map.
    pub fn lookup(&self, x: f64, y: f64) -> (f64, f64) {
        (x - self.shift[0], y - self.shift[1])
    }
}

/// The estimator's current error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct EstimateError {
    position: [f64; 3],
    yaw: f64,
    roll: f64,
    pitch: f64,
    velocity: [f64; 3],
    angular: [f64; 3],
}

/// One trial's perception: the perceived world and the state estimator's error.
#[derive(Clone)]
pub struct Perception {
    model: Arc<PerceptionModel>,
    world: Arc<World>,
    rng: Rng,
    /// Random-walk drift of x, y (m) and yaw (rad).
    drift: [f64; 3],
    white: EstimateError,
}

impl Perception {
    /// Perception of `world` under `model`, seeded by `seed` (per trial).
    pub fn new(world: &World, model: Arc<PerceptionModel>, seed: u64) -> Perception {
        let perceived = map::perceived_world(world, &model, seed);
        let mut p = Perception {
            world: Arc::new(perceived),
            rng: Rng::derive(seed, "perception.estimate", 0),
            drift: [0.0; 3],
            white: EstimateError::default(),
            model,
        };
        p.white = p.draw_white();
        p
    }

    pub fn model(&self) -> &PerceptionModel {
        &self.model
    }

    /// The world as perceived (what systems read as `Observation::world`).
    pub fn world(&self) -> &Arc<World> {
        &self.world
    }

    fn draw_white(&mut self) -> EstimateError {
        let m = &self.model;
        let (s, d) = (self.world.meta.scale, std::f64::consts::PI / 180.0);
        let rng = &mut self.rng;
        let mut g = |sigma: f64| {
            if sigma > 0.0 {
                rng.gauss(0.0, sigma)
            } else {
                0.0
            }
        };
        EstimateError {
            position: [
                g(m.pose.position_sigma * s),
                g(m.pose.position_sigma * s),
                g(m.pose.position_sigma * s),
            ],
            yaw: g(m.pose.yaw_sigma_deg * d),
            roll: g(m.pose.attitude_sigma_deg * d),
            pitch: g(m.pose.attitude_sigma_deg * d),
            velocity: [
                g(m.velocity.linear_sigma * s),
                g(m.velocity.linear_sigma * s),
                g(m.velocity.linear_sigma * s),
            ],
            angular: [
                g(m.velocity.angular_sigma_deg * d),
                g(m.velocity.angular_sigma_deg * d),
                g(m.velocity.angular_sigma_deg * d),
            ],
        }
    }

    /// Advances the estimator by `dt` seconds: the drift takes a random-walk step (standard
    /// deviation drift·√dt) and the white errors are redrawn.
    pub fn advance(&mut self, dt: f64) {
        let m = &self.model;
        let root = dt.max(0.0).sqrt();
        let (xy, yaw) = (
            m.pose.position_drift * self.world.meta.scale * root,
            m.pose.yaw_drift_deg.to_radians() * root,
        );
        if xy > 0.0 {
            self.drift[0] += self.rng.gauss(0.0, xy);
            self.drift[1] += self.rng.gauss(0.0, xy);
        }
        if yaw > 0.0 {
            self.drift[2] += self.rng.gauss(0.0, yaw);
        }
        self.white = self.draw_white();
    }

    /// The features the estimator reports for the true `truth`.
    pub fn estimate(&self, truth: &FeatureSource) -> FeatureSource {
        if self.model.exact_state() {
            // adding zeros and re-wrapping the yaw would still move its last bit
            return *truth;
        }
        let (e, d) = (&self.white, &self.drift);
        let mut out = *truth;
        let p = &mut out.pose;
        p.x += d[0] + e.position[0];
        p.y += d[1] + e.position[1];
        p.z += e.position[2];
        p.yaw = wrap(p.yaw + d[2] + e.yaw);
        p.roll += e.roll;
        p.pitch += e.pitch;
        let v = truth.velocity_body;
        out.velocity_body = Vec3::new(
            v.x + e.velocity[0],
            v.y + e.velocity[1],
            v.z + e.velocity[2],
        );
        let w = truth.angular_velocity_body;
        out.angular_velocity_body =
            Vec3::new(w.x + e.angular[0], w.y + e.angular[1], w.z + e.angular[2]);
        out.forward_speed = truth.forward_speed + e.velocity[0];
        out
    }

    /// How the map is sensed from the true pose `truth` at forward speed `speed`.
    pub fn sensing(&self, truth: &Pose6, speed: f64) -> Sensing {
        let e = &self.model.elevation;
        let travel = speed * e.latency;
        Sensing {
            centre: [truth.x, truth.y],
            range: if e.range > 0.0 {
                e.range * self.world.meta.scale
            } else {
                f64::INFINITY
            },
            ground: self.world.terrain.height_at(truth.x, truth.y),
            shift: [travel * truth.yaw.cos(), travel * truth.yaw.sin()],
        }
    }

    /// The current drift of x, y (m) and yaw (rad), for tests and logs.
    pub fn drift(&self) -> [f64; 3] {
        self.drift
    }
}

fn wrap(a: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    (a + std::f64::consts::PI).rem_euclid(two_pi) - std::f64::consts::PI
}

#[cfg(test)]
mod tests;
