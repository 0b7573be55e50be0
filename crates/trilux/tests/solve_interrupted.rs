//! SIGINT and SIGTERM during `trilux solve` through the binary (README,
//! "Stopping a solve"): the solve stops between shots, writes the solution
//! so far and its stats (stop reason `interrupted`, one warning line) and
//! exits with 128 + the signal's number; its stderr, a pipe and not a
//! terminal, shows plain progress lines. Nothing is timed: the signal is
//! sent once a progress line shows that shots are under way, on a solve
//! asked for a convergence it cannot reach soon; the waits are hang guards.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

mod common;
use common::{folder, scene, trilux};

/// A hang guard, not a speed figure.
const GUARD: Duration = Duration::from_secs(300);

/// Starts a solve of the 64 boxes towards a convergence of 1 (which takes
/// far longer than the test waits), sends `signal` once a plain progress
/// line of its shots shows, and returns its exit code and stderr.
fn interrupted_solve(dir: &Path, signal: &str) -> (Option<i32>, String) {
    // Through coreutils' `env --default-signal` (as in hostile_outputs):
    // a test runner started in the background of a non-interactive shell
    // passes SIGINT on ignored.
    let mut child = Command::new("env")
        .arg("--default-signal=INT,TERM")
        .arg("TRILUX_PROGRESS_SECONDS=0.05")
        .arg(env!("CARGO_BIN_EXE_trilux"))
        .current_dir(dir)
        .args(["solve", &scene("boxes-64.xml"), "-o", "s.sol"])
        .args(["--stats", "s.json", "--convergence", "1", "--threads", "2"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (tx, rx) = mpsc::channel();
    let stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut all = String::new();
        for line in BufReader::new(stderr).split(b'\n') {
            let line = String::from_utf8_lossy(&line.unwrap()).into_owned();
            let _ = tx.send(line.clone());
            all.push_str(&line);
            all.push('\n');
        }
        all
    });
    let start = Instant::now();
    loop {
        let line = rx
            .recv_timeout(GUARD.saturating_sub(start.elapsed()))
            .unwrap_or_else(|e| panic!("no progress line of the shots: {e}"));
        if line.starts_with("solve: CR") && !line.contains(" 0 shots") {
            break;
        }
    }
    let status = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > GUARD {
            let _ = child.kill();
            panic!("SIG{signal}: the solve had not ended after {GUARD:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let code = child.wait().unwrap().code();
    (code, reader.join().unwrap())
}

#[test]
fn a_signal_during_a_solve_writes_the_partial_solution_and_its_stats() {
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let dir = folder(&format!("interrupted-{signal}"));
        let (status, stderr) = interrupted_solve(&dir, signal);
        assert_eq!(status, Some(code), "SIG{signal}: {stderr}");
        assert!(!stderr.contains('\r'), "plain lines only: {stderr:?}");
        let warnings: Vec<_> = stderr
            .lines()
            .filter(|l| l.starts_with("warning:"))
            .collect();
        assert_eq!(warnings.len(), 1, "{stderr}");
        assert!(warnings[0].contains("interrupted"), "{stderr}");
        assert!(warnings[0].contains("partial"), "{stderr}");
        let stats: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("s.json")).unwrap()).unwrap();
        assert_eq!(stats["stop_reason"], "interrupted", "{stats}");
        assert!(stats["shots"].as_u64().unwrap() > 0, "{stats}");
        let cr = stats["convergence_ratio"].as_f64().unwrap();
        assert!(cr > 0.0 && cr < 1.0, "{cr}");
        // The partial solution loads and renders.
        let exr = dir.join("s.exr");
        let out = trilux(&[
            "render",
            &scene("boxes-64.xml"),
            "--solution",
            dir.join("s.sol").to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--width",
            "16",
            "--height",
            "16",
            "--spp",
            "1",
            // The solution is made for the solve's settings (its hash).
            "--convergence",
            "1",
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "SIG{signal}: {err}");
        assert!(exr.exists());
    }
}
