//! Loading a dataset: the manifest, every step table (checked against the schema), and its
//! trials as row ranges.

use crate::manifest::{DataOutcome, Manifest};
use crate::table::{Table, read_table_at_most, schema};
use crate::{DataError, Result};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_world::World;

/// A loaded dataset.
#[derive(Clone, Debug)]
pub struct Dataset {
    pub dir: PathBuf,
    pub manifest: Manifest,
    /// Every row of every file, in trial order.
    pub table: Table,
    /// Each trial's rows.
    spans: Vec<Span>,
}

#[derive(Clone, Debug, PartialEq)]
struct Span {
    trial: u32,
    world: u32,
    rows: Range<usize>,
    outcome: DataOutcome,
}

/// One trial of a dataset: its rows in the table.
#[derive(Clone, Copy, Debug)]
pub struct TrialView<'a> {
    pub trial: u32,
    pub world: u32,
    pub outcome: DataOutcome,
    pub rows: (usize, usize),
    table: &'a Table,
}

impl<'a> TrialView<'a> {
    pub fn len(&self) -> usize {
        self.rows.1 - self.rows.0
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// A DOUBLE column (a feature, a command, a wheel friction) over this trial's rows.
    pub fn f64(&self, column: &str) -> Option<&'a [f64]> {
        self.table.f64(column).map(|v| &v[self.rows.0..self.rows.1])
    }
    /// An INT32 column over this trial's rows.
    pub fn i32(&self, column: &str) -> Option<&'a [i32]> {
        self.table.i32(column).map(|v| &v[self.rows.0..self.rows.1])
    }
    /// Simulated seconds from the first row to the last.
    pub fn duration(&self) -> f64 {
        let t = self.f64("t").unwrap_or(&[]);
        match (t.first(), t.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }
}

impl Dataset {
    /// Loads `dir`: the manifest, then every file it lists, each checked against the schema of
    /// the manifest's vehicle. A missing, truncated or corrupt file is an error naming it.
    pub fn load(dir: &Path) -> Result<Dataset> {
        let manifest = Manifest::read(dir)?;
        let expected = schema(manifest.wheels);
        let mut table = Table::default();
        for f in &manifest.files {
            let path = dir.join(f);
            if let Some(sum) = manifest.checksums.get(f) {
                let bytes = std::fs::read(&path).map_err(|e| DataError::file(&path, e))?;
                if crate::manifest::checksum(&bytes) != *sum {
                    return Err(DataError::file(
                        &path,
                        "the file's checksum differs from the manifest's: it is damaged or was replaced",
                    ));
                }
            }
            let left = manifest.rows.saturating_sub(table.rows());
            table.append(read_table_at_most(&path, &expected, left)?);
        }
        let manifest_path = dir.join(crate::manifest::MANIFEST);
        if table.rows() != manifest.rows {
            return Err(DataError::file(
                &manifest_path,
                format!(
                    "lists {} rows but its files hold {} (a file was replaced or is missing)",
                    manifest.rows,
                    table.rows()
                ),
            ));
        }
        let spans = spans(&table).map_err(|m| DataError::file(dir, m))?;
        if spans.len() != manifest.trials {
            return Err(DataError::file(
                &manifest_path,
                format!(
                    "lists {} trials but its files hold {}",
                    manifest.trials,
                    spans.len()
                ),
            ));
        }
        Ok(Dataset {
            dir: dir.to_path_buf(),
            manifest,
            table,
            spans,
        })
    }

    pub fn trial_count(&self) -> usize {
        self.spans.len()
    }

    /// The trials in order.
    pub fn trials(&self) -> impl Iterator<Item = TrialView<'_>> {
        self.spans.iter().map(|s| TrialView {
            trial: s.trial,
            world: s.world,
            outcome: s.outcome,
            rows: (s.rows.start, s.rows.end),
            table: &self.table,
        })
    }

    /// Loads the worlds the data were recorded on (the manifest's set), checking that the set
    /// resolves to the same set name and holds every world index the data use.
    pub fn load_worlds(&self) -> Result<Vec<Arc<World>>> {
        let w = &self.manifest.worlds;
        let set = verti_world::sets::resolve_set(&w.set, w.scale, &|| {})
            .map_err(|e| DataError::Run(format!("the dataset's world set `{}`: {e}", w.set)))?;
        if set.name != w.name {
            return Err(DataError::Run(format!(
                "the world set `{}` is now `{}`, not `{}` as recorded",
                w.set, set.name, w.name
            )));
        }
        let worlds: Vec<Arc<World>> = set.worlds.into_iter().map(Arc::new).collect();
        for i in &w.indices {
            if !worlds.iter().any(|x| x.meta.index == *i) {
                return Err(DataError::Run(format!(
                    "the world set `{}` has no world {i}, which the data use",
                    w.set
                )));
            }
        }
        Ok(worlds)
    }
}

/// Splits the table into trials at `last` flags, checking that the trial and world ids are
/// constant within a trial and that every trial's last row carries a known outcome.
fn spans(table: &Table) -> std::result::Result<Vec<Span>, String> {
    let missing = |c: &str| format!("column {c} is missing");
    let trial = table.i32("trial").ok_or_else(|| missing("trial"))?;
    let world = table.i32("world").ok_or_else(|| missing("world"))?;
    let last = table.bool("last").ok_or_else(|| missing("last"))?;
    let outcome = table.outcomes().ok_or_else(|| missing("outcome"))?;
    let mut out = Vec::new();
    let mut start = 0;
    for i in 0..table.rows() {
        if trial[i] != trial[start] || world[i] != world[start] {
            return Err(format!(
                "row {i}: trial {} starts before trial {} has its last row",
                trial[i], trial[start]
            ));
        }
        if last[i] {
            let name = outcome[i]
                .as_deref()
                .ok_or_else(|| format!("row {i}: the last row of a trial has no outcome"))?;
            let o = DataOutcome::from_name(name)
                .ok_or_else(|| format!("row {i}: unknown outcome `{name}`"))?;
            out.push(Span {
                trial: trial[i] as u32,
                world: world[i] as u32,
                rows: start..i + 1,
                outcome: o,
            });
            start = i + 1;
        } else if outcome[i].is_some() {
            return Err(format!("row {i}: an outcome on a row that is not the last"));
        }
    }
    if start != table.rows() {
        return Err(format!("the last trial (from row {start}) has no last row"));
    }
    Ok(out)
}
