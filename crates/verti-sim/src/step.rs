//! [`Sim::step`] and the internal step that orchestrates the stages.
//!
//! One internal step is semi-implicit (symplectic) Euler at a fixed step, with implicit parts
//! that remove the stiff modes:
//! 1. staggered wheel update: after the chassis step, each wheel's suspension velocity is solved
//!    implicitly against its spring, damper, stops and tyre or soil stiffness, the contact
//!    acting on the wheel's absolute motion (the wheel-hop mode is the stiffest in a vehicle);
//! 2. per spin group, the spin and the tyres' longitudinal forces are solved together
//!    (linearised slip curve), then Coulomb brakes exactly;
//! 3. the transient slip relaxes implicitly (see [`crate::tyre`]).
//!
//! Every shipped vehicle is stable at its `internal_step`: 5 ms at full scale (Verti-Bench's
//! step), 2 ms for the 1/6 and 1/10 vehicles. Stability at those steps is what the validation
//! tests and the soak exercise.
//!
//! The order of the stages, and of the wheels within them, is part of the engine's contract:
//! the same inputs give bit-identical trajectories, and a wheel's soil contact sees the ruts
//! the wheels before it left in the same step.

use crate::contact::body::body_contacts;
use crate::contact::wheel::wheel_contact;
use crate::contact::{WheelContact, WheelKinematics};
use crate::drivetrain::{self, SpinLoads};
use crate::error::SimError;
use crate::friction::{self, TyreForces};
use crate::integrate::{self, Loads};
use crate::model::GRAVITY;
use crate::sim::Sim;
use crate::spec::MAX_WHEELS;
use crate::state::{ContactInfo, Controls, SimState, WheelState};
use crate::suspension::{self, AxisLoad, spring_force};
use verti_core::Vec3;

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
        let turn_radius = drivetrain::turn_radius(&self.spec, &self.model, state.steer);
        for (m, w) in self.model.wheels.iter().zip(state.wheels.iter_mut()) {
            w.steer_angle = drivetrain::ackermann_angle(m, turn_radius);
        }
        state.check(scale)
    }

    /// One internal step: driver inputs, wheel forces, spins, body contacts, integration.
    fn substep(&self, st: &mut SimState, ctl: &Controls, h: f64) {
        let (spec, model, terrain) = (&self.spec, &self.model, &self.terrain);
        let q = st.orientation;
        let ex = q.rotate(Vec3::X);
        let ey = q.rotate(Vec3::Y);
        let up = q.rotate(Vec3::Z);
        let omega_w = q.rotate(st.omega);
        let gravity = Vec3::new(0.0, 0.0, -GRAVITY);

        // ---- driver: steering, engine and gearbox ----
        let turn_radius = drivetrain::steer(spec, model, st, ctl, h);
        let wheel_torque = drivetrain::engine(spec, model, st, ctl.throttle);

        // ---- wheels: contact, suspension, tyre forces (the longitudinal one waits for the
        // spin solve) ----
        let mut loads = Loads::gravity(gravity, model.sprung_mass);
        let mut contacts = ContactInfo::default();
        let mut spin_loads = SpinLoads::ZERO;
        let mut axis_loads = [AxisLoad::default(); MAX_WHEELS];
        let mut axles = [Vec3::ZERO; MAX_WHEELS];
        let mut tyres = [TyreForces::default(); MAX_WHEELS];
        let near = terrain.obstacles.near(st.position.x, st.position.y);
        for (w, m) in model.wheels.iter().enumerate() {
            let ws = st.wheels[w];
            let (sin_steer, cos_steer) = drivetrain::ackermann_sin_cos(m, turn_radius);
            let arm = q.rotate(m.attach + Vec3::Z * ws.compression);
            let kin = WheelKinematics {
                hub: st.position + arm,
                axle: ex * (-sin_steer) + ey * cos_steer,
                hub_velocity: st.velocity + omega_w.cross(arm) + up * ws.compression_rate,
                up,
                chassis_omega: omega_w,
                spin: st.group_spin[m.group],
            };
            let contact = wheel_contact(
                terrain,
                &mut st.soil,
                &spec.tyre,
                m,
                ws.soil_patch_b,
                &kin,
                near,
            );
            let spring = spring_force(m, &ws);
            let tyre = friction::tyre_forces(&spec.tyre, spec.scale, m, &ws, &contact, &kin, h);

            // the spin gets rolling resistance and the soil pressure moment about the axle
            let axle_moment = contact.soil_moment.dot(kin.axle);
            spin_loads.add_wheel(m.group, tyre.roll_torque + axle_moment, &tyre.long);
            // the composite body gets the rest
            let mut f_ext = gravity * m.unsprung_mass + contact.force;
            if tyre.long.active {
                f_ext += tyre.lat_force;
            }
            let f_axis = f_ext.dot(up);
            loads.force += f_ext;
            let soil_perp = contact.soil_moment - kin.axle * axle_moment;
            loads.torque += arm.cross(f_ext - up * f_axis + up * spring.force)
                + soil_perp
                + tyre.contact_moment;
            loads.wheel_axis_force += f_axis;
            loads.suspension_force += spring.force;

            axis_loads[w] = AxisLoad::new(arm, f_axis, &spring, &contact);
            axles[w] = kin.axle;
            tyres[w] = tyre;
            record_wheel(&mut st.wheels[w], &mut contacts, &contact, &tyre);
        }

        // ---- spin groups: drive, brakes (exact Coulomb), skid steering ----
        let reaction = drivetrain::solve_spins(spec, model, st, ctl, wheel_torque, &spin_loads, h);
        // longitudinal tyre forces consistent with the new spins, onto the composite body
        for (w, m) in model.wheels.iter().enumerate() {
            let long = &tyres[w].long;
            if !long.active {
                st.wheels[w].long_force = 0.0;
                continue;
            }
            let fx = long.force_at(st.group_spin[m.group]);
            let f = long.e_long * fx;
            let f_axis = f.dot(up);
            loads.force += f;
            loads.torque += axis_loads[w].arm.cross(f - up * f_axis);
            loads.wheel_axis_force += f_axis;
            axis_loads[w].external += f_axis;
            st.wheels[w].long_force = fx;
        }
        for (w, m) in model.wheels.iter().enumerate() {
            loads.torque += axles[w] * reaction[m.group];
            st.wheels[w].spin_rate = st.group_spin[m.group];
        }

        // ---- chassis body contacts ----
        body_contacts(
            terrain,
            model,
            spec.chassis.friction,
            st,
            near,
            &mut loads,
            &mut contacts,
        );

        // ---- integration: chassis accelerations, then the implicit wheel updates, then the
        // chassis itself ----
        let acc = integrate::accelerations(model, st, &loads);
        let chassis_velocity = st.velocity;
        for (w, m) in model.wheels.iter().enumerate() {
            let ws = &mut st.wheels[w];
            suspension::update_wheel(
                ws,
                m,
                &axis_loads[w],
                &acc,
                chassis_velocity,
                omega_w,
                up,
                h,
            );
        }
        for (ws, tyre) in st.wheels.iter_mut().zip(&tyres) {
            friction::relax_slip(ws, tyre, &spec.tyre, h);
        }
        integrate::advance_chassis(model, st, &loads, &acc, h);
        st.contacts = contacts;
    }
}

/// The wheel's outputs of this internal step, and its share of the contact summary.
#[inline]
fn record_wheel(
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
