//! The training stack against things known in advance: exported networks compute what the
//! burn modules compute, the sliced-Wasserstein term has its closed form under a shift and
//! its gradient matches finite differences, and a tiny SWAE learns a toy family of images.

use burn::tensor::{Tensor, TensorData};
use verti_core::Rng;
use verti_nn::train::seq::{Act, SeqNet, values};
use verti_nn::train::swae::{BatchSource, SwaeConfig, sliced_w2, train};
use verti_nn::{ModelCard, Network, Shape};

/// Burn draws initial weights from one process-wide generator that `device.seed` resets, so
/// tests that build or train networks run one at a time (in parallel they would take each
/// other's draws, and a training test would start from different weights run to run).
fn serial() -> std::sync::MutexGuard<'static, ()> {
    static BURN: std::sync::Mutex<()> = std::sync::Mutex::new(());
    BURN.lock().unwrap_or_else(|e| e.into_inner())
}

fn tiny_config() -> SwaeConfig {
    SwaeConfig {
        side: 16,
        widths: vec![4, 8],
        latent: 2,
        steps: 300,
        batch: 16,
        lr: 3e-3,
        lr_final: 1e-4,
        projections: 20,
        swd_weight: 0.1,
        seed: 3,
        eval_every: 50,
    }
}

fn card_for(net: &SeqNet) -> ModelCard {
    ModelCard::new("test", net.input_shape(), net.layers().to_vec())
}

#[test]
fn exported_networks_compute_what_burn_computes() {
    let _burn = serial();
    let device = verti_nn::train::device();
    let cfg = tiny_config();
    for (input, layers) in [
        (cfg.input_shape(), cfg.encoder_layers()),
        (Shape::Flat(cfg.latent), cfg.decoder_layers()),
    ] {
        let net = SeqNet::new(input, &layers, &device).unwrap();
        let exported = Network::from_params(card_for(&net), &net.export_params()).unwrap();
        let mut rng = Rng::new(9);
        let x: Vec<f32> = (0..2 * input.len()).map(|_| rng.normal() as f32).collect();
        let batch = match input {
            Shape::Flat(n) => Act::Flat(Tensor::from_data(
                TensorData::new(x.clone(), [2, n]),
                &device,
            )),
            Shape::Image([c, h, w]) => Act::Image(Tensor::from_data(
                TensorData::new(x.clone(), [2, c, h, w]),
                &device,
            )),
        };
        let burn_out = values(net.forward(batch).flat());
        let ours: Vec<f32> = x
            .chunks(input.len())
            .flat_map(|one| exported.forward(one))
            .collect();
        assert_eq!(burn_out.len(), ours.len());
        for (a, b) in burn_out.iter().zip(&ours) {
            assert!(
                (a - b).abs() <= 1e-4 * (1.0 + a.abs()),
                "burn {a} vs verti-nn {b}"
            );
        }
    }
}

fn matrix(v: Vec<f32>, shape: [usize; 2]) -> Tensor<2> {
    Tensor::from_data(TensorData::new(v, shape), &verti_nn::train::device())
}

#[test]
fn sliced_w2_of_a_shift_is_the_mean_squared_projected_shift() {
    let _burn = serial();
    // shifting every sample by s keeps the sorted order along each direction, so each
    // direction θ contributes exactly (θ·s)²
    let mut rng = Rng::new(1);
    let (m, d, l) = (32, 3, 5);
    let a: Vec<f32> = (0..m * d).map(|_| rng.normal() as f32).collect();
    let s = [0.5f32, -1.0, 2.0];
    let b: Vec<f32> = a.iter().enumerate().map(|(i, v)| v + s[i % d]).collect();
    let mut dirs = vec![0f32; d * l];
    let mut expected = 0.0;
    for j in 0..l {
        let v: Vec<f64> = (0..d).map(|_| rng.normal()).collect();
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut proj = 0.0;
        for i in 0..d {
            dirs[i * l + j] = (v[i] / n) as f32;
            proj += v[i] / n * f64::from(s[i]);
        }
        expected += proj * proj / l as f64;
    }
    let got = values(sliced_w2(
        matrix(a, [m, d]),
        matrix(b, [m, d]),
        matrix(dirs, [d, l]),
    ))[0];
    assert!(
        (f64::from(got) - expected).abs() < 1e-4,
        "{got} vs {expected}"
    );
}

#[test]
fn sliced_w2_gradient_matches_finite_differences() {
    let _burn = serial();
    let mut rng = Rng::new(2);
    let (m, d, l) = (8, 2, 3);
    let a: Vec<f32> = (0..m * d).map(|_| rng.normal() as f32).collect();
    let b: Vec<f32> = (0..m * d).map(|_| rng.normal() as f32).collect();
    let dirs: Vec<f32> = (0..d * l).map(|_| rng.normal() as f32).collect();
    let f = |a: Vec<f32>| {
        f64::from(
            values(sliced_w2(
                matrix(a, [m, d]),
                matrix(b.clone(), [m, d]),
                matrix(dirs.clone(), [d, l]),
            ))[0],
        )
    };
    let at = matrix(a.clone(), [m, d]).require_grad();
    let loss = sliced_w2(
        at.clone(),
        matrix(b.clone(), [m, d]),
        matrix(dirs.clone(), [d, l]),
    );
    let grads = loss.backward();
    let g = values(at.grad(&grads).expect("a requires a gradient"));
    for k in [0, 5, 11] {
        let h = 1e-2;
        let (mut up, mut down) = (a.clone(), a.clone());
        up[k] += h;
        down[k] -= h;
        let fd = (f(up) - f(down)) / (2.0 * f64::from(h));
        assert!(
            (fd - f64::from(g[k])).abs() < 2e-3,
            "element {k}: autodiff {} vs finite difference {fd}",
            g[k]
        );
    }
}

/// Toy images with two degrees of freedom: a plane a·row + b·col (a, b ~ N(0, 1)/8).
struct Planes;

impl BatchSource for Planes {
    fn sample(&mut self, rng: &mut Rng, batch: usize) -> Vec<f32> {
        let mut out = Vec::new();
        for _ in 0..batch {
            let (a, b) = (rng.normal() / 8.0, rng.normal() / 8.0);
            for r in 0..16 {
                for c in 0..16 {
                    out.push((a * (r as f64 - 7.5) + b * (c as f64 - 7.5)) as f32);
                }
            }
        }
        out
    }
}

#[test]
fn a_tiny_swae_learns_a_two_parameter_family() {
    let _burn = serial();
    let device = verti_nn::train::device();
    let cfg = tiny_config();
    let val = Planes.sample(&mut Rng::new(77), 64);
    let variance = val.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>() / val.len() as f64;
    let (_, report) = train(&cfg, &mut Planes, &val, &device, &mut |_, _| {}).unwrap();
    let last = report.curve.last().unwrap();
    // a 2-d latent captures the whole family: the reconstruction error is a small fraction
    // of the data's variance (an untrained decoder gets about the variance itself)
    assert!(
        last.val_mse < 0.1 * variance,
        "val MSE {} vs variance {variance}",
        last.val_mse
    );
    assert!(report.curve.first().unwrap().val_mse > last.val_mse);
}

#[test]
fn bad_settings_are_named() {
    let _burn = serial();
    let mut c = tiny_config();
    c.side = 12;
    assert!(c.validate().unwrap_err().contains("power of two"));
    let mut c = tiny_config();
    c.batch = 1;
    assert!(c.validate().unwrap_err().contains("batch"));
    let mut c = tiny_config();
    c.lr_final = 1.0;
    assert!(c.validate().unwrap_err().contains("lr_final"));
}
