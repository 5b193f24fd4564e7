//! `verti learn va`: loads the data, trains one model (VertiAdaptor or a baseline), writes
//! its card, weights, training log and learning curve.

use super::export::to_model;
use super::fit::{LogRow, TrainConfig, train};
use crate::VaModel;
use crate::data::VaData;
use crate::model::VaTraining;
use burn::tensor::Device;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use verti_render::lines::{LinePanel, LineSeries, line_chart_image};

/// Loads a dataset for VertiAdaptor, refusing data driven on evaluation worlds.
pub fn load_data(
    dir: &Path,
    dt: f64,
    what: &str,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<VaData, String> {
    let encoder = verti_nn::shipped::patch_v1()?;
    let data =
        VaData::load(dir, dt, &encoder, progress).map_err(|e| format!("{what} data: {e}"))?;
    verti_kino::train::kino_command::refuse_eval_worlds(what, dir, data.eval_worlds, &data.set)?;
    Ok(data)
}

/// One training run.
pub struct VaRun {
    pub data: PathBuf,
    pub val: PathBuf,
    /// Card to write (weights, log and curve beside it).
    pub out: PathBuf,
    pub config: TrainConfig,
    pub command: String,
}

pub struct VaTrained {
    pub model: VaModel,
    pub log: Vec<LogRow>,
    pub wall_s: f64,
    pub curve_png: PathBuf,
}

fn summary(run: &VaRun) -> String {
    let s = &run.config.spec;
    let what = match s.method {
        crate::Method::Va => format!(
            "VertiAdaptor: {} neural-ODE basis fields (RK4, {} s), coefficients by least squares",
            s.bases, s.dt
        ),
        crate::Method::Node => "neural ODE baseline: one field integrated with RK4".into(),
        crate::Method::Mlp => "MLP baseline: one network predicting the change".into(),
        crate::Method::Maml => "first-order MAML baseline: meta-learned initial weights of one network predicting the change".into(),
    };
    let ablation = match (s.elevation, s.semantics) {
        (true, true) => "",
        (false, true) => " (ablation: without elevation)",
        (true, false) => " (ablation: without semantics)",
        (false, false) => " (ablation: without both embeddings)",
    };
    format!("{what}{ablation}; fields {:?} hidden, ReLU", s.hidden)
}

/// Trains and writes one model.
pub fn learn_va(
    run: &VaRun,
    device: &Device,
    progress: &mut dyn FnMut(usize, f64),
    loading: &(dyn Fn(usize, usize) + Sync),
) -> Result<VaTrained, String> {
    run.config.validate()?;
    let dt = run.config.spec.dt;
    let data = load_data(&run.data, dt, "training", loading)?;
    let val = load_data(&run.val, dt, "validation", loading)?;
    if data.vehicle != val.vehicle {
        return Err(format!(
            "training data drove {}, validation data {}",
            data.vehicle, val.vehicle
        ));
    }
    let trained = train(&data, &val, &run.config, device, progress)?;
    let name = run
        .out
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| format!("{}: not a card file name", run.out.display()))?
        .to_string();
    let last = trained.log.last().cloned();
    let mut metrics = BTreeMap::new();
    if let Some(l) = &last {
        metrics.insert("train_loss".to_string(), l.train_loss);
        metrics.insert("val_loss".to_string(), l.val_loss);
    }
    let training = VaTraining {
        data: run.data.display().to_string(),
        worlds: format!(
            "{} ({} trajectories in {} worlds); validation {} ({})",
            data.set,
            data.trajectories.len(),
            data.worlds.len(),
            val.set,
            run.val.display()
        ),
        command: run.command.clone(),
        seed: run.config.seed,
        steps: run.config.steps,
        wall_time_s: (trained.wall_s * 10.0).round() / 10.0,
        verti_version: env!("CARGO_PKG_VERSION").to_string(),
        settings: format!("{:?}", run.config),
    };
    let mut model = to_model(
        &trained.net,
        &name,
        &summary(run),
        run.config.lambda,
        &data,
        training,
        metrics,
    )?;
    model.save(&run.out).map_err(|e| e.to_string())?;
    let dir = run.out.parent().unwrap_or(Path::new("."));
    let csv: String = std::iter::once("step,train_loss,val_loss\n".to_string())
        .chain(
            trained
                .log
                .iter()
                .map(|r| format!("{},{},{}\n", r.step, r.train_loss, r.val_loss)),
        )
        .collect();
    let csv_path = dir.join(format!("{name}-log.csv"));
    std::fs::write(&csv_path, csv).map_err(|e| format!("{}: {e}", csv_path.display()))?;
    let curve_png = dir.join(format!("{name}-curve.png"));
    let pts = |f: fn(&LogRow) -> f64| -> Vec<[f64; 2]> {
        trained
            .log
            .iter()
            .map(|r| [r.step as f64, f(r).max(1e-9).log10()])
            .collect()
    };
    let panel = LinePanel {
        title: format!("{name}: training loss (mean squared error)"),
        x_label: "step".into(),
        y_label: "log10 loss".into(),
        series: vec![
            LineSeries {
                name: "train".into(),
                points: pts(|r| r.train_loss),
            },
            LineSeries {
                name: "validation".into(),
                points: pts(|r| r.val_loss),
            },
        ],
        marks: vec![],
    };
    let img = line_chart_image(&panel, 720, 400).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, &curve_png).map_err(|e| e.to_string())?;
    Ok(VaTrained {
        model,
        log: trained.log,
        wall_s: trained.wall_s,
        curve_png,
    })
}
