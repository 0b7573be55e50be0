//! No silent wrong output, through the binary: an output is written in the
//! format its name asks for or refused (status 2, one line, before any
//! file is read); only the outputs asked for are written, each reported
//! as `wrote PATH`; `render`, `solve` and `bake` share the `-o` rules
//! (a default under `out/` when `-o` is not given); a `-D` value the scene
//! never uses is refused (as Mitsuba 3 does); a scene without an emitter
//! is warned about.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::folder;
use common::hostile::{furnace, s, write};

/// The OpenEXR and PNG magic numbers.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
const PNG_MAGIC: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

/// Runs the binary in `dir` (so that a default `out/` lands there).
fn trilux_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trilux"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the trilux binary runs")
}

/// A folder with a small lit box `scene.xml` (12 × 12 pixels, 4 spp).
fn setup(name: &str) -> (PathBuf, PathBuf) {
    let dir = folder(name);
    let scene = write(&dir, "scene.xml", furnace("0.5", "1", 1.0));
    (dir, scene)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn assert_ok(out: &Output) {
    assert!(out.status.success(), "{}", stderr(out));
}

/// Every file below `dir`, relative to it, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut all = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap();
                all.push(rel.to_string_lossy().into_owned());
            }
        }
    }
    all.sort();
    all
}

/// One line `error: {option} {path}: ...` saying `what`, status 2, and
/// nothing written: a usage error.
fn assert_usage(out: &Output, start: &str, what: &str) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.starts_with(&format!("error: {start}")), "{err}");
    assert!(err.contains(what), "{err:?} should say {what:?}");
    assert!(out.stdout.is_empty(), "{}", stdout(out));
}

#[test]
fn an_image_is_written_in_the_format_its_name_asks_for() {
    let (dir, _) = setup("named-format");
    let args = ["render", "scene.xml", "--quality", "draft", "--preview"];
    // -o out.png: a PNG, and nothing else (no out/scene.exr).
    let out = trilux_in(&dir, &[&args[..], &["-o", "out.png"]].concat());
    assert_ok(&out);
    assert!(
        std::fs::read(dir.join("out.png"))
            .unwrap()
            .starts_with(&PNG_MAGIC)
    );
    assert_eq!(files(&dir), ["out.png", "scene.xml"]);
    assert_eq!(stdout(&out), "wrote out.png\n");
    // Upper case is the same format.
    assert_ok(&trilux_in(&dir, &[&args[..], &["-o", "OUT.EXR"]].concat()));
    assert!(
        std::fs::read(dir.join("OUT.EXR"))
            .unwrap()
            .starts_with(&EXR_MAGIC)
    );
}

#[test]
fn a_name_for_another_format_is_a_usage_error_before_any_work() {
    let dir = folder("named-refused");
    // The scene does not exist: a refusal that does not name it was made
    // before anything was read.
    let missing = s(&dir.join("missing.xml")).to_owned();
    let cases: [(&[&str], &str, &str); 8] = [
        (
            &["render", &missing, "-o", "out.jpg"],
            "-o out.jpg",
            "no JPEG",
        ),
        (
            &["render", &missing, "-o", "out.JPEG"],
            "-o out.JPEG",
            "no JPEG",
        ),
        (&["render", &missing, "-o", "out.tif"], "-o out.tif", ".exr"),
        (
            &["render", &missing, "--png", "x.exr"],
            "--png x.exr",
            ".png",
        ),
        (&["solve", &missing, "-o", "x.exr"], "-o x.exr", ".sol"),
        (&["solve", &missing, "-o", "x.glb"], "-o x.glb", ".sol"),
        (&["solve", &missing, "-o", "x.json"], "-o x.json", ".sol"),
        (&["bake", &missing, "-o", "x.gltf"], "-o x.gltf", ".glb"),
    ];
    for (args, start, what) in cases {
        let out = trilux_in(&dir, args);
        assert_usage(&out, start, what);
        assert!(!stderr(&out).contains("missing.xml"), "{args:?}");
        assert!(files(&dir).is_empty(), "{args:?} wrote a file");
        assert!(!dir.join("out").exists(), "{args:?} made out/");
    }
}

#[test]
fn only_the_outputs_asked_for_are_written_each_reported() {
    let (dir, _) = setup("named-only");
    let args = ["render", "scene.xml", "--quality", "draft", "--preview"];
    // --png alone: the PNG, no default EXR.
    let out = trilux_in(&dir, &[&args[..], &["--png", "a.png"]].concat());
    assert_ok(&out);
    assert_eq!(files(&dir), ["a.png", "scene.xml"]);
    assert_eq!(stdout(&out), "wrote a.png\n");
    // Three outputs: three lines, in the order given.
    let more = ["-o", "b.exr", "--png", "b.png", "--stats", "b.json"];
    let out = trilux_in(&dir, &[&args[..], &more].concat());
    assert_ok(&out);
    assert_eq!(stdout(&out), "wrote b.exr\nwrote b.png\nwrote b.json\n");
    assert!(
        std::fs::read(dir.join("b.exr"))
            .unwrap()
            .starts_with(&EXR_MAGIC)
    );
    assert!(
        std::fs::read(dir.join("b.png"))
            .unwrap()
            .starts_with(&PNG_MAGIC)
    );
    // Nothing named: the default EXR under out/.
    let out = trilux_in(&dir, &args);
    assert_ok(&out);
    assert_eq!(stdout(&out), "wrote out/scene.exr\n");
    assert!(
        std::fs::read(dir.join("out/scene.exr"))
            .unwrap()
            .starts_with(&EXR_MAGIC)
    );
}

/// `solve` and `bake` take the same `-o` rules as `render`: a default
/// under `out/` named after the scene, the path reported.
#[test]
fn solve_and_bake_default_to_out_and_report_their_files() {
    let (dir, _) = setup("named-defaults");
    let out = trilux_in(&dir, &["solve", "scene.xml", "--quality", "draft"]);
    assert_ok(&out);
    assert_eq!(stdout(&out), "wrote out/scene.sol\n");
    assert!(
        std::fs::read(dir.join("out/scene.sol"))
            .unwrap()
            .starts_with(b"TRILUXS\0")
    );
    let out = trilux_in(
        &dir,
        &[
            "bake",
            "scene.xml",
            "--quality",
            "draft",
            "--solution",
            "out/scene.sol",
        ],
    );
    assert_ok(&out);
    let lines: Vec<&str> = std::str::from_utf8(&out.stdout).unwrap().lines().collect();
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(lines[0].starts_with("wrote out/scene.glb ("), "{lines:?}");
    assert!(
        std::fs::read(dir.join("out/scene.glb"))
            .unwrap()
            .starts_with(b"glTF")
    );
}

#[test]
fn an_unused_define_is_refused_at_the_scene() {
    let (dir, scene) = setup("named-define");
    // The furnace uses no $name; Mitsuba 3 refuses an unused parameter
    // ("Found unused parameters"), and so does trilux, for every command.
    for command in ["info", "solve", "render", "bake"] {
        let out = trilux_in(&dir, &[command, "scene.xml", "-D", "spp=8"]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{command}: {err}");
        assert_eq!(err.lines().count(), 1, "{command}: {err}");
        assert!(
            err.starts_with("error: scene.xml:1:1: the parameter spp=8 is not used"),
            "{command}: {err}"
        );
        assert_eq!(files(&dir), ["scene.xml"], "{command} wrote a file");
    }
    // A used one is taken (the bundled Cornell box's $res).
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.xml");
    let out = trilux_in(&dir, &["info", s(&cornell), "-D", "res=8", "-D", "nope=1"]);
    assert!(
        stderr(&out).contains("nope=1 is not used"),
        "{}",
        stderr(&out)
    );
    let out = trilux_in(&dir, &["info", s(&cornell), "-D", "res=8", "-D", "spp=2"]);
    assert_ok(&out);
    drop(scene);
}

/// A scene without an emitter: one warning line, for `render` (the image
/// is black) as for `solve` and `bake` (meaningless but harmless); a lit
/// scene gets none.
#[test]
fn a_scene_without_an_emitter_is_warned_about() {
    let (dir, _) = setup("named-dark");
    let dark = furnace("0.5", "1", 1.0).replace(
        r#"<emitter type="area"><float name="radiance" value="1"/></emitter>"#,
        "",
    );
    assert!(!dark.contains("emitter"));
    write(&dir, "dark.xml", dark);
    let runs: [&[&str]; 3] = [
        &["render", "-o", "d.exr", "--preview"],
        &["solve", "-o", "d.sol"],
        &["bake", "-o", "d.glb"],
    ];
    for run in runs {
        for (scene, warned) in [("dark.xml", true), ("scene.xml", false)] {
            let args = [&run[..1], &[scene, "--quality", "draft"], &run[1..]].concat();
            let out = trilux_in(&dir, &args);
            assert_ok(&out);
            let err = stderr(&out);
            let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
            if warned {
                assert_eq!(warnings.len(), 1, "{args:?}: {err}");
                assert!(
                    warnings[0].starts_with("warning: dark.xml: the scene has no emitter"),
                    "{err}"
                );
            } else {
                assert!(warnings.is_empty(), "{args:?}: {err}");
            }
            if warned && run[0] == "render" {
                // The dark render is black: the warning is about a real loss.
                let image = trilux_render::Image::read_exr(&dir.join("d.exr")).unwrap();
                assert!(image.pixels().iter().flatten().all(|&v| v == 0.0));
            }
        }
    }
}
