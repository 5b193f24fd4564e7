//! `verti sim compare REF_DIR`: re-runs the tasks of a reference engine's runs (e.g.
//! `../shared/chrono-reference`) in verti and compares them; writes a page per task and the
//! summary. The work is done by `verti-compare` and the drawing by `verti-render`.

use crate::cli_common::{CmdResult, load_vehicle};
use crate::progress::bar;
use clap::Args;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use verti_bench::Outcome;
use verti_compare::ensemble::run_ensemble;
use verti_compare::markdown::{engine_label, markdown};
use verti_compare::reference::Sample;
use verti_compare::{
    CompareSetup, Driver, RefTask, VertiRun, compare_task, load_worlds, read_reference, run_tasks,
    select_tasks, summarize,
};
use verti_render::{ComparePage, RunTrace};

/// Where the worlds are by default, relative to the current directory (a checkout's sibling).
const DEFAULT_VB_WORLDS: &str = "../shared/verti-bench-data/worlds";

#[derive(Args)]
pub struct CompareArgs {
    /// Reference folder: outcomes.jsonl and trajectories/world-NNN_pP.csv.
    reference: PathBuf,
    /// Folder of the original Verti-Bench worlds the reference names (configN_LEVEL.yaml, ...).
    #[arg(long, default_value = DEFAULT_VB_WORLDS)]
    vb_worlds: PathBuf,
    /// Output folder for one PNG per task, summary.md and summary.json.
    #[arg(long, default_value = "compare")]
    out: PathBuf,
    /// Tasks: all, or a comma list of W:P (world index:pair), W:* (every pair of world W), N or
    /// N-M (the N-th task of outcomes.jsonl, from 1).
    #[arg(long, default_value = "all")]
    tasks: String,
    /// Parallel trials (default: all cores). Results do not depend on it.
    #[arg(long)]
    jobs: Option<usize>,
    /// Print the summary as JSON instead of the Markdown tables.
    #[arg(long)]
    json: bool,
    /// Vehicle: a built-in name or a vehicle YAML file (e.g. a rigid-tyre variant).
    #[arg(long, default_value = "hmmwv")]
    vehicle: String,
    /// Who drives verti: `pid` (verti's PID with the reference's steering law, the reference
    /// README's set-up) or `reference` (the reference runs' own driver law: local goal by arc
    /// length along the path, steering input slewed at most 0.05 per 5 ms).
    #[arg(long, default_value = "pid", value_parser = parse_driver)]
    driver: Driver,
    /// Period of verti's inner loop in seconds (speed controller; a system acts at most this
    /// often). Default: the benchmark's 0.01; the reference steps every 0.005.
    #[arg(long)]
    inner_dt: Option<f64>,
    /// How verti's vehicle starts: `drop` (default: the reference's spawn, level and 1 m above
    /// the ground) or `settled` (the benchmark's default, at rest on the ground).
    #[arg(long, default_value = "drop", value_parser = parse_start)]
    start: verti_bench::StartMode,
    /// Runs per task: 1 (default) runs each task once; N > 1 adds N − 1 runs from starts up to
    /// --jitter metres away, and reports the agreement to expect and the ceiling the tasks'
    /// chaos sets on it (the pages show the first run).
    #[arg(long, default_value_t = 1)]
    ensemble: usize,
    /// Also write verti's trajectory of each task as `verti-world-NNN_pP.csv` in --out, in the
    /// reference's columns (t, x, y, z, roll, pitch, yaw, v, steer, throttle, brake, agl; agl is
    /// the chassis position's height above the ground), to set beside the reference's file,
    /// and each wheel at the same times as `verti-world-NNN_pP-wheels.csv` (t, v, wheel, spin
    /// omega, ground forces fx fy fz, gear, rpm: the columns of the Chrono harness's per-wheel
    /// log).
    #[arg(long)]
    csv: bool,
    /// Compare every selected task, including reference trials that record an artifact of the
    /// reference engine (a chassis more than one wheel diameter below the ground: it fell
    /// through the soil). By default they are left out of every table and listed.
    #[arg(long)]
    keep_artifacts: bool,
    /// Largest start offset of the ensemble's runs, metres.
    #[arg(long, default_value_t = verti_compare::ensemble::DEFAULT_JITTER)]
    jitter: f64,
}

fn parse_start(s: &str) -> Result<verti_bench::StartMode, String> {
    use verti_bench::StartMode;
    StartMode::from_name(s).ok_or_else(|| format!("unknown start `{s}`: use drop or settled"))
}

fn parse_driver(s: &str) -> Result<Driver, String> {
    Driver::from_name(s).ok_or_else(|| format!("unknown driver `{s}`: use pid or reference"))
}

pub fn compare(a: CompareArgs) -> CmdResult {
    let t0 = std::time::Instant::now();
    let jobs = a.jobs.unwrap_or_else(rayon::current_num_threads);
    verti_bench::eval::check_jobs(jobs, "--jobs")?;
    let reference = read_reference(&a.reference)?;
    let outcomes: Vec<_> = reference.tasks.iter().map(|t| t.outcome.clone()).collect();
    let chosen = select_tasks(&outcomes, &a.tasks)?;
    let vehicle = load_vehicle(&a.vehicle)?;
    if let Some(w) = verti_bench::identity::scale_mismatch(&vehicle, 1.0) {
        eprintln!("warning: {w}");
    }
    let mut setup = CompareSetup::reference(vehicle);
    setup.driver = a.driver;
    setup.episode.start = a.start;
    if let Some(dt) = a.inner_dt {
        setup.episode.inner_dt = dt;
    }
    setup
        .episode
        .validate()
        .map_err(|e| format!("--inner-dt: {e}"))?;
    if a.ensemble == 0 || a.ensemble > 1000 {
        return Err(format!("--ensemble {}: give 1 to 1000 runs per task", a.ensemble).into());
    }
    if !(a.jitter.is_finite() && a.jitter > 0.0 && a.jitter <= 10.0) {
        return Err(format!("--jitter {}: give a distance in (0, 10] metres", a.jitter).into());
    }
    let refs: Vec<&RefTask> = chosen.iter().map(|&i| &reference.tasks[i]).collect();
    let (refs, excluded) = if a.keep_artifacts {
        (refs, Vec::new())
    } else {
        let diameter = setup.vehicle.largest_wheel_diameter();
        verti_compare::artifact::split_artifacts(refs, diameter)
    };
    for x in &excluded {
        eprintln!(
            "left out {} pair {} ({}): {} (--keep-artifacts compares it)",
            x.world, x.pair, x.ground, x.reason
        );
    }
    if refs.is_empty() {
        return Err("every selected reference trial was left out as an artifact (--keep-artifacts compares them)".into());
    }
    let worlds = load_worlds(
        &a.vb_worlds,
        &a.reference,
        &refs.iter().map(|t| &t.outcome).collect::<Vec<_>>(),
        &setup,
    )?;
    let tasks: Vec<(u32, u32)> = refs
        .iter()
        .map(|t| (t.outcome.world_index, t.outcome.pair))
        .collect();
    let pb = bar(tasks.len() as u64, "verti runs");
    let t_runs = std::time::Instant::now();
    let runs = run_tasks(&worlds, &tasks, &setup, jobs, &|| pb.inc(1))?;
    pb.finish_and_clear();
    let run_seconds = t_runs.elapsed().as_secs_f64();
    let engine = refs[0].outcome.engine.clone();
    let label = engine_label(&engine);

    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let pb = bar(tasks.len() as u64, "drawing");
    refs.par_iter()
        .zip(&runs)
        .try_for_each(|(r, run)| -> Result<(), String> {
            let o = &r.outcome;
            let page = page(r, run, &label);
            let out = a
                .out
                .join(verti_compare::reference::trajectory_file_name(
                    o.world_index,
                    o.pair,
                ))
                .with_extension("png");
            verti_render::comparison_png(&worlds[&o.world_index], &page, &out)
                .map_err(|e| e.to_string())?;
            if a.csv {
                let name = verti_compare::reference::trajectory_file_name(o.world_index, o.pair);
                let text = verti_compare::reference::format_trajectory(&run.samples);
                write(&a.out.join(format!("verti-{name}")), &text)?;
                let wheels = verti_compare::run::format_wheels(&run.wheels);
                let stem = name.trim_end_matches(".csv");
                write(&a.out.join(format!("verti-{stem}-wheels.csv")), &wheels)?;
            }
            pb.inc(1);
            Ok(())
        })?;
    pb.finish_and_clear();

    let comparisons = refs
        .iter()
        .zip(&runs)
        .map(|(r, run)| compare_task(r, run))
        .collect();
    let mut summary = summarize(&setup, &engine, comparisons);
    summary.excluded = excluded;
    if a.ensemble > 1 {
        let members: Vec<_> = summary
            .tasks
            .iter()
            .map(|t| (t.world_index, t.pair, t.level, t.reference.outcome))
            .collect();
        let first: Vec<Outcome> = runs.iter().map(|r| r.result.outcome).collect();
        let pb = bar((members.len() * (a.ensemble - 1)) as u64, "ensemble runs");
        let t_ens = std::time::Instant::now();
        summary.ensemble = Some(run_ensemble(
            &worlds,
            &members,
            &first,
            &setup,
            a.ensemble,
            a.jitter,
            jobs,
            &|| pb.inc(1),
        )?);
        pb.finish_and_clear();
        eprintln!(
            "ensemble: {} more runs in {:.1} s",
            members.len() * (a.ensemble - 1),
            t_ens.elapsed().as_secs_f64()
        );
    }
    let md = markdown(&summary);
    let json = serde_json::to_string_pretty(&summary)?;
    write(&a.out.join("summary.md"), &md)?;
    write(&a.out.join("summary.json"), &json)?;
    if a.json {
        println!("{json}");
    } else {
        println!("{md}");
    }
    let simulated: f64 = runs.iter().map(|r| r.result.time).sum();
    eprintln!(
        "{}, {:.0} s simulated in {:.1} s on {} ({:.1} s in all); pages, summary.md and summary.json in {}",
        crate::cli_common::count(runs.len(), "task"),
        simulated,
        run_seconds,
        crate::cli_common::count(jobs, "job"),
        t0.elapsed().as_secs_f64(),
        a.out.display()
    );
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// `rollover, 8.6 s`
fn ending(outcome: Outcome, time: f64) -> String {
    format!("{}, {time:.1} s", outcome.name())
}

fn trace(name: &str, label: String, samples: &[Sample]) -> RunTrace {
    RunTrace {
        name: name.to_string(),
        label,
        times: samples.iter().map(|s| s.t).collect(),
        points: samples.iter().map(|s| [s.x, s.y]).collect(),
        roll: samples.iter().map(|s| s.roll).collect(),
        pitch: samples.iter().map(|s| s.pitch).collect(),
    }
}

/// The page of one task: the reference first (the first series colour), verti second.
fn page(r: &RefTask, run: &VertiRun, label: &str) -> ComparePage {
    let o = &r.outcome;
    let res = &run.result;
    let reference = ending(o.outcome, o.time);
    let verti = ending(res.outcome, res.time);
    ComparePage {
        title: format!(
            "{} pair {}   ·   {label}: {reference}   ·   verti ({}): {verti}",
            o.world, o.pair, res.vehicle
        ),
        pair: o.pair,
        runs: vec![
            trace(label, format!("{label}: {reference}"), &r.trajectory),
            trace("verti", format!("verti: {verti}"), &run.samples),
        ],
        roll_marks: vec![-30.0, 30.0],
        pixels_per_cell: 4,
    }
}
