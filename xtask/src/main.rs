//! Project automation: `cargo xtask ci` runs everything the tests need
//! (fmt, the structure check, clippy, the workspace's tests in release mode, the colour check and
//! the golden images); `cargo xtask color` checks trilux's colorimetry
//! against colour-science; `cargo xtask golden` compares renders of every
//! bundled scene with stored Mitsuba 3 references; `cargo xtask sweep`
//! measures error against time; `cargo xtask rays` measures ray queries
//! against Embree; `cargo xtask scale` measures solve cost against scene
//! size on generated scenes.

mod counting_alloc;
mod deps;
mod golden;
mod package;
mod rays;
mod scale;
mod scale_scenes;
mod stopping;
mod structure;
mod surface;
mod sweep;
mod viewer;
mod viewer_glossy;
mod viewer_shots;

/// Counts the process's allocations (the peak memory `scale` reports).
#[global_allocator]
static ALLOCATOR: counting_alloc::Counting = counting_alloc::Counting;

use std::process::Command;

use anyhow::{Context, Result, bail};

mod color;

fn run(program: &str, args: &[&str]) -> Result<()> {
    eprintln!("xtask: {program} {}", args.join(" "));
    let status = Command::new(program)
        .args(args)
        .status()
        .with_context(|| format!("could not start {program}"))?;
    if !status.success() {
        bail!("{program} {} failed ({status})", args.join(" "));
    }
    Ok(())
}

/// [`run`] with one environment variable set.
fn run_env(var: (&str, &str), program: &str, args: &[&str]) -> Result<()> {
    eprintln!("xtask: {}={} {program} {}", var.0, var.1, args.join(" "));
    let status = Command::new(program)
        .env(var.0, var.1)
        .args(args)
        .status()
        .with_context(|| format!("could not start {program}"))?;
    if !status.success() {
        bail!("{program} {} failed ({status})", args.join(" "));
    }
    Ok(())
}

fn ci() -> Result<()> {
    run("cargo", &["fmt", "--all", "--", "--check"])?;
    // Module cycles, long files and long functions: read from the source
    // text, before anything is compiled.
    structure::main()?;
    // Every declared dependency used (a text check, see deps.rs for why
    // not cargo-machete).
    deps::main()?;
    // The public-item count of every library crate is the one
    // docs/architecture.md states (a change of surface is deliberate).
    surface::main(&["--check".to_string()])?;
    run(
        "cargo",
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    // Every feature on too, so that optional code (`trace-stats`) compiles.
    // The MSRV is checked here too: clippy's `incompatible_msrv` lint
    // (on by default) refuses any standard-library item newer than the
    // `rust-version` each package inherits from the workspace manifest
    // (xtask included), the one way to check it with the single toolchain
    // CI has. It checks library items, not language features.
    run(
        "cargo",
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--all-features",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    run_env(
        ("RUSTDOCFLAGS", "-D warnings"),
        "cargo",
        &["doc", "--workspace", "--no-deps"],
    )?;
    // One build for every test: the release profile (the one xtask itself
    // runs in, so the golden and viewer steps reuse it). .ci/run turns
    // overflow checks and debug assertions on in that profile for the whole
    // run, so unit, integration, golden and viewer tests all run with them.
    run("cargo", &["test", "--workspace", "--release"])?;
    package::main()?;
    color::color()?;
    // Every bundled scene against its stored Mitsuba 3 reference (the
    // golden test: relative RMSE ≤ 0.05, mean within 1 %).
    // Its solutions are saved for the viewer step, which bakes them.
    let solutions = "target/ci-solutions".to_string();
    golden::main(&[
        "--spp".to_string(),
        "64".to_string(),
        "--save-solutions".to_string(),
        solutions.clone(),
    ])?;
    // Every bundled scene baked, validated (Khronos glTF validator) and
    // photographed in docs/viewer beside its preview.
    // (.ci/run installs Chromium and the viewer's npm packages.)
    run("node", &["docs/viewer/scripts/vendor.mjs", "--check"])?;
    run("node", &["--test", "docs/viewer/test/viewer.test.mjs"])?;
    viewer::main(&["--solutions".to_string(), solutions])?;
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("ci") => ci(),
        Some("color") => color::color(),
        Some("structure") => structure::main(),
        Some("deps") => deps::main(),
        Some("surface") => surface::main(&args[1..]),
        Some("package") => package::main(),
        Some("golden") => golden::main(&args[1..]),
        Some("sweep") => sweep::main(&args[1..]),
        Some("rays") => rays::main(&args[1..]),
        Some("scale") => scale::main(&args[1..]),
        Some("stopping") => stopping::main(&args[1..]),
        Some("viewer") => viewer::main(&args[1..]),
        _ => {
            eprintln!(
                "usage: cargo xtask ci | structure | deps | surface | package | color | golden | sweep | rays | scale | stopping | viewer"
            );
            std::process::exit(2);
        }
    }
}
