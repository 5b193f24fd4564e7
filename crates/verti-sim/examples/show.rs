//! Prints the summary of every built-in vehicle (what `verti vehicle show NAME` prints).
fn main() {
    for spec in verti_sim::vehicles::all_builtin() {
        println!("{}\n", spec.summary());
    }
}
