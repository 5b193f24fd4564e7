//! Allowed `samples` and `horizon` values whose plans cannot fit are refused before the run
//! with the figures (issue 33, item 8). Before, the process aborted on allocation failure
//! (SIGABRT with a backtrace) under an address-space limit.

use std::process::Command;

#[test]
#[cfg(target_os = "linux")]
fn a_plan_too_big_for_the_address_space_is_refused_with_its_size() {
    let verti = env!("CARGO_BIN_EXE_verti");
    let out_dir = std::env::temp_dir().join(format!("verti-plan-memory-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).unwrap();
    for system in ["tal", "mppi", "pietra"] {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v 4000000; exec '{verti}' eval --system {system} --param samples=65536 --param horizon=1000 --worlds verti-1 --tasks 1 --max-time 1 --out '{}'",
                out_dir.join(system).display()
            ))
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{system}: {text}");
        assert!(
            text.contains("65536000 rollout steps") && text.contains("lower samples or horizon"),
            "{system}: {text}"
        );
        // refused before anything was written
        assert!(!out_dir.join(system).join("results.jsonl").exists());
    }
    let _ = std::fs::remove_dir_all(&out_dir);
}
