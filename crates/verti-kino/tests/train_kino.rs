//! The kinodynamic trainers on toy problems with known answers, and their exports computing
//! what burn computed.

use verti_core::Rng;
use verti_kino::KinoKind;
use verti_kino::attentive::{ATTENTIVE_INPUT_DIM, MAP_DIM, OFFSET_DIM, squash};
use verti_kino::features::OUTPUT_DIM;
use verti_kino::samples::Examples;
use verti_kino::train::kino::{KinoConfig, KinoProvenance, train};
use verti_world::ElevationLevel;

/// Rows whose change is a smooth function of a few map cells, the offset and the head: a
/// network of TAL's shape can learn it, a constant cannot.
fn toy(n: usize, seed: u64) -> Examples {
    let mut rng = Rng::new(seed);
    let mut ex = Examples {
        dim: ATTENTIVE_INPUT_DIM,
        ..Default::default()
    };
    for _ in 0..n {
        let x: Vec<f32> = (0..ATTENTIVE_INPUT_DIM)
            .map(|_| rng.normal() as f32)
            .collect();
        let head = MAP_DIM + OFFSET_DIM;
        for k in 0..OUTPUT_DIM {
            let y = 0.8 * x[head + k] + 0.5 * x[3 * k].max(0.0) * (1.0 + x[MAP_DIM].tanh())
                - 0.3 * x[head + 8];
            ex.targets.push(y);
        }
        ex.inputs.extend_from_slice(&x);
        ex.levels.push(ElevationLevel::Low);
    }
    ex
}

fn provenance() -> KinoProvenance {
    KinoProvenance {
        name: "toy".into(),
        summary: "toy".into(),
        vehicle: "hmmwv".into(),
        dt: 0.2,
        data: "synthetic".into(),
        worlds: "none".into(),
        command: "test".into(),
    }
}

#[test]
fn tal_learns_a_toy_dynamics_and_its_export_computes_the_same() {
    let (train_set, val_set) = (toy(3000, 1), toy(500, 2));
    let cfg = KinoConfig {
        kind: KinoKind::Attentive,
        members: 1,
        hidden: vec![16, 16],
        steps: 400,
        batch: 64,
        lr: 3e-3,
        lr_final: 1e-4,
        seed: 0,
        eval_every: 100,
    };
    let device = verti_nn::train::device();
    let (file, report) = train(
        &cfg,
        &train_set,
        &val_set,
        &provenance(),
        &device,
        &mut |_, _, _| {},
    )
    .unwrap();
    // standardised targets: predicting the mean scores about 1
    assert!(report.val_loss < 0.35, "validation MSE {}", report.val_loss);
    let first = report.curve.first().unwrap().val_loss;
    assert!(report.val_loss < first, "{first} -> {}", report.val_loss);

    // the exported, standardisation-folded networks (what planning runs) reproduce burn's
    // validation loss on raw inputs
    let [enc, gate, dynamics] = &file.mlps[..] else {
        panic!("three networks")
    };
    let card = &file.card;
    let (mut features, mut g, mut out) = (vec![0.0; 32], vec![0.0; 32], vec![0.0; OUTPUT_DIM]);
    let mut scratch = enc.scratch();
    let mut sq = 0.0;
    for (x, y) in val_set
        .inputs
        .chunks_exact(ATTENTIVE_INPUT_DIM)
        .zip(val_set.targets.chunks_exact(OUTPUT_DIM))
    {
        enc.forward_into(&x[..MAP_DIM], &mut scratch, &mut features);
        gate.forward_into(&x[MAP_DIM..MAP_DIM + OFFSET_DIM], &mut scratch, &mut g);
        let mut d: Vec<f32> = features
            .iter()
            .zip(&g)
            .map(|(e, g)| e * squash(*g))
            .collect();
        d.extend_from_slice(&x[MAP_DIM + OFFSET_DIM..]);
        dynamics.forward_into(&d, &mut scratch, &mut out);
        for k in 0..OUTPUT_DIM {
            let e = (f64::from(out[k]) - f64::from(y[k])) / card.output_std[k];
            sq += e * e;
        }
    }
    let exported = sq / (val_set.len() * OUTPUT_DIM) as f64;
    assert!(
        (exported - report.val_loss).abs() < 1e-3 * report.val_loss.max(1e-3) + 1e-5,
        "export {exported} vs burn {}",
        report.val_loss
    );
}

#[test]
fn attentive_training_refuses_ensembles_and_wrong_rows() {
    let cfg = KinoConfig {
        kind: KinoKind::Attentive,
        members: 2,
        hidden: vec![8],
        steps: 1,
        batch: 4,
        lr: 1e-3,
        lr_final: 1e-4,
        seed: 0,
        eval_every: 1,
    };
    let device = verti_nn::train::device();
    let ex = toy(10, 3);
    let e = train(&cfg, &ex, &ex, &provenance(), &device, &mut |_, _, _| {}).unwrap_err();
    assert!(e.contains("not 2 members"), "{e}");
    let narrow = Examples {
        dim: 22,
        ..ex.clone()
    };
    let cfg = KinoConfig { members: 1, ..cfg };
    let e = train(
        &cfg,
        &narrow,
        &ex,
        &provenance(),
        &device,
        &mut |_, _, _| {},
    )
    .unwrap_err();
    assert!(e.contains("22 inputs per row"), "{e}");
}
