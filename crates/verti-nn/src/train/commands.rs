//! What `verti learn swae` and `verti learn patch` do, as library functions: load the data,
//! train, export the network with its model card, draw the learning curve.

use crate::train::elev_maps::{AugmentedMaps, load_dir};
use crate::train::patches::{PatchSampler, PatchSettings};
use crate::train::seq::SeqNet;
use crate::train::swae::{SwaeConfig, SwaeReport, train};
use crate::{ModelCard, Network, TrainingInfo, WeightsInfo};
use burn::tensor::Device;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use verti_render::lines::{LinePanel, LineSeries, line_chart_image};

/// Where and how to train, common to both commands.
#[derive(Clone, Debug)]
pub struct RunSettings {
    pub config: SwaeConfig,
    /// Model name (`swae-v1`); the card is written to `out`, the weights beside it.
    pub name: String,
    pub out: PathBuf,
    /// The command line, recorded in the card.
    pub command: String,
}

/// What a training command reports.
#[derive(Clone, Debug)]
pub struct Trained {
    pub network: Network,
    pub report: SwaeReport,
    pub card_path: PathBuf,
    pub curve_png: PathBuf,
}

fn version() -> String {
    format!("verti {}", env!("CARGO_PKG_VERSION"))
}

fn settings_text(c: &SwaeConfig) -> String {
    format!(
        "Adam lr {} cosine to {}, batch {}, {} steps, widths {:?}, latent {}, {} projections, swd weight {}",
        c.lr, c.lr_final, c.batch, c.steps, c.widths, c.latent, c.projections, c.swd_weight
    )
}

/// Exports `net` under `run`'s name with a card, and writes it and its curve.
#[allow(clippy::too_many_arguments)]
fn export(
    run: &RunSettings,
    net: &SeqNet,
    summary: String,
    normalisation: String,
    data: String,
    report: &SwaeReport,
    metrics: BTreeMap<String, f64>,
    constants: BTreeMap<String, Vec<f64>>,
) -> Result<Trained, String> {
    let stem = run
        .out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("model")
        .to_string();
    let card = ModelCard {
        name: run.name.clone(),
        format: crate::card::CARD_FORMAT,
        summary,
        input: net.input_shape(),
        layers: net.layers().to_vec(),
        normalisation,
        weights: WeightsInfo {
            file: format!("{stem}.bin"),
            floats: 0,
            fnv1a64: String::new(),
        },
        training: TrainingInfo {
            data,
            command: run.command.clone(),
            seed: run.config.seed,
            steps: run.config.steps as u64,
            wall_time_s: (report.wall_time_s * 10.0).round() / 10.0,
            verti_version: version(),
            settings: settings_text(&run.config),
        },
        metrics,
        constants,
    };
    let network = Network::from_params(card, &net.export_params()).map_err(|e| e.to_string())?;
    network.save(&run.out).map_err(|e| e.to_string())?;
    let curve_png = run.out.with_file_name(format!("{stem}-curve.png"));
    draw_curve(report, &run.name, &curve_png)?;
    Ok(Trained {
        network,
        report: report.clone(),
        card_path: run.out.clone(),
        curve_png,
    })
}

fn draw_curve(report: &SwaeReport, name: &str, out: &Path) -> Result<(), String> {
    let series = |label: &str, f: fn(&crate::train::swae::CurvePoint) -> f64| LineSeries {
        name: label.into(),
        points: report
            .curve
            .iter()
            .map(|p| [p.step as f64, f(p).max(1e-9).log10()])
            .collect(),
    };
    let panel = LinePanel {
        title: format!("{name}: learning curve"),
        x_label: "step".into(),
        y_label: "log10".into(),
        series: vec![
            series("train loss", |p| p.train_loss),
            series("val MSE", |p| p.val_mse),
            series("val sliced W2^2", |p| p.val_swd),
        ],
        marks: vec![],
    };
    let img = line_chart_image(&panel, 720, 400).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, out).map_err(|e| e.to_string())
}

fn round(v: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (v * k).round() / k
}

/// Trains the terrain generator on Verti-Bench's elevation maps in `data_dir`.
pub fn learn_swae(
    run: &RunSettings,
    data_dir: &Path,
    val_fraction: f64,
    device: &Device,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<Trained, String> {
    let maps = load_dir(data_dir)?;
    if maps.side != run.config.side {
        return Err(format!(
            "{}: maps are {} x {}, the network takes {} x {}",
            data_dir.display(),
            maps.side,
            maps.side,
            run.config.side,
            run.config.side
        ));
    }
    let count = maps.maps.len();
    let (train_set, val_set) = maps.split(val_fraction, run.config.seed);
    let (mean, std) = train_set.moments();
    let val = val_set.standardised(mean, std);
    let (n_train, n_val) = (train_set.maps.len(), val_set.maps.len());
    let mut source = AugmentedMaps {
        set: train_set,
        mean,
        std,
    };
    let (model, report) = train(&run.config, &mut source, &val, device, progress)?;
    let last = report
        .curve
        .last()
        .copied()
        .expect("at least one evaluation");
    let metrics = BTreeMap::from([
        ("val_mse_standardised".to_string(), round(last.val_mse, 5)),
        (
            "val_rmse_fraction_of_max_height".to_string(),
            round(last.val_mse.sqrt() * std, 5),
        ),
        ("val_sliced_w2_to_prior".to_string(), round(last.val_swd, 5)),
        (
            "latent_std_mean".to_string(),
            round(
                report.latent_std.iter().sum::<f64>() / report.latent_std.len() as f64,
                4,
            ),
        ),
    ]);
    let constants = BTreeMap::from([
        ("fraction_mean".to_string(), vec![mean]),
        ("fraction_std".to_string(), vec![std]),
    ]);
    export(
        run,
        &model.decoder,
        "Decoder of a sliced-Wasserstein autoencoder trained on Verti-Bench's elevation maps: \
         z ~ N(0, I) in, a 128 x 128 terrain height map out. The elevation source `swae-v1` of \
         `verti world generate --elevation swae-v1`."
            .into(),
        "input: latent z (N(0, I) prior); output: standardised height, fraction of the \
         level's maximum height = fraction_mean + fraction_std * output, resampled to \
         129 x 129 (bicubic) and clamped to [0, 1]"
            .into(),
        format!(
            "{} ({count} Verti-Bench elevation maps, 128 x 128 grey, MIT): {n_train} for \
             training under the 8 rotations/mirrors of the square, {n_val} held out (seeded \
             split); no world of verti-100 or of the 80 original worlds",
            data_dir.display()
        ),
        &report,
        metrics,
        constants,
    )
}

/// Trains the local-patch encoder on crops from training worlds.
pub fn learn_patch(
    run: &RunSettings,
    patches: &PatchSettings,
    device: &Device,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<Trained, String> {
    let mut sampler = PatchSampler::new(patches, run.config.side)?;
    let val = sampler.validation(patches.validation_patches)?;
    let (model, report) = train(&run.config, &mut sampler, &val, device, progress)?;
    let last = report
        .curve
        .last()
        .copied()
        .expect("at least one evaluation");
    let metrics = BTreeMap::from([
        ("val_mse_normalised".to_string(), round(last.val_mse, 5)),
        (
            "val_rmse_m".to_string(),
            round(last.val_mse.sqrt() * patches.height_scale, 4),
        ),
        ("val_sliced_w2_to_prior".to_string(), round(last.val_swd, 5)),
    ]);
    let constants = BTreeMap::from([("height_scale".to_string(), vec![patches.height_scale])]);
    export(
        run,
        &model.encoder,
        "Encoder of a small sliced-Wasserstein autoencoder trained on heading-aligned 64 x 64 \
         elevation crops (0.1 m cells) under random poses of training worlds: the terrain \
         embedding (64 numbers) of learned systems, like Verti-Bench's BenchElev."
            .into(),
        format!(
            "input: 64 x 64 crop of terrain heights, row 0 ahead and column 0 left of the \
             vehicle, cells 0.1 m apart (verti_bench CropSpec {{ size: 64, resolution: 0.1 }}), \
             minus the height at the crop centre, divided by height_scale = {} m, clamped to \
             [-1, 1] (verti_nn::patch::normalise_patch); output: embedding, roughly N(0, I)",
            patches.height_scale
        ),
        format!(
            "crops from worlds {} (training) and {} (validation, {} crops); never verti-100",
            patches.train_worlds, patches.val_worlds, patches.validation_patches
        ),
        &report,
        metrics,
        constants,
    )
}
