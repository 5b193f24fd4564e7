//! `verti world ...`

use crate::cli_common::{CmdResult, ScaleArg, load_set_checked, note_shadowed};
use crate::outputs::ensure_parent;
use crate::progress::bar;
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use std::time::Instant;
use verti_world::format::{save_set, save_world};
use verti_world::generate::sources::DEFAULT_SOURCE;
use verti_world::generate::{SetConfig, generate_set_with, set_name};
use verti_world::import_vb::{ImportOptions, import_vb, scan_vb_dir};
use verti_world::paths::DEFAULT_CLEARANCE;
use verti_world::sets::resolve_world;
use verti_world::{World, WorldError};

#[derive(Subcommand)]
pub enum WorldCommand {
    /// Generate a world set (default: the built-in verti-100 set, seed 0).
    Generate(GenerateArgs),
    /// Import original Verti-Bench worlds (one config, or a whole folder with --dir).
    ImportVb(ImportArgs),
    /// Print a summary of one world (a world directory or SET:INDEX, e.g. verti-100:42).
    Show(ShowArgs),
    /// Render a top view of a world (elevation, classes, obstacles, tasks, paths) to PNG.
    Render(RenderArgs),
    /// Statistics of a world set: composition, elevation histograms, frictions, obstacles, paths.
    Stats(StatsArgs),
    /// List the elevation sources `generate --elevation` can use, with their parameters.
    Sources,
}

#[derive(Args)]
pub struct RenderArgs {
    /// A world directory or SET:INDEX (e.g. verti-100:42).
    world: String,
    /// Output PNG (a .png file in an existing directory).
    #[arg(long, value_parser = crate::outputs::png_file)]
    out: PathBuf,
    /// Pixels per heightfield cell.
    #[arg(long, default_value_t = 4)]
    px_per_cell: u32,
    /// Only these start/goal pairs (e.g. 0,5); default all.
    #[arg(long, value_delimiter = ',')]
    pairs: Option<Vec<u32>>,
    /// Draw the 16x16 semantic patch grid.
    #[arg(long)]
    grid: bool,
    #[command(flatten)]
    scale: ScaleArg,
}

#[derive(Args)]
pub struct StatsArgs {
    /// A set: verti-100 (built-in), a set or world directory, or a folder of Verti-Bench worlds.
    set: String,
    /// Print one JSON object instead of the text report.
    #[arg(long)]
    json: bool,
    /// Also write the per-level elevation histograms (like the paper's Fig. 2) to this PNG.
    #[arg(long, value_parser = crate::outputs::png_file)]
    histograms: Option<PathBuf>,
    #[command(flatten)]
    scale: ScaleArg,
}

#[derive(Args)]
pub struct GenerateArgs {
    /// Set seed; the same seed gives byte-identical files on every machine.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Number of worlds (10 tasks each).
    #[arg(long, default_value_t = 100)]
    count: u32,
    #[command(flatten)]
    scale: ScaleArg,
    /// Clearance global paths keep from obstacles, full-scale metres (scaled with the world).
    #[arg(long, default_value_t = DEFAULT_CLEARANCE)]
    clearance: f64,
    /// Elevation source (see `verti world sources`).
    #[arg(long, default_value = DEFAULT_SOURCE)]
    elevation: String,
    /// Elevation source parameter, name=value (repeatable).
    #[arg(long = "elevation-param", value_parser = crate::cli_common::assignment)]
    elevation_params: Vec<String>,
    /// Output directory (default: worlds/SET_NAME); its parent must exist.
    #[arg(long, value_parser = crate::outputs::out_dir)]
    out: Option<PathBuf>,
    /// Overwrite an existing non-empty output directory.
    #[arg(long)]
    force: bool,
}

#[derive(Args)]
pub struct ImportArgs {
    /// A Verti-Bench `configN_LEVEL.yaml` (omit with --dir).
    config: Option<PathBuf>,
    /// The world's 129x129 heightmap (`worldN.bmp`).
    #[arg(long)]
    heightmap: Option<PathBuf>,
    /// Optional `labelsN_LEVEL.npy`, cross-checked against the config's patches.
    #[arg(long)]
    labels: Option<PathBuf>,
    /// Import every configN_LEVEL.yaml of this folder (heightmaps and labels found by name).
    #[arg(long, conflicts_with_all = ["config", "heightmap", "labels"])]
    dir: Option<PathBuf>,
    #[command(flatten)]
    scale: ScaleArg,
    /// Path clearance from obstacles, full-scale metres.
    #[arg(long, default_value_t = DEFAULT_CLEARANCE)]
    clearance: f64,
    /// Output: a world directory (one config) or a set directory (--dir); its parent must exist.
    #[arg(long, value_parser = crate::outputs::out_dir)]
    out: PathBuf,
    /// Overwrite an existing non-empty output directory.
    #[arg(long)]
    force: bool,
}

#[derive(Args)]
pub struct ShowArgs {
    /// A world directory or SET:INDEX (e.g. verti-100:42).
    world: String,
    #[command(flatten)]
    scale: ScaleArg,
}

pub fn run(cmd: WorldCommand) -> CmdResult {
    match cmd {
        WorldCommand::Generate(a) => generate(a),
        WorldCommand::ImportVb(a) => import(a),
        WorldCommand::Show(a) => show(a),
        WorldCommand::Render(a) => render(a),
        WorldCommand::Stats(a) => stats(a),
        WorldCommand::Sources => {
            crate::registries::print_list(crate::registries::elevation_sources().list());
            Ok(())
        }
    }
}

/// Refuses to write into a non-empty directory unless forced, so a typo never clobbers data.
fn check_out_dir(out: &Path, force: bool) -> Result<(), WorldError> {
    if out.exists()
        && !force
        && out
            .read_dir()
            .map(|mut d| d.next().is_some())
            .unwrap_or(true)
    {
        return Err(WorldError::Argument(format!(
            "{} exists and is not empty (use --force to overwrite)",
            out.display()
        )));
    }
    if force && out.exists() {
        std::fs::remove_dir_all(out).map_err(|e| WorldError::io(out, e))?;
    }
    Ok(())
}

fn generate(a: GenerateArgs) -> CmdResult {
    let config = SetConfig {
        seed: a.seed,
        count: a.count,
        scale: a.scale.value(),
        clearance: a.clearance,
    };
    config.validate()?;
    let sources = crate::registries::elevation_sources();
    let given = a
        .elevation_params
        .iter()
        .map(|p| sources.parse_param(&a.elevation, p))
        .collect::<Result<Vec<_>, _>>()?;
    let source = sources.create(&a.elevation, &given)?;
    // sets from other sources or settings get their own names (each world's manifest records
    // the source's full name, settings included)
    let mut name = set_name(&config);
    if a.elevation != DEFAULT_SOURCE {
        name.push_str(&format!("-{}", a.elevation));
    }
    if !given.is_empty() {
        name.push_str("-custom");
    }
    let out = a.out.unwrap_or_else(|| PathBuf::from("worlds").join(&name));
    check_out_dir(&out, a.force)?;
    let t0 = Instant::now();
    let pb = bar(u64::from(a.count), "generating");
    let worlds = generate_set_with(&config, source.as_ref(), &|| pb.inc(1))?;
    pb.finish_and_clear();
    let t_gen = t0.elapsed();
    let pb = bar(u64::from(a.count), "writing");
    save_set(&worlds, &name, Some(a.seed), &out, &|| pb.inc(1))?;
    pb.finish_and_clear();
    println!(
        "generated {} ({} worlds, {} tasks) in {:.2} s, written to {} in {:.2} s",
        name,
        worlds.len(),
        worlds.iter().map(|w| w.tasks.len()).sum::<usize>(),
        t_gen.as_secs_f64(),
        out.display(),
        (t0.elapsed() - t_gen).as_secs_f64()
    );
    print_composition(&worlds);
    Ok(())
}

fn print_composition(worlds: &[World]) {
    println!("  levels: {}", count_by(worlds, |w| w.meta.level));
    println!("  types: {}", count_by(worlds, |w| w.meta.terrain_type));
    println!("  densities: {}", count_by(worlds, |w| w.meta.density));
}

/// "a 3, b 5" counts of a key over worlds, in key order.
fn count_by<K: Ord + std::fmt::Display>(worlds: &[World], key: impl Fn(&World) -> K) -> String {
    let mut counts = std::collections::BTreeMap::new();
    for w in worlds {
        *counts.entry(key(w)).or_insert(0usize) += 1;
    }
    counts
        .iter()
        .map(|(k, v)| format!("{k} {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn import(a: ImportArgs) -> CmdResult {
    let opts = ImportOptions {
        scale: a.scale.value(),
        clearance: a.clearance,
        index: None,
    };
    check_out_dir(&a.out, a.force)?;
    if let Some(dir) = a.dir {
        let files = scan_vb_dir(&dir)?;
        let pb = bar(files.len() as u64, "importing");
        let worlds = {
            use rayon::prelude::*;
            files
                .par_iter()
                .map(|f| {
                    let w = import_vb(&f.config, &f.heightmap, f.labels.as_deref(), &opts);
                    pb.inc(1);
                    w
                })
                .collect::<Result<Vec<_>, _>>()?
        };
        pb.finish_and_clear();
        let name = format!(
            "vb-{}",
            dir.file_name().and_then(|n| n.to_str()).unwrap_or("import")
        );
        save_set(&worlds, &name, None, &a.out, &|| {})?;
        println!(
            "imported {} Verti-Bench worlds into {}",
            worlds.len(),
            a.out.display()
        );
        print_composition(&worlds);
        return Ok(());
    }
    let config = a.config.ok_or_else(|| {
        WorldError::Argument("give a CONFIG.yaml with --heightmap, or --dir FOLDER".into())
    })?;
    let heightmap = a.heightmap.ok_or_else(|| {
        WorldError::Argument("--heightmap WORLD.bmp is required with a config".into())
    })?;
    let w = import_vb(&config, &heightmap, a.labels.as_deref(), &opts)?;
    save_world(&w, &a.out)?;
    println!("imported {} into {}", w.meta.name, a.out.display());
    Ok(())
}

fn show(a: ShowArgs) -> CmdResult {
    note_shadowed(&a.world);
    let w = resolve_world_checked(&a.world, &a.scale)?;
    print!("{}", describe(&w));
    Ok(())
}

fn render(a: RenderArgs) -> CmdResult {
    note_shadowed(&a.world);
    let w = resolve_world_checked(&a.world, &a.scale)?;
    let options = verti_render::RenderOptions {
        pixels_per_cell: a.px_per_cell,
        pairs: a.pairs,
        show_grid: a.grid,
        ..Default::default()
    };
    ensure_parent(&a.out)?;
    verti_render::render_world_png(&w, &options, &a.out)?;
    println!("rendered {} to {}", w.meta.name, a.out.display());
    Ok(())
}

fn stats(a: StatsArgs) -> CmdResult {
    let (set, _) = load_set_checked(&a.set, &a.scale, None)?;
    let stats = verti_world::stats::set_stats(&set.worlds);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&stats)?);
    } else {
        println!("{}: {} worlds", set.name, set.worlds.len());
        print!("{stats}");
    }
    if let Some(path) = a.histograms {
        ensure_parent(&path)?;
        verti_render::elevation_histograms_png(&stats, &path)?;
        if !a.json {
            println!("elevation histograms written to {}", path.display());
        }
    }
    Ok(())
}

/// A short multi-line description of a world.
pub fn describe(w: &World) -> String {
    let mut classes = std::collections::BTreeMap::new();
    for p in w.patches.patches() {
        *classes.entry(p.class).or_insert(0) += 1;
    }
    let rocks = w.obstacles.iter().filter(|o| o.is_rock()).count();
    let mut s = format!(
        "{}  (index {}, scale {})\n  level {}  type {}  density {}\n  terrain {:.1} m x {:.1} m, heights {:.2}..{:.2} m (max height {:.2} m)\n  classes: {}\n  obstacles: {} rocks, {} trees\n  tasks: {}\n",
        w.meta.name,
        w.meta.index,
        verti_world::scale::scale_label(w.meta.scale),
        w.meta.level,
        w.meta.terrain_type,
        w.meta.density,
        2.0 * w.terrain.half_extent(),
        2.0 * w.terrain.half_extent(),
        w.terrain.min_height(),
        w.terrain.max_height(),
        w.meta.max_height,
        classes
            .iter()
            .map(|(c, n)| format!("{c} {n}"))
            .collect::<Vec<_>>()
            .join(", "),
        rocks,
        w.obstacles.len() - rocks,
        w.tasks.len()
    );
    for (t, p) in w.tasks.iter().zip(&w.paths) {
        s.push_str(&format!(
            "    pair {}: ({:.1}, {:.1}) -> ({:.1}, {:.1}), path {:.1} m{}\n",
            t.pair,
            t.start[0],
            t.start[1],
            t.goal[0],
            t.goal[1],
            p.length(),
            if p.points.is_empty() {
                " (no path)"
            } else {
                ""
            }
        ));
    }
    s
}

/// One world at the requested scale (see [`load_set_checked`]).
fn resolve_world_checked(spec: &str, scale: &ScaleArg) -> Result<verti_world::World, WorldError> {
    let w = resolve_world(spec, scale.value())?;
    verti_world::scale::set_scale(spec, [&w], scale.scale)?;
    Ok(w)
}
