//! `verti_nn::embed!` on a composite card (a kinodynamic model lists its networks as parts):
//! the parts come with it, and a part that was not compiled in is named in the error.

use verti_nn::embed::Embedded;

const TAL: Embedded = verti_nn::embed!("tal-v1", ["tal-v1.encoder", "tal-v1.gate"]);

#[test]
fn a_composite_card_brings_its_parts() {
    assert!(TAL.weights.is_none());
    let gate = TAL.part("tal-v1.gate.yaml").unwrap();
    assert_eq!(gate.network().unwrap().card().name, "tal-v1.gate");
    let e = TAL.part("tal-v1.dynamics.yaml").unwrap_err().to_string();
    assert!(
        e.starts_with(
            "crates/verti-kino/models/tal-v1.yaml: part tal-v1.dynamics.yaml is not compiled in"
        ) && e.contains("tal-v1.encoder, tal-v1.gate"),
        "{e}"
    );
    let e = TAL.network().unwrap_err().to_string();
    assert!(
        e.starts_with("crates/verti-kino/models/tal-v1.yaml: "),
        "{e}"
    );
}
