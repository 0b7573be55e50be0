//! Hostile outputs through the binary (against data loss and damage):
//! a symbolic link stays a link, a FIFO stays a FIFO, an output equal to
//! an input or to another output is refused before any work, an unrelated
//! file is never touched by the temporary file, and a failing output
//! leaves every other one as it was.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::hostile::{assert_ok, assert_refused, furnace, mkfifo, s, write};
use common::{folder, trilux};

/// The same scene with a mesh that does not exist: any error it gives
/// shows that the scene was loaded, so an output error instead shows that
/// outputs are checked first.
const SCENE_MISSING_MESH: &str = r#"<scene version="3.0.0">
  <shape type="obj"><string name="filename" value="no-such-mesh.obj"/></shape>
</scene>
"#;

/// Every file under `dir` (recursively) with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let meta = std::fs::symlink_metadata(&p).unwrap();
        if meta.is_dir() {
            out.extend(snapshot(&p));
        } else if meta.is_file() {
            out.insert(p.clone(), std::fs::read(&p).unwrap());
        } else {
            out.insert(p.clone(), b"(not a regular file)".to_vec());
        }
    }
    out
}

/// A folder holding the scene, a mesh-less copy and a draft solution.
fn setup(name: &str) -> (PathBuf, PathBuf) {
    let dir = folder(name);
    let scene = dir.join("scene.xml");
    std::fs::write(&scene, furnace("0.5", "1.0", 1.0)).unwrap();
    std::fs::write(dir.join("missing-mesh.xml"), SCENE_MISSING_MESH).unwrap();
    (dir, scene)
}

fn solve(scene: &Path, sol: &Path) {
    assert_ok(&trilux(&[
        "solve",
        s(scene),
        "-o",
        s(sol),
        "--quality",
        "draft",
    ]));
}

#[test]
fn a_symbolic_link_output_stays_a_link() {
    let (dir, scene) = setup("out-symlink");
    let real = dir.join("real.exr");
    std::fs::write(&real, "old").unwrap();
    let link = dir.join("link.exr");
    std::os::unix::fs::symlink("real.exr", &link).unwrap();
    assert_ok(&trilux(&[
        "render",
        s(&scene),
        "-o",
        s(&link),
        "--quality",
        "draft",
    ]));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    let bytes = std::fs::read(&real).unwrap();
    assert_eq!(
        &bytes[..4],
        &[0x76, 0x2f, 0x31, 0x01],
        "an EXR behind the link"
    );
    // A link to the scene is the scene.
    let to_scene = dir.join("to-scene.exr");
    std::os::unix::fs::symlink("scene.xml", &to_scene).unwrap();
    let before = snapshot(&dir);
    let out = trilux(&["render", s(&scene), "-o", s(&to_scene)]);
    assert_refused(&out, "", "would overwrite the input");
    assert_eq!(snapshot(&dir), before);
}

#[test]
fn a_fifo_output_is_written_through() {
    let (dir, scene) = setup("out-fifo");
    let fifo = dir.join("pipe.exr");
    mkfifo(&fifo);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            std::fs::File::open(&fifo)
                .unwrap()
                .read_to_end(&mut bytes)
                .unwrap();
            bytes
        })
    };
    let png = dir.join("a.png");
    let args = ["render", s(&scene), "-o", s(&fifo), "--png", s(&png)];
    assert_ok(&trilux(&[&args[..], &["--quality", "draft"]].concat()));
    let bytes = reader.join().unwrap();
    assert_eq!(
        &bytes[..4],
        &[0x76, 0x2f, 0x31, 0x01],
        "an EXR through the FIFO"
    );
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(&meta.file_type()));
    assert!(png.is_file());
}

#[test]
fn an_output_equal_to_an_input_or_another_output_is_refused_first() {
    let (dir, scene) = setup("out-same");
    let sol = dir.join("x.sol");
    solve(&scene, &sol);
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::fs::hard_link(&scene, dir.join("hard.xml")).unwrap();
    let m = dir.join("missing-mesh.xml");
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["solve".into(), p("scene.xml"), "-o".into(), p("scene.xml")],
            "would overwrite the input",
        ),
        (
            vec![
                "solve".into(),
                p("missing-mesh.xml"),
                "-o".into(),
                p("sub/../missing-mesh.xml"),
            ],
            "would overwrite the input",
        ),
        (
            vec!["solve".into(), p("scene.xml"), "-o".into(), p("hard.xml")],
            "would overwrite the input",
        ),
        (
            vec![
                "solve".into(),
                s(&m).into(),
                "-o".into(),
                p("a.sol"),
                "--stats".into(),
                p("a.sol"),
            ],
            "the statistics and the solution are the same file",
        ),
        (
            vec![
                "solve".into(),
                s(&m).into(),
                "-o".into(),
                p("new.sol"),
                "--stats".into(),
                p("sub/../new.sol"),
            ],
            "are the same file",
        ),
        (
            vec![
                "render".into(),
                s(&m).into(),
                "-o".into(),
                p("a.png"),
                "--png".into(),
                p("a.png"),
            ],
            "the PNG and the image are the same file",
        ),
        (
            vec![
                "render".into(),
                s(&m).into(),
                "-o".into(),
                p("a.exr"),
                "--stats".into(),
                p("sub/../a.exr"),
            ],
            "are the same file",
        ),
        (
            vec![
                "render".into(),
                p("scene.xml"),
                "--solution".into(),
                p("x.sol"),
                "--stats".into(),
                p("x.sol"),
            ],
            "would overwrite the input",
        ),
        (
            vec!["render".into(), s(&m).into(), "-o".into(), p("sub")],
            "it is a folder",
        ),
        (
            vec![
                "render".into(),
                s(&m).into(),
                "-o".into(),
                p("a.exr"),
                "--stats".into(),
                p("no/such/folder/s.json"),
            ],
            "does not exist",
        ),
    ];
    for (args, what) in cases {
        let before = snapshot(&dir);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = trilux(&args);
        assert_refused(&out, "", what);
        assert!(
            !String::from_utf8_lossy(&out.stderr).contains("no-such-mesh"),
            "outputs are checked before the scene is loaded: {args:?}"
        );
        assert_eq!(snapshot(&dir), before, "nothing touched: {args:?}");
    }
}

#[test]
fn the_temporary_file_never_replaces_an_unrelated_file() {
    let (dir, scene) = setup("out-tmp-name");
    for name in ["keep.tmp-trilux", ".keep.sol.tmp", "keep.sol.tmp"] {
        std::fs::write(dir.join(name), "unrelated").unwrap();
    }
    solve(&scene, &dir.join("keep.sol"));
    for name in ["keep.tmp-trilux", ".keep.sol.tmp", "keep.sol.tmp"] {
        assert_eq!(
            std::fs::read_to_string(dir.join(name)).unwrap(),
            "unrelated"
        );
    }
    // Nothing else left beside the solution and the scenes.
    assert_eq!(snapshot(&dir).len(), 6);
}

#[test]
fn one_failing_output_leaves_the_others_as_they_were() {
    let (dir, scene) = setup("out-all-or-none");
    let exr = dir.join("a.exr");
    std::fs::write(&exr, "previous image").unwrap();
    let before = snapshot(&dir);
    let png = dir.join("a.png");
    let stats = dir.join("missing").join("a.json");
    let out = trilux(&[
        "render",
        s(&scene),
        "-o",
        s(&exr),
        "--png",
        s(&png),
        "--stats",
        s(&stats),
    ]);
    assert_refused(&out, "", "does not exist");
    assert_eq!(snapshot(&dir), before);
}

#[test]
fn the_default_out_folder_is_made_only_when_something_is_written() {
    let (dir, scene) = setup("out-default");
    std::fs::copy(&scene, dir.join("sub-scene.xml")).unwrap();
    let run = |scene: &str| {
        Command::new(env!("CARGO_BIN_EXE_trilux"))
            .current_dir(&dir)
            .args(["render", scene, "--quality", "draft"])
            .output()
            .unwrap()
    };
    // A failure leaves no out/ behind.
    let out = run("missing-mesh.xml");
    assert_refused(&out, "", "the scene has no <sensor>");
    assert!(!dir.join("out").exists());
    assert_ok(&run("sub-scene.xml"));
    assert!(dir.join("out/sub-scene.exr").is_file());
}

#[test]
fn an_output_naming_a_folder_is_refused_before_any_work() {
    let (dir, _scene) = setup("out-folder");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let before = snapshot(&dir);
    // The scene cannot load: an output error instead shows that the
    // outputs were checked first, before any solve.
    let m = dir.join("missing-mesh.xml");
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    for (command, flag, out) in [
        ("solve", "-o", p("new/")),
        ("solve", "-o", p("sub/")),
        ("solve", "-o", p("sub")),
        ("solve", "--stats", p("new/")),
        ("render", "-o", p("new/")),
        ("render", "--png", p("sub/")),
        ("bake", "-o", p("sub/")),
    ] {
        let mut args = vec![command, s(&m), flag, &out];
        if command == "solve" && flag != "-o" {
            args.extend(["-o", "unused.sol"]);
        }
        let out_file = Path::new(&out);
        let got = trilux(&args);
        let what = if out.ends_with('/') {
            "ends in '/'"
        } else {
            "it is a folder"
        };
        // A name without an extension asks for no other format: the
        // folder is refused as a folder, by every command alike.
        assert_refused(&got, &format!("{}", out_file.display()), what);
        assert!(!dir.join("new").exists(), "{args:?} made a folder");
    }
    assert_eq!(snapshot(&dir), before);
}

/// Bytes process `pid` has read so far (Linux's /proc: `rchar`).
fn bytes_read(pid: u32) -> u64 {
    let io = std::fs::read_to_string(format!("/proc/{pid}/io")).unwrap_or_default();
    io.lines()
        .find_map(|l| l.strip_prefix("rchar: "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or(0)
}

#[test]
fn a_render_interrupted_by_a_signal_leaves_no_out_folder() {
    let (dir, scene) = setup("out-signal");
    let sol = dir.join("x.sol");
    solve(&scene, &sol);
    for signal in ["INT", "TERM"] {
        // A render far longer than the test waits: a megapixel at 4096
        // samples a pixel.
        // Through coreutils' `env --default-signal`, which execs the render
        // (same pid) with SIGINT and SIGTERM at their default action: a
        // test runner started in the background of a non-interactive shell
        // passes SIGINT on ignored, and the render would then never end.
        let mut child = Command::new("env")
            .arg("--default-signal=INT,TERM")
            .arg(env!("CARGO_BIN_EXE_trilux"))
            .current_dir(&dir)
            .args(["render", "scene.xml", "--quality", "draft", "--solution"])
            .arg(&sol)
            .args(["--width", "1024", "--height", "1024", "--spp", "4096"])
            .args(["--threads", "2"])
            .spawn()
            .unwrap();
        // The solution is read only after the outputs are planned: once
        // the render has read as many bytes as it holds, it is at work (a
        // minute's guard against a hang).
        let sol_bytes = std::fs::metadata(&sol).unwrap().len();
        let start = std::time::Instant::now();
        while bytes_read(child.id()) < sol_bytes {
            assert!(
                child.try_wait().unwrap().is_none(),
                "the render ended before it was interrupted"
            );
            assert!(
                start.elapsed() < std::time::Duration::from_secs(60),
                "the solution not read after a minute"
            );
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let status = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let status = child.wait().unwrap();
        assert!(!status.success(), "SIG{signal} ended the render");
        assert!(!dir.join("out").exists(), "SIG{signal} left out/ behind");
    }
}

#[test]
fn an_output_naming_any_input_of_the_scene_is_refused_before_any_work() {
    let (dir, _) = setup("out-inputs");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    // An XML scene with an included file, an OBJ mesh and a PNG texture.
    write(
        &dir,
        "quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    );
    std::fs::copy(repo.join("textures/checker.png"), dir.join("checker.png")).unwrap();
    std::os::unix::fs::symlink("quad.obj", dir.join("link.obj")).unwrap();
    write(
        &dir,
        "part.xml",
        r#"<scene version="3.0.0"><shape type="obj"><string name="filename" value="quad.obj"/><bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="checker.png"/></texture></bsdf></shape></scene>"#,
    );
    let sensor = r#"<sensor type="perspective"><transform name="to_world"><lookat origin="0.5,0.5,2" target="0.5,0.5,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;
    write(
        &dir,
        "main.xml",
        format!(r#"<scene version="3.0.0">{sensor}<include filename="part.xml"/></scene>"#),
    );
    // A glTF scene with its .bin buffer and images beside it.
    for f in ["textured-room.gltf", "textured-room.bin"] {
        std::fs::copy(repo.join(f), dir.join(f)).unwrap();
    }
    let gltf_images: Vec<String> = {
        let text = std::fs::read_to_string(dir.join("textured-room.gltf")).unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        json["images"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|i| i["uri"].as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default()
    };
    for uri in &gltf_images {
        let to = dir.join(uri);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(repo.join(uri), to).unwrap();
    }
    let before = snapshot(&dir);
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let mut cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["solve".into(), p("main.xml"), "-o".into(), p("quad.obj")],
            "quad.obj",
        ),
        (
            vec!["solve".into(), p("main.xml"), "-o".into(), p("link.obj")],
            "quad.obj",
        ),
        (
            vec![
                "solve".into(),
                p("main.xml"),
                "-o".into(),
                p("x.sol"),
                "--stats".into(),
                p("part.xml"),
            ],
            "part.xml",
        ),
        (
            vec![
                "render".into(),
                p("main.xml"),
                "--quality".into(),
                "draft".into(),
                "-o".into(),
                p("y.exr"),
                "--png".into(),
                p("checker.png"),
            ],
            "checker.png",
        ),
        (
            vec![
                "bake".into(),
                p("main.xml"),
                "--quality".into(),
                "draft".into(),
                "-o".into(),
                p("z.glb"),
                "--stats".into(),
                p("quad.obj"),
            ],
            "quad.obj",
        ),
        (
            vec![
                "solve".into(),
                p("textured-room.gltf"),
                "-o".into(),
                p("textured-room.bin"),
            ],
            "textured-room.bin",
        ),
    ];
    for uri in &gltf_images {
        // A JPEG texture cannot be named by --png (a usage error, status
        // 2): the statistics name it instead.
        let option = if uri.ends_with(".png") {
            "--png"
        } else {
            "--stats"
        };
        cases.push((
            vec![
                "render".into(),
                p("textured-room.gltf"),
                "--quality".into(),
                "draft".into(),
                "-o".into(),
                p("w.exr"),
                option.into(),
                p(uri),
            ],
            "would overwrite the input",
        ));
    }
    assert!(!gltf_images.is_empty(), "the glTF scene has image files");
    for (args, what) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = trilux(&args);
        assert_refused(&out, "", "would overwrite the input");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(what), "{args:?}: {stderr}");
        assert_eq!(snapshot(&dir), before, "{args:?} changed a file");
    }
}
