//! `verti replay --3d` opened in a real headless browser (Chromium, software WebGL): the page
//! draws the scene and the time series. Skipped, saying so, where no Chromium is installed
//! (CI installs Debian's `chromium`; `VERTI_CHROMIUM` names another binary).

use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("VERTI_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    [
        "/usr/bin/chromium",
        "/usr/bin/chromium-browser",
        "/usr/bin/google-chrome",
    ]
    .iter()
    .map(PathBuf::from)
    .find(|p| p.exists())
}

fn verti(args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_verti"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "verti {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A headless screenshot of `url` at 1000 x 700 after 4-5 s of page time.
fn screenshot(browser: &Path, url: &str, png: &Path, profile: &Path) {
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
            "--window-size=1000,700",
            "--virtual-time-budget=4500",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(url)
        .output()
        .unwrap();
    assert!(
        png.exists(),
        "no screenshot: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_3d_page_draws_in_a_headless_browser() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set VERTI_CHROMIUM)");
        return;
    };
    let dir = std::env::temp_dir().join(format!("verti-viewer-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = dir.join("run");
    let page = dir.join("task.html");
    let png = dir.join("shot.png");
    verti(&[
        "eval",
        "--system",
        "pid",
        "--worlds",
        "verti-4",
        "--tasks",
        "1",
        "--out",
        run.to_str().unwrap(),
    ]);
    verti(&[
        "replay",
        run.to_str().unwrap(),
        "--task",
        "1",
        "--3d",
        "--out",
        page.to_str().unwrap(),
    ]);
    let url = format!("file://{}#t=0.5", page.display());
    screenshot(&browser, &url, &png, &dir.join("profile"));
    let img = image::open(&png).unwrap().to_rgb8();
    let (w, h) = img.dimensions();
    assert_eq!((w, h), (1000, 700));
    // the 3-D view is the top of the window (all but the 190-px panel): WebGL drew the
    // terrain over most of it — pixels far from both the GL clear colour (28, 33, 38) and the
    // page background (29, 34, 39), which is all a page without WebGL would show there
    let dark = |p: [u8; 3]| {
        [[28u8, 33, 38], [29, 34, 39]]
            .iter()
            .any(|c| (0..3).map(|i| u32::from(p[i].abs_diff(c[i]))).sum::<u32>() < 24)
    };
    let view_h = h - 190;
    let mut drawn = 0usize;
    let mut colours = std::collections::HashSet::new();
    for y in 0..view_h {
        for x in 0..w {
            let p = img.get_pixel(x, y).0;
            if !dark(p) {
                drawn += 1;
                colours.insert(p);
            }
        }
    }
    let share = drawn as f64 / (w * view_h) as f64;
    assert!(
        share > 0.5,
        "only {:.0} % of the 3-D view drawn",
        100.0 * share
    );
    // shading and class colours: a lit scene, not a flat fill
    assert!(colours.len() > 500, "{} colours", colours.len());
    // the chart panel has its curves: pixels of the speed series' colour (#58b4ff)
    let speed_pixels = (view_h + 40..h)
        .flat_map(|y| (0..w / 4).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = img.get_pixel(x, y).0;
            p[0].abs_diff(0x58) < 40 && p[1].abs_diff(0xb4) < 40 && p[2].abs_diff(0xff) < 40
        })
        .count();
    assert!(speed_pixels > 50, "{speed_pixels} speed-curve pixels");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `verti drive` (a person, or `system`) on task 1 of verti-4 at 4x real time, opens its
/// live page in headless Chromium at `url + hash`, stops it through `/quit`, and returns the
/// saved result after checking the demonstration's files.
fn live_session(browser: &Path, system: Option<&str>, hash: &str, name: &str) -> serde_json::Value {
    use std::io::{BufRead, BufReader, Read, Write};
    let dir = std::env::temp_dir().join(format!("verti-live-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("demo");
    let mut args = vec![
        "drive", "--worlds", "verti-4", "--task", "1", "--port", "0", "--speed", "4",
    ];
    if let Some(s) = system {
        args.extend(["--system", s]);
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_verti"))
        .args(&args)
        .arg("--out")
        .arg(&out)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let first = lines.next().unwrap().unwrap();
    let url = first
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap()
        .to_string();
    let png = dir.join("live.png");
    screenshot(browser, &format!("{url}{hash}"), &png, &dir.join("profile"));
    // stop the session the way the page's button does (unless the trial ended first and the
    // server, its end seen by the page, has already saved and gone)
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let request = |text: String| {
        let mut s = std::net::TcpStream::connect(addr).ok()?;
        s.write_all(text.as_bytes()).ok()?;
        let mut reply = String::new();
        let _ = s.read_to_string(&mut reply);
        Some(reply)
    };
    // the page carries the session's token; `/quit` wants it, by POST, addressed to the server
    let page = request(format!(
        "GET / HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    ));
    if let Some(token) = page.as_deref().and_then(verti_drive::server::token_in_page) {
        request(format!(
            "POST /quit HTTP/1.1\r\nHost: {addr}\r\nX-Verti-Token: {token}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
        ));
    }
    assert!(child.wait().unwrap().success());
    let rest: Vec<String> = lines.map_while(Result::ok).collect();
    assert!(
        rest.iter().any(|l| l.contains("demonstration in")),
        "{rest:?}"
    );
    assert_eq!(
        image::open(&png).unwrap().to_rgb8().dimensions(),
        (1000, 700)
    );
    // the dataset, the result and the replay page are there
    for f in [
        "manifest.yaml",
        "result.json",
        "replay.html",
        "steps-00000.parquet",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let result = std::fs::read_to_string(out.join("result.json")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    serde_json::from_str(&result).unwrap()
}

#[test]
fn the_live_view_shows_a_system_driving_and_the_session_is_saved() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set VERTI_CHROMIUM)");
        return;
    };
    let result = live_session(&browser, Some("pid"), "", "pid");
    assert_eq!(result["system"], "pid");
    assert!(result["path_length"].as_f64().unwrap() > 1.0, "{result}");
}

#[test]
fn keys_held_in_the_live_page_drive_the_vehicle() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set VERTI_CHROMIUM)");
        return;
    };
    // `#keys=u`: the page holds the accelerator, and sends it with every poll
    let driven = live_session(&browser, None, "#keys=u", "keys");
    assert_eq!(driven["system"], "human");
    assert!(driven["path_length"].as_f64().unwrap() > 1.0, "{driven}");
    // no keys: the vehicle stays where it settled
    let idle = live_session(&browser, None, "", "idle");
    assert!(idle["path_length"].as_f64().unwrap() < 0.5, "{idle}");
}
