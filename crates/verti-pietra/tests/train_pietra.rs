//! PIETRA's learning code: the radial flow's log-determinant against finite differences,
//! learning a toy problem with a known answer, the posterior falling back to the physics prior
//! far from the training data (the paper's central claim, on a case where it must hold),
//! determinism, and the benchmark's tables on a tiny grid.

use burn::tensor::{Device, Tensor, TensorData};
use std::collections::BTreeMap;
use verti_core::Rng;
use verti_nn::train::seq::values;
use verti_pietra::bins::{B, PARAMS, param_bins};
use verti_pietra::dataset::FEATURES;
use verti_pietra::prior::PriorConfig;
use verti_pietra::train::bench::{Grid, markdown, run_benchmark, runs_csv};
use verti_pietra::train::data::{PietraData, Prepared};
use verti_pietra::train::fit::{RunConfig, train, uniform_errors};
use verti_pietra::train::model::{LATENT, LossWeights, Method, RadialFlow, TravNet, expected_pmf};

fn dev() -> Device {
    verti_nn::train::device()
}

/// Determinant of a square matrix (row-major) by Gaussian elimination with pivoting.
fn det(mut m: Vec<f64>, n: usize) -> f64 {
    let mut d = 1.0;
    for c in 0..n {
        let p = (c..n)
            .max_by(|&a, &b| m[a * n + c].abs().total_cmp(&m[b * n + c].abs()))
            .unwrap();
        if p != c {
            for k in 0..n {
                m.swap(p * n + k, c * n + k);
            }
            d = -d;
        }
        let piv = m[c * n + c];
        d *= piv;
        for r in c + 1..n {
            let f = m[r * n + c] / piv;
            for k in c..n {
                m[r * n + k] -= f * m[c * n + k];
            }
        }
    }
    d
}

#[test]
fn radial_flow_log_det_matches_finite_differences() {
    let device = dev();
    let flow = RadialFlow::new(&mut Rng::new(3), &device);
    let mut rng = Rng::new(4);
    for _ in 0..3 {
        let z: Vec<f32> = (0..LATENT).map(|_| rng.normal() as f32 * 0.7).collect();
        let at = |v: &[f32]| {
            let t = Tensor::from_data(TensorData::new(v.to_vec(), [1, LATENT]), &device);
            let (y, ld) = flow.forward(t);
            (values(y), values(ld)[0])
        };
        let (_, log_det) = at(&z);
        let eps = 1e-2f32;
        let mut jac = vec![0.0f64; LATENT * LATENT];
        for j in 0..LATENT {
            let (mut a, mut b) = (z.clone(), z.clone());
            a[j] += eps;
            b[j] -= eps;
            let (ya, yb) = (at(&a).0, at(&b).0);
            for i in 0..LATENT {
                jac[i * LATENT + j] = f64::from(ya[i] - yb[i]) / f64::from(2.0 * eps);
            }
        }
        let numeric = det(jac, LATENT).abs().ln();
        assert!(
            (numeric - f64::from(log_det)).abs() < 2e-2,
            "log|det J| {log_det} vs finite differences {numeric}"
        );
    }
}

/// A toy problem with a known answer: every parameter's target bin is 9 where the first
/// feature is positive and 2 where it is negative; the physics prior is one-hot on bin 5.
fn toy(n: usize, spread: f32, seed: u64) -> Prepared {
    let mut rng = Rng::new(seed);
    let mut p = Prepared {
        n,
        ..Default::default()
    };
    for _ in 0..n {
        let f: Vec<f32> = (0..FEATURES)
            .map(|_| rng.normal() as f32 * spread)
            .collect();
        let bin = if f[0] > 0.0 { 9 } else { 2 };
        p.features.extend(&f);
        for _ in 0..PARAMS {
            p.targets
                .extend((0..B).map(|b| f32::from(u8::from(b == bin))));
            p.physics
                .extend((0..B).map(|b| f32::from(u8::from(b == 5))));
        }
        p.psi.push([0.0; PARAMS]);
        p.unevenness.push(f64::from(spread));
    }
    p
}

fn toy_data() -> PietraData {
    PietraData {
        train: toy(4096, 0.1, 1),
        val: toy(256, 0.1, 2),
        test: toy(256, 0.1, 3),
        threshold: 0.1,
        input_scale: 0.1,
        bins: param_bins(),
        prior: PriorConfig::default(),
        summary: BTreeMap::new(),
    }
}

fn run(method: Method, seed: u64, steps: usize) -> RunConfig {
    RunConfig {
        method,
        lr: 3e-3,
        weights: LossWeights {
            physics: 0.1,
            entropy: 1e-4,
        },
        seed,
        steps,
        batch: 64,
    }
}

#[test]
fn methods_learn_the_toy_problem() {
    let data = toy_data();
    let device = dev();
    let uniform = uniform_errors(&data.val).scores(&data.val, 1.0).overall;
    for method in [Method::Vanilla, Method::Pietra, Method::Evora] {
        let t = train(&data, &run(method, 0, 400), &device).unwrap();
        let got = t.val.scores(&data.val, 1.0).overall;
        // a perfect prediction scores 0; the uniform PMF about 2 per parameter here
        assert!(
            got < 0.25 * uniform,
            "{}: validation EMD² {got} vs uniform {uniform}",
            method.name()
        );
    }
}

#[test]
fn far_from_the_data_pietra_falls_back_to_the_physics_prior() {
    let data = toy_data();
    let device = dev();
    let t = train(&data, &run(Method::Pietra, 1, 300), &device).unwrap();
    // inputs a hundred times wider than anything trained on
    let far = toy(64, 10.0, 9);
    let (x, _, ph) = far.batch(&(0..64).collect::<Vec<_>>(), &device);
    let (p, _) = expected_pmf(&t.net, x, ph);
    let p = values(p);
    let near = data.test.clone();
    let (xn, _, phn) = near.batch(&(0..64).collect::<Vec<_>>(), &device);
    let (pn, _) = expected_pmf(&t.net, xn, phn);
    let pn = values(pn);
    let mass_on_prior_bin = |v: &[f32]| {
        (0..v.len() / B)
            .map(|r| f64::from(v[r * B + 5]))
            .sum::<f64>()
            / (v.len() / B) as f64
    };
    assert!(
        mass_on_prior_bin(&p) > 0.9,
        "far inputs: {} of the mass on the prior's bin",
        mass_on_prior_bin(&p)
    );
    assert!(
        mass_on_prior_bin(&pn) < 0.3,
        "near inputs keep the learned answer: {}",
        mass_on_prior_bin(&pn)
    );
    // EVORA falls back to the uniform prior instead: no bin gets most of the mass
    let e = train(&data, &run(Method::Evora, 1, 300), &device).unwrap();
    let (x, _, ph) = far.batch(&(0..64).collect::<Vec<_>>(), &device);
    let (pe, _) = expected_pmf(&e.net, x, ph.ones_like() / B as f64);
    let pe = values(pe);
    let max_mass = pe.iter().copied().fold(0.0f32, f32::max);
    assert!(
        max_mass < 0.2,
        "EVORA far from the data: largest bin mass {max_mass}"
    );
}

#[test]
fn a_run_is_deterministic_for_its_seed() {
    let data = toy_data();
    let device = dev();
    let a = train(&data, &run(Method::Pietra, 5, 20), &device).unwrap();
    let b = train(&data, &run(Method::Pietra, 5, 20), &device).unwrap();
    assert_eq!(a.val.total, b.val.total);
    let c = train(&data, &run(Method::Pietra, 6, 20), &device).unwrap();
    assert_ne!(a.val.total, c.val.total);
    let _ = TravNet::new(Method::Vanilla, 1.0, 0, &device).unwrap();
}

#[test]
fn the_benchmark_writes_both_tables() {
    let data = toy_data();
    let grid = Grid {
        lrs: vec![3e-3, 1e-5],
        physics: vec![0.1],
        entropy: vec![1e-4],
        seeds: vec![0, 1],
        steps: 40,
        batch: 32,
    };
    let result = run_benchmark(&data, &grid, &Method::ALL, &dev(), &|_| {}).unwrap();
    assert_eq!(result.runs.len(), 6 * 2 * 2);
    let names: Vec<&str> = result.table1.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "PIETRA",
            "Physics-Informed (PI)",
            "Vanilla",
            "EVORA",
            "Physics Prior",
            "Uniform Prior"
        ]
    );
    assert_eq!(result.table2.len(), 5);
    // 40 steps at 3e-3 beat 40 steps at 1e-5: validation picks the larger rate
    assert!(
        result.table1[0].config.starts_with("lr 3e-3"),
        "{}",
        result.table1[0].config
    );
    assert!(markdown(&result.table1).contains("| PIETRA |"));
    assert_eq!(
        runs_csv(&result.runs).lines().count(),
        1 + result.runs.len()
    );
}

#[test]
fn the_exported_model_computes_what_burn_computes() {
    use verti_pietra::train::export::to_model;
    let data = toy_data();
    let device = dev();
    for method in [Method::Pietra, Method::Vanilla, Method::Evora] {
        let t = train(&data, &run(method, 2, 60), &device).unwrap();
        let model = to_model(
            &t.net,
            &data,
            -50.0,
            verti_nn::TrainingInfo::default(),
            BTreeMap::new(),
            "toy-v1",
        )
        .unwrap();
        // a round trip through the files changes nothing
        let dir = std::env::temp_dir().join(format!("verti-pietra-export-{}", method.name()));
        model.save(&dir.join("toy-v1.yaml")).unwrap();
        let model = verti_pietra::model::TravModel::load(&dir.join("toy-v1.yaml")).unwrap();
        let idx: Vec<usize> = (0..16).collect();
        let (x, _, ph) = data.test.batch(&idx, &device);
        let prior = if method.physics_in_posterior() {
            ph
        } else {
            ph.ones_like() / B as f64
        };
        let (p, logd) = expected_pmf(&t.net, x, prior);
        let (p, logd) = (values(p), values(logd));
        let mut scratch = model.scratch();
        for &i in &idx {
            let f = &data.test.features[i * FEATURES..(i + 1) * FEATURES];
            let physics: [verti_pietra::bins::Pmf; PARAMS] = std::array::from_fn(|k| {
                std::array::from_fn(|b| f64::from(data.test.physics[(i * PARAMS + k) * B + b]))
            });
            let got = model.predict(f, &physics, &mut scratch);
            for k in 0..PARAMS {
                for b in 0..B {
                    let want = f64::from(p[(i * PARAMS + k) * B + b]);
                    assert!(
                        (got.pmf[k][b] - want).abs() < 1e-4,
                        "{} sample {i} param {k} bin {b}: {} vs {want}",
                        method.name(),
                        got.pmf[k][b]
                    );
                }
            }
            if method.evidential() {
                let want = f64::from(logd[i]);
                assert!((got.log_density - want).abs() < 1e-3 * want.abs().max(1.0));
            }
        }
    }
}
