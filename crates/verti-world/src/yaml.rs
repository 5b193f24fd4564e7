//! YAML for verti: a compact emitter, and the one bounded reader every YAML input goes through.
//!
//! Emitting: mappings and lists of mappings in block style, lists of scalars in flow style
//! (`[x, y, z]`). serde_norway writes every list element on its own line, which turned a world
//! manifest into thousands of one-number lines; this keeps it readable. Scalars are formatted by
//! serde_norway itself, so quoting and float round-trips stay exact.
//!
//! Reading: serde_norway's time and memory grow faster than linearly on deeply nested input (a
//! 200 KB file of nested lists took 56 s) and it holds a whole junk file in memory before it
//! fails. [`read_yaml_bounded`] and [`check_yaml_text`] refuse oversized files and deep nesting
//! with a linear pre-scan before the parser sees the text.

use serde::Serialize;
use serde_norway::Value;

/// Serialises `value` to YAML text.
pub fn to_yaml<T: Serialize>(value: &T) -> Result<String, serde_norway::Error> {
    let v = serde_norway::to_value(value)?;
    let mut out = String::new();
    emit_block(&v, 0, &mut out)?;
    Ok(out)
}

fn is_scalar(v: &Value) -> bool {
    !matches!(v, Value::Mapping(_) | Value::Sequence(_) | Value::Tagged(_))
}

fn is_flow(v: &Value) -> bool {
    match v {
        Value::Sequence(s) => s.iter().all(|x| is_scalar(x) || is_flow(x)),
        _ => is_scalar(v),
    }
}

/// A small record of scalars (a patch, a task) reads best on one line as `{k: v, ...}`.
fn is_flow_record(v: &Value) -> bool {
    matches!(v, Value::Mapping(m) if !m.is_empty() && m.len() <= 6 && m.values().all(|x| is_scalar(x) || (is_flow(x) && flow_len(x) <= 4)))
}

fn flow_len(v: &Value) -> usize {
    match v {
        Value::Sequence(s) => s.len(),
        _ => 1,
    }
}

fn flow_record(v: &Value) -> Result<String, serde_norway::Error> {
    let Value::Mapping(m) = v else { return flow(v) };
    let parts = m
        .iter()
        .map(|(k, x)| Ok(format!("{}: {}", scalar(k)?, flow(x)?)))
        .collect::<Result<Vec<_>, serde_norway::Error>>()?;
    Ok(format!("{{{}}}", parts.join(", ")))
}

fn scalar(v: &Value) -> Result<String, serde_norway::Error> {
    Ok(serde_norway::to_string(v)?.trim_end().to_string())
}

fn flow(v: &Value) -> Result<String, serde_norway::Error> {
    match v {
        Value::Sequence(s) => Ok(format!(
            "[{}]",
            s.iter()
                .map(flow)
                .collect::<Result<Vec<_>, _>>()?
                .join(", ")
        )),
        _ => scalar(v),
    }
}

fn emit_block(v: &Value, indent: usize, out: &mut String) -> Result<(), serde_norway::Error> {
    let pad = " ".repeat(indent);
    match v {
        Value::Mapping(m) => {
            if m.is_empty() {
                out.push_str(&format!("{pad}{{}}\n"));
            }
            for (k, val) in m {
                let key = scalar(k)?;
                if is_flow(val) || matches!(val, Value::Mapping(mm) if mm.is_empty()) {
                    let text = if matches!(val, Value::Mapping(_)) {
                        "{}".to_string()
                    } else {
                        flow(val)?
                    };
                    out.push_str(&format!("{pad}{key}: {text}\n"));
                } else if let Value::Sequence(s) = val {
                    out.push_str(&format!("{pad}{key}:\n"));
                    emit_seq(s, indent, out)?;
                } else {
                    out.push_str(&format!("{pad}{key}:\n"));
                    emit_block(val, indent + 2, out)?;
                }
            }
        }
        Value::Sequence(s) => emit_seq(s, indent, out)?,
        Value::Tagged(t) => {
            let text = serde_norway::to_string(t)?;
            for line in text.lines() {
                out.push_str(&format!("{pad}{line}\n"));
            }
        }
        _ => out.push_str(&format!("{pad}{}\n", flow(v)?)),
    }
    Ok(())
}

fn emit_seq(s: &[Value], indent: usize, out: &mut String) -> Result<(), serde_norway::Error> {
    let pad = " ".repeat(indent);
    for item in s {
        if is_flow(item) {
            out.push_str(&format!("{pad}- {}\n", flow(item)?));
        } else if is_flow_record(item) {
            out.push_str(&format!("{pad}- {}\n", flow_record(item)?));
        } else {
            // Emit the item one level deeper, then put the dash on its first line.
            let mut inner = String::new();
            emit_block(item, indent + 2, &mut inner)?;
            let mut lines = inner.lines();
            if let Some(first) = lines.next() {
                out.push_str(&format!("{pad}- {}\n", &first[indent + 2..]));
            }
            for l in lines {
                out.push_str(l);
                out.push('\n');
            }
        }
    }
    Ok(())
}

/// Limits on a YAML input, checked before it is parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct YamlLimits {
    /// Largest input accepted, bytes.
    pub max_bytes: u64,
    /// Deepest nesting accepted: block levels (indentation) plus flow levels (`[`, `{`).
    pub max_depth: usize,
}

impl YamlLimits {
    /// The limits of every YAML file verti reads, with a wide margin over the largest real
    /// inputs: a generated or imported world.yaml is at most 135 KiB and nests 5 levels, a
    /// Verti-Bench config 62 KiB, a vehicle file 4 KiB, and the set.yaml of the largest set
    /// the generator makes (100 000 worlds) 1.7 MB. The parser holds a whole file's events in
    /// memory before it can reject it: 4 MiB of YAML takes under a second to refuse, while
    /// 16 MiB took 3.5 s.
    pub const DEFAULT: YamlLimits = YamlLimits {
        max_bytes: 4 << 20,
        max_depth: 64,
    };
}

/// Why a YAML text was refused before parsing: the field (`size` or `nesting`) and the problem.
#[derive(Clone, Debug, PartialEq)]
pub struct YamlRefusal {
    pub field: &'static str,
    pub problem: String,
}

impl std::fmt::Display for YamlRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "field `{}`: {}", self.field, self.problem)
    }
}

/// Reads a YAML file for parsing: a file over `limits.max_bytes` is refused without reading
/// it, and text that is not UTF-8 or nests deeper than `limits.max_depth` is refused before
/// the parser sees it. `what` names the file's role in errors ("the world manifest").
pub fn read_yaml_bounded(
    path: &std::path::Path,
    limits: &YamlLimits,
    what: &str,
) -> crate::Result<String> {
    let bytes = crate::input::read_capped(path, limits.max_bytes, what)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        crate::WorldError::invalid(
            path,
            "encoding",
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    check_yaml_text(&text, limits)
        .map_err(|r| crate::WorldError::invalid(path, r.field, r.problem))?;
    Ok(text)
}

/// Checks YAML text against the limits in one linear pass. The pass tracks just enough of
/// YAML's syntax to count nesting: the indentation levels of block collections, `- `/`? `/`: `
/// indicators that open a node on the same line, `[`/`{` flow collections, and the quoted
/// scalars, block scalars and comments whose brackets do not count.
pub fn check_yaml_text(text: &str, limits: &YamlLimits) -> Result<(), YamlRefusal> {
    if text.len() as u64 > limits.max_bytes {
        return Err(YamlRefusal {
            field: "size",
            problem: format!(
                "the text is {} but YAML inputs may be at most {}",
                crate::input::human_bytes(text.len() as u64),
                crate::input::human_bytes(limits.max_bytes)
            ),
        });
    }
    let mut scan = DepthScan {
        max_depth: limits.max_depth,
        flow: 0,
        quote: None,
        indents: Vec::new(),
        block_scalar_parent: None,
    };
    for (k, raw) in text.split('\n').enumerate() {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        scan.line(line.as_bytes(), k + 1)?;
    }
    Ok(())
}

/// State of [`check_yaml_text`] between lines.
struct DepthScan {
    max_depth: usize,
    /// Open `[`/`{` collections.
    flow: usize,
    /// The quote character of a quoted scalar that continues on the next line.
    quote: Option<u8>,
    /// Strictly increasing indentation columns of the open block nodes.
    indents: Vec<usize>,
    /// Inside a `|`/`>` block scalar: lines indented deeper than this are its content.
    block_scalar_parent: Option<usize>,
}

impl DepthScan {
    fn check(&self, line: usize, column: usize) -> Result<(), YamlRefusal> {
        let depth = self.indents.len() + self.flow;
        if depth > self.max_depth {
            return Err(YamlRefusal {
                field: "nesting",
                problem: format!(
                    "nesting depth {depth} at line {line}, column {} exceeds the limit of {} levels (verti's YAML files nest a few levels deep; deeper input is refused before parsing because the parser slows down badly on it)",
                    column + 1,
                    self.max_depth
                ),
            });
        }
        Ok(())
    }

    fn push_indent(&mut self, column: usize, line: usize) -> Result<(), YamlRefusal> {
        if self.indents.last().is_none_or(|&top| top < column) {
            self.indents.push(column);
        }
        self.check(line, column)
    }

    fn line(&mut self, b: &[u8], line: usize) -> Result<(), YamlRefusal> {
        let indent = b.iter().take_while(|&&c| c == b' ').count();
        let blank = b[indent..].iter().all(|c| c.is_ascii_whitespace());
        if let Some(parent) = self.block_scalar_parent {
            if blank || indent > parent {
                return Ok(());
            }
            self.block_scalar_parent = None;
        }
        let mut pos = 0;
        if self.quote.is_none() && self.flow == 0 {
            if blank || b[indent] == b'#' || (indent == 0 && b[0] == b'%') {
                return Ok(());
            }
            let marker = b.starts_with(b"---") || b.starts_with(b"...");
            if marker && b.get(3).is_none_or(|c| c.is_ascii_whitespace()) {
                // a new document: nothing is open any more
                self.indents.clear();
                pos = 3;
            } else {
                while self.indents.last().is_some_and(|&top| top > indent) {
                    self.indents.pop();
                }
                self.push_indent(indent, line)?;
                pos = indent;
                // `- `, `? ` and `: ` open a node on this line, one level deeper each
                while matches!(b.get(pos), Some(b'-' | b'?' | b':'))
                    && b.get(pos + 1).is_none_or(|&c| c == b' ')
                {
                    let mut next = pos + 1;
                    while b.get(next) == Some(&b' ') {
                        next += 1;
                    }
                    if next >= b.len() {
                        return Ok(());
                    }
                    self.push_indent(next, line)?;
                    pos = next;
                }
            }
        }
        self.tokens(b, pos, line)
    }

    /// Scans the rest of a line from `pos` for flow brackets, quotes, block scalars and
    /// comments. `node_start` is true where a node may begin (where a bracket or a quote opens
    /// a collection or a quoted scalar rather than being part of a plain scalar).
    fn tokens(&mut self, b: &[u8], mut pos: usize, line: usize) -> Result<(), YamlRefusal> {
        // a line's first token may start a node: in block context it follows the indentation
        // and indicators, in flow context a line break separates tokens like a space
        let mut node_start = true;
        while pos < b.len() {
            let c = b[pos];
            if let Some(q) = self.quote {
                if q == b'"' && c == b'\\' {
                    pos += 2;
                    continue;
                }
                if c == q {
                    if q == b'\'' && b.get(pos + 1) == Some(&b'\'') {
                        pos += 2;
                        continue;
                    }
                    self.quote = None;
                    node_start = false;
                }
                pos += 1;
                continue;
            }
            let after_space = pos == 0 || matches!(b[pos - 1], b' ' | b'\t');
            let flow = self.flow > 0;
            match c {
                b'#' if after_space => return Ok(()),
                b' ' | b'\t' => {}
                b'[' | b'{' if flow || node_start => {
                    self.flow += 1;
                    self.check(line, pos)?;
                    node_start = true;
                }
                b']' | b'}' if flow => {
                    self.flow -= 1;
                    node_start = false;
                }
                b',' if flow => node_start = true,
                b':' if flow || b.get(pos + 1).is_none_or(|&n| n == b' ' || n == b'\t') => {
                    node_start = true
                }
                b'"' | b'\'' if node_start => self.quote = Some(c),
                b'|' | b'>' if node_start && !flow => {
                    self.block_scalar_parent = Some(self.indents.last().copied().unwrap_or(0));
                    return Ok(());
                }
                // an anchor or a tag before a node: the node still starts after it
                b'&' | b'!' if node_start => {
                    while pos + 1 < b.len() && !b" \t[]{},".contains(&b[pos + 1]) {
                        pos += 1;
                    }
                }
                _ => node_start = false,
            }
            pos += 1;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Inner {
        name: String,
        xs: Vec<f64>,
        grid: Vec<[f64; 2]>,
    }
    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Outer {
        title: String,
        list: Vec<Inner>,
        empty: Vec<u8>,
        map: std::collections::BTreeMap<String, u32>,
        weird: String,
    }

    #[test]
    fn round_trips_and_is_compact() {
        let v = Outer {
            title: "a: b".into(),
            list: vec![Inner {
                name: "yes".into(),
                xs: vec![0.1, 1e-300, -3.0],
                grid: vec![[1.0, 2.0], [3.0, 4.5]],
            }],
            empty: vec![],
            map: [("k".to_string(), 1)].into_iter().collect(),
            weird: "- x".into(),
        };
        let text = to_yaml(&v).unwrap();
        assert!(text.contains("xs: [0.1, 1e-300, -3.0]"), "{text}");
        assert!(text.contains("grid: [[1.0, 2.0], [3.0, 4.5]]"), "{text}");
        let back: Outer = serde_norway::from_str(&text).unwrap();
        assert_eq!(back, v);
    }

    fn depth_refused(text: &str) -> bool {
        match check_yaml_text(text, &YamlLimits::DEFAULT) {
            Ok(()) => false,
            Err(r) => {
                assert_eq!(r.field, "nesting", "{r}");
                assert!(r.problem.contains("limit of 64 levels"), "{r}");
                true
            }
        }
    }

    #[test]
    fn deep_nesting_of_every_kind_is_refused_before_parsing() {
        let flow = format!("a: {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
        let t0 = std::time::Instant::now();
        assert!(depth_refused(&flow));
        assert!(depth_refused(&"{a: ".repeat(70)));
        let block: String = (0..70)
            .map(|k| format!("{}k{k}:\n", " ".repeat(k)))
            .collect();
        assert!(depth_refused(&block));
        let dashes: String = (0..70).map(|k| format!("{}-\n", " ".repeat(k))).collect();
        assert!(depth_refused(&dashes));
        assert!(depth_refused(&format!("{}x\n", "- ".repeat(70))));
        // flow nesting counts on top of the block nesting it sits in
        let mixed = format!("{}{}\n", "- ".repeat(40), "[".repeat(30));
        assert!(depth_refused(&mixed));
        assert!(t0.elapsed().as_millis() < 500, "{:?}", t0.elapsed());
    }

    #[test]
    fn brackets_that_do_not_nest_are_not_counted() {
        let deep = "[".repeat(100);
        let texts = [
            format!("name: \"{deep}\"\nother: '{deep}'''\n"),
            format!("# {deep}\nkey: value # {deep}\n"),
            format!("description: a truck {deep}\nurl: http://x/{deep}\n"),
            format!("text: |\n  {deep}\n    {deep}\nnext: 1\n"),
            format!("- key: >-\n    {deep}\n  other: 2\n"),
            format!("quoted: \"first line\n  {deep}\n  last\"\nafter: [1, [2]]\n"),
            format!("flow: [\"{deep}\", '{deep}', plain # {deep}\n  , x]\n"),
            "--- &anchor !tag [1, {a: [2]}]\n".to_string(),
        ];
        for t in &texts {
            assert!(!depth_refused(t), "{t}");
        }
        // the emitter's own output is well within the limits
        let v: Vec<Vec<Vec<f64>>> = vec![vec![vec![1.0, 2.0]; 3]; 2];
        check_yaml_text(&to_yaml(&v).unwrap(), &YamlLimits::DEFAULT).unwrap();
    }

    #[test]
    fn oversized_text_is_refused_with_the_cap() {
        let limits = YamlLimits {
            max_bytes: 10,
            max_depth: 64,
        };
        let r = check_yaml_text("a: 12345678", &limits).unwrap_err();
        assert_eq!(r.field, "size");
        assert!(r.problem.contains("at most 10 bytes"), "{r}");
    }
}
