//! `verti kino`: the learned kinodynamic models' accuracy against the bicycle model.

use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_kino::eval::{Predictor, evaluate, table};
use verti_kino::samples::KinoData;
use verti_kino::{Geometry, KinoFile, KinoModel};

#[derive(Subcommand)]
pub enum KinoCommand {
    /// One-step and open-loop prediction error per pose dimension and elevation level, for
    /// models and the kinematic bicycle, on a held-out dataset.
    Eval(KinoEvalArgs),
}

#[derive(Args)]
pub struct KinoEvalArgs {
    /// Model cards (YAML); repeatable. Default: every shipped model.
    #[arg(long = "model")]
    pub models: Vec<PathBuf>,
    /// Dataset directory (held out: not the one the models trained on).
    #[arg(long)]
    pub data: PathBuf,
    /// Open-loop horizon in model steps.
    #[arg(long, default_value_t = 10)]
    pub horizon: usize,
}

/// The bicycle geometry of the vehicle a dataset was driven with.
pub fn geometry_of(dir: &Path) -> Result<Geometry, String> {
    let m = verti_data::Manifest::read(dir).map_err(|e| e.to_string())?;
    let spec = crate::cli_common::load_vehicle(&m.vehicle)
        .map_err(|e| format!("{}: vehicle {}: {e}", dir.display(), m.vehicle))?;
    Ok(Geometry {
        wheelbase: spec.wheelbase() * m.worlds.scale,
        max_steer: spec.steering.max_angle_deg.to_radians(),
    })
}

pub fn run(cmd: KinoCommand) -> Result<(), Box<dyn std::error::Error>> {
    match cmd {
        KinoCommand::Eval(a) => {
            let files: Vec<Arc<KinoFile>> = if a.models.is_empty() {
                verti_kino::shipped::all()?
            } else {
                a.models
                    .iter()
                    .map(|p| KinoFile::load(p).map(Arc::new))
                    .collect::<Result<_, _>>()?
            };
            let geometry = geometry_of(&a.data)?;
            let mut results = Vec::new();
            let mut dt_world = 0.0;
            if a.horizon == 0 {
                return Err("--horizon must be at least 1 model step".into());
            }
            for f in files {
                let data = KinoData::load(&a.data, f.card.dt)?;
                dt_world = data.dt_world;
                // a prediction needs the step before it and `horizon` steps after it: with no
                // trajectory that long the table would be empty, which is no answer
                let longest = data.trajectories.iter().map(|t| t.poses.len()).max();
                if longest.is_none_or(|n| n < a.horizon + 2) {
                    return Err(format!(
                        "{}: no trajectory is long enough for --horizon {} at the model's {} s steps (the longest has {} steps, {} needed): use a shorter --horizon",
                        a.data.display(),
                        a.horizon,
                        f.card.dt,
                        longest.unwrap_or(0),
                        a.horizon + 2
                    )
                    .into());
                }
                results.push(evaluate(
                    &data,
                    &Predictor::Model(KinoModel::new(f)),
                    geometry,
                    a.horizon,
                ));
                if results.len() == 1 {
                    results.push(evaluate(&data, &Predictor::Bicycle, geometry, a.horizon));
                }
            }
            print!("{}", table(&results, dt_world));
            Ok(())
        }
    }
}
