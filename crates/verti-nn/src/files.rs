//! Which files a model card brings with it: its weights, and for a composite card (a hybrid
//! planner's, PIETRA's) the cards of its parts with their weights. A run records every one of
//! them by content, so a card whose weights were retrained in place is not mistaken for the
//! model the run started with.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The longest string taken as a possible file name (summaries and commands are longer).
const MAX_NAME: usize = 255;

/// `card` and every file it names, recursively: a string value of the card (at any depth) that
/// names an existing file relative to the card's directory is a file it loads, and a named
/// `.yaml`/`.yml` file is read the same way. In the order found, each file once. Errors name
/// the card and what is wrong (missing, unreadable, not YAML).
pub fn card_files(card: &Path) -> Result<Vec<PathBuf>, String> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    collect(card, &mut seen, &mut out)?;
    Ok(out)
}

/// [`card_files`] of every non-empty path parameter of `params` (each a model card): what a
/// system with card parameters lists as its inputs (`Factory::inputs`; a file two cards share
/// is listed twice, and recorded once).
pub fn cards_in(params: &verti_core::params::Params) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for card in verti_core::registry::path_params(params) {
        out.extend(card_files(&card)?);
    }
    Ok(out)
}

fn collect(
    card: &Path,
    seen: &mut BTreeSet<PathBuf>,
    out: &mut Vec<PathBuf>,
) -> Result<(), String> {
    if !seen.insert(card.to_path_buf()) {
        return Ok(());
    }
    out.push(card.to_path_buf());
    let text = std::fs::read_to_string(card).map_err(|e| format!("{}: {e}", card.display()))?;
    let value: serde_norway::Value = serde_norway::from_str(&text)
        .map_err(|e| format!("{}: not a YAML model card: {e}", card.display()))?;
    let dir = card.parent().unwrap_or(Path::new(""));
    let mut names = Vec::new();
    strings(&value, &mut names);
    for name in names {
        if name.is_empty() || name.len() > MAX_NAME || name.contains('\n') {
            continue;
        }
        let path = dir.join(name);
        if !path.is_file() {
            continue;
        }
        let is_card = path.extension().is_some_and(|e| e == "yaml" || e == "yml");
        if is_card {
            collect(&path, seen, out)?;
        } else if seen.insert(path.clone()) {
            out.push(path);
        }
    }
    Ok(())
}

/// Every string scalar of `v`, depth first.
fn strings<'a>(v: &'a serde_norway::Value, out: &mut Vec<&'a str>) {
    use serde_norway::Value;
    match v {
        Value::String(s) => out.push(s),
        Value::Sequence(items) => items.iter().for_each(|x| strings(x, out)),
        Value::Mapping(m) => m.values().for_each(|x| strings(x, out)),
        Value::Tagged(t) => strings(&t.value, out),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_composite_card_brings_its_parts_and_their_weights() {
        // shipped cards of two families, read as files (as `--param model=...` would)
        let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let files = card_files(&crates.join("verti-kino/models/tal-v1.yaml")).unwrap();
        let names: Vec<String> = files
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        for part in [
            "tal-v1.yaml",
            "tal-v1.encoder.yaml",
            "tal-v1.encoder.bin",
            "tal-v1.gate.yaml",
            "tal-v1.gate.bin",
            "tal-v1.dynamics.yaml",
            "tal-v1.dynamics.bin",
        ] {
            assert!(
                names.iter().any(|n| n == part),
                "{part} missing from {names:?}"
            );
        }
        // a plain card: itself and its weights
        let files = card_files(&crates.join("verti-policy/models/acl-v1.yaml")).unwrap();
        assert_eq!(files.len(), 2, "{files:?}");
        let e = card_files(&crates.join("verti-policy/models/no-such-card.yaml")).unwrap_err();
        assert!(e.contains("no-such-card.yaml"), "{e}");
    }
}
