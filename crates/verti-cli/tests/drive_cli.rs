//! `verti drive` end to end (issue 7): an unwritable `--out` is refused before anyone
//! drives, SIGTERM and SIGHUP save the drive as Ctrl-C does, and a session that was never
//! driven writes no dataset (one of no rows would not load) and says so. Every wait is
//! bounded; all traffic goes to 127.0.0.1.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn verti() -> Command {
    Command::new(env!("CARGO_BIN_EXE_verti"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("verti-drive-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const DRIVE: [&str; 9] = [
    "drive", "--worlds", "verti-4", "--task", "1", "--port", "0", "--speed", "4",
];

/// Waits for `child` at most `limit`; kills it and fails if it runs on.
fn wait_bounded(mut child: Child, limit: Duration) -> Output {
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`verti drive` still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// A live session: the process, its address and the session token read from its page.
struct Live {
    child: Child,
    host: String,
    token: String,
}

fn start(out: &Path) -> Live {
    let mut child = verti()
        .args(DRIVE)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // the first line names the address; the rest of stdout stays in the pipe for the end
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    stdout.read_line(&mut first).unwrap();
    let host = first
        .split_whitespace()
        .find_map(|w| w.strip_prefix("http://"))
        .unwrap_or_else(|| panic!("no address in {first:?}"))
        .trim_end_matches('/')
        .to_string();
    child.stdout = Some(stdout.into_inner());
    let page = http(&host, &format!("GET / HTTP/1.1\r\nHost: {host}\r\n\r\n"));
    let token = verti_drive::server::token_in_page(&page)
        .expect("the page carries the token")
        .to_string();
    Live { child, host, token }
}

/// Sends `raw` and returns the whole response (10-s limit).
fn http(host: &str, raw: &str) -> String {
    let mut s = TcpStream::connect(host).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.write_all(raw.as_bytes()).unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    text
}

impl Live {
    fn post(&self, path: &str) -> String {
        http(
            &self.host,
            &format!(
                "POST {path} HTTP/1.1\r\nHost: {}\r\nX-Verti-Token: {}\r\nContent-Length: 0\r\n\r\n",
                self.host, self.token
            ),
        )
    }

    /// Drives a second or so with the accelerator held.
    fn drive_a_little(&self) {
        for _ in 0..4 {
            assert!(self.post("/step?keys=u").starts_with("HTTP/1.1 200"));
            std::thread::sleep(Duration::from_millis(150));
        }
    }

    fn signal(&self, name: &str) {
        let ok = Command::new("kill")
            .args(["-s", name, &self.child.id().to_string()])
            .status()
            .unwrap()
            .success();
        assert!(ok, "kill -s {name}");
    }
}

#[test]
fn an_unwritable_out_is_refused_before_anyone_drives() {
    let dir = tmp("unwritable");
    let file = dir.join("a-file");
    std::fs::write(&file, "not a directory").unwrap();
    let keys = dir.join("keys.txt");
    std::fs::write(&keys, "0 up\n").unwrap();
    let mut outs = vec![file.join("demo"), file.clone()];
    // a read-only directory, where permissions bind (not as root)
    let ro = dir.join("read-only");
    std::fs::create_dir(&ro).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    if std::fs::write(ro.join("probe"), "x").is_err() {
        outs.push(ro.clone());
    }
    for out in &outs {
        // live: refused before the server starts; headless: before the script is driven
        for headless in [false, true] {
            let mut cmd = verti();
            cmd.args(DRIVE).arg("--out").arg(out);
            if headless {
                cmd.arg("--keys").arg(&keys);
            }
            let child = cmd
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap();
            let o = wait_bounded(child, Duration::from_secs(60));
            let (stdout, stderr) = (
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr),
            );
            assert!(!o.status.success(), "{out:?}: {stdout}");
            assert!(!stdout.contains("live view"), "{out:?} served: {stdout}");
            assert!(
                stderr.contains(&format!("--out {}", out.display()))
                    && stderr.contains("writable directory"),
                "{stderr}"
            );
        }
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sigterm_and_sighup_save_the_drive_like_ctrl_c() {
    let dir = tmp("signals");
    for sig in ["TERM", "HUP", "INT"] {
        let out = dir.join(sig);
        let live = start(&out);
        live.drive_a_little();
        live.signal(sig);
        let o = wait_bounded(live.child, Duration::from_secs(30));
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "SIG{sig}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(stdout.contains("demonstration in"), "SIG{sig}: {stdout}");
        for f in ["manifest.yaml", "result.json", "replay.html"] {
            assert!(out.join(f).exists(), "SIG{sig}: no {f}");
        }
        // and it is a dataset the tools accept
        let stats = verti().args(["data", "stats"]).arg(&out).output().unwrap();
        assert!(
            stats.status.success(),
            "SIG{sig}: {}",
            String::from_utf8_lossy(&stats.stderr)
        );
        let result: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("result.json")).unwrap())
                .unwrap();
        assert!(result["time"].as_f64().unwrap() > 0.0, "{result}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_drive_never_polled_writes_no_dataset_and_says_so() {
    let dir = tmp("empty");
    // stopped by the page's button before any poll, or by SIGTERM with no page at all
    for how in ["quit", "TERM"] {
        let out = dir.join(how);
        let live = start(&out);
        if how == "quit" {
            assert!(live.post("/quit").starts_with("HTTP/1.1 200"));
        } else {
            live.signal(how);
        }
        let o = wait_bounded(live.child, Duration::from_secs(30));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{how}: an empty drive was saved");
        assert!(
            stderr.contains("nothing was recorded") && stderr.contains(&out.display().to_string()),
            "{how}: {stderr}"
        );
        // the directory made for it is gone again: nothing that looks like a dataset
        assert!(!out.exists(), "{how}: {out:?} left behind");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
