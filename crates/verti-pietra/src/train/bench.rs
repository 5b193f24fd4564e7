//! PIETRA's learning benchmark (paper §V-B, §V-C): every method over its hyper-parameter grid
//! and five seeds, the best configuration per method chosen by mean validation EMD², and Table
//! I, Table II and Fig. 6 written from the test scores of that configuration.
//!
//! Runs are independent and seeded, so they train in parallel (rayon) and are gathered in grid
//! order: results do not depend on the thread count.

use super::data::{PietraData, Prepared};
use super::fit::{
    RunConfig, SampleErrors, Scores, physics_if_ood, physics_pmf, train, train_log_density_min,
    uniform_errors,
};
use super::model::{LossWeights, Method};
use burn::tensor::Device;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Mutex;

/// The grid (paper §V-B).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub lrs: Vec<f64>,
    pub physics: Vec<f64>,
    pub entropy: Vec<f64>,
    pub seeds: Vec<u64>,
    pub steps: usize,
    pub batch: usize,
}

impl Grid {
    /// lr {1e-3, 1e-4, 1e-5}, κ {0.1, 0.5, 1.0}, entropy weight {1e-3, 1e-4, 1e-5}, 5 seeds.
    pub fn paper(steps: usize) -> Grid {
        Grid {
            lrs: vec![1e-3, 1e-4, 1e-5],
            physics: vec![0.1, 0.5, 1.0],
            entropy: vec![1e-3, 1e-4, 1e-5],
            seeds: (0..5).collect(),
            steps,
            batch: 256,
        }
    }

    /// Every run of `method`, grouped by configuration (seeds innermost).
    pub fn runs(&self, method: Method) -> Vec<RunConfig> {
        let kappas: &[f64] = if method.physics_in_loss() {
            &self.physics
        } else {
            &[0.0]
        };
        let ents: &[f64] = if method.evidential() {
            &self.entropy
        } else {
            &[0.0]
        };
        let mut out = Vec::new();
        for &lr in &self.lrs {
            for &physics in kappas {
                for &entropy in ents {
                    for &seed in &self.seeds {
                        out.push(RunConfig {
                            method,
                            lr,
                            weights: LossWeights { physics, entropy },
                            seed,
                            steps: self.steps,
                            batch: self.batch,
                        });
                    }
                }
            }
        }
        out
    }
}

/// A run's scores, aggregated so that runs from other processes can be merged: mean EMD²
/// overall / ID / OOD, per parameter, and per unevenness bin of Fig. 6.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunScores {
    pub config: RunConfig,
    pub val: f64,
    pub test: Aggregate,
    pub wall_s: f64,
    pub final_loss: f64,
    /// For EVORA runs: the same network with the physics model where OOD.
    pub phys_if_ood: Option<Aggregate>,
    /// For evidential methods: how the flow's density sees the test samples.
    pub density: Option<DensityStats>,
}

/// Whether the flow's density separates the (unevenness-defined) OOD test samples from the
/// training data: the mean latent log-density of ID and OOD test samples, and the fraction of
/// test samples below the lowest training density (what "use the physics model if OOD" flags).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DensityStats {
    pub train_min: f64,
    #[serde(with = "super::fit::nan_as_null")]
    pub test_id_mean: f64,
    #[serde(with = "super::fit::nan_as_null")]
    pub test_ood_mean: f64,
    pub flagged: f64,
}

/// A set of per-sample errors reduced to what the tables and Fig. 6 need.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aggregate {
    pub scores: Scores,
    pub per_param: [f64; 4],
    #[serde(with = "super::fit::nan_as_null::vec")]
    pub by_bin: Vec<f64>,
}

impl Aggregate {
    pub fn of(errors: &SampleErrors, data: &PietraData, edges: &[f64]) -> Aggregate {
        let mut per_param = [0.0; 4];
        let n = errors.per_param.len().max(1) as f64;
        for p in &errors.per_param {
            for (acc, v) in per_param.iter_mut().zip(p) {
                *acc += v / n;
            }
        }
        Aggregate {
            scores: errors.scores(&data.test, data.threshold),
            per_param,
            by_bin: by_bin(errors, &data.test, edges),
        }
    }
}

/// One table row: a method's mean ± std over seeds of its chosen configuration.
#[derive(Clone, Debug)]
pub struct Row {
    pub name: String,
    pub overall: (f64, f64),
    pub id: (f64, f64),
    pub ood: (f64, f64),
    /// Per-parameter mean test EMD² (the seeds' mean).
    pub per_param: [f64; 4],
    /// The configuration, e.g. "lr 1e-4, κ 0.1, entropy 1e-4"; empty for fixed priors.
    pub config: String,
    pub val: f64,
    /// Mean test error per unevenness bin (Fig. 6).
    pub by_bin: Vec<f64>,
    /// The seeds' mean density statistics (evidential methods).
    pub density: Option<DensityStats>,
}

/// What the benchmark produced.
pub struct BenchResult {
    pub runs: Vec<RunScores>,
    pub table1: Vec<Row>,
    pub table2: Vec<Row>,
    /// Edges of the unevenness bins of Fig. 6, metres.
    pub bin_edges: Vec<f64>,
    pub wall_s: f64,
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    let s = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt();
    (m, s)
}

/// Trains and scores one configuration.
pub fn score(data: &PietraData, cfg: &RunConfig, device: &Device) -> Result<RunScores, String> {
    let t = train(data, cfg, device)?;
    let edges = bin_edges(&data.test);
    let min = cfg
        .method
        .evidential()
        .then(|| train_log_density_min(&t.net, data, device));
    let phys_if_ood = min
        .filter(|_| cfg.method == Method::Evora)
        .map(|min| Aggregate::of(&physics_if_ood(&t.test, &data.test, min), data, &edges));
    let density = min.map(|train_min| {
        let d = &t.test.log_density;
        let mean = |id: bool| {
            let v: Vec<f64> = (0..data.test.n)
                .filter(|&i| data.test.is_id(i, data.threshold) == id)
                .map(|i| d[i])
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        DensityStats {
            train_min,
            test_id_mean: mean(true),
            test_ood_mean: mean(false),
            flagged: d.iter().filter(|v| **v < train_min).count() as f64 / d.len().max(1) as f64,
        }
    });
    Ok(RunScores {
        config: *cfg,
        val: t.val.scores(&data.val, data.threshold).overall,
        test: Aggregate::of(&t.test, data, &edges),
        wall_s: t.wall_s,
        final_loss: t.final_loss,
        phys_if_ood,
        density,
    })
}

/// Unevenness bins of Fig. 6: ten equal-count bins of the test samples.
pub fn bin_edges(test: &Prepared) -> Vec<f64> {
    let mut u = test.unevenness.clone();
    u.sort_by(f64::total_cmp);
    if u.is_empty() {
        return vec![0.0, 1.0];
    }
    (0..=10)
        .map(|k| u[((k * (u.len() - 1)) as f64 / 10.0).round() as usize])
        .collect()
}

fn by_bin(errors: &SampleErrors, test: &Prepared, edges: &[f64]) -> Vec<f64> {
    let nb = edges.len() - 1;
    let (mut sum, mut n) = (vec![0.0; nb], vec![0usize; nb]);
    for (i, v) in errors.total.iter().enumerate() {
        let u = test.unevenness[i];
        let b = edges[1..nb].partition_point(|x| *x <= u).min(nb - 1);
        sum[b] += v;
        n[b] += 1;
    }
    sum.iter()
        .zip(&n)
        .map(|(s, c)| if *c == 0 { f64::NAN } else { s / *c as f64 })
        .collect()
}

fn config_name(c: &RunConfig) -> String {
    let mut s = format!("lr {:.0e}", c.lr);
    if c.method.physics_in_loss() {
        let _ = write!(s, ", κ {}", c.weights.physics);
    }
    if c.method.evidential() {
        let _ = write!(s, ", entropy {:.0e}", c.weights.entropy);
    }
    s
}

fn same_config(a: &RunConfig, b: &RunConfig) -> bool {
    a.method == b.method && a.lr == b.lr && a.weights == b.weights
}

/// The runs of `method`'s configuration with the lowest mean validation EMD².
fn best(runs: &[RunScores], method: Method) -> Vec<&RunScores> {
    let mine: Vec<&RunScores> = runs.iter().filter(|r| r.config.method == method).collect();
    let mut groups: Vec<Vec<&RunScores>> = Vec::new();
    for r in mine {
        match groups
            .iter_mut()
            .find(|g| same_config(&g[0].config, &r.config))
        {
            Some(g) => g.push(r),
            None => groups.push(vec![r]),
        }
    }
    let mean_val = |g: &Vec<&RunScores>| {
        // a diverged run (NaN) disqualifies its configuration
        mean_std(&g.iter().map(|r| r.val).collect::<Vec<_>>()).0
    };
    groups
        .into_iter()
        .filter(|g| mean_val(g).is_finite())
        .min_by(|a, b| mean_val(a).total_cmp(&mean_val(b)))
        .unwrap_or_default()
}

fn test_pick(r: &RunScores) -> &Aggregate {
    &r.test
}

fn ood_pick(r: &RunScores) -> &Aggregate {
    r.phys_if_ood.as_ref().expect("EVORA runs carry it")
}

fn row_of(name: &str, group: &[&RunScores], pick: fn(&RunScores) -> &Aggregate) -> Row {
    let aggs: Vec<&Aggregate> = group.iter().map(|r| pick(r)).collect();
    let n = aggs.len().max(1) as f64;
    let mut per_param = [0.0; 4];
    for a in &aggs {
        for (p, v) in per_param.iter_mut().zip(a.per_param) {
            *p += v / n;
        }
    }
    let bins = aggs.first().map_or(0, |a| a.by_bin.len());
    // every seed scores the same test samples, so the mean of bin means is the pooled mean
    let by_bin = (0..bins)
        .map(|b| aggs.iter().map(|a| a.by_bin[b]).sum::<f64>() / n)
        .collect();
    let field =
        |f: fn(&Scores) -> f64| mean_std(&aggs.iter().map(|a| f(&a.scores)).collect::<Vec<_>>());
    Row {
        name: name.into(),
        overall: field(|s| s.overall),
        id: field(|s| s.id),
        ood: field(|s| s.ood),
        per_param,
        config: group
            .first()
            .map_or(String::new(), |r| config_name(&r.config)),
        val: mean_std(&group.iter().map(|r| r.val).collect::<Vec<_>>()).0,
        by_bin,
        density: mean_density(group),
    }
}

fn mean_density(group: &[&RunScores]) -> Option<DensityStats> {
    let d: Vec<DensityStats> = group.iter().filter_map(|r| r.density).collect();
    if d.is_empty() {
        return None;
    }
    let m = |f: fn(&DensityStats) -> f64| d.iter().map(f).sum::<f64>() / d.len() as f64;
    Some(DensityStats {
        train_min: m(|x| x.train_min),
        test_id_mean: m(|x| x.test_id_mean),
        test_ood_mean: m(|x| x.test_ood_mean),
        flagged: m(|x| x.flagged),
    })
}

/// How each evidential row's flow sees the test samples, as Markdown.
pub fn density_markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| Method | mean log p(z), ID test | mean log p(z), OOD test | lowest training log p(z) | test samples below it |\n|---|---|---|---|---|\n",
    );
    for r in rows {
        if let Some(d) = r.density {
            let _ = writeln!(
                s,
                "| {} | {:.1} | {:.1} | {:.1} | {:.1} % |",
                r.name,
                d.test_id_mean,
                d.test_ood_mean,
                d.train_min,
                100.0 * d.flagged
            );
        }
    }
    s
}

fn fixed_row(
    name: &str,
    e: &SampleErrors,
    data: &PietraData,
    val: &SampleErrors,
    edges: &[f64],
) -> Row {
    let a = Aggregate::of(e, data, edges);
    Row {
        name: name.into(),
        overall: (a.scores.overall, 0.0),
        id: (a.scores.id, 0.0),
        ood: (a.scores.ood, 0.0),
        per_param: a.per_param,
        config: String::new(),
        val: val.scores(&data.val, data.threshold).overall,
        by_bin: a.by_bin,
        density: None,
    }
}

/// Runs the whole grid for `methods` in this process (runs in parallel on rayon's pool;
/// `progress` is told after each run) and builds the tables.
pub fn run_benchmark(
    data: &PietraData,
    grid: &Grid,
    methods: &[Method],
    device: &Device,
    progress: &(dyn Fn(&RunScores) + Sync),
) -> Result<BenchResult, String> {
    let started = std::time::Instant::now();
    let configs: Vec<RunConfig> = methods.iter().flat_map(|m| grid.runs(*m)).collect();
    let failures = Mutex::new(Vec::new());
    let runs: Vec<RunScores> = configs
        .par_iter()
        .filter_map(|cfg| match score(data, cfg, device) {
            Ok(r) => {
                progress(&r);
                Some(r)
            }
            Err(e) => {
                failures.lock().expect("no panics").push(e);
                None
            }
        })
        .collect();
    let failures = failures.into_inner().expect("no panics");
    if !failures.is_empty() {
        eprintln!("{} runs failed: {}", failures.len(), failures.join("; "));
    }
    let mut result = tables(data, runs, methods)?;
    result.wall_s = started.elapsed().as_secs_f64();
    Ok(result)
}

/// Table I, Table II and Fig. 6's curves from scored runs (of this or other processes).
pub fn tables(
    data: &PietraData,
    runs: Vec<RunScores>,
    methods: &[Method],
) -> Result<BenchResult, String> {
    if runs.is_empty() {
        return Err("no run finished".into());
    }
    let edges = bin_edges(&data.test);
    let mut table1 = Vec::new();
    let mut table2 = Vec::new();
    let label = |m: Method| match m {
        Method::Pietra => "PIETRA",
        Method::Pi => "Physics-Informed (PI)",
        Method::Vanilla => "Vanilla",
        Method::Evora => "EVORA",
        Method::UpiOnly => "UPI",
        Method::PpOnly => "PP",
    };
    for m in [Method::Pietra, Method::Pi, Method::Vanilla, Method::Evora] {
        if methods.contains(&m) {
            table1.push(row_of(label(m), &best(&runs, m), test_pick));
        }
    }
    let phys = SampleErrors::of_pmfs(&data.test, physics_pmf(&data.test));
    let phys_val = SampleErrors::of_pmfs(&data.val, physics_pmf(&data.val));
    table1.push(fixed_row("Physics Prior", &phys, data, &phys_val, &edges));
    table1.push(fixed_row(
        "Uniform Prior",
        &uniform_errors(&data.test),
        data,
        &uniform_errors(&data.val),
        &edges,
    ));
    for m in [Method::Pietra, Method::UpiOnly, Method::PpOnly] {
        if methods.contains(&m) {
            let mut r = row_of(label(m), &best(&runs, m), test_pick);
            if m == Method::Pietra {
                r.name = "PP & UPI (PIETRA)".into();
            }
            table2.push(r);
        }
    }
    if methods.contains(&Method::Evora) {
        let evora = best(&runs, Method::Evora);
        table2.push(row_of("Use phys. model if OOD", &evora, ood_pick));
        table2.push(row_of("EVORA", &evora, test_pick));
    }
    Ok(BenchResult {
        runs,
        table1,
        table2,
        bin_edges: edges,
        wall_s: 0.0,
    })
}

/// A table as Markdown: mean ± std of the summed EMD², and the per-parameter mean.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| Method | Overall | ID | OOD | per parameter (mean) | chosen by validation |\n|---|---|---|---|---|---|\n",
    );
    let pm = |(m, sd): (f64, f64)| {
        if sd == 0.0 {
            format!("{m:.3}")
        } else {
            format!("{m:.3} ± {sd:.3}")
        }
    };
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.3} | {} |",
            r.name,
            pm(r.overall),
            pm(r.id),
            pm(r.ood),
            r.overall.0 / 4.0,
            if r.config.is_empty() {
                "—"
            } else {
                &r.config
            }
        );
    }
    s
}

/// Every run as CSV.
pub fn runs_csv(runs: &[RunScores]) -> String {
    let mut s = String::from(
        "method,lr,kappa,entropy,seed,steps,val_emd2,test_overall,test_id,test_ood,final_loss,wall_s\n",
    );
    for r in runs {
        let c = &r.config;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{:.5},{:.5},{:.5},{:.5},{:.5},{:.1}",
            c.method.name(),
            c.lr,
            c.weights.physics,
            c.weights.entropy,
            c.seed,
            c.steps,
            r.val,
            r.test.scores.overall,
            r.test.scores.id,
            r.test.scores.ood,
            r.final_loss,
            r.wall_s
        );
    }
    s
}

/// Fig. 6: mean test EMD² per unevenness bin, one line per Table I row.
pub fn figure6(result: &BenchResult, threshold: f64, out: &Path) -> Result<(), String> {
    use verti_render::lines::{LinePanel, LineSeries, line_chart_image};
    let centres: Vec<f64> = result
        .bin_edges
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]))
        .collect();
    let series = result
        .table1
        .iter()
        .map(|r| LineSeries {
            name: r.name.clone(),
            points: centres
                .iter()
                .zip(&r.by_bin)
                .map(|(c, v)| [*c * 100.0, *v])
                .collect(),
        })
        .collect();
    let panel = LinePanel {
        title: format!(
            "Test EMD² by footprint unevenness (ID/OOD boundary {:.1} cm)",
            threshold * 100.0
        ),
        x_label: "std of elevation in the footprint (cm)".into(),
        y_label: "EMD² (sum of 4)".into(),
        series,
        marks: Vec::new(),
    };
    let img = line_chart_image(&panel, 900, 520).map_err(|e| e.to_string())?;
    verti_render::save_png(&img, out).map_err(|e| e.to_string())
}

/// Per-method mean wall time of a run, for the README.
pub fn wall_by_method(runs: &[RunScores]) -> BTreeMap<&'static str, f64> {
    let mut m: BTreeMap<&'static str, (f64, usize)> = BTreeMap::new();
    for r in runs {
        let e = m.entry(r.config.method.name()).or_default();
        e.0 += r.wall_s;
        e.1 += 1;
    }
    m.into_iter().map(|(k, (s, n))| (k, s / n as f64)).collect()
}
