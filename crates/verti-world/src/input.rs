//! Opening and reading input files with errors that say what is actually wrong.
//!
//! `std::fs` reports a directory, a symbolic link loop and a dangling link as a bare OS error
//! (or, for a directory, not at all until the first read), and callers that probe with
//! `Path::is_file` first turn all of them into "not a world directory". Everything that reads a
//! world, a set or a vehicle goes through here instead, so the message names the path and the
//! real problem, and no read can grow without bound.

use crate::error::{Result, WorldError};
use std::io::{ErrorKind, Read};
use std::path::Path;

/// Why `path` cannot be opened as a file, in words; `None` when it can (as far as metadata
/// tells). `what` names the file's role, e.g. "the world manifest".
pub fn unreadable_reason(path: &Path, what: &str) -> Option<std::io::Error> {
    let link = std::fs::symlink_metadata(path);
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Some(std::io::Error::new(
            ErrorKind::IsADirectory,
            format!("is a directory, where {what} (a file) should be"),
        )),
        Ok(_) => None,
        // metadata follows links: a link whose target fails is a loop or dangles
        Err(e) if link.as_ref().is_ok_and(|l| l.file_type().is_symlink()) => {
            let target = std::fs::read_link(path)
                .map(|t| t.display().to_string())
                .unwrap_or_else(|_| "?".into());
            Some(if e.kind() == ErrorKind::NotFound {
                std::io::Error::new(
                    ErrorKind::NotFound,
                    format!("is a symbolic link to `{target}`, which does not exist"),
                )
            } else {
                std::io::Error::new(
                    e.kind(),
                    format!(
                        "is a symbolic link (to `{target}`) that cannot be followed: a symbolic link loop? ({e})"
                    ),
                )
            })
        }
        Err(e) if e.kind() == ErrorKind::PermissionDenied => Some(std::io::Error::new(
            e.kind(),
            format!("permission denied: cannot read {what} ({e})"),
        )),
        Err(e) => Some(e),
    }
}

/// Reads at most `cap` bytes of a file. A larger file is refused before it is read (and a file
/// that grows while it is read, or a device without a size, is cut off at `cap + 1` bytes and
/// refused), so a wrong path never makes verti read gigabytes. `what` names the file's role.
pub fn read_capped(path: &Path, cap: u64, what: &str) -> Result<Vec<u8>> {
    if let Some(e) = unreadable_reason(path, what) {
        return Err(WorldError::io(path, e));
    }
    let file = std::fs::File::open(path).map_err(|e| WorldError::io(path, e))?;
    let too_big = |size: u64| {
        WorldError::invalid(
            path,
            "size",
            format!(
                "the file is {} but {what} may be at most {}",
                human_bytes(size),
                human_bytes(cap)
            ),
        )
    };
    if let Ok(m) = file.metadata()
        && m.len() > cap
    {
        return Err(too_big(m.len()));
    }
    let mut bytes = Vec::new();
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| WorldError::io(path, e))?;
    if bytes.len() as u64 > cap {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// `1.5 MiB`, `300 KiB`, `12 bytes`.
pub fn human_bytes(n: u64) -> String {
    const KIB: u64 = 1024;
    if n >= KIB * KIB {
        format!("{:.1} MiB", n as f64 / (KIB * KIB) as f64)
    } else if n >= KIB {
        format!("{:.1} KiB", n as f64 / KIB as f64)
    } else {
        format!("{n} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("verti-input-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn directories_and_links_are_named_for_what_they_are() {
        let d = tmp("kinds");
        std::fs::create_dir(d.join("dir.yaml")).unwrap();
        let e = read_capped(&d.join("dir.yaml"), 100, "the world manifest")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("dir.yaml") && e.contains("is a directory"),
            "{e}"
        );
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.join("a"), d.join("b")).unwrap();
            std::os::unix::fs::symlink(d.join("b"), d.join("a")).unwrap();
            let e = read_capped(&d.join("a"), 100, "x").unwrap_err().to_string();
            assert!(e.contains("symbolic link loop"), "{e}");
            std::os::unix::fs::symlink(d.join("gone"), d.join("dangling")).unwrap();
            let e = read_capped(&d.join("dangling"), 100, "x")
                .unwrap_err()
                .to_string();
            assert!(e.contains("does not exist") && e.contains("gone"), "{e}");
        }
        std::fs::write(d.join("big"), vec![b'x'; 101]).unwrap();
        let e = read_capped(&d.join("big"), 100, "a test file")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("101 bytes") && e.contains("at most 100 bytes"),
            "{e}"
        );
        assert_eq!(read_capped(&d.join("big"), 101, "x").unwrap().len(), 101);
        std::fs::remove_dir_all(d).ok();
    }
}
