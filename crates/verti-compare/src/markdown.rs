//! The comparison as Markdown: the headline table in the layout of the reference's README,
//! then attitudes and divergence per group, the outcome confusion, and one row per task.

use crate::outcome_counts::OutcomeCounts;
use crate::run::Driver;
use crate::summary::{Aggregate, Summary, TaskComparison};
use std::fmt::Write;
use verti_bench::{Outcome, Rules};

/// Display name of the reference engine: `chrono-9.0.1` → `Chrono`.
pub fn engine_label(engine: &str) -> String {
    let name = engine.split('-').next().unwrap_or(engine);
    let mut c = name.chars();
    match c.next() {
        Some(first) => first.to_uppercase().chain(c).collect(),
        None => "reference".into(),
    }
}

fn num(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "–".into()
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "–".into(), |v| num(v, digits))
}

/// `success / stuck / rollover`, with timeouts and errors added when there are any.
fn counts(c: &OutcomeCounts) -> String {
    let mut s = format!("{} / {} / {}", c.success, c.stuck, c.rollover);
    if c.timeout > 0 {
        let _ = write!(s, " (+{} timeout)", c.timeout);
    }
    if c.error > 0 {
        let _ = write!(s, " (+{} error)", c.error);
    }
    s
}

fn group_name(a: &Aggregate) -> String {
    match a.group.as_str() {
        "all" => "all tasks".into(),
        level @ ("low" | "mid" | "high") => format!("{level} elevation"),
        ground => format!("on {ground}"),
    }
}

/// The report. Tables use `–` for values that do not exist (no common success, no samples).
pub fn markdown(s: &Summary) -> String {
    let r = engine_label(&s.engine);
    let mut out = String::new();
    let st = &s.setup;
    let (driver, gain) = match st.driver {
        Driver::Pid => ("PID", format!(", kp {}", st.kp)),
        Driver::Reference => ("the reference's driver law", String::new()),
    };
    let rules = match st.rules {
        Rules::Paper => "paper",
        Rules::VertiBench => "verti-bench",
    };
    let _ = writeln!(
        out,
        "# verti vs {r} ({})\n\nverti: {} driven by {driver} (speed {} m/s, lookahead {} m{gain}, rate {} Hz, inner step {} ms), {} start, {rules} rules, {} s, {}. Ratios are verti / {r}; the attitude ratios of the first table are medians of the per-task ratios.\n",
        s.engine,
        st.vehicle,
        st.speed,
        st.lookahead,
        st.rate,
        1000.0 * st.inner_dt,
        st.start.name(),
        st.max_time,
        ground_text(s)
    );
    let _ = writeln!(
        out,
        "| | tasks | outcome agreement | {r} success / stuck / rollover | verti success / stuck / rollover | verti/{r} time to goal (common successes, median) | mean \\|roll\\| ratio | mean \\|pitch\\| ratio |\n|---|---:|---:|---|---|---:|---:|---:|"
    );
    for a in &s.groups {
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} % | {} | {} | {} ({}) | {} | {} |",
            group_name(a),
            a.tasks,
            100.0 * a.agreement,
            counts(&a.reference),
            counts(&a.verti),
            opt(a.median_time_ratio, 3),
            a.common_successes,
            opt(a.mean_abs_roll.median_ratio, 2),
            opt(a.mean_abs_pitch.median_ratio, 2),
        );
    }
    let _ = writeln!(
        out,
        "\n## Attitude (degrees, mean over tasks: {r} / verti (ratio of the means; median of the per-task ratios))\n\n| | mean \\|roll\\| | max \\|roll\\| | mean \\|pitch\\| | max \\|pitch\\| |\n|---|---:|---:|---:|---:|"
    );
    for a in &s.groups {
        let p = |x: &crate::summary::Paired| {
            format!(
                "{} / {} ({}; {})",
                num(x.reference, 1),
                num(x.verti, 1),
                num(x.ratio_of_means, 2),
                opt(x.median_ratio, 2)
            )
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} |",
            group_name(a),
            p(&a.mean_abs_roll),
            p(&a.max_abs_roll),
            p(&a.mean_abs_pitch),
            p(&a.max_abs_pitch)
        );
    }
    let _ = writeln!(
        out,
        "\n## Divergence of verti from {r}'s trajectory\n\nLateral offset: distance of verti's position to {r}'s path (m); roll error: |Δroll| at the same time while both run (degrees). Mean of the per-task means / largest per-task maximum.\n\n| | lateral, first 10 s | lateral, whole trial | roll error, first 10 s | roll error, whole trial |\n|---|---:|---:|---:|---:|"
    );
    for a in &s.groups {
        let _ = writeln!(
            out,
            "| {} | {} / {} | {} / {} | {} / {} | {} / {} |",
            group_name(a),
            num(a.early.mean_lateral, 2),
            num(a.early.max_lateral, 1),
            num(a.whole.mean_lateral, 2),
            num(a.whole.max_lateral, 1),
            num(a.early.mean_roll_error, 2),
            num(a.early.max_roll_error, 1),
            num(a.whole.mean_roll_error, 2),
            num(a.whole.max_roll_error, 1),
        );
    }
    if !s.excluded.is_empty() {
        let _ = writeln!(
            out,
            "\n## Left out: {} reference trial(s) recording an artifact of {r}, not physics\n\nNot counted in any table.\n\n| world | pair | ground | {r}'s outcome | why |\n|---|---:|---|---|---|",
            s.excluded.len()
        );
        for x in &s.excluded {
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} |",
                x.world,
                x.pair,
                x.ground,
                x.reference_outcome.name(),
                x.reason
            );
        }
    }
    if let Some(e) = &s.ensemble {
        ensemble(&mut out, &r, e);
    }
    confusion(&mut out, &r, &s.tasks);
    per_task(&mut out, &r, &s.tasks);
    out
}

/// The ensemble's tables: expected agreement against the ceiling the tasks' chaos sets.
fn ensemble(out: &mut String, r: &str, e: &crate::ensemble::Ensemble) {
    let _ = writeln!(
        out,
        "\n## Ensemble: {} runs per task, starts up to {} cm apart\n\nExpected agreement: the share of verti's runs ending as {r}'s did, averaged over tasks. Self-agreement: the chance that two of verti's runs of a task end alike, the ceiling the tasks' chaos sets on any agreement. Settled tasks: every run ended the same way.\n\n| | tasks | expected agreement | self-agreement | settled tasks (agreeing) | {r} success / stuck / rollover | verti expected success / stuck / rollover |\n|---|---:|---:|---:|---:|---|---|",
        e.members,
        num(100.0 * e.jitter, 1)
    );
    for g in &e.groups {
        let x = &g.expected;
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} % | {:.0} % | {} ({}) | {} | {} / {} / {}{} |",
            g.group,
            g.tasks,
            100.0 * g.expected_agreement,
            100.0 * g.self_agreement,
            g.settled_tasks,
            g.settled_agreeing,
            counts(&g.reference),
            num(x.success, 1),
            num(x.stuck, 1),
            num(x.rollover, 1),
            if x.timeout + x.error > 0.0 {
                format!(" (+{} timeout/error)", num(x.timeout + x.error, 1))
            } else {
                String::new()
            }
        );
    }
    let _ = writeln!(
        out,
        "\n| world | pair | {r} | verti runs: success / stuck / rollover / other | share as {r} |\n|---|---:|---|---|---:|"
    );
    for t in e
        .tasks
        .iter()
        .filter(|t| t.self_agreement < 1.0 || t.p_reference < 1.0)
    {
        let c = &t.counts;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} / {} / {} / {} | {:.0} % |",
            t.world_index,
            t.pair,
            t.reference.name(),
            c.success,
            c.stuck,
            c.rollover,
            c.timeout + c.error,
            100.0 * t.p_reference
        );
    }
}

/// Outcome of the reference (rows) against verti's (columns), over all tasks.
fn confusion(out: &mut String, r: &str, tasks: &[TaskComparison]) {
    let present = |f: &dyn Fn(&TaskComparison) -> Outcome| -> Vec<Outcome> {
        Outcome::ALL
            .into_iter()
            .filter(|o| tasks.iter().any(|t| f(t) == *o))
            .collect()
    };
    let rows = present(&|t| t.reference.outcome);
    let cols = present(&|t| t.verti.outcome);
    let _ = write!(out, "\n## Outcomes: {r} (rows) vs verti (columns)\n\n| |");
    for c in &cols {
        let _ = write!(out, " {} |", c.name());
    }
    let _ = write!(out, "\n|---|");
    for _ in &cols {
        out.push_str("---:|");
    }
    out.push('\n');
    for row in &rows {
        let _ = write!(out, "| {} |", row.name());
        for c in &cols {
            let n = tasks
                .iter()
                .filter(|t| t.reference.outcome == *row && t.verti.outcome == *c)
                .count();
            let _ = write!(out, " {n} |");
        }
        out.push('\n');
    }
}

fn per_task(out: &mut String, r: &str, tasks: &[TaskComparison]) {
    let _ = writeln!(
        out,
        "\n## Tasks ({r} / verti)\n\n| world | pair | outcome | end time (s) | mean \\|roll\\| | max \\|roll\\| | mean \\|pitch\\| | lateral 10 s / whole (m) | roll error 10 s / whole (°) |\n|---|---:|---|---:|---:|---:|---:|---:|---:|"
    );
    for t in tasks {
        let (c, v) = (&t.reference, &t.verti);
        let outcome = if t.agree {
            c.outcome.name().to_string()
        } else {
            format!("**{} / {}**", c.outcome.name(), v.outcome.name())
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} |",
            t.world,
            t.pair,
            outcome,
            num(c.time, 1),
            num(v.time, 1),
            num(c.mean_abs_roll, 1),
            num(v.mean_abs_roll, 1),
            num(c.max_abs_roll, 1),
            num(v.max_abs_roll, 1),
            num(c.mean_abs_pitch, 1),
            num(v.mean_abs_pitch, 1),
            num(t.early.mean_lateral, 2),
            num(t.whole.mean_lateral, 2),
            num(t.early.mean_roll_error, 1),
            num(t.whole.mean_roll_error, 1),
        );
    }
}

/// How the compared worlds were prepared, by the grounds their tasks were run on.
fn ground_text(s: &Summary) -> String {
    let st = &s.setup;
    let mut parts = Vec::new();
    let mut soils = Vec::new();
    for g in &s.grounds {
        match g.as_str() {
            "one-friction" => parts.push(format!(
                "every patch {} with friction {}",
                st.surface, st.friction
            )),
            "rigid-sections" => parts.push(
                "rigid ground with each patch's friction that of its reference section".into(),
            ),
            soil => soils.push(soil.to_string()),
        }
    }
    if !soils.is_empty() {
        parts.push(format!(
            "the {} worlds as imported (one soil each, over the whole map)",
            soils.join(", ")
        ));
    }
    parts.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_and_counts() {
        assert_eq!(engine_label("chrono-9.0.1"), "Chrono");
        assert_eq!(engine_label(""), "reference");
        let c = OutcomeCounts {
            success: 21,
            stuck: 7,
            rollover: 3,
            timeout: 1,
            error: 0,
        };
        assert_eq!(counts(&c), "21 / 7 / 3 (+1 timeout)");
        assert_eq!(num(f64::NAN, 2), "–");
        assert_eq!(opt(Some(0.9974), 3), "0.997");
    }
}
