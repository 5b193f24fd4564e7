//! Per-step trial logs in Parquet: one file per trial, one row per inner step (10 ms by
//! default), with the vehicle state and the driver inputs. Kept in its own crate because the
//! Parquet dependency is large and most of verti does not need it.
//!
//! Columns: `task` (INT32), then one DOUBLE column per feature of
//! [`verti_bench::features::STEP_LOG`], named as the feature schema names them: `t` \[s\], `x`,
//! `y`, `z` \[m, chassis reference point, world frame\], `roll`, `pitch`, `yaw` \[rad\], `vx`, `vy`,
//! `vz` \[m/s, body frame\], `wx`, `wy`, `wz` \[rad/s, body frame\], `throttle`, `brake`,
//! `steering` \[driver inputs\].
//! File metadata (key/value): `verti.task`, `verti.world`, `verti.system`, `verti.vehicle`,
//! `verti.outcome`.

use parquet::basic::Compression;
use parquet::data_type::{DoubleType, Int32Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::record::RowAccessor;
use parquet::schema::parser::parse_message_type;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_bench::TrialResult;
use verti_bench::episode::StepRecord;
use verti_bench::features::{STEP_LOG, names_of};

#[derive(Debug, thiserror::Error)]
pub enum LogError {
    #[error("{path}: {message}")]
    Parquet { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The names of the DOUBLE columns, in file order.
pub fn columns() -> Vec<&'static str> {
    names_of(&STEP_LOG)
}

fn schema() -> String {
    let mut s = String::from("message verti_step {\n  REQUIRED INT32 task;\n");
    for c in columns() {
        s.push_str(&format!("  REQUIRED DOUBLE {c};\n"));
    }
    s.push('}');
    s
}

/// File name of a trial's log inside a steps directory.
pub fn log_file_name(task: u32) -> String {
    format!("task-{task:05}.parquet")
}

/// Writes one trial's steps (snappy-compressed, one row group).
pub fn write_steps(
    path: &Path,
    result: &TrialResult,
    steps: &[StepRecord],
) -> Result<(), LogError> {
    let err = |e: parquet::errors::ParquetError| LogError::Parquet {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let schema = Arc::new(parse_message_type(&schema()).map_err(err)?);
    let meta = [
        ("verti.task", result.task.to_string()),
        ("verti.world", result.world_name.clone()),
        ("verti.system", result.system.clone()),
        ("verti.vehicle", result.vehicle.clone()),
        ("verti.outcome", result.outcome.name().to_string()),
    ];
    let props = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_key_value_metadata(Some(
            meta.iter()
                .map(|(k, v)| KeyValue::new(k.to_string(), v.clone()))
                .collect(),
        ))
        .build();
    // write to a temporary name and rename, so a kill never leaves a half-written log
    let tmp = path.with_extension("parquet.partial");
    let file = std::fs::File::create(&tmp).map_err(|e| LogError::Io {
        path: tmp.clone(),
        source: e,
    })?;
    let mut writer = SerializedFileWriter::new(file, schema, Arc::new(props)).map_err(err)?;
    let mut rg = writer.next_row_group().map_err(err)?;
    let tasks = vec![result.task as i32; steps.len()];
    let mut column = 0usize;
    while let Some(mut col) = rg.next_column().map_err(err)? {
        if column == 0 {
            col.typed::<Int32Type>()
                .write_batch(&tasks, None, None)
                .map_err(err)?;
        } else {
            let values: Vec<f64> = steps.iter().map(|s| s.values[column - 1]).collect();
            col.typed::<DoubleType>()
                .write_batch(&values, None, None)
                .map_err(err)?;
        }
        col.close().map_err(err)?;
        column += 1;
    }
    rg.close().map_err(err)?;
    writer.close().map_err(err)?;
    std::fs::rename(&tmp, path).map_err(|e| LogError::Io {
        path: path.to_path_buf(),
        source: e,
    })
}

/// Reads a log back (for tests and tools).
pub fn read_steps(path: &Path) -> Result<(u32, Vec<StepRecord>), LogError> {
    let err = |e: parquet::errors::ParquetError| LogError::Parquet {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(|e| LogError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    let reader = SerializedFileReader::new(file).map_err(err)?;
    let mut task = 0u32;
    let mut out = Vec::new();
    for row in reader.get_row_iter(None).map_err(err)? {
        let row = row.map_err(err)?;
        task = row.get_int(0).map_err(err)? as u32;
        let mut step = StepRecord {
            values: [0.0; STEP_LOG.len()],
        };
        for (i, v) in step.values.iter_mut().enumerate() {
            *v = row.get_double(i + 1).map_err(err)?;
        }
        out.push(step);
    }
    Ok((task, out))
}
