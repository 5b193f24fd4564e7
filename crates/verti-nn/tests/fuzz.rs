//! Bounded property tests (hardening issue, item 9): no model card or weight file may panic.
//! Real cards and weights (a tiny network written by this crate with every layer kind, and a
//! small shipped decoder) are mutated the way `verti-world/tests/fuzz.rs` mutates worlds
//! (bytes flipped, inserted, deleted, the file cut short, numbers swapped for extreme ones)
//! and loaded; every load must return `Ok` or `Err`, and a network that loads must run.
//! Cards whose layer sizes were mutated are also re-signed (weight count and digest made to
//! match), since a wrapped parameter count once passed those checks; and layer lists are
//! drawn directly with sizes from tiny to `usize::MAX`.
//!
//! Case counts are capped so the file runs in seconds in the dev profile; `PROPTEST_CASES`
//! overrides them for a longer run (`PROPTEST_CASES=5000 cargo test --release -p verti-nn
//! --test fuzz`). A failing case is shrunk and printed by proptest.

use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use verti_nn::card::fnv1a64;
use verti_nn::network::parse_card;
use verti_nn::{LayerSpec, Mlp, ModelCard, ModelError, Network, Shape};
use verti_testkit::config;
use verti_testkit::mutate::{EXTREMES, edit_strategy, edited, number_edit, text_edit_strategy};

/// A card and its weights: (card text, weight file name, weight bytes).
struct Seed {
    card: String,
    weights_file: String,
    weights: Vec<u8>,
}

/// A tiny network with every layer kind, saved by the crate, and a small shipped decoder.
fn seeds() -> &'static [Seed] {
    static SEEDS: OnceLock<Vec<Seed>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let layers = vec![
            LayerSpec::Conv2d {
                in_channels: 1,
                out_channels: 2,
                kernel: 3,
                stride: 2,
                padding: 1,
            },
            LayerSpec::LeakyRelu { slope: 0.01 },
            LayerSpec::ConvTranspose2d {
                in_channels: 2,
                out_channels: 1,
                kernel: 3,
                stride: 2,
                padding: 1,
                output_padding: 1,
            },
            LayerSpec::Tanh,
            LayerSpec::Flatten,
            LayerSpec::Linear {
                inputs: 36,
                outputs: 8,
            },
            LayerSpec::Relu,
            LayerSpec::Reshape { shape: [2, 2, 2] },
            LayerSpec::Flatten,
        ];
        let card = ModelCard::new("tiny", Shape::Image([1, 6, 6]), layers);
        let n: usize = card.layers.iter().map(LayerSpec::parameter_count).sum();
        let params: Vec<f32> = (0..n).map(|i| ((i % 13) as f32 - 6.0) / 10.0).collect();
        let net = Network::from_params(card, &params).unwrap();
        let dir = case_dir("seed");
        net.save(&dir.join("tiny.yaml")).unwrap();
        let tiny = Seed {
            card: std::fs::read_to_string(dir.join("tiny.yaml")).unwrap(),
            weights_file: "tiny.bin".into(),
            weights: std::fs::read(dir.join("tiny.bin")).unwrap(),
        };
        std::fs::remove_dir_all(&dir).ok();
        let shipped = Seed {
            card: include_str!("../../verti-pietra/models/evora-v1.decoder1.yaml").into(),
            weights_file: "evora-v1.decoder1.bin".into(),
            weights: include_bytes!("../../verti-pietra/models/evora-v1.decoder1.bin").to_vec(),
        };
        vec![tiny, shipped]
    })
}

/// A fresh directory per call (cases may run on several threads of one process).
fn case_dir(tag: &str) -> PathBuf {
    verti_testkit::case_dir("verti-nn-fuzz", tag)
}

/// Most multiply-adds a loaded network is run for (the fuzzer checks that a network that
/// loads runs; a mutated stride can make a valid but slow one).
const MAX_WORK: usize = 1 << 24;

/// Multiply-adds of one forward pass, roughly, or None when the sizes are too large to run
/// here (the library bounds each activation; this bounds the time).
fn work(net: &Network) -> Option<usize> {
    let mut shape = net.input_shape();
    let mut total = shape.checked_len()?;
    for layer in &net.card().layers {
        let scratch = layer.scratch_len(shape)?;
        shape = layer.output_shape(shape).ok()?;
        let per_output = layer.parameter_count().checked_add(1)?;
        let w = per_output.checked_mul(shape.checked_len()?)?;
        total = total.checked_add(w)?.checked_add(scratch)?;
        if total > MAX_WORK {
            return None;
        }
    }
    Some(total)
}

/// A network that loaded must run: `forward` on an input of its declared shape gives an
/// output of its declared shape, and so does the MLP path when the network is an MLP.
fn exercise(net: &Network) -> Result<(), TestCaseError> {
    if work(net).is_none() {
        return Ok(());
    }
    let n = net.input_shape().len();
    let x: Vec<f32> = (0..n).map(|i| ((i % 5) as f32 - 2.0) * 0.25).collect();
    let y = net.forward(&x);
    prop_assert_eq!(y.len(), net.output_shape().len());
    if let Ok(mlp) = Mlp::from_network(net) {
        prop_assert_eq!(mlp.inputs(), n);
        prop_assert_eq!(mlp.forward(&x).len(), mlp.outputs());
    }
    Ok(())
}

/// Writes `card` as `card.yaml` and `weights` under the seed's weight file name, loads it,
/// and runs what loads. An error names the card (or, for I/O, the file it could not read).
fn load_files(seed: &Seed, card: &[u8], weights: &[u8]) -> Result<(), TestCaseError> {
    let dir = case_dir("load");
    let card_path = dir.join("card.yaml");
    std::fs::write(&card_path, card).unwrap();
    std::fs::write(dir.join(&seed.weights_file), weights).unwrap();
    let r = Network::load(&card_path);
    std::fs::remove_dir_all(&dir).ok();
    match r {
        Ok(net) => exercise(&net),
        Err(e @ ModelError::Invalid { .. }) => {
            prop_assert!(e.to_string().contains("card.yaml"), "{}", e);
            Ok(())
        }
        Err(ModelError::Io { .. }) => Ok(()),
        Err(e @ ModelError::Data(_)) => {
            prop_assert!(false, "loading a card reported a data error: {}", e);
            Ok(())
        }
    }
}

/// `card` with its weight count and digest made to match weights of its layers' size (when
/// that is small enough to write): only the layer sizes can then be wrong.
fn resigned(card: &ModelCard) -> Option<(ModelCard, Vec<u8>)> {
    let mut n: usize = 0;
    for l in &card.layers {
        n = n.checked_add(l.checked_parameter_count()?)?;
    }
    if n > 1 << 16 {
        return None;
    }
    let bytes: Vec<u8> = (0..n)
        .flat_map(|i| (((i % 11) as f32 - 5.0) / 8.0).to_le_bytes())
        .collect();
    let mut card = card.clone();
    card.weights.floats = n;
    card.weights.fnv1a64 = format!("{:016x}", fnv1a64(&bytes));
    Some((card, bytes))
}

fn from_parts(card: ModelCard, bytes: &[u8]) -> Result<(), TestCaseError> {
    match Network::from_bytes(card, bytes, Path::new("crafted.yaml")) {
        Ok(net) => exercise(&net),
        Err(e) => {
            let m = e.to_string();
            prop_assert!(m.starts_with("crafted.yaml: "), "{}", m);
            Ok(())
        }
    }
}

/// A layer size: mostly small, sometimes an edge or a value whose products overflow.
fn size() -> impl Strategy<Value = usize> {
    prop_oneof![
        4 => 0usize..6,
        1 => prop::sample::select(vec![
            1usize << 16,
            1 << 31,
            1 << 32,
            (1 << 32) + 1,
            1 << 62,
            1 << 63,
            usize::MAX,
        ]),
        1 => any::<usize>(),
    ]
}

fn layer() -> impl Strategy<Value = LayerSpec> {
    prop_oneof![
        (size(), size()).prop_map(|(inputs, outputs)| LayerSpec::Linear { inputs, outputs }),
        (size(), size(), size(), size(), size()).prop_map(|(i, o, k, s, p)| LayerSpec::Conv2d {
            in_channels: i,
            out_channels: o,
            kernel: k,
            stride: s,
            padding: p,
        }),
        (size(), size(), size(), size(), size(), size()).prop_map(|(i, o, k, s, p, op)| {
            LayerSpec::ConvTranspose2d {
                in_channels: i,
                out_channels: o,
                kernel: k,
                stride: s,
                padding: p,
                output_padding: op,
            }
        }),
        Just(LayerSpec::Relu),
        prop_oneof![
            Just(0.01f32),
            Just(f32::NAN),
            Just(f32::INFINITY),
            any::<f32>()
        ]
        .prop_map(|slope| LayerSpec::LeakyRelu { slope }),
        Just(LayerSpec::Tanh),
        (size(), size(), size()).prop_map(|(c, h, w)| LayerSpec::Reshape { shape: [c, h, w] }),
        Just(LayerSpec::Flatten),
    ]
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        size().prop_map(Shape::Flat),
        (size(), size(), size()).prop_map(|(c, h, w)| Shape::Image([c, h, w])),
    ]
}

proptest! {
    #![proptest_config(config(96))]

    #[test]
    fn mutated_cards_never_panic(
        seed in 0usize..2,
        edits in prop::collection::vec(text_edit_strategy(), 1..6),
    ) {
        let s = &seeds()[seed];
        load_files(s, &edited(s.card.as_bytes(), &edits), &s.weights)?;
    }

    #[test]
    fn mutated_weights_never_panic(
        seed in 0usize..2,
        edits in prop::collection::vec(edit_strategy(), 1..6),
        resign in any::<bool>(),
    ) {
        let s = &seeds()[seed];
        let weights = edited(&s.weights, &edits);
        let mut card = parse_card(&s.card, Path::new("seed.yaml")).unwrap();
        if resign {
            // past the size and digest checks: the values themselves are read
            card.weights.floats = weights.len() / 4;
            card.weights.fnv1a64 = format!("{:016x}", fnv1a64(&weights));
        }
        from_parts(card, &weights)?;
    }

    /// Numbers of the card swapped for extreme ones, then the card re-signed for weights of
    /// its new size: the case a wrapped parameter count used to get through.
    #[test]
    fn resigned_cards_with_extreme_sizes_never_panic(
        seed in 0usize..2,
        edits in prop::collection::vec(number_edit(EXTREMES), 1..4),
    ) {
        let s = &seeds()[seed];
        let text = String::from_utf8(edited(s.card.as_bytes(), &edits)).unwrap();
        if let Ok(card) = parse_card(&text, Path::new("crafted.yaml"))
            && let Some((card, bytes)) = resigned(&card)
        {
            from_parts(card, &bytes)?;
        }
    }

    #[test]
    fn random_layer_lists_never_panic(
        input in shape(),
        layers in prop::collection::vec(layer(), 0..5),
    ) {
        let card = ModelCard::new("crafted", input, layers);
        if let Some((card, bytes)) = resigned(&card) {
            from_parts(card, &bytes)?;
        }
    }

    #[test]
    fn random_cards_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let s = &seeds()[0];
        load_files(s, &bytes, &s.weights)?;
    }
}
