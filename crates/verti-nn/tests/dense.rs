//! The allocation-free MLP path gives exactly what the general network evaluator gives.

use std::collections::BTreeMap;
use verti_core::Rng;
use verti_nn::{LayerSpec, ModelCard, Mlp, Network, Shape, TrainingInfo, WeightsInfo};

fn card(layers: Vec<LayerSpec>, inputs: usize) -> ModelCard {
    ModelCard {
        name: "mlp".into(),
        format: verti_nn::card::CARD_FORMAT,
        summary: "test".into(),
        input: Shape::Flat(inputs),
        layers,
        normalisation: "none".into(),
        weights: WeightsInfo {
            file: "mlp.bin".into(),
            floats: 0,
            fnv1a64: String::new(),
        },
        training: TrainingInfo {
            data: "none".into(),
            command: "none".into(),
            seed: 0,
            steps: 0,
            wall_time_s: 0.0,
            verti_version: "test".into(),
            settings: String::new(),
        },
        metrics: BTreeMap::new(),
        constants: BTreeMap::new(),
    }
}

fn random_network(layers: Vec<LayerSpec>, inputs: usize, rng: &mut Rng) -> Network {
    let n: usize = layers.iter().map(|l| l.parameter_count()).sum();
    let params: Vec<f32> = (0..n).map(|_| rng.normal() as f32 * 0.5).collect();
    Network::from_params(card(layers, inputs), &params).unwrap()
}

#[test]
fn mlp_matches_the_network_bit_for_bit() {
    let mut rng = Rng::new(7);
    let lin = |inputs, outputs| LayerSpec::Linear { inputs, outputs };
    let layers = vec![
        lin(13, 37),
        LayerSpec::LeakyRelu { slope: 0.1 },
        lin(37, 24),
        LayerSpec::Relu,
        lin(24, 9),
        LayerSpec::Tanh,
        lin(9, 6),
    ];
    let net = random_network(layers, 13, &mut rng);
    let mlp = Mlp::from_network(&net).unwrap();
    assert_eq!((mlp.inputs(), mlp.outputs()), (13, 6));
    assert_eq!(mlp.multiply_adds(), 13 * 37 + 37 * 24 + 24 * 9 + 9 * 6);
    let mut scratch = mlp.scratch();
    let mut out = [0.0f32; 6];
    for _ in 0..50 {
        let x: Vec<f32> = (0..13).map(|_| rng.normal() as f32 * 2.0).collect();
        mlp.forward_into(&x, &mut scratch, &mut out);
        let want = net.forward(&x);
        let same = out.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{out:?} vs {want:?}");
    }
}

#[test]
fn networks_that_are_not_mlps_are_refused_by_name() {
    let mut rng = Rng::new(1);
    let conv = vec![
        LayerSpec::Reshape { shape: [1, 2, 2] },
        LayerSpec::Conv2d {
            in_channels: 1,
            out_channels: 1,
            kernel: 1,
            stride: 1,
            padding: 0,
        },
    ];
    let err = Mlp::from_network(&random_network(conv, 4, &mut rng)).unwrap_err();
    assert!(err.contains("layer 0 (reshape)"), "{err}");
    let double = vec![
        LayerSpec::Linear {
            inputs: 2,
            outputs: 2,
        },
        LayerSpec::Relu,
        LayerSpec::Tanh,
    ];
    let err = Mlp::from_network(&random_network(double, 2, &mut rng)).unwrap_err();
    assert!(err.contains("layer 2"), "{err}");
}
