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

/// Writes `card` (YAML text) as `NAME.yaml` with `floats` zero weights beside it, the card's
/// count and digest filled in so that only the layer sizes can be wrong.
fn crafted(dir: &std::path::Path, name: &str, card: &str, floats: usize) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let bytes = vec![0u8; 4 * floats];
    std::fs::write(dir.join(format!("{name}.bin")), &bytes).unwrap();
    let text = format!(
        "name: {name}\nformat: 1\nsummary: crafted\n{card}normalisation: none\n\
         weights:\n  file: {name}.bin\n  floats: {floats}\n  fnv1a64: {:016x}\n\
         training:\n  data: ''\n  command: ''\n  seed: 0\n  steps: 0\n  wall_time_s: 0.0\n  \
         verti_version: test\n  settings: ''\n",
        verti_nn::card::fnv1a64(&bytes)
    );
    let path = dir.join(format!("{name}.yaml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Layer sizes whose products overflow `usize` used to wrap (release) or panic on overflow
/// (debug); a wrapped count could even match the weight file and pass the size and digest
/// checks, leaving `forward` to slice out of bounds. Each is now refused, naming the card and
/// the field.
#[test]
fn overflowing_layer_sizes_are_refused_naming_the_field() {
    let dir = std::env::temp_dir().join(format!("verti-nn-overflow-{}", std::process::id()));
    let big = "- !conv_transpose2d\n  in_channels: 1\n  out_channels: 1\n  kernel: 2147483648\n  \
               stride: 1\n  padding: 1073741824\n  output_padding: 1\n";
    let four_transposes = format!("input: [1, 1, 1]\nlayers:\n{}", big.repeat(4));
    let cases: [(&str, &str, usize, &str); 8] = [
        // 2^63 x 2 weights wrap to 0: the count is the 2 biases (refused for its input's size)
        (
            "linear",
            "input: 9223372036854775808\nlayers:\n- !linear\n  inputs: 9223372036854775808\n  outputs: 2\n",
            2,
            "field input",
        ),
        // a small input, and 4 x 2^62 weights
        (
            "outputs",
            "input: 4\nlayers:\n- !linear\n  inputs: 4\n  outputs: 4611686018427387904\n",
            4,
            "field layers[0]: the parameter count overflows at this linear layer",
        ),
        // 2^62 x 4 x 1 x 1 wraps to 0, and so does the input's length 2^62 x 4 x 1
        (
            "conv",
            "input: [4611686018427387904, 4, 1]\nlayers:\n- !conv2d\n  in_channels: 4611686018427387904\n  out_channels: 4\n  kernel: 1\n  stride: 1\n  padding: 0\n",
            4,
            "field input",
        ),
        // four layers of 2^62 + 1 parameters each (a 2^31 kernel, padded back to a 1 x 1
        // output): the total wraps to 4, so before the fix this card passed the size and
        // digest checks of a 16-byte weight file and `forward` sliced out of bounds
        (
            "sum",
            &four_transposes,
            4,
            "field layers[3]: the parameter count overflows",
        ),
        // a side (n - 1) stride + kernel that overflows
        (
            "transpose",
            "input: [1, 2, 2]\nlayers:\n- !conv_transpose2d\n  in_channels: 1\n  out_channels: 1\n  kernel: 1\n  stride: 18446744073709551615\n  padding: 0\n  output_padding: 0\n",
            2,
            "layers[0]",
        ),
        // an empty image (side 0) reaching the transposed convolution's (side - 1)
        (
            "empty",
            "input: [1, 0, 2]\nlayers:\n- !conv_transpose2d\n  in_channels: 1\n  out_channels: 1\n  kernel: 1\n  stride: 1\n  padding: 0\n  output_padding: 0\n",
            2,
            "input",
        ),
        // a reshape to a shape whose length overflows
        (
            "reshape",
            "input: 4\nlayers:\n- !reshape\n  shape: [4294967296, 4294967296, 4]\n",
            0,
            "layers[0]",
        ),
        // a stride that makes a huge activation from a tiny one (memory, not overflow)
        (
            "huge",
            "input: [1, 2, 2]\nlayers:\n- !conv_transpose2d\n  in_channels: 1\n  out_channels: 1\n  kernel: 1\n  stride: 4294967296\n  padding: 0\n  output_padding: 0\n",
            2,
            "layers[0]",
        ),
    ];
    for (name, card, floats, field) in cases {
        let path = crafted(&dir, name, card, floats);
        let r = std::panic::catch_unwind(|| Network::load(&path));
        let Ok(r) = r else {
            panic!("{name}: loading panicked")
        };
        let e = match r {
            Ok(net) => panic!(
                "{name}: a card with overflowing sizes loaded: {}",
                net.describe()
            ),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains(&format!("{name}.yaml")) && e.contains(field),
            "{name}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
