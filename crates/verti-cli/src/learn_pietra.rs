//! `verti learn pietra --benchmark` (with the `learn` feature): PIETRA's learning benchmark —
//! drive the 30 PIETRA maps, train every method over the paper's grid and seeds, and write
//! Table I, Table II, every run and Fig. 6.
//!
//! Runs train in worker processes (this same binary with a hidden `--worker K/N`): burn's
//! autodiff registers every operation under one process-wide lock, so threads of one process
//! barely overlap while processes scale with the cores. Worker K trains runs K, K+N, ... of
//! the grid and appends each finished run to `OUT/runs/runs-K.jsonl`; the parent follows the
//! files for its progress bar and builds the tables from them, so a killed benchmark resumes
//! (`--resume`) with every finished run kept.

use crate::cli_common::load_vehicle;
use crate::learn_args::PietraArgs;
use crate::progress::bar;
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use verti_nn::train::Device;
use verti_pietra::dataset::DataConfig;
use verti_pietra::maps;
use verti_pietra::prior::PriorConfig;
use verti_pietra::train::bench::{
    Grid, RunScores, density_markdown, figure6, markdown, runs_csv, score, tables, wall_by_method,
};
use verti_pietra::train::data::PietraData;
use verti_pietra::train::fit::RunConfig;
use verti_pietra::train::model::Method;

fn methods(spec: &str) -> Result<Vec<Method>, String> {
    if spec == "all" {
        return Ok(Method::ALL.to_vec());
    }
    spec.split(',')
        .map(|s| {
            Method::from_name(s.trim()).ok_or_else(|| {
                format!(
                    "--methods: unknown method `{s}` (known: {})",
                    Method::ALL.map(Method::name).join(", ")
                )
            })
        })
        .collect()
}

/// A run's identity in the grid (its configuration, printed exactly).
fn key(c: &RunConfig) -> String {
    format!(
        "{}|{:e}|{:e}|{:e}|{}|{}|{}",
        c.method.name(),
        c.lr,
        c.weights.physics,
        c.weights.entropy,
        c.seed,
        c.steps,
        c.batch
    )
}

/// Every finished run in `dir` (a torn last line of a killed worker is skipped).
fn read_runs(dir: &Path) -> Result<Vec<RunScores>, String> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(out);
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "jsonl"))
        .collect();
    files.sort();
    for f in files {
        let text = std::fs::read_to_string(&f).map_err(|e| format!("{}: {e}", f.display()))?;
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            if let Ok(r) = serde_json::from_str::<RunScores>(line) {
                out.push(r);
            }
        }
    }
    Ok(out)
}

fn build_data(a: &PietraArgs, report: &mut dyn FnMut(String)) -> Result<PietraData, String> {
    let vehicle = load_vehicle(&a.vehicle).map_err(|e| e.to_string())?;
    let cfg = DataConfig {
        trials_per_map: a.trials_per_map,
        seed: a.data_seed,
        ..DataConfig::paper(vehicle)
    };
    PietraData::build(&cfg, PriorConfig::default(), &mut |split, d| {
        report(format!(
            "{:<10} maps {:?}: {} trials, {:.0} s driven, {} samples, endings {:?}",
            split.name(),
            split.indices(),
            d.trials,
            d.seconds,
            d.samples.len(),
            d.endings
        ))
    })
}

fn grid_of(a: &PietraArgs) -> Grid {
    Grid {
        seeds: (0..a.seeds as u64).collect(),
        ..Grid::paper(a.steps)
    }
}

/// The hyper-parameters the learning benchmark chose for each method (lowest mean validation
/// EMD² over 5 seeds; `results/pietra-bench/tables.md`): (lr, κ, entropy weight).
fn chosen(method: Method) -> (f64, f64, f64) {
    match method {
        Method::Pietra => (1e-3, 0.1, 1e-4),
        Method::Evora => (1e-4, 0.0, 1e-5),
        Method::Vanilla => (1e-4, 0.0, 0.0),
        Method::Pi => (1e-4, 0.1, 0.0),
        Method::UpiOnly => (1e-3, 0.1, 1e-5),
        Method::PpOnly => (1e-3, 0.0, 1e-5),
    }
}

/// Trains one model for the planner and writes its card and networks.
fn train_one(a: &PietraArgs, command: &str, device: &Device) -> Result<(), String> {
    let method = Method::from_name(&a.method).ok_or_else(|| {
        format!(
            "--method: unknown method `{}` (known: {})",
            a.method,
            Method::ALL.map(Method::name).join(", ")
        )
    })?;
    let (lr, kappa, entropy) = chosen(method);
    let cfg = RunConfig {
        method,
        lr: a.lr.unwrap_or(lr),
        weights: verti_pietra::train::model::LossWeights {
            physics: a.kappa.unwrap_or(kappa),
            entropy: a.entropy.unwrap_or(entropy),
        },
        seed: a.seed,
        steps: a.steps,
        batch: 256,
    };
    let out = a.model_out.clone().unwrap_or_else(|| {
        PathBuf::from(format!(
            "crates/verti-pietra/models/{}-v1.yaml",
            method.name()
        ))
    });
    let name = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("pietra-v1")
        .to_string();
    let data = build_data(a, &mut |line| println!("{line}"))?;
    let info = verti_pietra::train::export::ExportInfo {
        name,
        command: command.to_string(),
        data: format!(
            "PIETRA maps {:?} (training, {} ID samples) and {:?} (validation, {} ID samples), \
             {} trials per map with sinusoidal steering at 2 m/s, data seed {}; test maps {:?}; \
             never verti-100",
            maps::Split::Train.indices(),
            data.train.n,
            maps::Split::Validation.indices(),
            data.val.n,
            a.trials_per_map,
            a.data_seed,
            maps::Split::Test.indices()
        ),
    };
    let model = verti_pietra::train::export::train_model(&data, &cfg, &info, device)?;
    model.save(&out)?;
    println!(
        "wrote {} ({} networks beside it); {:?}; {:.1} s",
        out.display(),
        model.networks.len(),
        model.card.metrics,
        model.card.training.wall_time_s
    );
    Ok(())
}

/// Worker `k` of `n`: trains its share of the runs not yet finished.
fn work(a: &PietraArgs, spec: &str, device: &Device) -> Result<(), String> {
    let (k, n) = spec
        .split_once('/')
        .and_then(|(k, n)| Some((k.parse::<usize>().ok()?, n.parse::<usize>().ok()?)))
        .filter(|(k, n)| k < n)
        .ok_or_else(|| format!("--worker {spec}: expected K/N with K < N"))?;
    // one run at a time per worker: the parallelism is the processes
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global();
    let dir = a.out.join("runs");
    let done: BTreeSet<String> = read_runs(&dir)?.iter().map(|r| key(&r.config)).collect();
    let data = build_data(a, &mut |_| {})?;
    let grid = grid_of(a);
    let mine: Vec<RunConfig> = methods(&a.methods)?
        .iter()
        .flat_map(|m| grid.runs(*m))
        .enumerate()
        .filter(|(i, c)| i % n == k && !done.contains(&key(c)))
        .map(|(_, c)| c)
        .collect();
    let path = dir.join(format!("runs-{k}.jsonl"));
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    for cfg in mine {
        match score(&data, &cfg, device) {
            Ok(r) => {
                let line = serde_json::to_string(&r).map_err(|e| e.to_string())?;
                writeln!(file, "{line}").map_err(|e| format!("{}: {e}", path.display()))?;
            }
            // a diverged configuration is reported and left out of the tables
            Err(e) => eprintln!("{e}"),
        }
    }
    Ok(())
}

pub fn run(a: &PietraArgs, command: &str, device: &Device) -> Result<(), String> {
    if a.seeds == 0 || a.steps == 0 {
        return Err("--seeds and --steps must be at least 1".into());
    }
    if let Some(spec) = &a.worker {
        return work(a, spec, device);
    }
    if !a.benchmark {
        return train_one(a, command, device);
    }
    let methods = methods(&a.methods)?;
    let dir = a.out.join("runs");
    if dir.exists() && !a.resume {
        std::fs::remove_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    // 1. the data (each worker drives the same maps again: 5 s, cheaper than shipping it)
    let started = std::time::Instant::now();
    let data = build_data(a, &mut |line| println!("{line}"))?;
    let data_s = started.elapsed().as_secs_f64();
    let ood = (0..data.test.n)
        .filter(|&i| !data.test.is_id(i, data.threshold))
        .count();
    println!(
        "ID/OOD boundary {:.3} m (median training unevenness); {} training, {} validation (ID \
         only), {} test samples ({:.0} % OOD); data in {data_s:.0} s",
        data.threshold,
        data.train.n,
        data.val.n,
        data.test.n,
        100.0 * ood as f64 / data.test.n.max(1) as f64
    );
    // 2. the sweep, in worker processes
    let grid = grid_of(a);
    let wanted: BTreeSet<String> = methods
        .iter()
        .flat_map(|m| grid.runs(*m))
        .map(|c| key(&c))
        .collect();
    let workers = a
        .workers
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .clamp(1, wanted.len().max(1));
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this program: {e}"))?;
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    args.push("--resume".into());
    let mut children = Vec::new();
    for k in 0..workers {
        let log = dir.join(format!("worker-{k}.log"));
        let log = std::fs::File::create(&log).map_err(|e| format!("{}: {e}", log.display()))?;
        let child = std::process::Command::new(&exe)
            .args(&args)
            .arg("--worker")
            .arg(format!("{k}/{workers}"))
            .stdout(std::process::Stdio::null())
            .stderr(log)
            .spawn()
            .map_err(|e| format!("cannot start worker {k}: {e}"))?;
        children.push(child);
    }
    let count = || {
        read_runs(&dir).map_or(0, |r| {
            r.iter()
                .filter(|r| wanted.contains(&key(&r.config)))
                .count()
        })
    };
    let pb = bar(wanted.len() as u64, "training");
    let sweep_started = std::time::Instant::now();
    loop {
        pb.set_position(count() as u64);
        let mut running = false;
        for c in &mut children {
            if c.try_wait().map_err(|e| e.to_string())?.is_none() {
                running = true;
            }
        }
        if !running {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(500));
    }
    pb.finish_and_clear();
    for (k, c) in children.iter_mut().enumerate() {
        let status = c.wait().map_err(|e| e.to_string())?;
        let log = std::fs::read_to_string(dir.join(format!("worker-{k}.log"))).unwrap_or_default();
        if !status.success() {
            return Err(format!(
                "worker {k} failed ({status}): {}",
                log.lines().last().unwrap_or("no message")
            ));
        }
        for line in log.lines() {
            eprintln!("worker {k}: {line}");
        }
    }
    let sweep_s = sweep_started.elapsed().as_secs_f64();
    // 3. the tables, every run and Fig. 6
    let mut runs: Vec<RunScores> = Vec::new();
    let mut seen = BTreeSet::new();
    for r in read_runs(&dir)? {
        let k = key(&r.config);
        if wanted.contains(&k) && seen.insert(k) {
            runs.push(r);
        }
    }
    // grid order, whatever order the workers finished in
    let order: Vec<String> = methods
        .iter()
        .flat_map(|m| grid.runs(*m))
        .map(|c| key(&c))
        .collect();
    runs.sort_by_key(|r| order.iter().position(|k| *k == key(&r.config)));
    let result = tables(&data, runs, &methods)?;
    let t1 = markdown(&result.table1);
    let t2 = markdown(&result.table2);
    figure6(&result, data.threshold, &a.out.join("fig6.png"))?;
    let mut report = String::new();
    let _ = writeln!(
        report,
        "# PIETRA learning benchmark\n\n`{command}`\n\nEMD² of the expected PMF against the \
         one-hot target, **summed over the four parameters** (linear traction, angular \
         traction, roll, pitch); the per-parameter column is the sum / 4. Test maps {:?} \
         (vertical scale x{}); ID/OOD boundary {:.3} m. Mean ± std over {} seeds of the \
         configuration with the lowest mean validation EMD²; {} steps of batch {} per run. \
         Trained on maps {:?} (ID samples), validated on maps {:?} (ID samples).\n",
        maps::Split::Test.indices(),
        maps::TEST_SCALE,
        data.threshold,
        a.seeds,
        a.steps,
        grid.batch,
        maps::Split::Train.indices(),
        maps::Split::Validation.indices(),
    );
    let _ = writeln!(report, "## Table I\n\n{t1}\n## Table II\n\n{t2}");
    let _ = writeln!(
        report,
        "## What the flows see\n\nOOD is defined by unevenness; the evidence comes from the \
         latent density. Seeds' mean for each chosen configuration:\n\n{}",
        density_markdown(&result.table1)
    );
    let _ = writeln!(
        report,
        "Wall time: data {data_s:.0} s, sweep {sweep_s:.0} s with {workers} workers ({} runs); \
         mean per run: {}",
        result.runs.len(),
        wall_by_method(&result.runs)
            .iter()
            .map(|(m, s)| format!("{m} {s:.1} s"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let write = |name: &str, text: &str| {
        let p = a.out.join(name);
        std::fs::write(&p, text).map_err(|e| format!("{}: {e}", p.display()))
    };
    write("tables.md", &report)?;
    write("runs.csv", &runs_csv(&result.runs))?;
    print!("{report}");
    println!("wrote {}/tables.md, runs.csv, fig6.png", a.out.display());
    Ok(())
}
