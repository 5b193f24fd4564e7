//! A compact YAML emitter: mappings and lists of mappings in block style, lists of scalars in
//! flow style (`[x, y, z]`). serde_norway writes every list element on its own line, which
//! turned a world manifest into thousands of one-number lines; this keeps it readable.
//! Scalars are formatted by serde_norway itself, so quoting and float round-trips stay exact.

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
}
