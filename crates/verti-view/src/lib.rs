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
    VIEWER.replacen("/*VERTI_DATA*/", &script_data(&json), 1)
}

/// JSON made safe to sit inside a `<script>` element. Not only `</script>` ends it early: in
/// the script-data state `<!--` followed by `<script` makes the parser wait for a second
/// `</script>`, so the data would run to the end of the page. JSON has `<` (and `>`, `&`) only
/// inside strings, where `\u003c` means the same; with none left, the HTML parser sees plain
/// text. U+2028 and U+2029 are escaped too, for pages that read the data as JavaScript.
pub fn script_data(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    for c in json.chars() {
        match c {
            '<' => out.push_str("\\u003c"),
            '>' => out.push_str("\\u003e"),
            '&' => out.push_str("\\u0026"),
            '\u{2028}' => out.push_str("\\u2028"),
            '\u{2029}' => out.push_str("\\u2029"),
            c => out.push(c),
        }
    }
    out
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
