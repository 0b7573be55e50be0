//! `--time-budget` through the binary: a budget stops the solve with the
//! best solution so far, which still renders and whose stats say why it
//! stopped; a budget that is not a duration is a usage error before any
//! file is read. Nothing is timed: a budget of zero stops before the first
//! shot whatever the machine.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::Path;

mod common;
use common::{folder, scene, trilux};

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn stats(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn a_spent_budget_saves_the_solution_so_far_and_says_why() {
    let dir = folder("budget-zero");
    let (sol, json) = (dir.join("c.sol"), dir.join("c.json"));
    let out = trilux(&[
        "solve",
        &scene("cornell-box.xml"),
        "-o",
        s(&sol),
        "--stats",
        s(&json),
        "--quality",
        "draft",
        "--time-budget",
        "0",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("time budget"), "a warning: {stderr}");
    let st = stats(&json);
    assert_eq!(st["stop_reason"], "time_budget");
    assert_eq!(st["shots"], 0);
    assert_eq!(st["time_budget_seconds"], 0.0);
    // The saved solution loads and renders (its budget is not part of it).
    let exr = dir.join("c.exr");
    let out = trilux(&[
        "render",
        &scene("cornell-box.xml"),
        "--solution",
        s(&sol),
        "-o",
        s(&exr),
        "--quality",
        "draft",
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(exr.exists());
}

#[test]
fn a_solve_within_its_budget_converges_as_without_one() {
    let dir = folder("budget-ample");
    let run = |name: &str, budget: Option<&str>| {
        let json = dir.join(name);
        let mut args = vec![
            "solve",
            "--quality",
            "draft",
            "--stats",
            s(&json),
            "-o",
            "/dev/null",
        ];
        if let Some(b) = budget {
            args.extend(["--time-budget", b]);
        }
        let furnace = scene("furnace.xml");
        args.push(&furnace);
        let out = trilux(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        stats(&json)
    };
    let (free, ample) = (run("free.json", None), run("ample.json", Some("31536000")));
    assert_eq!(free["stop_reason"], "converged");
    assert_eq!(ample["stop_reason"], "converged");
    assert_eq!(free["shots"], ample["shots"]);
    assert_eq!(free["convergence_ratio"], ample["convergence_ratio"]);
}

#[test]
fn a_budget_that_is_not_a_duration_is_a_usage_error() {
    for bad in ["-1", "nan", "inf", "1e12", "soon"] {
        let out = trilux(&[
            "solve",
            "/no/such/scene.xml",
            "-o",
            "/tmp/never.sol",
            "--time-budget",
            bad,
        ]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("--time-budget"), "{bad}: {stderr}");
    }
}
