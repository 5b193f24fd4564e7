//! Driving headless: scripted keys through a session, and the live view's server driven by a
//! scripted HTTP client the way the page drives it.

mod common;

use common::{Server, world};
use std::time::Duration;
use verti_bench::EpisodeConfig;
use verti_drive::script::KeyScript;
use verti_drive::{DemoInfo, DriveSession};

#[test]
fn a_scripted_drive_follows_the_rules_and_records_a_dataset() {
    let (worlds, spec) = world();
    let w = &worlds[0];
    let cfg = EpisodeConfig {
        max_time: 12.0,
        ..Default::default()
    };
    let script = KeyScript::parse("0 up\n4 up left\n5 up\n").unwrap();
    let mut session = DriveSession::start(w, &spec, w.tasks[0].pair, &cfg, None).unwrap();
    let outcome = script.drive(&mut session);
    let end = session.finish();
    assert_eq!(end.result.outcome, outcome);
    assert_eq!(end.result.system, "human");
    // 10 Hz rows up to the end; the commands are the keys' ramps
    let rows = &end.record.rows;
    assert_eq!(rows.len(), (end.result.time * 10.0).round() as usize);
    // row k holds the command given from step k: k + 1 updates of 0.15 m/s
    assert!((rows[19].speed - 3.0).abs() < 1e-9, "{}", rows[19].speed);
    assert!(rows[45].steering > 0.0 && rows[30].steering == 0.0);
    assert_eq!(end.recording.frames.len(), rows.len() + 1);
    assert!(end.result.path_length > 10.0, "{}", end.result.path_length);

    // the dataset loads as any other, recorded as an expert demonstration by a human
    let dir = std::env::temp_dir().join(format!("verti-demo-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let info = DemoInfo {
        set: "verti-4",
        spec: &spec,
        max_time: 12.0,
        source: "human",
        rate: 10.0,
        command: "test",
    };
    let m = verti_drive::write_demonstrations(
        &dir,
        std::slice::from_ref(&end.record),
        &worlds,
        &info,
        false,
    )
    .unwrap();
    assert_eq!(
        (m.trials, m.rows, m.source.as_str()),
        (1, rows.len(), "human")
    );
    let data = verti_data::Dataset::load(&dir).unwrap();
    assert_eq!(data.trial_count(), 1);
    let trial = data.trials().next().unwrap();
    assert_eq!(trial.len(), rows.len());
    assert_eq!(trial.f64("cmd_speed").unwrap()[20], rows[20].speed);
    // a second demonstration into the same directory needs force
    assert!(verti_drive::write_demonstrations(&dir, &[end.record], &worlds, &info, false).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_live_server_steps_in_time_with_the_keys_it_is_sent() {
    // 20x real time keeps the test short
    let server = Server::start(20.0, Duration::from_secs(10));
    let mut frames = 1usize;
    let mut top_speed = 0.0f64;
    // poll until the goal of the test is reached rather than a fixed number of times: the
    // simulated clock runs at 20x wall time, so on a loaded machine a fixed count of slow polls
    // would run the trial into its time limit, and the server ends with the trial
    for _ in 0..400 {
        if frames > 50 && top_speed > 4.0 {
            break;
        }
        let body = server.post(&format!("/step?keys=u&since={frames}")).body;
        let j: serde_json::Value = serde_json::from_str(&body).unwrap();
        let new = j["frames"].as_array().unwrap();
        frames += new.len();
        for f in new {
            top_speed = f64::max(top_speed, f["speed"].as_f64().unwrap());
        }
        std::thread::sleep(Duration::from_millis(25));
    }
    // many control periods, and the held accelerator brought the vehicle up to the driver's
    // top target speed (5 m/s)
    assert!(frames > 50, "{frames}");
    assert!(top_speed > 4.0, "{top_speed}");
    let bad = server.post("/step?keys=x");
    assert_eq!(bad.status, 400);
    assert!(bad.body.contains("unknown key `x`"), "{}", bad.body);
    // keys in a form body work as well as in the query
    let body = format!("keys=u&since={frames}");
    let form = common::exchange(
        server.addr,
        &format!(
            "POST /step HTTP/1.1\r\nHost: {}\r\nX-Verti-Token: {}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\n\r\n{body}",
            server.host,
            server.token,
            body.len()
        ),
    );
    assert_eq!(form.status, 200, "{}", form.body);
    let j: serde_json::Value = serde_json::from_str(&form.body).unwrap();
    frames += j["frames"].as_array().unwrap().len();
    let end = server.quit();
    // stopped while running: kept, as a trial that did not end
    assert_eq!(end.recording.frames.len(), frames);
    assert_eq!(end.record.rows.len(), frames - 1);
    assert!(
        end.result
            .error
            .as_deref()
            .unwrap_or("")
            .contains("did not end")
    );
}
