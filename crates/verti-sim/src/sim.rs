//! [`Sim`]: the immutable model of one vehicle on one world (like MuJoCo's `mjModel`); all that
//! changes lives in [`SimState`] (like `mjData`). Built once per (world, vehicle) and shared by
//! any number of states, starts and threads.

use crate::contact::body::body_contacts;
use crate::contact::track_run::track_run_contacts;
use crate::drivetrain::SpinLoads;
use crate::error::SimError;
use crate::integrate::Loads;
use crate::model::{GRAVITY, Model};
use crate::spec::VehicleSpec;
use crate::start::{dropped, seat, state_at_rest};
use crate::state::{ContactInfo, Pose, SimState, StartPose};
use crate::terrain::Terrain;
use std::sync::Arc;
use verti_core::Vec3;
use verti_world::World;

/// A simulation of one vehicle on one world. Immutable: all mutable data lives in
/// [`SimState`], so one `Sim` can step many states (planners, parallel rollouts) from any
/// number of start poses. [`Sim::step`] advances a state.
#[derive(Clone, Debug)]
pub struct Sim {
    pub(crate) spec: VehicleSpec,
    pub(crate) model: Model,
    pub(crate) terrain: Terrain,
}

impl Sim {
    /// Compiles `spec` for `world`: validates it, derives the model and builds the world's
    /// lookup structures (obstacle broad phase, soil grid layout).
    pub fn new(world: &Arc<World>, spec: &VehicleSpec) -> Result<Sim, SimError> {
        spec.validate(&spec.name)
            .map_err(|e| SimError::InvalidSetup(e.to_string()))?;
        let scale = world.meta.scale;
        if !(scale.is_finite() && scale > 0.0) {
            return Err(SimError::InvalidSetup(format!(
                "world scale {scale} is not positive"
            )));
        }
        let model = Model::compile(spec, scale);
        let terrain = Terrain::new(world, model.reach)?;
        Ok(Sim {
            spec: spec.clone(),
            model,
            terrain,
        })
    }

    /// The vehicle at rest at `start`: pitched and rolled to the terrain plane fitted under its
    /// wheels, springs at their static compression, tyres at their static deflection (on soil,
    /// at their static sinkage) and, on a slope, pre-wound to hold the vehicle. Errors when
    /// the start is not finite, off the map or inside an obstacle.
    ///
    /// The plane fitted under the wheels does not see a bump under the hull or a track's
    /// raised end, a hill under an overhang or a rock edge under the belly. Where the hull and
    /// track ends, at rest, would be pushed by the ground harder than the whole vehicle's
    /// weight, the stiff contact would throw it (the M113 up to 4.7 m/s within 30 ms, from 98
    /// of verti-100's 1000 starts, before this check): such a start is raised until they carry
    /// just its weight (bisection to a tenth of a millimetre at full scale), so the vehicle
    /// rests on what it touches and settles from there.
    pub fn state_at(&self, start: StartPose) -> Result<SimState, SimError> {
        let pose = seat(&self.terrain.world, &self.spec, start)?;
        let at_rest = |lift: f64| {
            let lifted = Pose {
                position: pose.position + Vec3::Z * lift,
                orientation: pose.orientation,
            };
            state_at_rest(&self.model, &self.spec, &self.terrain, lifted)
        };
        let state = at_rest(0.0)?;
        let weight = self.model.total_mass * GRAVITY;
        if self.hull_push(&state) <= weight {
            return Ok(state);
        }
        // the push falls to 0 once the hull and track ends are clear of the ground
        let scale = self.terrain.world.meta.scale;
        let (mut low, mut high) = (0.0, 0.01 * scale);
        while self.hull_push(&at_rest(high)?) > weight {
            (low, high) = (high, 2.0 * high);
            if high > 100.0 * scale {
                return Err(SimError::InvalidStart(format!(
                    "at ({:.2}, {:.2}) the ground still pushes the vehicle up 100 m above its seat",
                    start.x, start.y
                )));
            }
        }
        while high - low > 1e-4 * scale {
            let mid = 0.5 * (low + high);
            if self.hull_push(&at_rest(mid)?) > weight {
                low = mid;
            } else {
                high = mid;
            }
        }
        at_rest(high)
    }

    /// The upward force of the ground on the chassis and a track's raised ends in `state`, as
    /// the engine's contacts compute it (at rest: their springs alone) \[N\].
    fn hull_push(&self, state: &SimState) -> f64 {
        let (terrain, model) = (&self.terrain, &self.model);
        let near = terrain.obstacles.near(state.position.x, state.position.y);
        let mut loads = Loads::gravity(Vec3::ZERO, 0.0);
        let mut contacts = ContactInfo::default();
        let mu = self.spec.chassis.friction;
        body_contacts(terrain, model, mu, state, near, &mut loads, &mut contacts);
        if let Some(runs) = &model.track_runs {
            let mut spin = SpinLoads::ZERO;
            track_run_contacts(terrain, model, runs, state, near, &mut spin)
                .apply(&state.group_spin, &mut loads);
        }
        loads.force.z
    }

    /// The state of Verti-Bench's spawn at `start`: level, the chassis reference frame
    /// `height` above the ground (higher where that would start the body or a wheel inside
    /// rigid ground beside it), at rest, springs at their static compression and tyres
    /// undeflected, ready to fall onto the terrain (see `start::dropped`).
    pub fn state_dropped(&self, start: StartPose, height: f64) -> Result<SimState, SimError> {
        let pose = dropped(&self.terrain.world, &self.spec, start, height)?;
        let mut state = state_at_rest(&self.model, &self.spec, &self.terrain, pose)?;
        // in the air no tyre is wound up against a slope
        for w in &mut state.wheels {
            w.slip_long = 0.0;
            w.slip_lat = 0.0;
        }
        Ok(state)
    }

    pub fn world(&self) -> &Arc<World> {
        &self.terrain.world
    }
    pub fn spec(&self) -> &VehicleSpec {
        &self.spec
    }
    /// The fixed internal step \[s\].
    pub fn internal_step(&self) -> f64 {
        self.model.step
    }
    /// Total mass including unsprung masses and tracks \[kg\].
    pub fn total_mass(&self) -> f64 {
        self.model.total_mass
    }
    /// Soil node spacing \[m\], when the world has soil.
    pub fn soil_spacing(&self) -> Option<f64> {
        self.terrain.soil.map(|l| l.delta)
    }
    /// Bounding radius of the vehicle around its centre of mass (plus margin) \[m\].
    pub fn reach(&self) -> f64 {
        self.model.reach
    }

    /// Pose of the chassis reference frame (the frame the vehicle file is written in).
    pub fn reference_pose(&self, state: &SimState) -> Pose {
        Pose {
            position: state.position - state.orientation.rotate(self.model.com),
            orientation: state.orientation,
        }
    }

    /// World position of a point given in the chassis reference frame.
    pub fn point_world(&self, state: &SimState, local: Vec3) -> Vec3 {
        state.position + state.orientation.rotate(local - self.model.com)
    }

    /// World position of each wheel centre.
    pub fn wheel_centers(&self, state: &SimState) -> Vec<Vec3> {
        self.model
            .wheels
            .iter()
            .zip(&state.wheels)
            .map(|(m, w)| {
                state.position + state.orientation.rotate(m.attach + Vec3::Z * w.compression)
            })
            .collect()
    }

    /// Ground height under (x, y) as the vehicle sees it: the undeformed terrain plus the soil
    /// heaped on the nearest soil node, minus its plastic sinkage.
    pub fn ground_height_at(&self, state: &SimState, x: f64, y: f64) -> f64 {
        let (h, gx, gy) = self.terrain.world.terrain.sample(x, y);
        if let Some(layout) = &self.terrain.soil {
            let i = (x / layout.delta).round() as i64;
            let j = (y / layout.delta).round() as i64;
            if let Some(at) = layout.locate(i, j) {
                let node = state.soil.node(at);
                let ca = 1.0 / (1.0 + gx * gx + gy * gy).sqrt();
                return h + node.heap - node.plastic / ca;
            }
        }
        h
    }

    /// Total mechanical energy \[J\]: kinetic (chassis, unsprung masses, spinning wheels) plus
    /// gravity, suspension and tyre-spring potential (a rigid tyre's: its contact and friction
    /// anchor springs). Soil deformation is dissipative and not counted.
    pub fn energy(&self, state: &SimState) -> f64 {
        let model = &self.model;
        let q = state.orientation;
        let omega_w = q.rotate(state.omega);
        let om = state.omega;
        let i = model.chassis_inertia;
        let mut e = 0.5 * model.sprung_mass * state.velocity.norm_sq()
            + 0.5 * (i.x * om.x * om.x + i.y * om.y * om.y + i.z * om.z * om.z)
            + model.sprung_mass * GRAVITY * state.position.z;
        let up = q.rotate(Vec3::Z);
        let k_tyre = self.spec.tyre.radial_stiffness;
        let rigid = self.spec.tyre.model == crate::spec::TyreModel::Rigid;
        for (m, w) in model.wheels.iter().zip(&state.wheels) {
            let r = q.rotate(m.attach + Vec3::Z * w.compression);
            let v = state.velocity + omega_w.cross(r) + up * w.compression_rate;
            let hub = state.position + r;
            e += 0.5 * m.unsprung_mass * v.norm_sq() + m.unsprung_mass * GRAVITY * hub.z;
            e += 0.5 * m.spring * w.compression * w.compression;
            if let Some(sc) = &m.coupling {
                let other = &state.wheels[sc.partner];
                // half of the axle's cross term k_x·s_l·s_r (beam, anti-roll bar); the partner adds
                // the other half
                e += 0.5 * sc.spring_cross * w.compression * other.compression;
                if let (Some((_, cross)), true) = (sc.beam, m.y > 0.0) {
                    // a beam rolling as one bar (I) rather than as two points at its ends:
                    // ½·(I − M_b·t²/4)·Ω² = −½·cross·t²·Ω², Ω the beam's own roll rate
                    let t = 2.0 * m.y;
                    let roll = om.x + (w.compression_rate - other.compression_rate) / t;
                    e -= 0.5 * cross * t * t * roll * roll;
                }
            }
            if w.compression > m.bump {
                e += 0.5 * m.stop * (w.compression - m.bump).powi(2);
            }
            if w.compression < -m.rebound {
                e += 0.5 * m.stop * (w.compression + m.rebound).powi(2);
            }
            let d = w.tyre_deflection;
            e += 0.5 * k_tyre * d * d;
            if rigid {
                // the friction anchors' springs; a rigid tyre has no rim to bottom on
                e += 0.5 * k_tyre * (w.anchor_long.powi(2) + w.anchor_lat.powi(2));
            } else if d > m.rim_depth {
                e += 0.5 * 10.0 * k_tyre * (d - m.rim_depth).powi(2);
            }
        }
        for (g, grp) in model.groups.iter().enumerate() {
            e += 0.5 * grp.inertia * state.group_spin[g].powi(2);
        }
        e
    }
}

/// State methods that need the `Sim`: they live here, not in `state.rs`, so that the plain
/// state types stay below everything that uses them.
impl SimState {
    /// Sets the chassis velocity (world, m/s) and keeps everything else; for tests and planners
    /// that start from a moving state. Wheels are spun up to roll without slip.
    pub fn set_velocity(&mut self, sim: &Sim, velocity_world: Vec3) {
        self.velocity = velocity_world;
        let forward = self.orientation.rotate(Vec3::X).dot(velocity_world);
        let model = &sim.model;
        for (g, grp) in model.groups.iter().enumerate() {
            let r = grp
                .wheels
                .iter()
                .map(|&w| model.wheels[w].radius)
                .sum::<f64>()
                / grp.wheels.len() as f64;
            self.group_spin[g] = forward / r;
        }
    }
}
