//! Reading and writing the NPY arrays of the world format, with errors that name the file.

use crate::error::{Result, WorldError};
use npyz::WriterBuilder;
use std::io::{BufWriter, Write};
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

/// Largest array the reader accepts: a world grid of 4097 x 4097 vertices.
pub const MAX_ELEMENTS: usize = 4097 * 4097;

/// Reads a 2-D numeric array (f4, f8, i1..i8, u1..u8; either byte order; C or Fortran order).
///
/// The header is parsed here rather than by npyz, because npyz trusts it: a corrupt shape made
/// it multiply sizes until they overflowed, or reserve memory for billions of elements, and a
/// corrupt header length made it allocate up to 4 GiB before reading anything. Here every size
/// is checked against the file before memory is reserved.
pub fn read_array2(path: &Path) -> Result<Array2> {
    // header (at most 64 KiB in practice) plus the largest array of 8-byte elements
    let cap = 65_536 + 8 * MAX_ELEMENTS as u64;
    let bytes = crate::input::read_capped(path, cap, "an NPY array")?;
    parse_array2(&bytes).map_err(|(field, problem)| WorldError::invalid(path, field, problem))
}

/// The element types the reader knows: NumPy kind and size.
fn element_size(kind: u8, size: u8) -> Option<usize> {
    match (kind, size) {
        (b'f', b'4' | b'8') | (b'i' | b'u', b'1' | b'2' | b'4' | b'8') => {
            Some(usize::from(size - b'0'))
        }
        _ => None,
    }
}

/// Parses NPY bytes; errors are (field, problem).
fn parse_array2(bytes: &[u8]) -> std::result::Result<Array2, (&'static str, String)> {
    let bad_header = |p: String| ("npy header", p);
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad_header(
            "not a valid NPY file (no \\x93NUMPY magic)".into(),
        ));
    }
    let (header_len, start) = match bytes[6] {
        1 => (
            usize::from(u16::from_le_bytes([bytes[8], bytes[9]])),
            10usize,
        ),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(bad_header(format!("unsupported NPY version {v}"))),
    };
    let end = start
        .checked_add(header_len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| {
            bad_header(format!(
                "header length {header_len} runs past the end of the file ({} bytes)",
                bytes.len()
            ))
        })?;
    let header = std::str::from_utf8(&bytes[start..end])
        .map_err(|_| bad_header("the header is not text".into()))?;
    let descr = header_value(header, "descr")
        .ok_or_else(|| bad_header("no 'descr' entry".into()))?
        .trim_matches(|c| c == '\'' || c == '"');
    let fortran = match header_value(header, "fortran_order") {
        Some("True") => true,
        Some("False") => false,
        other => {
            return Err(bad_header(format!(
                "'fortran_order' must be True or False, found {other:?}"
            )));
        }
    };
    let shape = header_value(header, "shape").ok_or_else(|| bad_header("no 'shape'".into()))?;
    let dims: Vec<&str> = shape
        .trim_start_matches('(')
        .trim_end_matches(')')
        .split(',')
        .map(str::trim)
        .filter(|d| !d.is_empty())
        .collect();
    let dims = dims
        .iter()
        .map(|d| d.parse::<usize>())
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|_| ("shape", format!("{shape} is not a tuple of sizes")))?;
    let [rows, cols] = dims[..] else {
        return Err((
            "shape",
            format!("expected a 2-D array, found shape {shape}"),
        ));
    };
    let count = rows
        .checked_mul(cols)
        .filter(|&c| c <= MAX_ELEMENTS)
        .ok_or_else(|| {
            (
                "shape",
                format!("{rows}x{cols} is larger than any world grid (at most 4097x4097)"),
            )
        })?;
    let d = descr.as_bytes();
    let (order, kind, size) = match d {
        [o @ (b'<' | b'>' | b'|' | b'='), k, s] => (*o, *k, *s),
        _ => (b'?', 0, 0),
    };
    let item = element_size(kind, size)
        .ok_or_else(|| ("dtype", format!("unsupported element type `{descr}`")))?;
    let data = &bytes[end..];
    if data.len() != count * item {
        return Err((
            "data",
            format!(
                "expected {} bytes of data for shape {rows}x{cols} of `{descr}`, found {} (truncated or corrupt)",
                count * item,
                data.len()
            ),
        ));
    }
    let big = order == b'>' || (order == b'=' && cfg!(target_endian = "big"));
    let values: Vec<f64> = data
        .chunks_exact(item)
        .map(|chunk| {
            let mut b = [0u8; 8];
            b[..item].copy_from_slice(chunk);
            if big {
                b[..item].reverse();
            }
            decode(kind, item, b)
        })
        .collect();
    let values = if fortran {
        let mut c = vec![0.0; count];
        for r in 0..rows {
            for k in 0..cols {
                c[r * cols + k] = values[k * rows + r];
            }
        }
        c
    } else {
        values
    };
    Ok(Array2 {
        rows,
        cols,
        data: values,
        dtype: descr.to_string(),
    })
}

/// One little-endian element (in the first `size` bytes of `b`) as f64.
fn decode(kind: u8, size: usize, b: [u8; 8]) -> f64 {
    match (kind, size) {
        (b'f', 4) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        (b'f', _) => f64::from_le_bytes(b),
        (b'u', _) => u64::from_le_bytes(b) as f64,
        // sign-extend from the element's width
        (_, _) => {
            let shift = 64 - 8 * size as u32;
            ((i64::from_le_bytes(b) << shift) >> shift) as f64
        }
    }
}

/// The text of `'key': VALUE` in an NPY header dict: a quoted string, a parenthesised tuple
/// or a bare word.
fn header_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header
        .find(&format!("'{key}'"))
        .or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = header[at + key.len() + 2..]
        .trim_start()
        .strip_prefix(':')?;
    let rest = rest.trim_start();
    let end = match rest.chars().next()? {
        '(' => rest.find(')')? + 1,
        q @ ('\'' | '"') => rest[1..].find(q)? + 2,
        _ => rest.find([',', '}']).unwrap_or(rest.len()),
    };
    Some(rest[..end].trim())
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

#[cfg(test)]
mod tests {
    use super::*;

    /// An NPY v1 file with the given header dict and data bytes.
    fn npy(dict: &str, data: &[u8]) -> Vec<u8> {
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
        out.extend_from_slice(dict.as_bytes());
        out.extend_from_slice(data);
        out
    }

    #[test]
    fn reads_what_it_writes_and_numpy_variants() {
        let dir = std::env::temp_dir().join(format!("verti-npy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_f32(&dir.join("f.npy"), 2, 3, &[1.0, -2.5, 3.0, 4.0, 5.0, 6.0]).unwrap();
        let a = read_array2(&dir.join("f.npy")).unwrap();
        assert_eq!((a.rows, a.cols, a.dtype.as_str()), (2, 3, "<f4"));
        assert_eq!(a.data, vec![1.0, -2.5, 3.0, 4.0, 5.0, 6.0]);
        write_i32(&dir.join("i.npy"), 1, 2, &[-7, 9]).unwrap();
        assert_eq!(
            read_array2(&dir.join("i.npy")).unwrap().data,
            vec![-7.0, 9.0]
        );
        std::fs::remove_dir_all(dir).ok();

        // big-endian 16-bit ints in Fortran order
        let bytes = npy(
            "{'descr': '>i2', 'fortran_order': True, 'shape': (2, 2), }\n",
            &[0, 1, 0xff, 0xfe, 0, 3, 0, 4],
        );
        let a = parse_array2(&bytes).unwrap();
        assert_eq!(a.data, vec![1.0, 3.0, -2.0, 4.0]);
    }

    #[test]
    fn corrupt_headers_are_refused_before_memory_is_reserved() {
        let cases: [(Vec<u8>, &str); 7] = [
            (b"not npy".to_vec(), "magic"),
            (
                npy(
                    "{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999, 99999999999), }",
                    &[],
                ),
                "larger than any world grid",
            ),
            (
                npy(
                    "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }",
                    &[],
                ),
                "2-D",
            ),
            (
                npy(
                    "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), }",
                    &[0; 15],
                ),
                "expected 16 bytes",
            ),
            (
                npy(
                    "{'descr': '<U8', 'fortran_order': False, 'shape': (1, 1), }",
                    &[0; 32],
                ),
                "unsupported element type",
            ),
            (
                npy(
                    "{'descr': '<f4', 'fortran_order': maybe, 'shape': (1, 1), }",
                    &[0; 4],
                ),
                "fortran_order",
            ),
            (
                // version 2 with a 4 GiB header length
                b"\x93NUMPY\x02\x00\xff\xff\xff\xff{}".to_vec(),
                "runs past the end",
            ),
        ];
        for (bytes, want) in cases {
            let (field, problem) = parse_array2(&bytes).unwrap_err();
            assert!(problem.contains(want), "{field}: {problem} (wanted {want})");
        }
    }
}
