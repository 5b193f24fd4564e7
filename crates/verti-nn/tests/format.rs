//! The model file format: round trip, and bad files named with their problem.

use std::collections::BTreeMap;
use verti_nn::{LayerSpec, ModelCard, Network, Shape, TrainingInfo, WeightsInfo};

fn card() -> ModelCard {
    ModelCard {
        name: "tiny".into(),
        format: verti_nn::card::CARD_FORMAT,
        summary: "a test network".into(),
        input: Shape::Flat(3),
        layers: vec![
            LayerSpec::Linear {
                inputs: 3,
                outputs: 4,
            },
            LayerSpec::Tanh,
            LayerSpec::Linear {
                inputs: 4,
                outputs: 2,
            },
        ],
        normalisation: "none".into(),
        weights: WeightsInfo {
            file: "tiny.bin".into(),
            floats: 0,
            fnv1a64: String::new(),
        },
        training: TrainingInfo {
            data: "none".into(),
            command: "none".into(),
            seed: 1,
            steps: 0,
            wall_time_s: 0.0,
            verti_version: "test".into(),
            settings: String::new(),
        },
        metrics: BTreeMap::from([("loss".to_string(), 0.5)]),
        constants: BTreeMap::new(),
    }
}

fn params() -> Vec<f32> {
    (0..26).map(|i| (i as f32 - 13.0) / 10.0).collect()
}

#[test]
fn a_saved_network_loads_back_identically() {
    let net = Network::from_params(card(), &params()).unwrap();
    let dir = std::env::temp_dir().join(format!("verti-nn-format-{}", std::process::id()));
    let path = dir.join("tiny.yaml");
    net.save(&path).unwrap();
    let back = Network::load(&path).unwrap();
    assert_eq!(back.card(), net.card());
    assert_eq!(back.params(), net.params());
    let x = [0.3, -0.7, 1.1];
    assert_eq!(back.forward(&x), net.forward(&x));
    assert_eq!(net.output_shape(), Shape::Flat(2));
    assert_eq!(net.weight_bytes(), 26 * 4);

    // a truncated weight file is caught, naming the card and the file
    let bytes = std::fs::read(dir.join("tiny.bin")).unwrap();
    std::fs::write(dir.join("tiny.bin"), &bytes[..bytes.len() - 4]).unwrap();
    let e = Network::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("tiny.yaml") && e.contains("tiny.bin") && e.contains("truncated"),
        "{e}"
    );
    // so is a file of the right size with other values
    let mut other = bytes.clone();
    other[0] ^= 1;
    std::fs::write(dir.join("tiny.bin"), &other).unwrap();
    let e = Network::load(&path).unwrap_err().to_string();
    assert!(e.contains("digest"), "{e}");
    // a card with a bad field names it
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("inputs: 4", "inputs: 5")).unwrap();
    std::fs::write(dir.join("tiny.bin"), &bytes).unwrap();
    let e = Network::load(&path).unwrap_err().to_string();
    assert!(e.contains("layers[2]"), "{e}");
    std::fs::write(&path, "name: [").unwrap();
    let e = Network::load(&path).unwrap_err().to_string();
    assert!(e.contains("not a model card"), "{e}");
    let e = Network::load(&dir.join("missing.yaml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.yaml"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn non_finite_weights_are_refused() {
    let mut p = params();
    p[5] = f32::NAN;
    let e = Network::from_params(card(), &p).unwrap_err().to_string();
    assert!(e.contains("non-finite value at index 5"), "{e}");
}
