//! Output arguments, checked while the command line is read so that a typo fails at once,
//! before minutes of work: pictures must be `.png` files, and no command creates a missing
//! parent directory (see `verti_core::output`).

use clap::Command;
use std::path::{Path, PathBuf};
use verti_core::output::{IMAGE_FORMATS, check_output_dir, check_output_file};
use verti_world::WorldError;

/// A picture to write: a `.png` file in an existing directory.
pub fn png_file(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    check_output_file(&path, IMAGE_FORMATS)?;
    Ok(path)
}

/// A replay's output: a `.png` picture, or with `--3d` an `.html` page or the `.json` recording,
/// in an existing directory.
pub fn replay_file(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    check_output_file(&path, &["png", "html", "json"])?;
    Ok(path)
}

/// A directory to write into: an existing one, or a new one inside an existing directory.
pub fn out_dir(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    check_output_dir(&path)?;
    Ok(path)
}

/// Checks that an output file can be written: a picture format verti writes, in a directory
/// that exists. Missing directories are not created (a typo should not grow a tree).
pub fn ensure_parent(path: &Path) -> Result<(), WorldError> {
    verti_core::output::check_output_file(path, verti_core::output::IMAGE_FORMATS)
        .map_err(|problem| WorldError::Argument(format!("{}: {problem}", path.display())))
}

/// Puts the checks on the output arguments of `verti eval`, `verti replay` and `verti
/// report`, whose argument structs live in `eval_cmd` (the `world` commands declare theirs in
/// place).
pub fn check_outputs(cli: Command) -> Command {
    cli.mut_subcommand("eval", |c| c.mut_arg("out", |a| a.value_parser(out_dir)))
        .mut_subcommand("replay", |c| {
            c.mut_arg("out", |a| a.value_parser(replay_file))
        })
        .mut_subcommand("report", |c| c.mut_arg("out", |a| a.value_parser(out_dir)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn every_checked_argument_exists() {
        // mut_arg on a name that does not exist panics; build the command as main does
        check_outputs(crate::Cli::command()).debug_assert();
    }
}
