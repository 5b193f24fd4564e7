//! Errors of the vehicle engine. Every message says what was wrong and where, so a user can fix
//! a vehicle file or a caller can tell which episode blew up and why.

use std::path::PathBuf;

/// A vehicle description that could not be read or does not make physical sense.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file is not valid YAML for a vehicle (unknown or missing field, wrong type...).
    #[error("{origin}: {message}")]
    Parse { origin: String, message: String },
    /// A field has a value the engine cannot simulate.
    #[error("{origin}: field `{field}`: {problem}")]
    Invalid {
        origin: String,
        field: String,
        problem: String,
    },
    /// `vehicles::builtin` was asked for a name it does not know.
    #[error("unknown vehicle `{name}`; built-in vehicles are: {known}")]
    UnknownVehicle { name: String, known: String },
}

/// Errors while building or stepping a simulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A control input is NaN or outside its range.
    #[error("invalid control `{name}` = {value}: must be a finite number in [{lo}, {hi}]")]
    InvalidControl {
        name: &'static str,
        value: f64,
        lo: f64,
        hi: f64,
    },
    /// The requested step is not a positive finite duration.
    #[error("invalid step dt = {0}: must be finite and in (0, 10] seconds")]
    InvalidStep(f64),
    /// The start pose is not finite or lies off the map.
    #[error("invalid start pose: {0}")]
    InvalidStart(String),
    /// The vehicle does not fit the world (e.g. no room for the soil grid).
    #[error("invalid setup: {0}")]
    InvalidSetup(String),
    /// The state stopped being finite: names the quantity and the simulated time.
    #[error("simulation blew up at t = {time:.4} s: {what} is not finite")]
    NonFinite { what: String, time: f64 },
    /// The state is finite but physically absurd (e.g. the chassis moves faster than sound).
    #[error("simulation blew up at t = {time:.4} s: {what}")]
    BlowUp { what: String, time: f64 },
}
