//! `verti systems`, `verti eval`, `verti replay`.

use crate::cli_common::{CmdResult, ScaleArg, assignment, load_set_checked, load_vehicle};
use crate::outputs::ensure_parent;
use crate::progress::bar;
use clap::Args;
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::episode::{EpisodeLog, Outcome, Rules, StartMode};
use verti_bench::eval::{EvalSetup, RunInfo, evaluate, parse_tasks};
use verti_bench::identity::SplitRecord;
use verti_bench::{EpisodeConfig, run_episode};
use verti_registry::ReadySystem;
use verti_world::World;

pub fn systems_list() -> CmdResult {
    crate::registries::print_list(crate::registries::systems().list());
    Ok(())
}

fn parse_start(s: &str) -> Result<StartMode, String> {
    StartMode::from_name(s).ok_or_else(|| format!("unknown start `{s}`: use settled or drop"))
}

fn parse_rules(s: &str) -> Result<Rules, String> {
    match s {
        "paper" => Ok(Rules::Paper),
        "verti-bench" => Ok(Rules::VertiBench),
        other => Err(format!("unknown rules `{other}`: use paper or verti-bench")),
    }
}

#[derive(Args)]
pub struct EvalArgs {
    /// Mobility system (see `verti systems list`).
    #[arg(long, default_value = "pid")]
    system: String,
    /// System parameter override, name=value (repeatable); see `verti systems list`.
    #[arg(long = "param", value_parser = assignment)]
    params: Vec<String>,
    /// World set: verti-100 (built-in), a set directory, or a folder of Verti-Bench worlds.
    #[arg(long, default_value = "verti-100")]
    worlds: String,
    /// Task numbers, e.g. 1-1000, 5, 1,3,10-20, or all (default: every task of the set).
    #[arg(long, default_value = "all")]
    tasks: String,
    /// Vehicle: a built-in name or a vehicle YAML file (default: hmmwv; the 1/6 and 1/10 sets
    /// default to artcar and verti4).
    #[arg(long)]
    vehicle: Option<String>,
    #[command(flatten)]
    scale: ScaleArg,
    /// Parallel trials (default: all cores). Results do not depend on it.
    #[arg(long)]
    jobs: Option<usize>,
    /// Output directory (default: results/SYSTEM-SET).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Continue an interrupted run in --out, skipping finished tasks.
    #[arg(long)]
    resume: bool,
    /// Start over, discarding the results in --out.
    #[arg(long, conflicts_with = "resume")]
    force: bool,
    /// Success and failure rules: paper (default) or verti-bench (the reference code's).
    #[arg(long = "compat", default_value = "paper", value_parser = parse_rules)]
    rules: Rules,
    /// Time limit per trial, simulated seconds.
    #[arg(long, default_value_t = 60.0)]
    max_time: f64,
    /// How the vehicle starts: settled on the ground (default), or drop (Verti-Bench's spawn:
    /// level, 1 m above the ground, scaled, and dropped).
    #[arg(long, default_value = "settled", value_parser = parse_start)]
    start: StartMode,
    /// Run seed (systems with randomness derive their per-task seed from it).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Write a per-step Parquet log of every trial to OUT/steps/: `last10` keeps the last 10 s
    /// (what the failure-case dataset needs), `all` the whole trial.
    #[arg(long, value_parser = ["last10", "all"])]
    log_steps: Option<String>,
    /// Perception noise on what the system observes (never on the physics): none (default),
    /// low, medium, high, or a YAML file (see the guide docs/src/guides/perception.md).
    #[arg(long, default_value = "none")]
    perception: String,
    /// Run only shard i of N (0 <= i < N) of the selected tasks, for cluster array jobs;
    /// join the shards' directories with `verti merge`.
    #[arg(long, value_parser = verti_bench::shard::Shard::parse)]
    shard: Option<verti_bench::shard::Shard>,
}

/// The systems `--system` names: one name, a comma-separated list, or `all` (every registered
/// system except the privileged `oracle`, which reads the simulator and is an upper bound, not
/// a contestant).
fn system_names(spec: &str, registry: &verti_bench::SystemRegistry) -> Result<Vec<String>, String> {
    let names: Vec<String> = if spec == "all" {
        registry
            .list()
            .map(|i| i.name.clone())
            .filter(|n| n != "oracle")
            .collect()
    } else {
        spec.split(',').map(|s| s.trim().to_string()).collect()
    };
    if names.iter().any(|n| n.is_empty()) {
        return Err(format!("--system `{spec}`: an empty system name"));
    }
    Ok(names)
}

pub fn eval(a: EvalArgs) -> CmdResult {
    let registry = crate::registries::systems();
    let systems = system_names(&a.system, &registry)?;
    let several = systems.len() > 1;
    // every system's parameters, checked against its declarations before any work: a typo
    // fails now
    let mut resolved = Vec::new();
    for system in &systems {
        let info = registry.info(system)?;
        let given = a
            .params
            .iter()
            // with several systems, a parameter goes to those that declare it
            .filter(|p| {
                !several || {
                    let name = p.split('=').next().unwrap_or("");
                    info.params.iter().any(|s| s.name == name)
                }
            })
            .map(|p| registry.parse_param(system, p))
            .collect::<Result<Vec<_>, _>>()?;
        resolved.push(registry.resolve(system, &given)?);
    }
    if several {
        for p in &a.params {
            let name = p.split('=').next().unwrap_or("");
            let known = systems.iter().any(|s| {
                registry
                    .info(s)
                    .is_ok_and(|i| i.params.iter().any(|x| x.name == name))
            });
            if !known {
                return Err(format!(
                    "--param {p}: none of {} has a parameter `{name}`",
                    systems.join(", ")
                )
                .into());
            }
        }
    }
    // what only building checks (a model card that must load, a plan that must fit in memory,
    // the oracle's whole control periods), still before any work: each system's instance built
    // for it drives that system's first trial
    let ready = systems
        .iter()
        .zip(resolved)
        .map(|(system, params)| ReadySystem::new(&registry, system, params))
        .collect::<Result<Vec<_>, _>>()?;
    let perception = verti_bench::perception::PerceptionModel::load(&a.perception)
        .map_err(|e| format!("--perception: {e}"))?;
    // a selection of tasks needs only the worlds they are on (a shard of all tasks needs the
    // set to list them)
    let given = verti_bench::eval::parse_tasks(&a.tasks)?;
    let first_needed = if a.shard.is_some() && given.is_empty() {
        None
    } else {
        let mine = match &a.shard {
            Some(shard) => shard.select(&given),
            None => given,
        };
        match &a.out {
            // a resume there may need its recorded tasks' worlds too
            Some(dir) => systems
                .iter()
                .map(|s| {
                    let out = if several { dir.join(s) } else { dir.clone() };
                    verti_bench::run::worlds_to_load(&out, a.resume, a.force, &mine)
                })
                .collect::<Option<Vec<_>>>()
                .map(|each| each.into_iter().flatten().collect()),
            None => (!mine.is_empty()).then(|| verti_bench::run::task_worlds(&mine)),
        }
    };
    let (set, scale) = load_set_checked(&a.worlds, &a.scale, first_needed.as_ref())?;
    let vehicle_name = a
        .vehicle
        .clone()
        .unwrap_or_else(|| verti_sim::vehicles::default_for_scale(scale).to_string());
    let vehicle = load_vehicle(&vehicle_name)?;
    if let Some(w) = verti_bench::identity::scale_mismatch(&vehicle, scale) {
        eprintln!("warning: {w}");
    }
    let set_name = set.name.clone();
    let some_worlds = Loaded::new(set.worlds, first_needed.as_ref());
    let (selection, split) = shard_selection(&some_worlds.worlds, &a.tasks, a.shard)?;
    let per_system = verti_bench::eval::select_tasks(&some_worlds.worlds, &selection)?.len();
    // the whole set, loaded only when a system's run needs it (a resume of a run recorded
    // over the whole set)
    let mut whole: Option<Loaded> = None;
    // one progress display for the whole sequence
    let pb = bar((per_system * systems.len()) as u64, &systems.join(", "));
    for system in &ready {
        let out = match (&a.out, several) {
            (Some(dir), false) => dir.clone(),
            (Some(dir), true) => dir.join(system.name()),
            (None, _) => PathBuf::from("results").join(format!("{}-{set_name}", system.name())),
        };
        pb.set_message(system.name().to_string());
        let needed = verti_bench::run::worlds_to_load(&out, a.resume, a.force, &selection);
        let loaded = if some_worlds.holds(needed.as_ref()) {
            &some_worlds
        } else {
            if whole.is_none() {
                let (set, _) = load_set_checked(&a.worlds, &a.scale, None)?;
                whole = Some(Loaded::new(set.worlds, None));
            }
            whole.as_ref().expect("loaded above")
        };
        let shared = Shared {
            selection: &selection,
            perception: (!perception.is_none()).then(|| Arc::new(perception.clone())),
            worlds: &loaded.worlds,
            whole_set: loaded.whole,
            vehicle: &vehicle,
            scale,
            set_name: &set_name,
            pb: &pb,
            shard: split.clone(),
        };
        let lines = eval_system(&a, system, &shared, &out)?;
        for line in lines {
            // above the bar where there is one; plain stdout otherwise (logs, pipes)
            if pb.is_hidden() {
                println!("{line}");
            } else {
                pb.println(line);
            }
        }
    }
    pb.finish_and_clear();
    Ok(())
}

/// The task numbers a run covers: `--tasks`, cut to `--shard` where given (an explicit list,
/// so a shard's run.json records exactly its tasks and resumes them), and the split it is a
/// shard of (recorded, so that `verti merge` can check its shards cover the selection).
fn shard_selection(
    worlds: &[Arc<World>],
    tasks: &str,
    shard: Option<verti_bench::shard::Shard>,
) -> Result<(Vec<u32>, Option<SplitRecord>), verti_bench::eval::EvalError> {
    let selection = parse_tasks(tasks)?;
    let Some(shard) = shard else {
        return Ok((selection, None));
    };
    let all: Vec<u32> = if selection.is_empty() {
        verti_bench::eval::select_tasks(worlds, &[])?
            .into_iter()
            .map(|(wi, pair)| worlds[wi].task_id(pair).number())
            .collect()
    } else {
        selection
    };
    let mine = shard.select(&all);
    if mine.is_empty() {
        return Err(verti_bench::eval::EvalError::Argument(format!(
            "--shard {}/{}: no tasks (the selection has only {})",
            shard.index,
            shard.count,
            all.len()
        )));
    }
    let split = SplitRecord {
        index: shard.index,
        count: shard.count,
        of: verti_bench::eval::format_tasks(&all),
    };
    Ok((mine, Some(split)))
}

/// The worlds a run loaded: the whole set, or only the worlds of its tasks.
struct Loaded {
    worlds: Vec<Arc<World>>,
    whole: bool,
}

impl Loaded {
    /// `worlds` as loaded for `needed` (`None`: the whole set). A loader may return more than
    /// was asked (a saved set is read whole): those are kept only when it lacks a world asked
    /// for, so that the task check names the set's real range.
    fn new(worlds: Vec<World>, needed: Option<&BTreeSet<u32>>) -> Self {
        let (worlds, whole) = match needed {
            Some(n) => verti_world::sets::keep_worlds(worlds, n),
            None => (worlds, true),
        };
        Loaded {
            worlds: worlds.into_iter().map(Arc::new).collect(),
            whole,
        }
    }

    /// Whether these worlds serve a run that needs `needed`.
    fn holds(&self, needed: Option<&BTreeSet<u32>>) -> bool {
        match needed {
            None => self.whole,
            Some(n) => {
                self.whole
                    || n.iter()
                        .all(|i| self.worlds.iter().any(|w| w.meta.index == *i))
            }
        }
    }
}

/// What every system of one `verti eval` shares.
struct Shared<'a> {
    selection: &'a [u32],
    perception: Option<Arc<verti_bench::perception::PerceptionModel>>,
    worlds: &'a [Arc<World>],
    whole_set: bool,
    vehicle: &'a verti_sim::VehicleSpec,
    scale: f64,
    set_name: &'a str,
    pb: &'a indicatif::ProgressBar,
    /// The split the run is a shard of (`--shard`).
    shard: Option<SplitRecord>,
}

/// One system's evaluation; returns its summary lines.
fn eval_system(
    a: &EvalArgs,
    ready: &ReadySystem,
    sh: &Shared,
    out: &std::path::Path,
) -> Result<Vec<String>, verti_bench::eval::EvalError> {
    let (worlds, vehicle, scale, pb) = (sh.worlds, sh.vehicle, sh.scale, sh.pb);
    let (system, params) = (ready.name(), ready.params());
    let selection = sh.selection;
    let jobs = a.jobs.unwrap_or_else(rayon::current_num_threads);
    let episode = EpisodeConfig {
        rules: a.rules,
        max_time: a.max_time,
        seed: a.seed,
        start: a.start,
        perception: sh.perception.clone(),
        ..Default::default()
    };
    let warn = |m: &str| pb.println(format!("warning: {m}"));
    let steps_dir = out.join(verti_bench::eval::STEPS_DIR);
    let write_log = |r: &verti_bench::TrialResult, log: &EpisodeLog| {
        let path = steps_dir.join(verti_log::log_file_name(r.task));
        verti_log::write_steps(&path, r, &log.steps).map_err(|e| e.to_string())
    };
    let inputs = |tasks: &[(usize, u32)]| {
        verti_bench::identity::system_inputs(ready.registry(), system, params, worlds, tasks)
    };
    let setup = EvalSetup {
        worlds,
        whole_set: sh.whole_set,
        vehicle,
        episode,
        jobs,
        out: out.to_path_buf(),
        resume: a.resume,
        force: a.force,
        inputs: Some(&inputs),
        shard: sh.shard.clone(),
        run: RunInfo {
            system: system.to_string(),
            params: params.clone(),
            vehicle: vehicle.name.clone(),
            worlds: a.worlds.clone(),
            scale,
            rules: a.rules,
            seed: a.seed,
            max_time: a.max_time,
        },
        // `evaluate` creates the directory (and empties it on a fresh start)
        step_log: a
            .log_steps
            .as_deref()
            .map(|kind| verti_bench::eval::StepLogSink {
                seconds: if kind == "all" { f64::INFINITY } else { 10.0 },
                write: &write_log,
            }),
        cancel: None,
        warn: Some(&warn),
    };
    let make = || ready.make();
    let t0 = std::time::Instant::now();
    let results = evaluate(&setup, selection, &make, &|_| pb.inc(1))?;
    let wall = t0.elapsed().as_secs_f64();
    let count = |o: Outcome| results.iter().filter(|r| r.outcome == o).count();
    let n = results.len().max(1) as f64;
    let mut lines = vec![format!(
        "{} on {} with {} ({}, {}, {:.1} s): success {:.1}%  rollover {:.1}%  stuck {:.1}%  timeout {:.1}%  error {:.1}%",
        system,
        sh.set_name,
        vehicle.name,
        crate::cli_common::count(results.len(), "task"),
        crate::cli_common::count(jobs, "job"),
        wall,
        100.0 * count(Outcome::Success) as f64 / n,
        100.0 * count(Outcome::Rollover) as f64 / n,
        100.0 * count(Outcome::Stuck) as f64 / n,
        100.0 * count(Outcome::Timeout) as f64 / n,
        100.0 * count(Outcome::Error) as f64 / n,
    )];
    let sim_seconds: f64 = results.iter().map(|r| r.time).sum();
    lines.push(format!(
        "simulated {:.0} s in {:.1} s of wall time; results in {}",
        sim_seconds,
        wall,
        out.join("results.jsonl").display()
    ));
    for r in results
        .iter()
        .filter(|r| r.outcome == Outcome::Error)
        .take(5)
    {
        lines.push(format!(
            "  task {} ({}): {}",
            r.task,
            r.world_name,
            r.error.as_deref().unwrap_or("?")
        ));
    }
    Ok(lines)
}

#[derive(Args)]
pub struct ReplayArgs {
    /// A results directory written by `verti eval`.
    result: PathBuf,
    /// Task number to replay.
    #[arg(long)]
    task: u32,
    /// Output: a PNG (top view), or with --3d an HTML page.
    #[arg(long)]
    out: PathBuf,
    /// A 3-D recording instead: one self-contained HTML page (WebGL, no server) with the
    /// terrain, obstacles, vehicle body and wheels, path, trail and time series; or, with a
    /// .json --out, the recording itself (for `python -m verti.rerun`, Rerun's .rrd).
    #[arg(long = "3d")]
    three_d: bool,
    /// Pixels per heightfield cell.
    #[arg(long, default_value_t = 4)]
    px_per_cell: u32,
    /// The run's world set (as `verti eval --worlds`, or one world as SET:INDEX), at the run's
    /// scale and checked by content against the run's record; by default the set the run names.
    /// Needed for a run made on worlds held in memory (`verti.evaluate` on a list of worlds),
    /// whose record names no set.
    #[arg(long)]
    worlds: Option<String>,
}

/// Re-runs one task of an evaluation (trials are deterministic) with a per-step log and draws
/// its trajectory over the world, coloured by speed, with the failure point marked.
pub fn replay(a: ReplayArgs) -> CmdResult {
    let registry = crate::registries::systems();
    let by_name = |name: &str| load_vehicle(name).map_err(|e| e.to_string());
    use verti_bench::replay::ReplayWorlds;
    let worlds = a
        .worlds
        .clone()
        .map_or(ReplayWorlds::Recorded, ReplayWorlds::Named);
    let mut setup = verti_bench::replay::prepare(&a.result, a.task, &registry, &by_name, worlds)?;
    let (world, vehicle, pair) = (setup.world.clone(), setup.vehicle.clone(), setup.pair);
    let ext = a.out.extension().and_then(|e| e.to_str()).unwrap_or("");
    let three_d_file = ext == "html" || ext == "json";
    if !a.three_d && three_d_file {
        return Err(format!(
            "--out {}: an .{ext} output is a 3-D replay: pass --3d (or name the picture .png)",
            a.out.display()
        )
        .into());
    }
    if a.three_d {
        if !three_d_file {
            return Err(format!(
                "--out {}: a 3-D replay is an HTML page (.html) or its recording (.json)",
                a.out.display()
            )
            .into());
        }
        let (recording, replayed) =
            verti_view::record_trial(&world, &vehicle, pair, setup.system.as_mut(), &setup.cfg);
        if let Some(w) = setup.mismatch(&replayed) {
            eprintln!("warning: {w}");
        }
        let written = if ext == "json" {
            verti_view::write_json(&recording, &a.out)
        } else {
            verti_view::write_html(&recording, &a.out)
        };
        written.map_err(|e| format!("{}: {e}", a.out.display()))?;
        println!(
            "task {} ({} pair {pair}): {} after {:.1} s; {} frames in {}{}",
            a.task,
            world.meta.name,
            replayed.outcome.name(),
            replayed.time,
            recording.frames.len(),
            a.out.display(),
            if ext == "json" {
                " (a Rerun recording: python -m verti.rerun FILE.json FILE.rrd)"
            } else {
                " (open it in a browser)"
            }
        );
        return Ok(());
    }
    let cfg = EpisodeConfig {
        log_seconds: Some(f64::INFINITY),
        ..setup.cfg.clone()
    };
    let mut log = EpisodeLog::default();
    let replayed = run_episode(
        &world,
        &vehicle,
        pair,
        setup.system.as_mut(),
        &cfg,
        Some(&mut log),
    );
    if let Some(w) = setup.mismatch(&replayed) {
        eprintln!("warning: {w}");
    }
    use verti_bench::features::Feature;
    let value = |s: &verti_bench::episode::StepRecord, f: Feature| s.get(f).unwrap_or(f64::NAN);
    let points: Vec<[f64; 2]> = log
        .steps
        .iter()
        .map(|s| [value(s, Feature::X), value(s, Feature::Y)])
        .collect();
    let speeds: Vec<f64> = log
        .steps
        .iter()
        .map(|s| {
            let (vx, vy, vz) = (
                value(s, Feature::Vx),
                value(s, Feature::Vy),
                value(s, Feature::Vz),
            );
            (vx * vx + vy * vy + vz * vz).sqrt()
        })
        .collect();
    let options = verti_render::RenderOptions {
        pixels_per_cell: a.px_per_cell,
        pairs: Some(vec![pair]),
        ..Default::default()
    };
    let mut img = verti_render::render_world(&world, &options)?;
    let failure = (replayed.outcome != Outcome::Success)
        .then(|| points.last().copied())
        .flatten();
    let style = verti_render::TrajectoryStyle {
        failure,
        ..Default::default()
    };
    verti_render::draw_trajectory(&mut img, &points, &speeds, &style)?;
    ensure_parent(&a.out)?;
    img.save_png(&a.out)?;
    println!(
        "task {} ({} pair {pair}): {} after {:.1} s, {:.1} m driven; trajectory written to {}",
        a.task,
        world.meta.name,
        replayed.outcome.name(),
        replayed.time,
        replayed.path_length,
        a.out.display()
    );
    Ok(())
}

#[derive(Args)]
pub struct ReportArgs {
    /// Results: run directories written by `verti eval`, `.jsonl` files, or folders of runs.
    #[arg(required = true)]
    results: Vec<PathBuf>,
    /// Output directory for report.md, report.html, summary.json and fig6.png.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// Print the summary as JSON instead of writing files.
    #[arg(long)]
    json: bool,
}

/// Table I and Fig. 6 from one or more evaluation runs (several systems side by side).
pub fn report(a: ReportArgs) -> CmdResult {
    use verti_bench::report::{fig6_charts, html, load_results_from, markdown, summarize};
    let loaded = load_results_from(&a.results)?;
    for f in loaded.files.iter().filter(|f| !f.clean) {
        eprintln!(
            "warning: {}: dropped a torn last line (an interrupted run?)",
            f.path.display()
        );
    }
    if loaded.results.is_empty() {
        return Err("no trial results found in the given paths".into());
    }
    let summary = summarize(&loaded.results);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
        return Ok(());
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let panels: Vec<verti_render::Panel> = fig6_charts(&summary)
        .into_iter()
        .map(|p| verti_render::Panel {
            title: p.title,
            y_label: p.y_label,
            y_max: p.y_max,
            groups: p.groups,
            series: p
                .series
                .into_iter()
                .map(|x| verti_render::Series {
                    name: x.name,
                    values: x.values,
                    errors: x.errors,
                })
                .collect(),
        })
        .collect();
    verti_render::grouped_bars_png(&panels, 4, &a.out.join("fig6.png"))?;
    let md = markdown(&summary);
    let write = |name: &str, text: &str| {
        std::fs::write(a.out.join(name), text)
            .map_err(|e| format!("{}: {e}", a.out.join(name).display()))
    };
    write("report.md", &format!("{md}\n![Fig. 6](fig6.png)\n"))?;
    write(
        "report.html",
        &html(
            &summary,
            &[(
                "Fig. 6: success, traversal time, roll and pitch by elevation, terrain and density",
                "fig6.png",
            )],
        ),
    )?;
    write("summary.json", &serde_json::to_string_pretty(&summary)?)?;
    let mut pages = 0;
    if summary.systems.len() > 1 {
        for (i, s) in summary.systems.iter().enumerate() {
            if let Some(page) = verti_bench::report::system_page(&summary, i) {
                write(&verti_bench::report::system_page_name(&s.name), &page)?;
                pages += 1;
            }
        }
    }
    println!("{md}");
    println!(
        "report written to {} (report.md, report.html{}, summary.json, fig6.png)",
        a.out.display(),
        if pages > 0 {
            format!(" with {pages} per-system pages")
        } else {
            String::new()
        }
    );
    Ok(())
}
