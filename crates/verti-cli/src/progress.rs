//! Progress bars for long work (hidden automatically when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};

pub fn bar(len: u64, what: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    pb.set_style(
        ProgressStyle::with_template(
            "{msg:>12} [{bar:40.cyan/blue}] {pos}/{len} {elapsed_precise} ETA {eta}",
        )
        .expect("static template is valid")
        .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// A counter for work of unknown length (`loading 37 worlds 00:00:02`): a bar would show `N/0`.
pub fn counter(what: &str, unit: &str) -> ProgressBar {
    let pb = ProgressBar::new_spinner();
    pb.set_style(
        ProgressStyle::with_template(&format!("{{msg:>12}} {{pos}} {unit} {{elapsed_precise}}"))
            .expect("the template has only known keys"),
    );
    pb.set_message(what.to_string());
    pb
}
