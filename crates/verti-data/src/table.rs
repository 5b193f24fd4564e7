//! The step table: the schema of a dataset's rows and its Parquet files.
//!
//! One row per control step (10 Hz by default). Columns, in file order:
//!
//! | column | type | meaning |
//! |---|---|---|
//! | `trial` | INT32 | trial id (exploration: 0, 1, ...; system runs: the task number) |
//! | `world` | INT32 | world index in the set (`WorldMeta::index`) |
//! | `step` | INT32 | control step within the trial (row k is at about k / rate seconds) |
//! | every feature of `verti_bench::features::Feature::ALL` | DOUBLE | by its schema name (`t`, `x`, ..., `time_left`) |
//! | `cmd_steering`, `cmd_speed` | DOUBLE | the command issued at this row, held until the next |
//! | `wheel{i}_class`, `wheel{i}_friction`, `wheel{i}_soil` | INT32, DOUBLE, BOOLEAN | ground under wheel i's centre |
//! | `last` | BOOLEAN | true on the last row of a trial |
//! | `outcome` | optional UTF8 | how the trial ended, on its last row only (null elsewhere) |

use crate::manifest::DataOutcome;
use crate::{DataError, Result};
use parquet::basic::Compression;
use parquet::column::reader::ColumnReader;
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int32Type};
use parquet::file::properties::WriterProperties;
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::parser::parse_message_type;
use std::path::Path;
use std::sync::Arc;
use verti_bench::features::Feature;

/// Features per row (all of the schema).
pub const FEATURES: usize = Feature::ALL.len();

/// The ground under one wheel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelGround {
    /// Semantic class id (Verti-Bench label ids 0..9).
    pub class: u8,
    /// Coulomb friction of rigid ground; tan φ of soil (`Surface::effective_friction`).
    pub friction: f64,
    /// True on deformable ground (snow, mud, sand).
    pub soil: bool,
}

/// One recorded control step.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `Feature::ALL` values.
    pub features: [f64; FEATURES],
    /// Steering in [-1, 1] and target speed (m/s) commanded at this row.
    pub steering: f64,
    pub speed: f64,
    pub wheels: Vec<WheelGround>,
}

/// One recorded trial (or a failure window of one).
#[derive(Clone, Debug, PartialEq)]
pub struct TrialRecord {
    pub trial: u32,
    pub world: u32,
    /// `step` of the first row (failure windows start inside their trial).
    pub first_step: u32,
    pub rows: Vec<Row>,
    pub outcome: DataOutcome,
}

impl TrialRecord {
    /// Simulated seconds covered: from the first row to the last.
    pub fn duration(&self) -> f64 {
        let t = |r: &Row| r.features[0];
        match (self.rows.first(), self.rows.last()) {
            (Some(a), Some(b)) => t(b) - t(a),
            _ => 0.0,
        }
    }
}

/// The values of one column.
#[derive(Clone, Debug, PartialEq)]
pub enum Column {
    I32(Vec<i32>),
    F64(Vec<f64>),
    Bool(Vec<bool>),
    /// Optional UTF-8 strings.
    Str(Vec<Option<String>>),
}

impl Column {
    pub fn len(&self) -> usize {
        match self {
            Column::I32(v) => v.len(),
            Column::F64(v) => v.len(),
            Column::Bool(v) => v.len(),
            Column::Str(v) => v.len(),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn type_name(&self) -> &'static str {
        match self {
            Column::I32(_) => "INT32",
            Column::F64(_) => "DOUBLE",
            Column::Bool(_) => "BOOLEAN",
            Column::Str(_) => "BYTE_ARRAY",
        }
    }
    fn extend(&mut self, other: Column) {
        match (self, other) {
            (Column::I32(a), Column::I32(b)) => a.extend(b),
            (Column::F64(a), Column::F64(b)) => a.extend(b),
            (Column::Bool(a), Column::Bool(b)) => a.extend(b),
            (Column::Str(a), Column::Str(b)) => a.extend(b),
            _ => unreachable!("columns are checked against the schema before they are joined"),
        }
    }
}

/// Column names and types in file order for a vehicle with `wheels` wheels.
pub fn schema(wheels: usize) -> Vec<(String, &'static str)> {
    let mut s: Vec<(String, &'static str)> = ["trial", "world", "step"]
        .iter()
        .map(|n| (n.to_string(), "INT32"))
        .collect();
    s.extend(
        Feature::ALL
            .iter()
            .map(|f| (f.name().to_string(), "DOUBLE")),
    );
    s.push(("cmd_steering".into(), "DOUBLE"));
    s.push(("cmd_speed".into(), "DOUBLE"));
    for i in 0..wheels {
        s.push((format!("wheel{i}_class"), "INT32"));
        s.push((format!("wheel{i}_friction"), "DOUBLE"));
        s.push((format!("wheel{i}_soil"), "BOOLEAN"));
    }
    s.push(("last".into(), "BOOLEAN"));
    s.push(("outcome".into(), "BYTE_ARRAY"));
    s
}

/// Rows as named columns, in schema order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub columns: Vec<(String, Column)>,
}

impl Table {
    /// The rows of `trials` (in order) as columns.
    pub fn from_trials(trials: &[TrialRecord], wheels: usize) -> Table {
        let n: usize = trials.iter().map(|t| t.rows.len()).sum();
        let rows = || trials.iter().flat_map(|t| t.rows.iter());
        let per_row = |f: &dyn Fn(&TrialRecord, usize) -> i32| -> Vec<i32> {
            let mut v = Vec::with_capacity(n);
            for t in trials {
                v.extend((0..t.rows.len()).map(|k| f(t, k)));
            }
            v
        };
        let mut columns = vec![
            (
                "trial".to_string(),
                Column::I32(per_row(&|t, _| t.trial as i32)),
            ),
            (
                "world".to_string(),
                Column::I32(per_row(&|t, _| t.world as i32)),
            ),
            (
                "step".to_string(),
                Column::I32(per_row(&|t, k| (t.first_step as usize + k) as i32)),
            ),
        ];
        for (i, f) in Feature::ALL.iter().enumerate() {
            columns.push((
                f.name().to_string(),
                Column::F64(rows().map(|r| r.features[i]).collect()),
            ));
        }
        columns.push((
            "cmd_steering".into(),
            Column::F64(rows().map(|r| r.steering).collect()),
        ));
        columns.push((
            "cmd_speed".into(),
            Column::F64(rows().map(|r| r.speed).collect()),
        ));
        for w in 0..wheels {
            let at = |r: &Row| r.wheels.get(w).copied();
            columns.push((
                format!("wheel{w}_class"),
                Column::I32(
                    rows()
                        .map(|r| at(r).map_or(-1, |g| i32::from(g.class)))
                        .collect(),
                ),
            ));
            columns.push((
                format!("wheel{w}_friction"),
                Column::F64(
                    rows()
                        .map(|r| at(r).map_or(f64::NAN, |g| g.friction))
                        .collect(),
                ),
            ));
            columns.push((
                format!("wheel{w}_soil"),
                Column::Bool(rows().map(|r| at(r).is_some_and(|g| g.soil)).collect()),
            ));
        }
        let mut last = Vec::with_capacity(n);
        let mut outcome = Vec::with_capacity(n);
        for t in trials {
            for k in 0..t.rows.len() {
                let end = k + 1 == t.rows.len();
                last.push(end);
                outcome.push(end.then(|| t.outcome.name().to_string()));
            }
        }
        columns.push(("last".into(), Column::Bool(last)));
        columns.push(("outcome".into(), Column::Str(outcome)));
        Table { columns }
    }

    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.1.len())
    }

    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.0 == name).map(|c| &c.1)
    }

    /// A DOUBLE column by name (e.g. a feature).
    pub fn f64(&self, name: &str) -> Option<&[f64]> {
        match self.column(name)? {
            Column::F64(v) => Some(v),
            _ => None,
        }
    }

    /// An INT32 column by name.
    pub fn i32(&self, name: &str) -> Option<&[i32]> {
        match self.column(name)? {
            Column::I32(v) => Some(v),
            _ => None,
        }
    }

    pub fn bool(&self, name: &str) -> Option<&[bool]> {
        match self.column(name)? {
            Column::Bool(v) => Some(v),
            _ => None,
        }
    }

    pub fn outcomes(&self) -> Option<&[Option<String>]> {
        match self.column("outcome")? {
            Column::Str(v) => Some(v),
            _ => None,
        }
    }

    /// Appends `other`'s rows (same schema).
    pub fn append(&mut self, other: Table) {
        if self.columns.is_empty() {
            *self = other;
            return;
        }
        for ((_, a), (_, b)) in self.columns.iter_mut().zip(other.columns) {
            a.extend(b);
        }
    }
}

fn message_type(table: &Table) -> String {
    let mut s = String::from("message verti_data_step {\n");
    for (name, col) in &table.columns {
        let line = match col {
            Column::Str(_) => format!("  OPTIONAL BYTE_ARRAY {name} (UTF8);\n"),
            c => format!("  REQUIRED {} {name};\n", c.type_name()),
        };
        s.push_str(&line);
    }
    s.push('}');
    s
}

/// Writes `table` as one snappy-compressed row group. Written to a temporary name and
/// renamed, so an interrupted run never leaves a half-written file under the final name.
pub fn write_table(path: &Path, table: &Table) -> Result<()> {
    let err = |e: parquet::errors::ParquetError| DataError::file(path, e);
    let schema = Arc::new(parse_message_type(&message_type(table)).map_err(err)?);
    let props = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_max_row_group_size(table.rows().max(1))
        .build();
    let tmp = path.with_extension("parquet.partial");
    let file = std::fs::File::create(&tmp).map_err(|e| DataError::file(&tmp, e))?;
    let mut writer = SerializedFileWriter::new(file, schema, Arc::new(props)).map_err(err)?;
    let mut rg = writer.next_row_group().map_err(err)?;
    let mut columns = table.columns.iter();
    while let Some(mut out) = rg.next_column().map_err(err)? {
        let (_, col) = columns.next().expect("one column per schema field");
        match col {
            Column::I32(v) => out.typed::<Int32Type>().write_batch(v, None, None),
            Column::F64(v) => out.typed::<DoubleType>().write_batch(v, None, None),
            Column::Bool(v) => out.typed::<BoolType>().write_batch(v, None, None),
            Column::Str(v) => {
                let def: Vec<i16> = v.iter().map(|s| i16::from(s.is_some())).collect();
                let values: Vec<ByteArray> = v
                    .iter()
                    .flatten()
                    .map(|s| ByteArray::from(s.as_str()))
                    .collect();
                out.typed::<ByteArrayType>()
                    .write_batch(&values, Some(&def), None)
            }
        }
        .map_err(err)?;
        out.close().map_err(err)?;
    }
    rg.close().map_err(err)?;
    writer.close().map_err(err)?;
    std::fs::rename(&tmp, path).map_err(|e| DataError::file(path, e))
}

/// Reads a table written by [`write_table`], checking its columns against `expected` (names
/// and types, in order). Any damage (truncation, a bad footer or page) is an error naming the file.
pub fn read_table(path: &Path, expected: &[(String, &'static str)]) -> Result<Table> {
    read_table_at_most(path, expected, usize::MAX)
}

/// [`read_table`] of a file that may hold at most `max_rows` rows (what its manifest leaves
/// for it): a footer claiming more is refused before any column is read, so that a damaged row
/// count cannot size the reader's buffers.
pub fn read_table_at_most(
    path: &Path,
    expected: &[(String, &'static str)],
    max_rows: usize,
) -> Result<Table> {
    let file = std::fs::File::open(path).map_err(|e| DataError::file(path, e))?;
    // The parquet crate panics on some damaged files instead of returning an error (a
    // dictionary index past the dictionary in `rle.rs`, a negative offset or a bad thrift
    // field in the footer). Parquet pages carry no checksum to check first, and a manifest's
    // checksum may be absent (hand-made data) or rewritten with the file, so the decoder's
    // panic is caught here and reported as damage to this file. The decoding touches only
    // its own reader and the table it builds, both dropped on a panic, so nothing broken is
    // observed afterwards (hence `AssertUnwindSafe`). The panic message is still printed by
    // the process's panic hook: silencing it would need a process-wide hook.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        decode_table(path, file, expected, max_rows)
    }))
    .unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "the decoder failed".to_string());
        Err(DataError::file(
            path,
            format!("damaged Parquet data ({what})"),
        ))
    })
}

fn decode_table(
    path: &Path,
    file: std::fs::File,
    expected: &[(String, &'static str)],
    max_rows: usize,
) -> Result<Table> {
    let err = |e: parquet::errors::ParquetError| DataError::file(path, e);
    let reader = SerializedFileReader::new(file).map_err(err)?;
    let meta = reader.metadata();
    let fields = meta.file_metadata().schema_descr().columns().to_vec();
    let found: Vec<String> = fields.iter().map(|c| c.name().to_string()).collect();
    let want: Vec<&str> = expected.iter().map(|c| c.0.as_str()).collect();
    if found != want {
        let missing: Vec<&str> = want
            .iter()
            .filter(|w| !found.iter().any(|f| f == *w))
            .copied()
            .collect();
        return Err(DataError::file(
            path,
            format!(
                "columns do not match the dataset schema (missing: {missing:?}; found {} columns, expected {})",
                found.len(),
                want.len()
            ),
        ));
    }
    let mut table = Table::default();
    let mut rows: usize = 0;
    for g in 0..meta.num_row_groups() {
        let rg = reader.get_row_group(g).map_err(err)?;
        let claimed = rg.metadata().num_rows();
        let n = usize::try_from(claimed).map_err(|_| {
            DataError::file(
                path,
                format!("row group {g} claims {claimed} rows (a damaged footer)"),
            )
        })?;
        if rows.checked_add(n).is_none_or(|r| r > max_rows) {
            return Err(DataError::file(
                path,
                format!(
                    "row group {g} claims {claimed} rows, more than the {} the manifest leaves for this file (the file or the manifest is damaged, or the file was replaced)",
                    max_rows - rows
                ),
            ));
        }
        rows += n;
        let mut part = Table::default();
        for (c, (name, ty)) in expected.iter().enumerate() {
            let col = read_column(rg.get_column_reader(c).map_err(err)?, n).map_err(err)?;
            let col = col.ok_or_else(|| {
                DataError::file(path, format!("column {name} has an unexpected type"))
            })?;
            if col.type_name() != *ty || col.len() != n {
                return Err(DataError::file(
                    path,
                    format!(
                        "column {name}: {} values of type {}, expected {n} of {ty}",
                        col.len(),
                        col.type_name()
                    ),
                ));
            }
            part.columns.push((name.clone(), col));
        }
        table.append(part);
    }
    Ok(table)
}

/// Reads `n` records of one column chunk (None for a type the schema never uses).
fn read_column(reader: ColumnReader, n: usize) -> parquet::errors::Result<Option<Column>> {
    // `n` comes from the file's footer: reserve for at most a modest number of rows up front
    // (the vectors grow as values are read), so that a damaged count cannot ask for more
    // memory than exists
    let reserve = n.min(1 << 16);
    // read_records may stop at a page boundary; loop until the chunk is exhausted
    macro_rules! read_all {
        ($r:expr, $def:expr) => {{
            let mut values = Vec::with_capacity(reserve);
            let mut got = 0;
            while got < n {
                let (records, _, _) = $r.read_records(n - got, $def, None, &mut values)?;
                if records == 0 {
                    break;
                }
                got += records;
            }
            values
        }};
    }
    Ok(Some(match reader {
        ColumnReader::Int32ColumnReader(mut r) => Column::I32(read_all!(r, None)),
        ColumnReader::DoubleColumnReader(mut r) => Column::F64(read_all!(r, None)),
        ColumnReader::BoolColumnReader(mut r) => Column::Bool(read_all!(r, None)),
        ColumnReader::ByteArrayColumnReader(mut r) => {
            let mut def: Vec<i16> = Vec::with_capacity(reserve);
            let values: Vec<ByteArray> = read_all!(r, Some(&mut def));
            let mut values = values.into_iter();
            let mut out = Vec::with_capacity(def.len());
            for d in def {
                out.push(if d > 0 {
                    let v = values.next().ok_or_else(|| {
                        parquet::errors::ParquetError::General("missing string value".into())
                    })?;
                    Some(v.as_utf8()?.to_string())
                } else {
                    None
                });
            }
            Column::Str(out)
        }
        _ => return Ok(None),
    }))
}
