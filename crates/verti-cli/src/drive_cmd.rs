//! `verti drive`: a person drives one task in real time, watching it live in the browser (or
//! a system drives while the person watches), recorded as a demonstration dataset.

use crate::eval_cmd::assignment;
use crate::vehicle_cmd::load_vehicle;
use crate::world_cmd::{CmdResult, ScaleArg, load_set_checked};
use clap::Args;
use std::path::PathBuf;
use std::sync::Arc;
use verti_bench::EpisodeConfig;
use verti_drive::script::KeyScript;
use verti_drive::server::{ServeOptions, serve};
use verti_drive::{DemoInfo, DriveSession};
use verti_world::World;

/// Raised by Ctrl-C while the live view runs.
static STOP: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

#[derive(Args)]
pub struct DriveArgs {
    /// World set (as `verti eval --worlds`).
    #[arg(long, default_value = "verti-100")]
    worlds: String,
    /// Task number to drive.
    #[arg(long)]
    task: u32,
    /// Vehicle: a built-in name or a vehicle YAML file (default: the set's scale's vehicle).
    #[arg(long)]
    vehicle: Option<String>,
    #[command(flatten)]
    scale: ScaleArg,
    /// Watch a system drive instead of driving yourself (`verti systems list`).
    #[arg(long)]
    system: Option<String>,
    /// System parameter, name=value (repeatable; with --system).
    #[arg(long = "param", value_parser = assignment)]
    params: Vec<String>,
    /// Drive headless from a key script (lines `SECONDS KEYS...`, keys up down left right
    /// brake none) as fast as the simulator runs, instead of opening the live view.
    #[arg(long)]
    keys: Option<PathBuf>,
    /// Port of the live view on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = 8765)]
    port: u16,
    /// Simulated seconds per wall-clock second in the live view.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Time limit, simulated seconds.
    #[arg(long, default_value_t = 60.0)]
    max_time: f64,
    /// Where the demonstration goes: a dataset directory (Parquet + manifest, kind `expert`,
    /// source `human`), with `result.json` and a 3-D replay `replay.html` beside it.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace a demonstration already in --out.
    #[arg(long)]
    force: bool,
}

pub fn drive(a: DriveArgs) -> CmdResult {
    if !(a.speed.is_finite() && a.speed > 0.0 && a.speed <= 100.0) {
        return Err(format!("--speed {}: must be in (0, 100]", a.speed).into());
    }
    let (set, scale) = load_set_checked(&a.worlds, &a.scale)?;
    let worlds: Vec<Arc<World>> = set.worlds.into_iter().map(Arc::new).collect();
    let id = verti_world::TaskId::from_number(a.task).ok_or("task numbers start at 1")?;
    let world = worlds
        .iter()
        .find(|w| w.meta.index == id.world && w.tasks.iter().any(|t| t.pair == id.pair))
        .cloned()
        .ok_or_else(|| format!("task {} is not in `{}`", a.task, a.worlds))?;
    let vehicle_name = a
        .vehicle
        .clone()
        .unwrap_or_else(|| verti_sim::vehicles::default_for_scale(scale).to_string());
    let vehicle = load_vehicle(&vehicle_name)?;
    let system = match &a.system {
        None => {
            if !a.params.is_empty() {
                return Err("--param needs --system".into());
            }
            None
        }
        Some(name) => {
            let registry = crate::registries::systems();
            let given = a
                .params
                .iter()
                .map(|p| registry.parse_param(name, p))
                .collect::<Result<Vec<_>, _>>()?;
            let params = registry.resolve(name, &given)?;
            Some(registry.build(name, &params)?)
        }
    };
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("demos").join(format!("task-{}", a.task)));
    // the dataset writer refuses a non-empty directory without --force: check before anyone
    // drives, so no drive is lost to it at the end
    let occupied = out.exists()
        && std::fs::read_dir(&out)
            .map_err(|e| format!("--out {}: {e}", out.display()))?
            .next()
            .is_some();
    if occupied && !a.force {
        return Err(format!(
            "{} is not empty (a demonstration already there?): pass --force to replace it, or choose another --out",
            out.display()
        )
        .into());
    }
    let cfg = EpisodeConfig {
        max_time: a.max_time,
        ..Default::default()
    };
    let mut session = DriveSession::start(&world, &vehicle, id.pair, &cfg, system)?;
    let rate = 1.0 / session.period();
    let end = match &a.keys {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let script = KeyScript::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
            script.drive(&mut session);
            session.finish()
        }
        None => {
            let listener = std::net::TcpListener::bind(("127.0.0.1", a.port))
                .map_err(|e| format!("--port {}: cannot listen on 127.0.0.1: {e}", a.port))?;
            let addr = listener.local_addr()?;
            println!(
                "live view: open http://{addr}/ in a browser ({}; Ctrl-C stops and saves)",
                if a.system.is_some() {
                    "watch the system drive"
                } else {
                    "drive with the arrow keys or WASD, space stops; a gamepad works too"
                }
            );
            // Ctrl-C ends the session like the page's Stop button: what was driven is saved
            extern "C" fn on_interrupt(_: libc::c_int) {
                STOP.store(true, std::sync::atomic::Ordering::SeqCst);
            }
            // SAFETY: the handler only stores to an atomic, which is async-signal-safe
            unsafe {
                libc::signal(
                    libc::SIGINT,
                    on_interrupt as extern "C" fn(libc::c_int) as libc::sighandler_t,
                );
            }
            let opts = ServeOptions {
                speed: a.speed,
                stop: Some(&STOP),
                ..Default::default()
            };
            serve(session, &listener, opts)?
        }
    };
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty())
        && !parent.exists()
    {
        std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    }
    let command: Vec<String> = std::env::args().collect();
    let info = DemoInfo {
        set: &a.worlds,
        spec: &vehicle,
        max_time: a.max_time,
        source: &end.result.system,
        rate,
        command: &command.join(" "),
    };
    verti_drive::write_demonstrations(&out, &[end.record], &worlds, &info, a.force)?;
    let result_path = out.join("result.json");
    std::fs::write(&result_path, serde_json::to_string_pretty(&end.result)?)
        .map_err(|e| format!("{}: {e}", result_path.display()))?;
    verti_view::write_html(&end.recording, &out.join("replay.html"))
        .map_err(|e| format!("{}: {e}", out.display()))?;
    println!(
        "task {} ({} pair {}): {} after {:.1} s, {:.1} m driven; demonstration in {} (dataset, result.json, replay.html)",
        a.task,
        world.meta.name,
        id.pair,
        end.result.outcome.name(),
        end.result.time,
        end.result.path_length,
        out.display()
    );
    Ok(())
}
