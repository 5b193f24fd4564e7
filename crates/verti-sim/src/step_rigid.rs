//! The wheel and spin stages of the internal step for rigid tyres (`tyre.model: rigid`), in
//! place of the handling tyre's in `step.rs`; driver, body contacts and integration are shared.
//!
//! Per wheel: the rigid cylinder's contact ([`crate::contact::rigid`]); on rigid ground its
//! Coulomb friction ([`friction::coulomb_tyre`]), on soil the soil shear of the handling path
//! (the SCM stage already treats a wheel as a rigid cylinder). The spins are then solved with
//! each Coulomb contact sticking or sliding ([`drivetrain::solve_spins_coulomb`]), and the
//! tangential forces of the contacts act where they touch.
//!
//! Kept apart from the handling tyre's stage so that stage compiles exactly as it did before
//! rigid tyres existed.

use crate::contact::rigid::rigid_wheel_contact;
use crate::drivetrain::{self, CoulombResult};
use crate::friction::{self, CoulombTyre, TyreForces};
use crate::integrate::Loads;
use crate::model::GRAVITY;
use crate::sim::Sim;
use crate::spec::MAX_WHEELS;
use crate::state::{ContactInfo, Controls, SimState};
use crate::step::{RigidStage, record_wheel};
use crate::suspension::{AxisLoad, spring_force};
use verti_core::Vec3;

/// The internal step's per-wheel arrays the rigid stage fills: the wheels' loads along their
/// suspension axes, scratch space for tyre forces, and the lateral ground forces.
pub(crate) type Scratch<'a> = (
    &'a mut [AxisLoad; MAX_WHEELS],
    &'a mut [TyreForces; MAX_WHEELS],
    &'a mut [f64; MAX_WHEELS],
);

impl Sim {
    /// Wheel contacts, tyre forces and spins of one internal step for rigid tyres: adds the
    /// wheels' forces to `loads` and `contacts`, fills `axis_loads` for the implicit wheel
    /// updates, and advances each wheel's friction anchor (or soil slip). `tyres` is scratch
    /// space (the soil traction of wheels on soil).
    pub(crate) fn rigid_wheels(
        &self,
        st: &mut SimState,
        ctl: &Controls,
        stage: &RigidStage,
        loads: &mut Loads,
        contacts: &mut ContactInfo,
        (axis_loads, tyres, lateral): Scratch,
    ) {
        let (spec, model, terrain) = (&self.spec, &self.model, &self.terrain);
        let (frame, h) = (stage.frame, stage.h);
        let gravity = Vec3::new(0.0, 0.0, -GRAVITY);
        let mut coulomb: [Option<CoulombTyre>; MAX_WHEELS] = [None; MAX_WHEELS];
        // explicit spin torques, and the forces of the wheels without a Coulomb contact
        let mut spin_loads = stage.spin_base;
        let mut axles = [Vec3::ZERO; MAX_WHEELS];
        // a Coulomb contact has no force before the spin solve
        let none = TyreForces::default();
        for (w, m) in model.wheels.iter().enumerate() {
            let ws = st.wheels[w];
            let kin = frame.wheel(st, m, &ws, &stage.wheel_steer);
            let soil_b = ws.soil_patch_b;
            let near = stage.near;
            let (contact, rigid) =
                rigid_wheel_contact(terrain, &mut st.soil, &spec.tyre, m, soil_b, &kin, near);
            let spring = spring_force(m, &ws, &st.wheels);
            // Coulomb friction where the rigid contact carries the load, the soil's shear
            // where the soil does (and nothing in the air)
            // the spin gets rolling resistance and the soil pressure moment about the axle
            let axle_moment = contact.soil_moment.dot(kin.axle) - contact.belt_axle_moment;
            let mut f_ext = gravity * m.unsprung_mass + contact.force;
            lateral[w] = contact.force.dot(frame.ey);
            // moments reaching the chassis through the bearing: the soil's pressure moment
            // off the axle and the rigid contacts' camber moment
            let mut off_axle = contact.soil_moment - kin.axle * axle_moment + rigid.moment;
            if contact.rigid_load > 0.0 && contact.rigid_load >= contact.soil_load {
                // A Coulomb contact's tangential forces come after the spin solve.
                let (roll, ct) = friction::coulomb_tyre(&spec.tyre, &ws, &contact, &rigid, &kin, h);
                coulomb[w] = Some(ct);
                spin_loads.torque[m.group] += roll + axle_moment;
                record_wheel(&mut st.wheels[w], contacts, &contact, &none);
            } else {
                // soil (or air): the linearised soil traction joins the spin solve, its lateral
                // force and that force's moment are final now
                let t = friction::tyre_forces(&spec.tyre, spec.scale, m, &ws, &contact, &kin, h);
                spin_loads.add_wheel(m.group, t.roll_torque + axle_moment, &t.long);
                if t.long.active {
                    f_ext += t.lat_force;
                    lateral[w] += t.lat_force.dot(frame.ey);
                }
                off_axle += t.contact_moment;
                record_wheel(&mut st.wheels[w], contacts, &contact, &t);
                tyres[w] = t;
            }
            let moments = (off_axle, Vec3::ZERO);
            let f_axis = loads.add_wheel(kin.arm, frame.up, f_ext, spring.force, moments);
            axis_loads[w] = AxisLoad::new(kin.arm, f_axis, &spring, &contact);
            axles[w] = kin.axle;
        }

        let mut out = [CoulombResult::default(); MAX_WHEELS];
        let reaction = drivetrain::solve_spins_coulomb(
            spec,
            model,
            st,
            ctl,
            stage.wheel_torque,
            &spin_loads,
            &coulomb,
            &mut out,
            h,
        );
        for (w, m) in model.wheels.iter().enumerate() {
            let spin = st.group_spin[m.group];
            let ws = &mut st.wheels[w];
            if let Some(ct) = &coulomb[w] {
                // Both tangential forces act at the contact point: their moment about the
                // axle drove the spin, the rest reaches the chassis through the bearing.
                let r = &out[w];
                let f = ct.e_long * r.fx + ct.e_lat * r.fy;
                lateral[w] += f.dot(frame.ey);
                axis_loads[w].external += loads.add_wheel_force(axis_loads[w].arm, frame.up, f);
                let moment = ct.arm.cross(f);
                loads.torque += moment - axles[w] * moment.dot(axles[w]);
                ws.long_force = r.fx;
                ws.lat_force = r.fy;
                ws.anchor_long = r.anchor_long;
                ws.anchor_lat = r.anchor_lat;
                ws.sliding = r.sliding;
                ws.slip_long = 0.0;
                ws.slip_lat = 0.0;
            } else {
                let long = &tyres[w].long;
                ws.long_force = if long.active {
                    let fx = long.force_at(spin);
                    let f = long.e_long * fx;
                    lateral[w] += f.dot(frame.ey);
                    axis_loads[w].external += loads.add_wheel_force(axis_loads[w].arm, frame.up, f);
                    fx
                } else {
                    0.0
                };
                // soil and air forget the anchor
                ws.anchor_long = 0.0;
                ws.anchor_lat = 0.0;
                ws.sliding = false;
            }
            loads.torque += axles[w] * reaction[m.group];
            ws.spin_rate = spin;
            if coulomb[w].is_none() {
                friction::relax_slip(ws, &tyres[w], &spec.tyre, h);
            }
        }
    }
}
