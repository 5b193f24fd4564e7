//! The accuracy benchmark's tables and figures from its rows: Table II (MSE per elevation
//! level and adaptation time), Table III (the ablations are rows of the same table), and
//! Fig. 3 (one-step error per pose dimension, error by rollout step) on the high level.

use super::bench::{Row, pooled, read_rows};
use std::path::Path;
use verti_render::lines::{LinePanel, LineSeries, draw_line_panel};
use verti_render::{Panel, Series, grouped_bars_image};

const DIMS: [&str; 6] = ["forward", "left", "up", "yaw", "roll", "pitch"];

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The paper's order of its rows; other labels follow alphabetically.
const ORDER: [&str; 13] = [
    "va",
    "node",
    "maml",
    "mlp",
    "va-retrained",
    "va-no-semantics",
    "va-no-elevation",
    "va-no-both",
    "va-every",
    "va-slide",
    "va-rls",
    "va-small",
    "va-small-rls",
];

/// The figures show the paper's four methods and RLS (when they are there): more lines
/// than that do not read.
const FIGURE: [&str; 5] = ["va", "node", "maml", "mlp", "va-rls"];

/// The labels in the rows, in the paper's order.
fn labels(rows: &[Row]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        if !out.contains(&r.label) {
            out.push(r.label.clone());
        }
    }
    let rank = |l: &String| ORDER.iter().position(|o| o == l).unwrap_or(ORDER.len());
    out.sort_by(|a, b| rank(a).cmp(&rank(b)).then(a.cmp(b)));
    out
}

/// Writes `table.md`, `fig3-one-step.png` and `fig3-steps.png` into `out`; returns the
/// markdown.
pub fn write(out: &Path, mse_steps: usize) -> Result<String, String> {
    let rows = read_rows(out)?;
    if rows.is_empty() {
        return Err(format!("{}: no benchmark rows yet", out.display()));
    }
    let pool = pooled(&rows);
    let labels = labels(&rows);
    let in_figure: Vec<String> = {
        let chosen: Vec<String> = labels
            .iter()
            .filter(|l| FIGURE.contains(&l.as_str()))
            .cloned()
            .collect();
        if chosen.is_empty() {
            labels.clone()
        } else {
            chosen
        }
    };
    let fmt = |v: f64| {
        if v.is_finite() {
            format!("{v:.4}")
        } else {
            "–".into()
        }
    };
    let mut md = String::new();
    md.push_str(&format!(
        "MSE of {mse_steps}-step open-loop rollouts (mean over steps and the six pose \
         dimensions; m² and rad², full scale), pooled over the test worlds of each level; \
         adaptation time: median per world, this machine.\n\n"
    ));
    md.push_str("| model | adapted low | mid | high | unadapted low | mid | high | adaptation s (median) | worlds |\n|---|---|---|---|---|---|---|---|---|\n");
    for l in &labels {
        let cell = |adapted: bool, level: &str| {
            pool.get(&(l.clone(), adapted, level.to_string()))
                .map_or(f64::NAN, |(s, _)| s.rollout_mse(mse_steps))
        };
        let mut times: Vec<f64> = rows
            .iter()
            .filter(|r| &r.label == l && r.adapted)
            .map(|r| r.adapt_s)
            .collect();
        let worlds = times.len();
        md.push_str(&format!(
            "| {l} | {} | {} | {} | {} | {} | {} | {} | {worlds} |\n",
            fmt(cell(true, "low")),
            fmt(cell(true, "mid")),
            fmt(cell(true, "high")),
            fmt(cell(false, "low")),
            fmt(cell(false, "mid")),
            fmt(cell(false, "high")),
            if median(&mut times) < 0.01 {
                format!("{:.2} ms", 1e3 * median(&mut times))
            } else {
                format!("{:.2}", median(&mut times))
            },
        ));
    }
    md.push_str("\nOne-step mean absolute error on the high level, adapted (Fig. 3 left; m and rad):\n\n| model | forward | left | up | yaw | roll | pitch | mean |\n|---|---|---|---|---|---|---|---|\n");
    let mut bars = Vec::new();
    for l in &labels {
        if let Some((s, _)) = pool.get(&(l.clone(), true, "high".to_string())) {
            let mae = s.one_step_mae();
            let mean = mae.iter().sum::<f64>() / 6.0;
            md.push_str(&format!(
                "| {l} | {} | {:.4} |\n",
                mae.map(|v| format!("{v:.4}")).join(" | "),
                mean
            ));
            if in_figure.contains(l) {
                bars.push(Series {
                    name: l.clone(),
                    values: mae.to_vec(),
                    errors: None,
                });
            }
        }
    }
    let panel = Panel {
        title: "one-step mean absolute error, high elevation (m, rad)".into(),
        y_label: "error".into(),
        y_max: None,
        groups: DIMS.iter().map(|s| s.to_string()).collect(),
        series: bars,
    };
    let img = grouped_bars_image(&[panel], 1).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, &out.join("fig3-one-step.png")).map_err(|e| e.to_string())?;
    // error by rollout step on the high level (Fig. 3 middle and right)
    let mut img = image::RgbImage::from_pixel(1400, 460, image::Rgb([255, 255, 255]));
    for (p, angular) in [false, true].into_iter().enumerate() {
        let mut series = Vec::new();
        for l in &in_figure {
            if let Some((s, _)) = pool.get(&(l.clone(), true, "high".to_string())) {
                series.push(LineSeries {
                    name: l.clone(),
                    points: s
                        .by_step(angular)
                        .iter()
                        .enumerate()
                        .map(|(t, (m, _))| [(t + 1) as f64, *m])
                        .collect(),
                });
            }
        }
        let panel = LinePanel {
            title: format!(
                "{} error by prediction step (0.1 s), high elevation",
                if angular { "angular" } else { "position" }
            ),
            x_label: "prediction step".into(),
            y_label: if angular { "rad" } else { "m" }.into(),
            series,
            marks: vec![],
        };
        draw_line_panel(&mut img, &panel, 700.0 * p as f64, 0.0, 700.0, 460.0)
            .map_err(|e| e.to_string())?;
    }
    verti_render::save_png(&img, &out.join("fig3-steps.png")).map_err(|e| e.to_string())?;
    let path = out.join("table.md");
    std::fs::write(&path, &md).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(md)
}
