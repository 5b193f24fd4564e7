//! [`Sim::step`] and the internal step that orchestrates the stages.
//!
//! One internal step is semi-implicit (symplectic) Euler at a fixed step, with implicit parts
//! that remove the stiff modes:
//! 1. staggered wheel update: after the chassis step, each wheel's suspension velocity is solved
//!    implicitly against its spring, damper, stops and tyre or soil stiffness, the contact
//!    acting on the wheel's absolute motion (the wheel-hop mode is the stiffest in a vehicle);
//! 2. per spin group, the spin and the tyres' longitudinal forces are solved together
//!    (linearised slip curve), then Coulomb brakes exactly;
//! 3. the transient slip relaxes implicitly (`friction::relax_slip`; see [`crate::tyre`]).
//!
//! Rigid tyres (`tyre.model: rigid`) have their own wheel and spin stages
//! ([`crate::step_rigid`]); everything else is shared.
//!
//! Every shipped vehicle is stable at its `internal_step`: 5 ms at full scale (Verti-Bench's
//! step), 2 ms for the 1/6 and 1/10 vehicles. Stability at those steps is what the validation
//! tests and the soak exercise.
//!
//! The order of the stages, and of the wheels within them, is part of the engine's contract:
//! the same inputs give bit-identical trajectories, and a wheel's soil contact sees the ruts
//! the wheels before it left in the same step.

use crate::contact::body::body_contacts;
use crate::contact::track_run::track_run_contacts;
use crate::contact::wheel::wheel_contact;
use crate::contact::{WheelContact, WheelKinematics};
use crate::drivetrain::{self, SpinLoads};
use crate::error::SimError;
use crate::friction::{self, TyreForces};
use crate::integrate::{self, Loads};
use crate::model::{AxleCoupling, GRAVITY, Model, WheelModel};
use crate::sim::Sim;
use crate::spec::{MAX_WHEELS, TyreModel};
use crate::state::{ContactInfo, Controls, SimState, WheelState};
use crate::suspension::{self, AxisLoad, spring_force};
use verti_core::{Quat, Vec3};

impl Sim {
    /// Advances `state` by `dt` seconds with `controls` held. The internal step is the largest
    /// step not above `spec.internal_step` that divides `dt` evenly.
    pub fn step(&self, state: &mut SimState, controls: Controls, dt: f64) -> Result<(), SimError> {
        controls.validate()?;
        if !(dt.is_finite() && dt > 0.0 && dt <= 10.0) {
            return Err(SimError::InvalidStep(dt));
        }
        let scale = self.terrain.world.meta.scale;
        state.check(scale)?;
        let n = ((dt / self.model.step) - 1e-9).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        state.controls = controls;
        let t0 = state.time;
        for k in 0..n {
            self.substep(state, &controls, h);
            state.time = t0 + (k + 1) as f64 * h;
            // cheap guard so a blow-up cannot run away inside a long step
            if !(state.position.x.abs() < 1e9
                && state.position.y.abs() < 1e9
                && state.position.z.abs() < 1e9)
            {
                break;
            }
        }
        // per-wheel steer angles are outputs only: computed once per call, not per internal step
        let wheel_steer = drivetrain::wheel_steer(&self.spec, &self.model, state.steer);
        for (m, w) in self.model.wheels.iter().zip(state.wheels.iter_mut()) {
            w.steer_angle = drivetrain::steer_angle(m, &wheel_steer);
        }
        state.check(scale)
    }

    /// Each wheel's spin axis in the world frame (pointing to the wheel's left): steered, and
    /// tilted by its camber or its beam axle's roll, as the contacts see it.
    pub fn wheel_axles(&self, state: &SimState) -> Vec<Vec3> {
        let frame = Frame::of(state);
        let steer = drivetrain::wheel_steer(&self.spec, &self.model, state.steer);
        self.model
            .wheels
            .iter()
            .zip(&state.wheels)
            .map(|(m, ws)| frame.wheel(state, m, ws, &steer).axle)
            .collect()
    }

    /// One internal step: driver inputs, wheel forces, spins, body contacts, integration.
    fn substep(&self, st: &mut SimState, ctl: &Controls, h: f64) {
        let (spec, model, terrain) = (&self.spec, &self.model, &self.terrain);
        let frame = Frame::of(st);
        let gravity = Vec3::new(0.0, 0.0, -GRAVITY);

        // ---- driver: steering, engine and gearbox ----
        let wheel_steer = drivetrain::steer(spec, model, st, ctl, h);
        let wheel_torque = drivetrain::engine(spec, model, st, ctl.throttle);

        // ---- wheels: contact, suspension, tyre forces (the longitudinal one waits for the
        // spin solve) ----
        let mut loads = Loads::gravity(gravity, model.sprung_mass);
        let mut contacts = ContactInfo::default();
        let mut axis_loads = [AxisLoad::default(); MAX_WHEELS];
        let mut tyres = [TyreForces::default(); MAX_WHEELS];
        // each wheel's lateral ground force, for the roll-centre links
        let mut lateral = [0.0; MAX_WHEELS];
        let near = terrain.obstacles.near(st.position.x, st.position.y);
        // a tracked vehicle's raised track ends: their friction joins the spin solve
        let mut spin_base = SpinLoads::ZERO;
        let runs = (model.track_runs.as_ref())
            .map(|r| track_run_contacts(terrain, model, r, st, near, &mut spin_base));
        let rigid = spec.tyre.model == TyreModel::Rigid;
        crate::contact::soil::begin_soil_step();
        if rigid {
            let stage = RigidStage {
                frame: &frame,
                wheel_steer,
                wheel_torque,
                near,
                spin_base,
                h,
            };
            let scratch = (&mut axis_loads, &mut tyres, &mut lateral);
            self.rigid_wheels(st, ctl, &stage, &mut loads, &mut contacts, scratch);
        } else {
            let mut spin_loads = spin_base;
            let mut axles = [Vec3::ZERO; MAX_WHEELS];
            for (w, m) in model.wheels.iter().enumerate() {
                let ws = st.wheels[w];
                let kin = frame.wheel(st, m, &ws, &wheel_steer);
                let soil_b = ws.soil_patch_b;
                let contact =
                    wheel_contact(terrain, &mut st.soil, &spec.tyre, m, soil_b, &kin, near);
                let spring = spring_force(m, &ws, &st.wheels);
                let tyre = friction::tyre_forces(&spec.tyre, spec.scale, m, &ws, &contact, &kin, h);

                // the spin gets rolling resistance and the soil pressure moment about the axle,
                // the composite body everything else
                let axle_moment = contact.soil_moment.dot(kin.axle) - contact.belt_axle_moment;
                spin_loads.add_wheel(m.group, tyre.roll_torque + axle_moment, &tyre.long);
                let mut f_ext = gravity * m.unsprung_mass + contact.force;
                lateral[w] = contact.force.dot(frame.ey);
                if tyre.long.active {
                    f_ext += tyre.lat_force;
                    lateral[w] += tyre.lat_force.dot(frame.ey);
                }
                let soil_off_axle = contact.soil_moment - kin.axle * axle_moment;
                let moments = (soil_off_axle, tyre.contact_moment);
                let f_axis = loads.add_wheel(kin.arm, frame.up, f_ext, spring.force, moments);

                axis_loads[w] = AxisLoad::new(kin.arm, f_axis, &spring, &contact);
                axles[w] = kin.axle;
                tyres[w] = tyre;
                record_wheel(&mut st.wheels[w], &mut contacts, &contact, &tyre);
            }

            // ---- spin groups: drive, brakes (exact Coulomb), skid steering; then the
            // longitudinal tyre forces at the new spins and the drive reactions ----
            let reaction =
                drivetrain::solve_spins(spec, model, st, ctl, wheel_torque, &spin_loads, h);
            for (w, m) in model.wheels.iter().enumerate() {
                let long = &tyres[w].long;
                if !long.active {
                    st.wheels[w].long_force = 0.0;
                    continue;
                }
                let fx = long.force_at(st.group_spin[m.group]);
                lateral[w] += (long.e_long * fx).dot(frame.ey);
                let f_axis = loads.add_wheel_force(axis_loads[w].arm, frame.up, long.e_long * fx);
                axis_loads[w].external += f_axis;
                st.wheels[w].long_force = fx;
            }
            for (w, m) in model.wheels.iter().enumerate() {
                loads.torque += axles[w] * reaction[m.group];
                st.wheels[w].spin_rate = st.group_spin[m.group];
            }
        }

        // ---- soil: what the wheels displaced is heaped around their patches (SCM's
        // bulldozing, after every wheel's contact as in Chrono) ----
        crate::contact::soil::bulldoze_step(terrain, &mut st.soil);

        if let Some(runs) = &runs {
            runs.apply(&st.group_spin[..model.groups.len()], &mut loads);
            contacts.track_run_points = runs.points;
        }

        // ---- links: the share of the lateral forces a roll centre off the ground carries ----
        if model.roll_centres {
            suspension::roll_centre_links(model, &lateral, frame.up, &mut axis_loads, &mut loads);
        }

        // ---- chassis body contacts ----
        let mu_body = spec.chassis.friction;
        body_contacts(terrain, model, mu_body, st, near, &mut loads, &mut contacts);

        // ---- integration: chassis accelerations, the implicit wheel updates against them,
        // then the chassis itself ----
        let acc = integrate::accelerations(model, st, &loads);
        let v = st.velocity;
        if model.beams {
            update_wheels_with_beams(model, st, &axis_loads, &acc, &frame, h);
        } else {
            for ((ws, m), load) in st.wheels.iter_mut().zip(&model.wheels).zip(&axis_loads) {
                suspension::update_wheel(ws, m, load, &acc, v, frame.omega, frame.up, h);
            }
        }
        if !rigid {
            for (ws, tyre) in st.wheels.iter_mut().zip(&tyres) {
                friction::relax_slip(ws, tyre, &spec.tyre, h);
            }
        }
        integrate::advance_chassis(model, st, &loads, &acc, h);
        st.contacts = contacts;
    }
}

/// The implicit wheel updates when some solid axle's beam has its own roll inertia: its two
/// wheels are updated together, every other wheel alone, in wheel order.
fn update_wheels_with_beams(
    model: &Model,
    st: &mut SimState,
    axis_loads: &[AxisLoad; MAX_WHEELS],
    acc: &integrate::Accelerations,
    frame: &Frame,
    h: f64,
) {
    let v = st.velocity;
    let mut w = 0;
    while w < model.wheels.len() {
        let m = &model.wheels[w];
        match m.coupling {
            // left wheels are even, their partner the next one
            Some(
                coupling @ AxleCoupling {
                    beam: Some(masses), ..
                },
            ) if w % 2 == 0 => {
                let (left, right) = st.wheels.split_at_mut(w + 1);
                let pair = [&mut left[w], &mut right[0]];
                let loads = [&axis_loads[w], &axis_loads[w + 1]];
                suspension::update_axle_pair(
                    pair,
                    &coupling,
                    loads,
                    masses,
                    acc,
                    v,
                    frame.omega,
                    frame.up,
                    h,
                );
                w += 2;
            }
            _ => {
                let load = &axis_loads[w];
                suspension::update_wheel(
                    &mut st.wheels[w],
                    m,
                    load,
                    acc,
                    v,
                    frame.omega,
                    frame.up,
                    h,
                );
                w += 1;
            }
        }
    }
}

/// The chassis attitude at the start of an internal step: its axes and angular velocity in
/// the world frame.
pub(crate) struct Frame {
    q: Quat,
    ex: Vec3,
    pub ey: Vec3,
    pub up: Vec3,
    pub omega: Vec3,
}

/// What the rigid tyres' stages need of the internal step ([`crate::step_rigid`]).
pub(crate) struct RigidStage<'a> {
    pub frame: &'a Frame,
    pub wheel_steer: drivetrain::WheelSteer,
    pub wheel_torque: f64,
    /// Obstacles near the vehicle.
    pub near: &'a [u32],
    /// Spin loads from before the wheels (the raised track ends' friction).
    pub spin_base: SpinLoads,
    pub h: f64,
}

impl Frame {
    #[inline]
    fn of(st: &SimState) -> Frame {
        let q = st.orientation;
        Frame {
            q,
            ex: q.rotate(Vec3::X),
            ey: q.rotate(Vec3::Y),
            up: q.rotate(Vec3::Z),
            omega: q.rotate(st.omega),
        }
    }

    /// Where wheel `m` (state `ws`) is and how it moves. (Always inlined, see
    /// `friction::tyre_forces`.)
    #[inline(always)]
    pub(crate) fn wheel(
        &self,
        st: &SimState,
        m: &WheelModel,
        ws: &WheelState,
        steer: &drivetrain::WheelSteer,
    ) -> WheelKinematics {
        let (sin_steer, cos_steer) = drivetrain::steer_sin_cos(m, steer);
        let arm = self.q.rotate(m.attach + Vec3::Z * ws.compression);
        // the wheel's plane tilts about the chassis' x axis, steered or not
        let lateral = match m.tilt.angle(ws.compression, &st.wheels) {
            None => self.ey,
            Some(tilt) => self.ey * libm::cos(tilt) + self.up * libm::sin(tilt),
        };
        WheelKinematics {
            arm,
            hub: st.position + arm,
            axle: self.ex * (-sin_steer) + lateral * cos_steer,
            hub_velocity: st.velocity + self.omega.cross(arm) + self.up * ws.compression_rate,
            up: self.up,
            chassis_omega: self.omega,
            spin: st.group_spin[m.group],
        }
    }
}

/// The wheel's outputs of this internal step, and its share of the contact summary.
#[inline]
pub(crate) fn record_wheel(
    out: &mut WheelState,
    contacts: &mut ContactInfo,
    contact: &WheelContact,
    tyre: &TyreForces,
) {
    let fz_total = contact.normal_load();
    out.normal_force = fz_total;
    out.lat_force = tyre.lat;
    out.in_contact = fz_total > 0.0;
    out.on_soil = contact.soil_nodes > 0;
    out.touches_obstacle = contact.obstacle;
    out.sinkage = contact.sinkage;
    out.tyre_deflection = contact.depth;
    if contact.soil_nodes > 0 {
        out.soil_patch_b = contact.soil_b;
    }
    contacts.wheels_in_contact += u32::from(fz_total > 0.0);
    contacts.wheels_on_soil += u32::from(contact.soil_nodes > 0);
    contacts.wheel_obstacle_contacts += u32::from(contact.obstacle);
    contacts.soil_nodes_in_contact += contact.soil_nodes;
}
