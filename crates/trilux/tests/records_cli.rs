//! The record of a run, through the binary (docs/architecture.md, "The
//! record"): `--stats` of `solve`, `render` and `bake` and a rendered EXR's
//! header carry trilux's version, the command line, every setting, the
//! seconds of each phase, the peak resident memory and the convergence
//! trace. Checked against what the test itself knows: the arguments it
//! passed, the settings it asked for, the wall time it measured around
//! the process, the machine's memory.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

use serde_json::Value;

mod common;
use common::folder;
use common::hostile::{furnace, write};

/// Runs the binary in `dir` with `args`; also the seconds the test saw it
/// run (an upper bound of any time it reports).
fn run_in(dir: &Path, args: &[&str]) -> (Output, f64) {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_trilux"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the trilux binary runs");
    let seconds = start.elapsed().as_secs_f64();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    (out, seconds)
}

fn json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// The command line the record must hold: the program, then `args`.
fn command_line(args: &[&str]) -> Value {
    let mut all = vec![env!("CARGO_BIN_EXE_trilux")];
    all.extend_from_slice(args);
    serde_json::json!(all)
}

/// The machine's memory in bytes (/proc/meminfo's MemTotal).
fn mem_total() -> u64 {
    let info = std::fs::read_to_string("/proc/meminfo").unwrap();
    let line = info.lines().find(|l| l.starts_with("MemTotal:")).unwrap();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024
}

/// What holds for every record: the version, the command line, the phases
/// (none negative, their sum within the wall time, which is within what
/// the test measured), the memory (more than a megabyte, less than the
/// machine has), the trace the same as the statistics'.
fn check_record(stats: &Value, args: &[&str], seen_seconds: f64) -> Value {
    let r = stats["record"].clone();
    assert_eq!(r["trilux_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(r["command_line"], command_line(args));
    let p = &r["phases"];
    let phases = [
        "read_seconds",
        "prepare_seconds",
        "solve_seconds",
        "bake_seconds",
        "render_seconds",
    ];
    let sum: f64 = phases.iter().map(|k| p[*k].as_f64().unwrap()).sum();
    assert!(phases.iter().all(|k| p[*k].as_f64().unwrap() >= 0.0), "{p}");
    let wall = p["wall_seconds"].as_f64().unwrap();
    assert!(
        sum <= wall && wall <= seen_seconds,
        "{p}, seen {seen_seconds}"
    );
    let memory = r["peak_resident_bytes"].as_u64().unwrap();
    assert!(memory > 1 << 20 && memory < mem_total(), "{memory}");
    assert_eq!(r["convergence_trace"], stats["convergence_trace"]);
    r
}

#[test]
fn a_solve_records_its_command_line_settings_phases_and_memory() {
    let dir = folder("record-solve");
    write(&dir, "scene.xml", furnace("0.5", "1", 1.0));
    let args = [
        "solve",
        "scene.xml",
        "-o",
        "s.sol",
        "--stats",
        "s.json",
        "--quality",
        "draft",
        "--convergence",
        "0.97",
        "--time-budget",
        "600",
        "--mode",
        "rgb",
        "--threads",
        "1",
    ];
    let (_, seen) = run_in(&dir, &args);
    let stats = json(&dir.join("s.json"));
    let r = check_record(&stats, &args, seen);
    let s = &r["settings"];
    assert_eq!(s["solver"]["convergence"], 0.97);
    assert_eq!(s["solver"]["time_budget_seconds"], 600.0);
    assert_eq!(s["mode"], "rgb");
    assert_eq!(s["threads"], 1);
    assert_eq!(s["scene"], "scene.xml");
    assert_eq!(s["solution"], Value::Null);
    assert_eq!((&s["render"], &s["bake"]), (&Value::Null, &Value::Null));
    // A solve renders and bakes nothing; it solved, so it has a trace
    // ending at the statistics' last shot.
    assert_eq!(r["phases"]["render_seconds"], 0.0);
    assert_eq!(r["phases"]["bake_seconds"], 0.0);
    let last = r["convergence_trace"].as_array().unwrap().last().unwrap();
    assert_eq!(last["shots"], stats["shots"]);
    assert_eq!(last["convergence_ratio"], stats["convergence_ratio"]);
}

/// The `trilux.*` attributes of an EXR header, read back with the `exr`
/// crate, and its `software` attribute.
fn exr_header(path: &Path) -> (serde_json::Map<String, Value>, String) {
    use exr::meta::attribute::AttributeValue;
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    let layer = &meta.headers[0].own_attributes;
    let text = |v: &AttributeValue| match v {
        AttributeValue::Text(t) => t.to_string(),
        other => panic!("not text: {other:?}"),
    };
    let mut found = serde_json::Map::new();
    for (name, value) in &layer.other {
        let name = name.to_string();
        let key = name.strip_prefix("trilux.").unwrap().to_string();
        let value = text(value);
        let parsed = serde_json::from_str(&value).unwrap_or(Value::String(value));
        found.insert(key, parsed);
    }
    let software = layer.software_name.as_ref().unwrap().to_string();
    (found, software)
}

#[test]
fn a_render_writes_its_record_into_the_exr_header_and_the_stats() {
    // A folder whose name is not ASCII: the header's text stays ASCII
    // (JSON escapes) and reads back as the same path.
    let dir = folder("record-render-é");
    write(&dir, "scene.xml", furnace("0.5", "1", 1.0));
    let args = [
        "render",
        "scene.xml",
        "-o",
        "ré.exr",
        "--stats",
        "r.json",
        "--quality",
        "draft",
        "--spp",
        "3",
        "--seed",
        "7",
        "--width",
        "10",
        "--height",
        "6",
        "--gather",
        "links",
        "--extra-bounce",
        "never",
        "--exposure",
        "-1.5",
    ];
    let (_, seen) = run_in(&dir, &args);
    let stats = json(&dir.join("r.json"));
    let r = check_record(&stats, &args, seen);
    let render = &r["settings"]["render"];
    assert_eq!(render["spp"], 3);
    assert_eq!(render["seed"], 7);
    assert_eq!(
        (&render["view"]["width"], &render["view"]["height"]),
        (&10.into(), &6.into())
    );
    assert_eq!(render["estimator"], "links");
    assert_eq!(render["extra_bounce"], "never");
    assert_eq!(r["settings"]["png_exposure"], -1.5);
    // The scene's own camera: furnace() writes a 60° field of view.
    assert_eq!(render["scene_camera"]["fov"], 60.0);
    assert!(r["phases"]["render_seconds"].as_f64().unwrap() > 0.0);
    // The header holds the same record, key by key.
    let (header, software) = exr_header(&dir.join("ré.exr"));
    assert_eq!(software, format!("trilux {}", env!("CARGO_PKG_VERSION")));
    assert_eq!(header["version"], r["trilux_version"]);
    assert_eq!(header["commandLine"], command_line(&args));
    assert_eq!(header["settings"], r["settings"]);
    assert_eq!(header["phases"], r["phases"]);
    assert_eq!(header["peakResidentBytes"], r["peak_resident_bytes"]);
    assert_eq!(header["convergenceTrace"], r["convergence_trace"]);
    // And the image still reads as one.
    let image = trilux_render::Image::read_exr(&dir.join("ré.exr")).unwrap();
    assert_eq!((image.width(), image.height()), (10, 6));
}

#[test]
fn a_bake_of_a_saved_solution_records_the_solution_and_its_phase() {
    let dir = folder("record-bake");
    write(&dir, "scene.xml", furnace("0.5", "1", 1.0));
    let solve = ["solve", "scene.xml", "-o", "s.sol", "--quality", "draft"];
    run_in(&dir, &[&solve[..], &["--stats", "s.json"]].concat());
    let args = [
        "bake",
        "scene.xml",
        "--solution",
        "s.sol",
        "--quality",
        "draft",
        "-o",
        "b.glb",
        "--stats",
        "b.json",
        "--exposure",
        "2",
        "--no-albedo-maps",
    ];
    let (_, seen) = run_in(&dir, &args);
    let stats = json(&dir.join("b.json"));
    let r = check_record(&stats, &args, seen);
    let s = &r["settings"];
    assert_eq!(s["solution"], "s.sol");
    assert_eq!(s["bake"]["exposure"], 2.0);
    assert_eq!(s["bake"]["albedo_maps"], false);
    assert_eq!(r["phases"]["bake_seconds"], stats["bake"]["seconds"]);
    // A loaded solution's trace is that of the solve that made it.
    let solved = json(&dir.join("s.json"));
    assert!(!solved["convergence_trace"].as_array().unwrap().is_empty());
    assert_eq!(r["convergence_trace"], solved["convergence_trace"]);
}

/// `info --json` of `scene`.
fn info_json(scene: &Path) -> Value {
    let (out, _) = run_in(Path::new("."), &["info", scene.to_str().unwrap(), "--json"]);
    serde_json::from_slice(&out.stdout).unwrap()
}

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn info_json_lists_every_shape_as_the_text_does() {
    // The Cornell box's shapes, read from the file itself: each
    // `<shape type=... id=...>` in order.
    let path = scenes().join("cornell-box.xml");
    let text = std::fs::read_to_string(&path).unwrap();
    let attr = |tag: &str, name: &str| {
        let at = tag.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        tag[at..at + tag[at..].find('"').unwrap()].to_string()
    };
    let shapes: Vec<(String, String)> = text
        .split("<shape ")
        .skip(1)
        .map(|t| (attr(t, "type"), attr(t, "id")))
        .collect();
    let v = info_json(&path);
    let list = v["shape_list"].as_array().unwrap();
    assert_eq!(list.len(), shapes.len());
    assert_eq!(v["shapes"], shapes.len());
    for (i, (s, (kind, id))) in list.iter().zip(&shapes).enumerate() {
        assert_eq!(
            (&s["index"], &s["kind"], &s["id"]),
            (&i.into(), &kind.as_str().into(), &id.as_str().into())
        );
        assert_eq!(s["emitter"], id == "light", "{s}");
    }
    // The text lists the same shapes, one line each.
    let (out, _) = run_in(Path::new("."), &["info", path.to_str().unwrap()]);
    let out = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("  shape ")).collect();
    assert_eq!(lines.len(), shapes.len());
    for (line, (_, id)) in lines.iter().zip(&shapes) {
        assert!(line.contains(id.as_str()), "{line}");
    }
    // A cube scaled by 3 spans [-3, 3]³: area 6 · 6².
    let dir = folder("record-info-area");
    let cube = write(&dir, "scene.xml", furnace("0.5", "1", 3.0));
    let s = &info_json(&cube)["shape_list"][0];
    assert_eq!(s["kind"], "cube");
    assert!((s["area"].as_f64().unwrap() - 216.0).abs() < 1e-9, "{s}");
    assert_eq!(s["triangles"], Value::Null);
}

#[test]
fn info_names_the_gltf_cameras() {
    // The names as the glTF crate reads them: each camera's, else its
    // node's.
    let path = scenes().join("product-shot.glb");
    let doc = gltf::Gltf::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let names: Vec<Value> = doc
        .nodes()
        .filter_map(|n| {
            let c = n.camera()?;
            Some(c.name().or(n.name()).map_or(Value::Null, Value::from))
        })
        .collect();
    assert!(names.len() >= 2, "{names:?}");
    let v = info_json(&path);
    assert_eq!(v["cameras"], Value::Array(names.clone()));
    let (out, _) = run_in(Path::new("."), &["info", path.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    let listed: Vec<&str> = names.iter().map(|n| n.as_str().unwrap()).collect();
    let line = format!("cameras        {}", listed.join(", "));
    assert!(text.lines().any(|l| l == line), "{text}");
    // An XML scene has one sensor and no named cameras.
    assert_eq!(
        info_json(&scenes().join("cornell-box.xml"))["cameras"],
        serde_json::json!([])
    );
}

/// Columns of the test's terminal.
const COLUMNS: usize = 80;

/// The screen a terminal of [`COLUMNS`] shows after `bytes`: a minimal
/// emulator of what progress bars send (carriage return, newline, erase
/// line, cursor up and down, erase below, and a long line wrapping onto
/// the next), enough to see a line left behind.
fn screen(bytes: &[u8]) -> Vec<String> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = vec![String::new()];
    let (mut row, mut col) = (0usize, 0usize);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\r' => col = 0,
            '\n' => {
                row += 1;
                col = 0;
                if row == lines.len() {
                    lines.push(String::new());
                }
            }
            '\x1b' if chars.peek() == Some(&'[') => {
                chars.next();
                let mut arg = String::new();
                let mut end = ' ';
                for c in chars.by_ref() {
                    if c.is_ascii_alphabetic() {
                        end = c;
                        break;
                    }
                    arg.push(c);
                }
                let n: usize = arg.parse().unwrap_or(1);
                match end {
                    'K' => lines[row].clear(),
                    'A' => row = row.saturating_sub(n),
                    'B' => {
                        row += n;
                        lines.resize(lines.len().max(row + 1), String::new());
                    }
                    'J' => {
                        lines[row].truncate(col);
                        lines.truncate(row + 1);
                    }
                    _ => {}
                }
            }
            c => {
                if col == COLUMNS {
                    row += 1;
                    col = 0;
                    lines.resize(lines.len().max(row + 1), String::new());
                }
                let mut line: Vec<char> = lines[row].chars().collect();
                line.resize(line.len().max(col), ' ');
                if col < line.len() {
                    line[col] = c;
                } else {
                    line.push(c);
                }
                lines[row] = line.into_iter().collect();
                col += 1;
            }
        }
    }
    while lines.last().is_some_and(String::is_empty) {
        lines.pop();
    }
    lines
}

#[test]
fn the_emulated_screen_sees_a_stale_line() {
    // The emulator itself: a cleared line stays, empty, when the cursor
    // moved on below it.
    assert_eq!(screen(b"bar\r\x1b[2Kdone\n"), ["done"]);
    assert_eq!(screen(b"bar\n\x1b[2Kdone\n"), ["bar", "done"]);
    assert_eq!(screen(b"bar\r\x1b[2K\ndone\n"), ["", "done"]);
    // A line longer than the terminal wraps: erasing the last row leaves
    // the first.
    let long = format!("{}tail\r\x1b[2Kdone\n", "x".repeat(COLUMNS));
    assert_eq!(
        screen(long.as_bytes()),
        ["x".repeat(COLUMNS), "done".into()]
    );
}

#[test]
fn the_progress_bar_estimates_the_time_left_and_leaves_no_line_behind() {
    // A terminal for the binary: util-linux's `script` (Debian's
    // essential bsdutils), which runs the command on a pseudo-terminal of
    // COLUMNS columns and copies what it shows. (trilux 0.1.0 before this
    // test drew a bar for the solve and one for the render at once and
    // let the solve's message wrap: lines of both stayed on the screen.)
    let dir = folder("record-progress");
    let scene = scenes().join("cornell-box.xml");
    let command = format!(
        "stty cols {COLUMNS} rows 24; '{}' render '{}' --quality draft --spp 2 --width 64 --height 48 -o a.exr",
        env!("CARGO_BIN_EXE_trilux"),
        scene.display()
    );
    let out = Command::new("script")
        .current_dir(&dir)
        .args(["-qec", &command, "/dev/null"])
        .output()
        .expect("script (util-linux) runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let shown = String::from_utf8_lossy(&out.stdout);
    // The solve's bar, with its estimate from the convergence.
    assert!(
        shown.contains("solve [") && shown.contains(" s left, CR "),
        "{shown:?}"
    );
    // Once done, the terminal shows the report and nothing else: no bar,
    // no empty line.
    assert_eq!(screen(&out.stdout), ["wrote a.exr"], "{shown:?}");
}
