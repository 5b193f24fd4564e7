//! VertiAdaptor's training pieces: the burn network computes what the plain-Rust model
//! computes, the least-squares gradient is the solve's, and Algorithm 1 learns a toy family
//! of dynamics it can represent.

use burn::tensor::{Tensor, TensorData};
use std::path::Path;
use verti_core::Rng;
use verti_nn::train::seq::values;
use verti_va::lsq::cholesky_solve;
use verti_va::model::{VA_FORMAT, VaCard, VaTraining, WeightsRef};
use verti_va::terrain::TERRAIN_DIM;
use verti_va::train::net::{NetSpec, VaNet, coefficients};
use verti_va::{Method, VaModel};

fn spec(method: Method, bases: usize) -> NetSpec {
    NetSpec {
        method,
        bases,
        hidden: vec![16, 16],
        elevation: true,
        semantics: true,
        dt: 0.1,
    }
}

fn card_for(net: &VaNet) -> VaCard {
    let s = &net.spec;
    VaCard {
        name: "test".into(),
        format: VA_FORMAT,
        summary: String::new(),
        method: s.method,
        vehicle: "hmmwv".into(),
        dt: s.dt,
        bases: s.bases,
        hidden: s.hidden.clone(),
        elevation: s.elevation,
        semantics: s.semantics,
        lambda: 1e-3,
        alpha_prior: vec![1.0; s.bases],
        weights: WeightsRef {
            file: "test.bin".into(),
            floats: net.export_params().len(),
            fnv1a64: String::new(),
        },
        training: VaTraining {
            data: String::new(),
            worlds: String::new(),
            command: String::new(),
            seed: 0,
            steps: 0,
            wall_time_s: 0.0,
            verti_version: String::new(),
            settings: String::new(),
        },
        metrics: Default::default(),
    }
}

#[test]
fn burn_and_plain_rust_agree() {
    let device = verti_nn::train::device();
    let mut rng = Rng::new(4);
    for (method, k) in [(Method::Va, 3), (Method::Node, 1), (Method::Mlp, 1)] {
        let net = VaNet::new(spec(method, k), 7, &device);
        let model = VaModel::new(card_for(&net), &net.export_params(), Path::new("test")).unwrap();
        let n = 5;
        let terrain: Vec<f32> = (0..n * TERRAIN_DIM)
            .map(|_| rng.range(-1.0, 1.0) as f32)
            .collect();
        let rp: Vec<f32> = (0..n * 2).map(|_| rng.range(-0.3, 0.3) as f32).collect();
        let cmd: Vec<f32> = (0..n * 2).map(|_| rng.range(-1.0, 2.0) as f32).collect();
        let t = |v: &[f32], w: usize| {
            Tensor::<2>::from_data(TensorData::new(v.to_vec(), [n, w]), &device)
        };
        let e = net.embed(t(&terrain, TERRAIN_DIM));
        let g = values(net.basis_changes(t(&rp, 2), e.clone(), t(&cmd, 2)));
        let e = values(e);
        for i in 0..n {
            let emb = model.embed(&terrain[i * TERRAIN_DIM..(i + 1) * TERRAIN_DIM]);
            for (a, b) in emb.iter().zip(&e[i * 16..(i + 1) * 16]) {
                assert!((a - b).abs() < 1e-5, "{method:?} embedding {a} vs {b}");
            }
            let mut out = vec![0.0; k * 6];
            model.basis_changes(
                rp[2 * i] as f64,
                rp[2 * i + 1] as f64,
                &emb,
                (cmd[2 * i] as f64, cmd[2 * i + 1] as f64),
                &mut out,
            );
            for b in 0..k {
                for d in 0..6 {
                    let burn = g[(b * n + i) * 6 + d] as f64;
                    assert!(
                        (out[b * 6 + d] - burn).abs() < 1e-5,
                        "{method:?} basis {b} dim {d}: {} vs {burn}",
                        out[b * 6 + d]
                    );
                }
            }
        }
    }
}

/// α(g) by the host solve, for finite differences.
fn host_alpha(g: &[f64], y: &[f64], k: usize, m: usize, lambda: f64) -> Vec<f64> {
    let mut a = vec![0.0; k * k];
    let mut f = vec![0.0; k];
    for i in 0..k {
        for j in 0..k {
            a[i * k + j] = (0..m * 6)
                .map(|p| g[i * m * 6 + p] * g[j * m * 6 + p])
                .sum::<f64>()
                / m as f64;
        }
        a[i * k + i] += lambda;
        f[i] = (0..m * 6).map(|p| g[i * m * 6 + p] * y[p]).sum::<f64>() / m as f64;
    }
    cholesky_solve(&a, k, &f).unwrap()
}

#[test]
fn least_squares_gradient_matches_finite_differences() {
    let device = verti_nn::train::device();
    let (k, m) = (3, 4);
    let mut rng = Rng::new(12);
    let g: Vec<f64> = (0..k * m * 6).map(|_| rng.range(-1.0, 1.0)).collect();
    let y: Vec<f64> = (0..m * 6).map(|_| rng.range(-1.0, 1.0)).collect();
    let w: Vec<f64> = (0..k).map(|_| rng.range(-1.0, 1.0)).collect();
    // L = Σ_i w_i α_i
    let gt = Tensor::<3>::from_data(
        TensorData::new(g.iter().map(|&v| v as f32).collect::<Vec<_>>(), [k, m, 6]),
        &device,
    )
    .require_grad();
    let yt = Tensor::<2>::from_data(
        TensorData::new(y.iter().map(|&v| v as f32).collect::<Vec<_>>(), [m, 6]),
        &device,
    );
    let wt = Tensor::<2>::from_data(
        TensorData::new(w.iter().map(|&v| v as f32).collect::<Vec<_>>(), [k, 1]),
        &device,
    );
    let alpha = coefficients(gt.clone(), yt, 0.05).unwrap();
    let loss = (alpha * wt).sum();
    let grads = loss.backward();
    let analytic = values(gt.grad(&grads).unwrap());
    let l = |g: &[f64]| -> f64 {
        host_alpha(g, &y, k, m, 0.05)
            .iter()
            .zip(&w)
            .map(|(a, b)| a * b)
            .sum()
    };
    let h = 1e-6;
    for p in (0..k * m * 6).step_by(5) {
        let (mut up, mut down) = (g.clone(), g.clone());
        up[p] += h;
        down[p] -= h;
        let numeric = (l(&up) - l(&down)) / (2.0 * h);
        let a = analytic[p] as f64;
        assert!(
            (a - numeric).abs() < 2e-3 * (1.0 + numeric.abs()),
            "param {p}: {a} vs {numeric}"
        );
    }
}
