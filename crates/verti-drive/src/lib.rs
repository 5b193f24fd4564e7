//! # verti-drive
//!
//! Driving a benchmark trial by hand (paper §III-E: manual driving; §III-G.1: human expert
//! demonstrations), and watching any trial live:
//!
//! * [`driver`]: keys (keyboard or gamepad) to a target speed and steering, as a person's foot
//!   and hands would move them: pressed keys ramp the commands, released steering recentres.
//! * [`session`]: one trial stepped one control period at a time under the benchmark's rules,
//!   recording each step as a dataset row (the learning-foundation format, so human and oracle
//!   demonstrations mix) and as a 3-D frame for the live view.
//! * [`script`]: scripted key input (`0.0 +up`, `2.5 -up +left`...), for tests and for
//!   replaying a person's inputs headless.
//! * [`server`]: a small local web server: the browser shows the 3-D view (the same page as
//!   `verti replay --3d`, in live mode) and sends the keys it holds; the server steps the trial
//!   in real time and streams the new frames back; [`http`] parses its requests and
//!   [`access`] decides who may send them (loopback names only, same origin, a session
//!   token).

pub mod access;
pub mod driver;
pub mod http;
pub mod script;
pub mod server;
pub mod session;

pub use driver::{Driver, Keys};
pub use session::{DriveSession, SessionEnd};

/// Where demonstrations were driven, by whom, for their dataset's manifest.
pub struct DemoInfo<'a> {
    /// The world set as given (`verti-100`, a directory).
    pub set: &'a str,
    pub spec: &'a verti_sim::VehicleSpec,
    pub max_time: f64,
    /// `human`, or the system that drove.
    pub source: &'a str,
    /// Rows per simulated second (the driver's control rate).
    pub rate: f64,
    /// The command line that recorded them.
    pub command: &'a str,
}

/// Writes the demonstrations `records` (driven on `worlds`) as an `expert` dataset in `dir`,
/// the format `verti data generate expert` writes, so they load with `verti.data` and mix
/// with the oracle's.
pub fn write_demonstrations(
    dir: &std::path::Path,
    records: &[verti_data::table::TrialRecord],
    worlds: &[std::sync::Arc<verti_world::World>],
    info: &DemoInfo,
    force: bool,
) -> Result<verti_data::Manifest, String> {
    let first = &worlds.first().ok_or("no worlds")?.meta;
    let (seed, generator) = match &first.source {
        verti_world::WorldSource::Generated {
            set_seed,
            generator,
        } => (Some(*set_seed), generator.clone()),
        verti_world::WorldSource::VertiBench { .. } => (None, "verti-bench-import".to_string()),
    };
    let manifest = verti_data::Manifest {
        format: String::new(),
        kind: verti_data::Kind::Expert,
        profile: None,
        source: info.source.to_string(),
        worlds: verti_data::manifest::WorldsInfo {
            set: info.set.to_string(),
            name: info.set.to_string(),
            seed,
            generator,
            scale: first.scale,
            indices: Vec::new(),
        },
        vehicle: info.spec.name.clone(),
        wheels: info.spec.wheel_count(),
        rate: info.rate,
        max_trial_seconds: info.max_time,
        seed: 0,
        hours_requested: 0.0,
        hours: 0.0,
        hours_simulated: 0.0,
        trials: 0,
        rows: 0,
        outcomes: Default::default(),
        eval_worlds: verti_data::generate::eval_world_reason(worlds).is_some(),
        files: Vec::new(),
        checksums: Default::default(),
        command: info.command.to_string(),
        verti_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    verti_data::write_trials(dir, records, manifest, force).map_err(|e| e.to_string())
}
