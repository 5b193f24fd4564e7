//! `verti drive`: a person drives one task in real time, watching it live in the browser (or
//! a system drives while the person watches), recorded as a demonstration dataset.

use crate::cli_common::{CmdResult, ScaleArg, assignment, load_set_checked, load_vehicle};
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use verti_bench::EpisodeConfig;
use verti_drive::script::KeyScript;
use verti_drive::server::{ServeOptions, serve};
use verti_drive::{DemoInfo, DriveSession};
use verti_world::World;

/// Raised by Ctrl-C, SIGTERM or SIGHUP while the live view runs.
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
    let (set, scale) = load_set_checked(&a.worlds, &a.scale, None)?;
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
    let script = match &a.keys {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            Some(KeyScript::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?)
        }
        None => None,
    };
    let cfg = EpisodeConfig {
        max_time: a.max_time,
        ..Default::default()
    };
    let session = DriveSession::start(&world, &vehicle, id.pair, &cfg, system)?;
    let rate = 1.0 / session.period();
    // check --out before anyone drives, so no drive is lost to it at the end
    let created_out = prepare_out(&out, a.force)?;
    let end = match run_session(session, script.as_ref(), &a) {
        Ok(end) => end,
        Err(e) => {
            discard_out(&out, created_out);
            return Err(e);
        }
    };
    // no control period driven (the page was never opened, or stopped before its first
    // poll): an empty demonstration is not data, and a dataset of no rows does not load
    if end.record.rows.is_empty() {
        discard_out(&out, created_out);
        return Err(format!(
            "nothing was recorded: the session ended before the trial was driven a single control period ({}), so no demonstration was written to {}",
            if a.keys.is_some() {
                "the key script drove no step"
            } else {
                "the live page never polled; open the address `verti drive` printed in a browser"
            },
            out.display()
        )
        .into());
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
    // after SIGHUP the terminal may be gone: a failed print must not turn a saved drive into
    // a panic
    let _ = writeln!(
        std::io::stdout(),
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

/// Drives `session` headless with `script`, or serves the live view until it ends.
fn run_session(
    mut session: DriveSession,
    script: Option<&KeyScript>,
    a: &DriveArgs,
) -> Result<verti_drive::SessionEnd, Box<dyn std::error::Error>> {
    if let Some(script) = script {
        script.drive(&mut session);
        return Ok(session.finish());
    }
    let listener = std::net::TcpListener::bind(("127.0.0.1", a.port)).map_err(|e| {
        let hint = if e.kind() == std::io::ErrorKind::AddrInUse {
            " (another program uses it: pass another --port, or --port 0 for any free one)"
        } else {
            ""
        };
        format!("--port {}: cannot listen on 127.0.0.1: {e}{hint}", a.port)
    })?;
    let addr = listener.local_addr()?;
    // Ctrl-C, SIGTERM (a supervisor, `kill`) and SIGHUP (the terminal closed) end the session
    // like the page's Stop button: what was driven is saved. Installed before the address is
    // printed, so whoever reads it can already stop the session.
    extern "C" fn on_signal(_: libc::c_int) {
        STOP.store(true, std::sync::atomic::Ordering::SeqCst);
    }
    for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        // SAFETY: the handler only stores to an atomic, which is async-signal-safe
        unsafe {
            libc::signal(
                signal,
                on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t,
            );
        }
    }
    println!(
        "live view: open http://{addr}/ in a browser ({}; Ctrl-C stops and saves)",
        if a.system.is_some() {
            "watch the system drive"
        } else {
            "drive with the arrow keys or WASD, space stops; a gamepad works too"
        }
    );
    let opts = ServeOptions {
        speed: a.speed,
        stop: Some(&STOP),
        ..Default::default()
    };
    Ok(serve(session, &listener, opts)?)
}

/// Removes `out` again if it was created for this drive and nothing went in.
fn discard_out(out: &Path, created: bool) {
    if created {
        // remove_dir refuses a directory that is not empty
        let _ = std::fs::remove_dir(out);
    }
}

/// Makes sure a demonstration can be written to `out` before anyone drives: the directory
/// exists (created here, with its parents), is empty unless `force`, and takes a file.
/// Returns whether it was created here (and so may be removed if nothing is recorded).
fn prepare_out(out: &Path, force: bool) -> Result<bool, String> {
    let fail = |what: &str, e: std::io::Error| {
        format!(
            "--out {}: {what} ({e}); choose a writable directory",
            out.display()
        )
    };
    let created = !out.exists();
    std::fs::create_dir_all(out).map_err(|e| fail("cannot create the directory", e))?;
    // the dataset writer refuses a non-empty directory without --force
    let occupied = std::fs::read_dir(out)
        .map_err(|e| fail("cannot read the directory", e))?
        .next()
        .is_some();
    if occupied && !force {
        return Err(format!(
            "{} is not empty (a demonstration already there?): pass --force to replace it, or choose another --out",
            out.display()
        ));
    }
    let probe = out.join(format!(".verti-write-probe-{}", std::process::id()));
    let written = std::fs::File::create(&probe).and_then(|mut f| {
        f.write_all(b"probe")?;
        f.sync_all()
    });
    let _ = std::fs::remove_file(&probe);
    written.map_err(|e| fail("cannot write there", e))?;
    Ok(created)
}
