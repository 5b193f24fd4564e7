//! Draws a Fig. 6-like grid of grouped bar charts from made-up numbers:
//! `cargo run -p verti-render --example report_demo -- /tmp/report` writes `fig6.png` (ten
//! systems, as in the paper) and `fig6_small.png` (three systems, one with a missing value).
//!
//! The numbers are invented to look plausible (success falls and times and angles rise with
//! difficulty); they are not results of any system.

use std::path::PathBuf;
use verti_render::{Panel, Series, grouped_bars_png};

const SYSTEMS: [&str; 10] = [
    "PID", "EH", "MPPI", "RL", "MCL", "ACL", "WMVCT", "MPPI-6", "TAL", "TNT",
];
/// Overall skill of each system in [0, 1] (made up, loosely following Table I).
const SKILL: [f64; 10] = [0.49, 0.44, 0.41, 0.10, 0.42, 0.37, 0.42, 0.47, 0.58, 0.57];

const ROWS: [(&str, [&str; 3]); 3] = [
    ("elevation", ["low", "mid", "high"]),
    ("terrain", ["rigid", "deformable", "mixed"]),
    ("density", ["sparse", "medium", "dense"]),
];
const METRICS: [(&str, &str); 4] = [
    ("Success rate", "success (%)"),
    ("Traversal time", "time (s)"),
    ("Roll", "mean |roll| (°)"),
    ("Pitch", "mean |pitch| (°)"),
];

/// Made-up value and spread of metric `m` for system `s` in group `g` (0 easy .. 2 hard).
fn value(m: usize, s: usize, g: usize, row: usize) -> (f64, f64) {
    let hard = g as f64 * if row == 2 { 0.5 } else { 1.0 };
    let skill = SKILL[s];
    let wobble = ((s * 7 + g * 3 + row) % 5) as f64 / 5.0;
    match m {
        0 => ((skill * 100.0 * (1.25 - 0.3 * hard)).clamp(2.0, 95.0), 0.0),
        1 => (
            22.0 + 6.0 * hard + 8.0 * (1.0 - skill) + 3.0 * wobble,
            4.0 + 2.0 * hard,
        ),
        2 => (
            4.0 + 3.0 * hard + 5.0 * (1.0 - skill) + wobble,
            2.0 + 1.5 * hard + wobble,
        ),
        _ => (
            5.0 + 2.5 * hard + 4.0 * (1.0 - skill) + wobble,
            2.0 + 1.2 * hard,
        ),
    }
}

fn panels(systems: usize) -> Vec<Panel> {
    let mut out = Vec::new();
    for (row, (rname, groups)) in ROWS.iter().enumerate() {
        for (m, (title, y_label)) in METRICS.iter().enumerate() {
            let series = (0..systems)
                .map(|s| {
                    let v: Vec<(f64, f64)> = (0..3).map(|g| value(m, s, g, row)).collect();
                    Series {
                        name: SYSTEMS[s].to_string(),
                        values: v.iter().map(|x| x.0).collect(),
                        errors: (m > 0).then(|| v.iter().map(|x| x.1).collect()),
                    }
                })
                .collect();
            out.push(Panel {
                title: format!("{title} – {rname}"),
                y_label: y_label.to_string(),
                y_max: (m == 0).then_some(100.0),
                groups: groups.iter().map(|g| g.to_string()).collect(),
                series,
            });
        }
    }
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "/tmp/report".into()),
    );
    std::fs::create_dir_all(&out)?;
    grouped_bars_png(&panels(10), 4, &out.join("fig6.png"))?;
    // Three systems; RL never succeeds on high elevation, so its time there is missing.
    let mut small = panels(3);
    for p in &mut small {
        for s in &mut p.series {
            s.name = ["PID", "RL", "TNT"][SYSTEMS.iter().position(|n| *n == s.name).unwrap_or(0)]
                .to_string();
        }
        if p.title.starts_with("Traversal time – elevation") {
            p.series[1].values[2] = f64::NAN;
        }
    }
    grouped_bars_png(&small, 4, &out.join("fig6_small.png"))?;
    println!("wrote {}/fig6.png and fig6_small.png", out.display());
    Ok(())
}
