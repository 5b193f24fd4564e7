//! The compact text report of [`SetStats`] (`verti world stats` without `--json`).

use super::SetStats;
use std::fmt;

/// `value` with `digits` decimals, or `-` when absent.
fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"))
}

fn percent(part: usize, whole: usize) -> String {
    if whole == 0 {
        "-".to_string()
    } else {
        format!("{:.0}%", 100.0 * part as f64 / whole as f64)
    }
}

impl fmt::Display for SetStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.composition;
        writeln!(
            f,
            "worlds {}   tasks {}   scale {}{}",
            self.worlds,
            self.tasks,
            self.scale,
            if self.mixed_scales {
                " (mixed; largest shown)"
            } else {
                ""
            }
        )?;

        writeln!(f, "\ncomposition")?;
        for (title, rows) in [
            ("level", &c.by_level),
            ("terrain type", &c.by_terrain_type),
            ("density", &c.by_density),
        ] {
            let cells: Vec<String> = rows
                .iter()
                .map(|r| {
                    format!(
                        "{:<20}",
                        format!("{} {} ({})", r.name, r.count, percent(r.count, self.worlds))
                    )
                })
                .collect();
            writeln!(f, "  {title:<13} {}", cells.join(" ").trim_end())?;
        }
        writeln!(
            f,
            "  {:<13} {:>10} {:>10} {:>10} {:>10}",
            "level\\type", "rigid", "deformable", "mixed", "total"
        )?;
        for r in &c.level_by_type {
            writeln!(
                f,
                "  {:<13} {:>10} {:>10} {:>10} {:>10}",
                r.level,
                r.rigid,
                r.deformable,
                r.mixed,
                r.rigid + r.deformable + r.mixed
            )?;
        }

        writeln!(
            f,
            "\nelevation (metres; histogram {} bins of {} m)",
            self.elevation.first().map_or(0, |e| e.counts.len()),
            self.elevation.first().map_or(0.0, |e| e.bin_width)
        )?;
        writeln!(
            f,
            "  {:<6} {:>6} {:>8} {:>7} {:>7} {:>20} {:>9}",
            "level", "worlds", "ceiling", "mean", "std", "relief mean [min,max]", "world std"
        )?;
        for e in &self.elevation {
            let relief = e.relief.map_or_else(
                || "-".to_string(),
                |r| format!("{:.2} [{:.2},{:.2}]", r.mean, r.min, r.max),
            );
            writeln!(
                f,
                "  {:<6} {:>6} {:>8.2} {:>7} {:>7} {:>20} {:>9}",
                e.level,
                e.worlds,
                e.ceiling,
                opt(e.mean, 2),
                opt(e.std, 2),
                relief,
                opt(e.world_std.map(|s| s.mean), 2)
            )?;
        }

        if self.elevation.iter().any(|e| e.shape.is_some()) {
            writeln!(
                f,
                "\nterrain shape (mean over worlds; fractions of the level's ceiling)"
            )?;
            writeln!(
                f,
                "  {:<6} {:>10} {:>9} {:>9} {:>7} {:>9} {:>9} {:>9}",
                "level",
                "slope p95",
                "ac lag 1",
                "ac lag 2",
                "skew",
                "kurtosis",
                "mean/max",
                "std/max"
            )?;
            for e in &self.elevation {
                if let Some(s) = e.shape {
                    writeln!(
                        f,
                        "  {:<6} {:>9.1}° {:>9.2} {:>9.2} {:>7.2} {:>9.1} {:>9.2} {:>9.3}",
                        e.level,
                        s.slope_p95_deg,
                        s.autocorr_lag1,
                        s.autocorr_lag2,
                        s.skewness,
                        s.kurtosis,
                        s.mean_fraction,
                        s.std_fraction
                    )?;
                }
            }
        }

        writeln!(f, "\nterrain classes")?;
        writeln!(
            f,
            "  {:<9} {:<10} {:>7} {:>6} {:>6} {:>8} {:>7} {:>6} {:>6}",
            "class", "kind", "patches", "share", "worlds", "friction", "std", "min", "max"
        )?;
        for k in &self.classes {
            let fr = k.friction;
            writeln!(
                f,
                "  {:<9} {:<10} {:>7} {:>5.1}% {:>6} {:>8} {:>7} {:>6} {:>6}",
                k.class,
                if k.deformable { "deformable" } else { "rigid" },
                k.patches,
                100.0 * k.share,
                k.worlds,
                opt(fr.map(|s| s.mean), 3),
                opt(fr.map(|s| s.std), 3),
                opt(fr.map(|s| s.min), 2),
                opt(fr.map(|s| s.max), 2),
            )?;
        }

        let o = &self.obstacles;
        writeln!(f, "\nobstacles")?;
        writeln!(
            f,
            "  rocks {}   trees {}   per world {} [{}, {}]",
            o.rocks,
            o.trees,
            opt(o.per_world.map(|s| s.mean), 1),
            opt(o.per_world.map(|s| s.min), 0),
            opt(o.per_world.map(|s| s.max), 0)
        )?;
        writeln!(
            f,
            "  rock footprint radius {} m [{}, {}]",
            opt(o.rock_radius.map(|s| s.mean), 2),
            opt(o.rock_radius.map(|s| s.min), 2),
            opt(o.rock_radius.map(|s| s.max), 2)
        )?;
        for (what, m) in [
            ("obstacle-obstacle", &o.min_obstacle_spacing),
            ("obstacle-start/goal", &o.min_task_spacing),
        ] {
            match m {
                Some(m) => writeln!(
                    f,
                    "  min centre distance {what:<20} {:>7.2} m  ({})",
                    m.metres, m.world
                )?,
                None => writeln!(f, "  min centre distance {what:<20} {:>7}", "-")?,
            }
        }

        let p = &self.paths;
        writeln!(f, "\nglobal paths")?;
        writeln!(f, "  planned {}   missing {}", p.planned, p.missing)?;
        writeln!(
            f,
            "  length {} m (std {}, [{}, {}])   length / straight line {} (max {})   waypoints {}",
            opt(p.length.map(|s| s.mean), 1),
            opt(p.length.map(|s| s.std), 1),
            opt(p.length.map(|s| s.min), 1),
            opt(p.length.map(|s| s.max), 1),
            opt(p.straight_ratio.map(|s| s.mean), 3),
            opt(p.straight_ratio.map(|s| s.max), 3),
            opt(p.waypoints.map(|s| s.mean), 1)
        )?;
        Ok(())
    }
}
