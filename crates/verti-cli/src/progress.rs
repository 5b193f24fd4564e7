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
