//! What `verti learn kino` does, as a library function: load a training and a validation
//! dataset, train, measure the model against the bicycle on the validation trajectories,
//! write the model, its card and its learning curve.

use crate::eval::{Accuracy, Predictor, evaluate};
use crate::features::OUTPUT_NAMES;
use crate::samples::KinoData;
use crate::train::kino::{KinoConfig, KinoProvenance, KinoReport, train};
use crate::{Geometry, KinoFile, KinoModel};
use burn::tensor::Device;
use std::path::{Path, PathBuf};
use verti_render::lines::{LinePanel, LineSeries, line_chart_image};

/// Where and how to train.
#[derive(Clone, Debug)]
pub struct KinoRun {
    pub config: KinoConfig,
    /// Model name; the card goes to `out`, networks and curve beside it.
    pub name: String,
    pub out: PathBuf,
    pub data: PathBuf,
    pub val: PathBuf,
    /// Model step, full-scale seconds.
    pub dt: f64,
    /// Open-loop horizon of the multi-step metric, model steps.
    pub horizon: usize,
    pub geometry: Geometry,
    pub summary: String,
    pub command: String,
}

/// What training reports.
pub struct KinoTrained {
    pub file: KinoFile,
    pub report: KinoReport,
    /// Validation accuracy of the model and of the bicycle.
    pub accuracy: Vec<Accuracy>,
    pub curve_png: PathBuf,
    pub train_examples: usize,
    pub val_examples: usize,
}

/// Refuses `what` data in `dir` driven on evaluation worlds: `verti learn` never trains or
/// validates on them.
pub fn refuse_eval_worlds(
    what: &str,
    dir: &Path,
    eval_worlds: bool,
    set: &str,
) -> Result<(), String> {
    if eval_worlds {
        return Err(format!(
            "{what} data {} were driven on the evaluation set {set}; train on other seeds \
             (verti-100-s1, ...)",
            dir.display()
        ));
    }
    Ok(())
}

/// A kinodynamic dataset cut at step `dt`, refused if driven on evaluation worlds.
pub(crate) fn load(dir: &Path, dt: f64, what: &str) -> Result<KinoData, String> {
    let data = KinoData::load(dir, dt).map_err(|e| format!("{what} data: {e}"))?;
    refuse_eval_worlds(what, dir, data.eval_worlds, &data.set)?;
    Ok(data)
}

/// Trains and writes a kinodynamic model.
pub fn learn_kino(
    run: &KinoRun,
    device: &Device,
    progress: &mut dyn FnMut(usize, usize, f64),
) -> Result<KinoTrained, String> {
    let train_data = load(&run.data, run.dt, "training")?;
    let val_data = load(&run.val, run.dt, "validation")?;
    let kind = run.config.kind;
    let (train_ex, val_ex) = (
        train_data.examples_for(kind, run.config.seed),
        val_data.examples_for(kind, run.config.seed),
    );
    let prov = KinoProvenance {
        name: run.name.clone(),
        summary: run.summary.clone(),
        vehicle: train_data.vehicle.clone(),
        dt: run.dt,
        data: format!(
            "{} ({:.1} h of driving) for training, {} ({:.1} h) for validation: {} and {} \
             one-step examples",
            run.data.display(),
            train_data.hours,
            run.val.display(),
            val_data.hours,
            train_ex.len(),
            val_ex.len()
        ),
        worlds: format!(
            "training {}, validation {}; never verti-100",
            train_data.set, val_data.set
        ),
        command: run.command.clone(),
    };
    let (mut file, report) = train(&run.config, &train_ex, &val_ex, &prov, device, progress)?;
    let model = KinoModel::new(std::sync::Arc::new(file.clone()));
    let accuracy = vec![
        evaluate(
            &val_data,
            &Predictor::Model(model),
            run.geometry,
            run.horizon,
        ),
        evaluate(&val_data, &Predictor::Bicycle, run.geometry, run.horizon),
    ];
    let round = |v: f64| (v * 1e4).round() / 1e4;
    file.card
        .metrics
        .insert("val_mse_standardised".into(), round(report.val_loss));
    for (a, tag) in accuracy.iter().zip(["", "bicycle_"]) {
        let (one, multi) = (a.one_step[0].rmse(), a.multi_step[0].rmse());
        for (i, name) in OUTPUT_NAMES.iter().enumerate() {
            file.card
                .metrics
                .insert(format!("{tag}val_rmse_1step_{name}"), round(one[i]));
            file.card.metrics.insert(
                format!("{tag}val_rmse_{}step_{name}", run.horizon),
                round(multi[i]),
            );
        }
    }
    file.card.training.wall_time_s = (report.wall_time_s * 10.0).round() / 10.0;
    file.save(&run.out).map_err(|e| e.to_string())?;
    let curve_png = run.out.with_file_name(format!("{}-curve.png", run.name));
    draw_curve(&report.curve, &run.name, &curve_png)?;
    Ok(KinoTrained {
        file,
        report,
        accuracy,
        curve_png,
        train_examples: train_ex.len(),
        val_examples: val_ex.len(),
    })
}

/// The learning curve (log10 MSE per member, training and validation) as a PNG.
pub fn draw_curve(
    curve: &[crate::train::kino::KinoCurvePoint],
    name: &str,
    out: &Path,
) -> Result<(), String> {
    let members = curve.iter().map(|p| p.member).max().unwrap_or(0) + 1;
    let mut series = Vec::new();
    for m in 0..members {
        let pts = |f: fn(&crate::train::kino::KinoCurvePoint) -> f64| {
            curve
                .iter()
                .filter(|p| p.member == m)
                .map(|p| [p.step as f64, f(p).max(1e-9).log10()])
                .collect()
        };
        series.push(LineSeries {
            name: format!("member {m} train"),
            points: pts(|p| p.train_loss),
        });
        series.push(LineSeries {
            name: format!("member {m} validation"),
            points: pts(|p| p.val_loss),
        });
    }
    let panel = LinePanel {
        title: format!("{name}: MSE of standardised targets"),
        x_label: "step".into(),
        y_label: "log10 MSE".into(),
        series,
        marks: vec![],
    };
    let img = line_chart_image(&panel, 720, 400).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, out).map_err(|e| e.to_string())
}
