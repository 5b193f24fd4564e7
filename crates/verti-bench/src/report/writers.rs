//! Writers: the tables of `tables` as Markdown ([`markdown`]) and as a self-contained HTML
//! page ([`html`]).

use super::tables::{
    PAIRED_NOTE, Table, VARIANCE_NOTE, extra_table, fig6_table, paired_table, table_i,
};
use super::{Breakdown, Summary};
use std::fmt::Write as _;

fn md_cell(s: &str) -> String {
    s.replace('\\', "\\\\")
        .replace('|', "\\|")
        .replace('\n', " ")
}

fn md_table(out: &mut String, t: &Table) {
    let line = |cells: &[String]| {
        let cells: Vec<String> = cells.iter().map(|c| md_cell(c)).collect();
        format!("| {} |\n", cells.join(" | "))
    };
    out.push_str(&line(&t.header));
    let mut sep = vec![":---".to_string()];
    sep.extend((1..t.header.len()).map(|_| "---:".to_string()));
    out.push_str(&format!("|{}|\n", sep.join("|")));
    for r in &t.rows {
        out.push_str(&line(r));
    }
}

/// The summary as Markdown: Table I (systems as columns), one Fig. 6 table per breakdown, and
/// the extra metrics.
pub fn markdown(summary: &Summary) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Evaluation report\n\n{} trials, {} system(s).\n",
        summary.trials,
        summary.systems.len()
    );
    if summary.systems.is_empty() {
        out.push_str("No results.\n");
        return out;
    }
    out.push_str("## Table I: outcomes\n\n");
    md_table(&mut out, &table_i(summary));
    out.push_str("\nTraversal time: mean over successful trials.\n");
    for b in Breakdown::ALL {
        let _ = writeln!(out, "\n## Fig. 6: {}\n", b.title().to_lowercase());
        md_table(&mut out, &fig6_table(summary, b));
    }
    let _ = writeln!(out, "\n{VARIANCE_NOTE}");
    if !summary.paired.is_empty() {
        out.push_str("\n## Paired comparison: tasks only one system reached\n\n");
        md_table(&mut out, &paired_table(summary));
        let _ = writeln!(out, "\n{PAIRED_NOTE}");
    }
    out.push_str("\n## Other metrics\n\n");
    md_table(&mut out, &extra_table(summary));
    out.push_str(
        "\nThrottle and steering: per-trial mean |value| and total variation (sum of \
         |change|), averaged over trials.\n",
    );
    out
}

fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

fn html_table(out: &mut String, t: &Table) {
    out.push_str("<table>\n<thead><tr>");
    for h in &t.header {
        let _ = write!(out, "<th>{}</th>", esc(h));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for r in &t.rows {
        out.push_str("<tr>");
        for (i, c) in r.iter().enumerate() {
            let tag = if i == 0 { "th" } else { "td" };
            let _ = write!(out, "<{tag}>{}</{tag}>", esc(c));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table>\n");
}

const CSS: &str = "body{font-family:-apple-system,'Segoe UI',Helvetica,Arial,sans-serif;\
margin:2em auto;max-width:1200px;padding:0 1em;color:#222;line-height:1.4}\
h1,h2{font-weight:600}h2{margin-top:1.8em;border-bottom:1px solid #ddd;padding-bottom:.2em}\
table{border-collapse:collapse;margin:.6em 0;font-size:.92em}\
th,td{padding:.3em .7em;border-bottom:1px solid #e4e4e4;text-align:right;white-space:nowrap}\
thead th{border-bottom:2px solid #888;text-align:center}tbody th{text-align:left;font-weight:500}\
tbody tr:hover{background:#f6f8fa}.note{color:#555;font-size:.9em}\
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #eee}\
figcaption{color:#444;font-size:.9em;margin-top:.3em}";

/// The file name of a system's own page in the HTML report (`system-<name>.html`, with
/// anything but letters, digits, `-` and `_` replaced by `_`).
pub fn system_page_name(name: &str) -> String {
    let slug: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("system-{slug}.html")
}

/// One system's page: its outcomes, its Fig. 6 rows and other metrics, on their own (the
/// side-by-side tables get hard to read with ten systems), linked back to the report.
pub fn system_page(summary: &Summary, index: usize) -> Option<String> {
    let one = summary.systems.get(index)?;
    let alone = Summary {
        trials: one.outcomes.trials,
        systems: vec![one.clone()],
        paired: Vec::new(),
    };
    let mut out = html_with(
        &alone,
        &[],
        &format!("{} ({})", one.name, one.vehicle),
        false,
    );
    let back = "<p><a href=\"report.html\">← all systems</a></p>\n</body>";
    out = out.replacen("</body>", back, 1);
    Some(out)
}

/// The summary as a self-contained HTML page (inline CSS, no scripts) with the given figures
/// embedded by relative path: `(title, png file name)`, e.g. `("Fig. 6", "fig6.png")`. With
/// several systems it links each one's page ([`system_page`]).
pub fn html(summary: &Summary, figures: &[(&str, &str)]) -> String {
    html_with(
        summary,
        figures,
        "Evaluation report",
        summary.systems.len() > 1,
    )
}

fn html_with(summary: &Summary, figures: &[(&str, &str)], heading: &str, links: bool) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>verti: {}</title>\n<style>{CSS}</style>\n</head>\n<body>\n\
         <h1>{}</h1>\n<p>{} trials, {} system(s).</p>\n",
        esc(heading),
        esc(heading),
        summary.trials,
        summary.systems.len()
    );
    if links {
        out.push_str("<p>Per system: ");
        let items: Vec<String> = summary
            .systems
            .iter()
            .map(|s| {
                format!(
                    "<a href=\"{}\">{}</a>",
                    esc(&system_page_name(&s.name)),
                    esc(&s.name)
                )
            })
            .collect();
        out.push_str(&items.join(" · "));
        out.push_str("</p>\n");
    }
    if summary.systems.is_empty() {
        out.push_str("<p>No results.</p>\n");
    } else {
        out.push_str("<h2>Table I: outcomes</h2>\n");
        html_table(&mut out, &table_i(summary));
        out.push_str("<p class=\"note\">Traversal time: mean over successful trials.</p>\n");
    }
    for (title, file) in figures {
        let _ = write!(
            out,
            "<figure>\n<img src=\"{}\" alt=\"{}\">\n<figcaption>{}</figcaption>\n</figure>\n",
            esc(file),
            esc(title),
            esc(title)
        );
    }
    if !summary.systems.is_empty() {
        for b in Breakdown::ALL {
            let _ = writeln!(out, "<h2>Fig. 6: {}</h2>", esc(&b.title().to_lowercase()));
            html_table(&mut out, &fig6_table(summary, b));
        }
        let _ = writeln!(out, "<p class=\"note\">{}</p>", esc(VARIANCE_NOTE));
        if !summary.paired.is_empty() {
            out.push_str("<h2>Paired comparison: tasks only one system reached</h2>\n");
            html_table(&mut out, &paired_table(summary));
            let _ = writeln!(out, "<p class=\"note\">{}</p>", esc(PAIRED_NOTE));
        }
        out.push_str("<h2>Other metrics</h2>\n");
        html_table(&mut out, &extra_table(summary));
    }
    out.push_str("</body>\n</html>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures::sample;
    use crate::report::summarize;

    #[test]
    fn markdown_and_html_show_systems_side_by_side() {
        let s = summarize(&sample());
        let md = markdown(&s);
        assert!(md.contains("|  | A | B |"), "{md}");
        assert!(md.contains("| Success (%) | 50.0 | 0.0 |"), "{md}");
        assert!(md.contains("| Stuck (%) | 25.0 | 0.0 |"), "{md}");
        assert!(md.contains("| Traversal time (s) | 25.00 | – |"), "{md}");
        // low elevation, A: roll mean 3 variance 1; B: no trials
        assert!(md.contains("| low: roll (°) | 3.00 (1.00) | – |"), "{md}");
        // the pair's row starts with its three counts, and the note explains the test
        let p = &s.paired[0];
        let row = format!(
            "| A vs B | {} | {} | {} |",
            p.common_tasks, p.only_a, p.only_b
        );
        assert!(md.contains(&row), "{md}");
        assert!(md.contains("sign (McNemar) test"), "{md}");
        let mut odd = sample();
        odd[0].system = "<x|y>".into();
        let h = html(&summarize(&odd), &[("Fig. 6 <all>", "fig6.png")]);
        assert!(h.contains("&lt;x|y&gt;") && !h.contains("<x|y>"));
        assert!(h.contains("<img src=\"fig6.png\" alt=\"Fig. 6 &lt;all&gt;\">"));
        assert!(markdown(&summarize(&odd)).contains("<x\\|y>"));
        // one page per system, linked from the report
        let page = system_page_name("<x|y>");
        assert_eq!(page, "system-_x_y_.html");
        assert!(
            h.contains(&format!("<a href=\"{page}\">&lt;x|y&gt;</a>")),
            "{h}"
        );
        let own = system_page(&summarize(&odd), 0).unwrap();
        assert!(own.contains("&lt;x|y&gt;") && own.contains("report.html"));
        // only its own column
        assert!(
            h.contains("<th>B</th>") && !own.contains("<th>B</th>"),
            "{own}"
        );
        assert!(h.contains("Paired comparison") && !own.contains("Paired comparison"));
        assert!(system_page(&summarize(&odd), 9).is_none());
    }
}
