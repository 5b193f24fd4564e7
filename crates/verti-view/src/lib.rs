//! # verti-view
//!
//! 3-D recordings of trials: [`record_trial`] drives a system through one task (the benchmark's
//! own episode loop, so the trial is the evaluated one, bit for bit) and samples the scene after
//! every control period; [`write_html`] turns the [`Recording`] into one self-contained web page
//! (WebGL, no server, nothing downloaded) with the terrain mesh coloured by class, obstacles,
//! the vehicle body and wheels (steer and suspension travel visible), the global path and the
//! trail, and time series of speed, roll, pitch, throttle, steering and wheel sinkage on one
//! timeline.

mod record;

pub use record::{Frame, Recording, frame, record_trial};

/// The viewer page; `/*VERTI_DATA*/` is replaced by the recording as JSON.
const VIEWER: &str = include_str!("viewer.html");

/// The recording as a self-contained HTML page.
pub fn html(recording: &Recording) -> String {
    let json = serde_json::to_string(recording).expect("a recording serialises");
    // inside <script type="application/json">, only "</" could end the element early
    let json = json.replace("</", "<\\/");
    VIEWER.replacen("/*VERTI_DATA*/", &json, 1)
}

/// Writes the recording as JSON (for other viewers: `python -m verti.rerun` turns it into a
/// Rerun `.rrd`).
pub fn write_json(recording: &Recording, path: &std::path::Path) -> std::io::Result<()> {
    std::fs::write(
        path,
        serde_json::to_string(recording).expect("a recording serialises"),
    )
}

/// Writes [`html`] to `path`.
pub fn write_html(recording: &Recording, path: &std::path::Path) -> std::io::Result<()> {
    std::fs::write(path, html(recording))
}
