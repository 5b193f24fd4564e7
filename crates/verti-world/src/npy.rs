//! Reading and writing the NPY arrays of the world format, with errors that name the file.

use crate::error::{Result, WorldError};
use npyz::WriterBuilder;
use std::io::{BufReader, BufWriter, Write};
use std::path::Path;

/// A 2-D array read from an NPY file, converted to f64, row-major.
#[derive(Debug, Clone)]
pub struct Array2 {
    pub rows: usize,
    pub cols: usize,
    pub data: Vec<f64>,
    /// NumPy type string of the file, e.g. `<f4`.
    pub dtype: String,
}

/// Reads a 2-D numeric array (f4, f8, i1..i8, u1..u8; C or Fortran order).
pub fn read_array2(path: &Path) -> Result<Array2> {
    let file = std::fs::File::open(path).map_err(|e| WorldError::io(path, e))?;
    let npy = npyz::NpyFile::new(BufReader::new(file)).map_err(|e| {
        WorldError::invalid(path, "npy header", format!("not a valid NPY file: {e}"))
    })?;
    let shape = npy.shape().to_vec();
    if shape.len() != 2 {
        return Err(WorldError::invalid(
            path,
            "shape",
            format!("expected a 2-D array, found shape {shape:?}"),
        ));
    }
    let (rows, cols) = (shape[0] as usize, shape[1] as usize);
    let fortran = npy.order() == npyz::Order::Fortran;
    let dtype = match npy.dtype() {
        npyz::DType::Plain(ts) => ts.to_string(),
        other => {
            return Err(WorldError::invalid(
                path,
                "dtype",
                format!("unsupported dtype {other:?}"),
            ));
        }
    };
    let bad = |e: std::io::Error| {
        WorldError::invalid(
            path,
            "data",
            format!(
                "cannot read array data ({dtype_err}): {e}",
                dtype_err = "truncated or corrupt"
            ),
        )
    };
    let data: Vec<f64> = match dtype.trim_start_matches(['<', '>', '|', '=']) {
        "f4" => npy
            .into_vec::<f32>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        "f8" => npy.into_vec::<f64>().map_err(bad)?,
        "i1" => npy
            .into_vec::<i8>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        "i2" => npy
            .into_vec::<i16>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        "i4" => npy
            .into_vec::<i32>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        "i8" => npy
            .into_vec::<i64>()
            .map_err(bad)?
            .into_iter()
            .map(|v| v as f64)
            .collect(),
        "u1" => npy
            .into_vec::<u8>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        "u2" => npy
            .into_vec::<u16>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        "u4" => npy
            .into_vec::<u32>()
            .map_err(bad)?
            .into_iter()
            .map(f64::from)
            .collect(),
        other => {
            return Err(WorldError::invalid(
                path,
                "dtype",
                format!("unsupported element type `{other}`"),
            ));
        }
    };
    if data.len() != rows * cols {
        return Err(WorldError::invalid(
            path,
            "data",
            format!(
                "expected {} values for shape {rows}x{cols}, found {}",
                rows * cols,
                data.len()
            ),
        ));
    }
    let data = if fortran {
        let mut c = vec![0.0; data.len()];
        for r in 0..rows {
            for k in 0..cols {
                c[r * cols + k] = data[k * rows + r];
            }
        }
        c
    } else {
        data
    };
    Ok(Array2 {
        rows,
        cols,
        data,
        dtype,
    })
}

fn write_with<T: npyz::AutoSerialize + Copy>(
    path: &Path,
    rows: usize,
    cols: usize,
    data: &[T],
) -> Result<()> {
    let file = std::fs::File::create(path).map_err(|e| WorldError::io(path, e))?;
    let mut buf = BufWriter::new(file);
    {
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&[rows as u64, cols as u64])
            .writer(&mut buf)
            .begin_nd()
            .map_err(|e| WorldError::io(path, e))?;
        w.extend(data.iter().copied())
            .map_err(|e| WorldError::io(path, e))?;
        w.finish().map_err(|e| WorldError::io(path, e))?;
    }
    buf.flush().map_err(|e| WorldError::io(path, e))
}

/// Writes a row-major f32 array.
pub fn write_f32(path: &Path, rows: usize, cols: usize, data: &[f32]) -> Result<()> {
    write_with(path, rows, cols, data)
}

/// Writes a row-major i32 array.
pub fn write_i32(path: &Path, rows: usize, cols: usize, data: &[i32]) -> Result<()> {
    write_with(path, rows, cols, data)
}
