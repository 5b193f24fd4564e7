//! Checks of output paths, made before any work so a typo costs nothing.
//!
//! verti never creates a missing parent directory of an output: `--out reslts/run1/map.png`
//! with a mistyped directory is refused instead of growing a tree in the wrong place. An
//! output directory itself (a results or report directory, a world set) may be created; its
//! parent must exist. A file output must carry the extension of a format verti writes, since
//! the bytes are that format whatever the name says.

use std::path::Path;

/// The image formats verti writes.
pub const IMAGE_FORMATS: &[&str] = &["png"];

/// Why `path` cannot be an output file in one of `formats` (extensions without the dot,
/// matched without regard to case), or `Ok` when it can.
pub fn check_output_file(path: &Path, formats: &[&str]) -> Result<(), String> {
    let supported = || {
        formats
            .iter()
            .map(|f| format!(".{f}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match path.extension().and_then(|e| e.to_str()) {
        None => {
            return Err(format!(
                "the file name has no extension; supported: {}",
                supported()
            ));
        }
        Some(ext) if !formats.iter().any(|f| f.eq_ignore_ascii_case(ext)) => {
            return Err(format!(
                "`.{ext}` is not a supported format; supported: {}",
                supported()
            ));
        }
        Some(_) => {}
    }
    if path.is_dir() {
        return Err("it is a directory".into());
    }
    check_parent(path)
}

/// Why `path` cannot be an output directory, or `Ok` when it can: it is a directory or can be
/// created as one inside an existing directory.
pub fn check_output_dir(path: &Path) -> Result<(), String> {
    if path.as_os_str().is_empty() {
        return Err("the path is empty".into());
    }
    if path.exists() && !path.is_dir() {
        return Err("it exists and is not a directory".into());
    }
    check_parent(path)
}

/// The directory `path` would be written into exists.
fn check_parent(path: &Path) -> Result<(), String> {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() && !p.is_dir() => Err(if p.exists() {
            format!("{} is not a directory", p.display())
        } else {
            format!("directory {} does not exist", p.display())
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_need_a_supported_extension_and_an_existing_directory() {
        let dir = std::env::temp_dir();
        assert_eq!(check_output_file(&dir.join("a.png"), IMAGE_FORMATS), Ok(()));
        assert_eq!(check_output_file(&dir.join("a.PNG"), IMAGE_FORMATS), Ok(()));
        assert_eq!(check_output_file(Path::new("a.png"), IMAGE_FORMATS), Ok(()));
        assert_eq!(
            check_output_file(&dir.join("a.jpg"), IMAGE_FORMATS),
            Err("`.jpg` is not a supported format; supported: .png".into())
        );
        assert_eq!(
            check_output_file(&dir.join("a"), IMAGE_FORMATS),
            Err("the file name has no extension; supported: .png".into())
        );
        let missing = dir.join("verti-no-such-dir-7f3a").join("sub");
        assert_eq!(
            check_output_file(&missing.join("a.png"), IMAGE_FORMATS),
            Err(format!("directory {} does not exist", missing.display()))
        );
        assert!(!missing.exists());
    }

    #[test]
    fn directories_may_be_created_only_inside_an_existing_one() {
        let dir = std::env::temp_dir();
        assert_eq!(check_output_dir(&dir.join("verti-new-out")), Ok(()));
        assert_eq!(check_output_dir(Path::new("report")), Ok(()));
        let missing = dir.join("verti-no-such-dir-7f3a");
        assert_eq!(
            check_output_dir(&missing.join("run")),
            Err(format!("directory {} does not exist", missing.display()))
        );
        assert!(check_output_dir(Path::new("")).is_err());
    }
}
