//! The allocation-free MLP path gives exactly what the general network evaluator gives.

use verti_core::Rng;
use verti_nn::{LayerSpec, Mlp, ModelCard, Network, Shape};

fn card(layers: Vec<LayerSpec>, inputs: usize) -> ModelCard {
    ModelCard::new("mlp", Shape::Flat(inputs), layers)
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
        let same = out
            .iter()
            .zip(&want)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{out:?} vs {want:?}");
        // the baseline build of the kernel (used where the CPU has no AVX) agrees too
        let portable = mlp.portable().forward(&x);
        let same = portable
            .iter()
            .zip(&want)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{portable:?} vs {want:?}");
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

#[test]
fn folded_standardisation_equals_standardising_around_the_network() {
    let mut rng = Rng::new(3);
    let lin = |inputs, outputs| LayerSpec::Linear { inputs, outputs };
    let net = random_network(vec![lin(5, 12), LayerSpec::Relu, lin(12, 3)], 5, &mut rng);
    let mlp = Mlp::from_network(&net).unwrap();
    let (im, is) = (
        vec![1.0, -2.0, 0.5, 3.0, 0.0],
        vec![2.0, 0.5, 1.0, 4.0, 0.1],
    );
    let (om, os) = (vec![0.3, -1.0, 10.0], vec![0.01, 2.0, 5.0]);
    let folded = mlp.fold_standardisation(&im, &is, &om, &os).unwrap();
    for _ in 0..20 {
        let x: Vec<f32> = (0..5).map(|_| rng.normal() as f32 * 3.0).collect();
        let z: Vec<f32> = x
            .iter()
            .zip(im.iter().zip(&is))
            .map(|(v, (m, s))| ((*v as f64 - m) / s) as f32)
            .collect();
        let want: Vec<f64> = mlp
            .forward(&z)
            .iter()
            .zip(om.iter().zip(&os))
            .map(|(v, (m, s))| *v as f64 * s + m)
            .collect();
        let got = folded.forward(&x);
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (*g as f64 - w).abs() <= 1e-4 * (1.0 + w.abs()),
                "{got:?} vs {want:?}"
            );
        }
    }
    let tanh_last = random_network(vec![lin(5, 3), LayerSpec::Tanh], 5, &mut rng);
    let m = Mlp::from_network(&tanh_last).unwrap();
    assert!(m.fold_standardisation(&im, &is, &om, &os).is_err());
}

#[test]
fn a_pair_of_inputs_gives_two_single_calls_bit_for_bit() {
    let mut rng = Rng::new(11);
    let lin = |inputs, outputs| LayerSpec::Linear { inputs, outputs };
    // widths that fill whole groups of blocks, leave partial ones and need several groups
    for layers in [
        vec![
            lin(22, 32),
            LayerSpec::Relu,
            lin(32, 32),
            LayerSpec::Relu,
            lin(32, 6),
        ],
        vec![
            lin(13, 37),
            LayerSpec::LeakyRelu { slope: 0.1 },
            lin(37, 50),
            LayerSpec::Tanh,
            lin(50, 9),
        ],
        vec![lin(5, 3)],
    ] {
        let inputs = match layers[0] {
            LayerSpec::Linear { inputs, .. } => inputs,
            _ => unreachable!(),
        };
        let mlp = Mlp::from_network(&random_network(layers, inputs, &mut rng)).unwrap();
        let n = mlp.outputs();
        let (mut s1, mut s2) = (mlp.scratch(), mlp.scratch());
        for m in [mlp.clone(), mlp.portable()] {
            for _ in 0..30 {
                let x1: Vec<f32> = (0..inputs).map(|_| rng.normal() as f32 * 2.0).collect();
                let x2: Vec<f32> = (0..inputs).map(|_| rng.normal() as f32 * 2.0).collect();
                let (mut o1, mut o2) = (vec![0.0f32; n], vec![0.0f32; n]);
                m.forward_pair_into([&x1, &x2], [&mut s1, &mut s2], [&mut o1, &mut o2]);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&o1), bits(&m.forward(&x1)));
                assert_eq!(bits(&o2), bits(&m.forward(&x2)));
            }
        }
    }
}
