//! `verti pietra`: the PIETRA maps as world sets, and the paper's navigation benchmark (§V-D,
//! Fig. 7) — risk-aware MPPI over six traversability models at three risk tolerances on the
//! ten test maps.

use crate::cli_common::load_vehicle;
use crate::progress::bar;
use clap::{Args, Subcommand};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::eval::{EvalSetup, RunInfo, evaluate};
use verti_bench::{EpisodeConfig, Outcome, TrialResult};
use verti_core::params::{ParamValue, Params};
use verti_pietra::maps::{self, Split};
use verti_render::{Panel, Series, grouped_bars_png};

#[derive(Subcommand)]
pub enum PietraCommand {
    /// Draw the 30 PIETRA maps (hillshade, the ten navigation tasks) as PNGs under --out. The
    /// maps live in memory: they are a function of their index, 50 m at 0.39 m (finer than
    /// verti's world format, which fixes 1 m cells at full scale).
    Maps(MapsArgs),
    /// The navigation benchmark: each method at each α on the test maps' 100 tasks.
    Navigate(NavigateArgs),
}

#[derive(Args)]
pub struct MapsArgs {
    #[arg(long, default_value = "worlds/pietra")]
    pub out: PathBuf,
}

#[derive(Args)]
pub struct NavigateArgs {
    /// Risk tolerances (paper: 0.4, 0.6, 0.8).
    #[arg(long, default_value = "0.4,0.6,0.8", value_delimiter = ',')]
    pub alpha: Vec<f64>,
    /// Methods: pietra, pietra-ood, evora, pi, vanilla, physics.
    #[arg(
        long,
        default_value = "pietra,pietra-ood,evora,pi,vanilla,physics",
        value_delimiter = ','
    )]
    pub methods: Vec<String>,
    /// Folder with the models `evora-v1.yaml`, `pi-v1.yaml`, `vanilla-v1.yaml` (and
    /// `pietra-v1.yaml`; the shipped one is used if absent).
    #[arg(long, default_value = "crates/verti-pietra/models")]
    pub models: PathBuf,
    /// Maximum speed, m/s. The paper's robot crawled at 1 m/s; the HMMWV stalls on rock at that
    /// speed (a first look at 10 test tasks with the physics prior: 4 reached at 1 m/s, 9 at 2
    /// m/s, the speed its data were driven at), so the default is 2.
    #[arg(long, default_value_t = 2.0)]
    pub speed: f64,
    /// Cost per rollout step on OOD terrain for the methods that avoid it.
    #[arg(long, default_value_t = 10.0)]
    pub w_ood: f64,
    /// Time limit per trial, s (40 m at up to 1 m/s).
    #[arg(long, default_value_t = 150.0)]
    pub max_time: f64,
    #[arg(long, default_value = "hmmwv")]
    pub vehicle: String,
    /// Parallel trials (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Continue runs already in --out.
    #[arg(long)]
    pub resume: bool,
    #[arg(long, default_value = "results/pietra-nav")]
    pub out: PathBuf,
    /// Task numbers of the test maps (default: all 100: 201-300).
    #[arg(long, default_value = "201-300")]
    pub tasks: String,
}

pub fn run(cmd: PietraCommand) -> Result<(), String> {
    match cmd {
        PietraCommand::Maps(a) => write_maps(&a),
        PietraCommand::Navigate(a) => navigate(&a),
    }
}

fn write_maps(a: &MapsArgs) -> Result<(), String> {
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    for split in Split::ALL {
        let mut relief = 0.0;
        for i in split.indices() {
            let w = maps::map(split, i);
            relief += maps::relief_std(&w) / f64::from(maps::PER_SPLIT);
            let path = a.out.join(format!("{}-{i:02}.png", split.name()));
            let options = verti_render::RenderOptions {
                show_tasks: split == Split::Test,
                show_paths: false,
                ..Default::default()
            };
            verti_render::render_world_png(&w, &options, &path).map_err(|e| e.to_string())?;
        }
        println!(
            "{}: maps {:?}, relief std {relief:.2} m on average → {}/{}-NN.png",
            split.name(),
            split.indices(),
            a.out.display(),
            split.name()
        );
    }
    Ok(())
}

/// The `pietra` parameters of a navigation method at risk tolerance α.
fn method_params(
    a: &NavigateArgs,
    method: &str,
    alpha: f64,
) -> Result<Vec<(String, ParamValue)>, String> {
    let model = |name: &str| -> Result<(String, ParamValue), String> {
        let p = a.models.join(format!("{name}-v1.yaml"));
        if !p.exists() {
            if name == "pietra" {
                return Ok(("model".into(), ParamValue::Path(PathBuf::new())));
            }
            return Err(format!(
                "{} is missing: train it with `verti learn pietra --method {name}`",
                p.display()
            ));
        }
        Ok(("model".into(), ParamValue::Path(p)))
    };
    let mut p = vec![
        ("alpha".to_string(), ParamValue::Float(alpha)),
        ("speed".to_string(), ParamValue::Float(a.speed)),
        // the goal itself, not a point on the way: the paper's time-to-goal objective
        ("lookahead".to_string(), ParamValue::Float(60.0)),
    ];
    match method {
        "pietra" => p.push(model("pietra")?),
        "pietra-ood" => {
            p.push(model("pietra")?);
            p.push(("w_ood".into(), ParamValue::Float(a.w_ood)));
        }
        "evora" => {
            p.push(model("evora")?);
            p.push(("w_ood".into(), ParamValue::Float(a.w_ood)));
        }
        "pi" | "vanilla" => p.push(model(method)?),
        "physics" => p.push(("prior_only".into(), ParamValue::Bool(true))),
        other => {
            return Err(format!(
                "--methods: unknown method `{other}` (known: pietra, pietra-ood, evora, pi, vanilla, physics)"
            ));
        }
    }
    Ok(p)
}

/// Success rate and the mean ± std time to goal of the successful trials.
fn summarise(results: &[TrialResult]) -> (f64, f64, f64) {
    let n = results.len().max(1) as f64;
    let times: Vec<f64> = results
        .iter()
        .filter(|r| r.outcome == Outcome::Success)
        .map(|r| r.time)
        .collect();
    let m = times.iter().sum::<f64>() / times.len().max(1) as f64;
    let sd =
        (times.iter().map(|t| (t - m).powi(2)).sum::<f64>() / times.len().max(1) as f64).sqrt();
    (
        100.0 * times.len() as f64 / n,
        if times.is_empty() { f64::NAN } else { m },
        if times.is_empty() { f64::NAN } else { sd },
    )
}

fn navigate(a: &NavigateArgs) -> Result<(), String> {
    let registry = crate::registries::systems();
    let info = registry.info("pietra").map_err(|e| e.to_string())?;
    let vehicle = load_vehicle(&a.vehicle).map_err(|e| e.to_string())?;
    let worlds: Vec<Arc<verti_world::World>> = maps::split_maps(Split::Test);
    let selection = verti_bench::eval::parse_tasks(&a.tasks).map_err(|e| e.to_string())?;
    let per_run = verti_bench::eval::select_tasks(&worlds, &selection)
        .map_err(|e| e.to_string())?
        .len();
    let jobs = a.jobs.unwrap_or_else(rayon::current_num_threads);
    let runs: Vec<(String, f64)> = a
        .methods
        .iter()
        .flat_map(|m| a.alpha.iter().map(move |x| (m.clone(), *x)))
        .collect();
    // every run's parameters first: a missing model fails now, not an hour in
    let mut resolved = Vec::new();
    for (m, alpha) in &runs {
        let pairs = method_params(a, m, *alpha)?;
        resolved.push(
            Params::resolve("pietra", info.params.clone(), &pairs).map_err(|e| e.to_string())?,
        );
    }
    let pb = bar((per_run * runs.len()) as u64, "navigating");
    let mut summary: Vec<(String, f64, (f64, f64, f64))> = Vec::new();
    for ((m, alpha), params) in runs.iter().zip(resolved) {
        pb.set_message(format!("{m} α {alpha}"));
        let out = a.out.join(format!("{m}-a{alpha}"));
        let inputs = |tasks: &[(usize, u32)]| {
            verti_bench::identity::system_inputs(&registry, "pietra", &params, &worlds, tasks)
        };
        let setup = EvalSetup {
            worlds: &worlds,
            whole_set: true,
            vehicle: &vehicle,
            episode: EpisodeConfig {
                max_time: a.max_time,
                ..Default::default()
            },
            jobs,
            out: out.clone(),
            resume: a.resume,
            force: !a.resume,
            run: RunInfo {
                system: "pietra".into(),
                params: params.clone(),
                vehicle: vehicle.name.clone(),
                worlds: "pietra-test".into(),
                scale: 1.0,
                rules: Default::default(),
                seed: 0,
                max_time: a.max_time,
            },
            inputs: Some(&inputs),
            shard: None,
            step_log: None,
            cancel: None,
            warn: None,
        };
        let make = || {
            registry
                .build("pietra", &params)
                .expect("built once already")
        };
        let results =
            evaluate(&setup, &selection, &make, &|_| pb.inc(1)).map_err(|e| e.to_string())?;
        let s = summarise(&results);
        pb.println(format!(
            "{m:<11} α {alpha}: success {:.0} %, time to goal {:.1} ± {:.1} s",
            s.0, s.1, s.2
        ));
        summary.push((m.clone(), *alpha, s));
    }
    pb.finish_and_clear();
    // the table and Fig. 7
    let mut md = String::from("| Method |");
    for x in &a.alpha {
        let _ = write!(md, " success α {x} | time to goal α {x} (s) |");
    }
    md.push_str("\n|---|");
    md.push_str(&"---|---|".repeat(a.alpha.len()));
    md.push('\n');
    for m in &a.methods {
        let _ = write!(md, "| {m} |");
        for x in &a.alpha {
            let (_, _, (succ, t, sd)) = summary
                .iter()
                .find(|(mm, xx, _)| mm == m && xx == x)
                .expect("every run summarised");
            let _ = write!(md, " {succ:.0} % | {t:.1} ± {sd:.1} |");
        }
        md.push('\n');
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    std::fs::write(a.out.join("table.md"), &md).map_err(|e| e.to_string())?;
    let panel =
        |title: &str, y: &str, pick: fn(&(f64, f64, f64)) -> (f64, f64), max: Option<f64>| Panel {
            title: title.into(),
            y_label: y.into(),
            y_max: max,
            // short labels: six groups of three bars share a 360 px panel
            groups: a
                .methods
                .iter()
                .map(|m| {
                    match m.as_str() {
                        "pietra" => "PIETRA",
                        "pietra-ood" => "+OOD",
                        "evora" => "EVORA",
                        "pi" => "PI",
                        "vanilla" => "Vanilla",
                        "physics" => "Prior",
                        other => other,
                    }
                    .to_string()
                })
                .collect(),
            series: a
                .alpha
                .iter()
                .map(|x| {
                    let vals: Vec<(f64, f64)> = a
                        .methods
                        .iter()
                        .map(|m| {
                            summary
                                .iter()
                                .find(|(mm, xx, _)| mm == m && xx == x)
                                .map_or((f64::NAN, f64::NAN), |(_, _, s)| pick(s))
                        })
                        .collect();
                    Series {
                        name: format!("α = {x}"),
                        values: vals.iter().map(|v| v.0).collect(),
                        errors: Some(vals.iter().map(|v| v.1).collect()),
                    }
                })
                .collect(),
        };
    let fig = a.out.join("fig7.png");
    grouped_bars_png(
        &[
            panel("Success rate", "%", |s| (s.0, f64::NAN), Some(100.0)),
            panel(
                "Time to goal (successful trials)",
                "s",
                |s| (s.1, s.2),
                None,
            ),
        ],
        2,
        &fig,
    )
    .map_err(|e| e.to_string())?;
    print!("{md}");
    println!("wrote {}/table.md and {}", a.out.display(), fig.display());
    Ok(())
}
