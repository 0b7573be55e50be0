//! Hostile scene files through the binary (against crashes, and for
//! "errors a person can act on"): deep nesting, exponential `$name` and
//! `<ref>` expansion, files that never end or are too large, other
//! encodings, malformed versions and megabyte values all give one line
//! `error: FILE:LINE:COL: ...` (status 1), from every command, without
//! hanging. (That refusing `<ref>` expansion costs work proportional to
//! the file, not to its expansion, is tested where the work is done, in
//! the scene crate's `resolve`.)
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::Path;
use std::time::Duration;

mod common;
use common::hostile::{assert_refused, mkfifo, s, trilux_or_hang, write};
use common::{folder, trilux};

/// Runs `info`, `solve` and `render` on `scene` and checks each error: one
/// line starting with `error: {prefix}` and containing `what`, status 1,
/// no panic, at most 1000 characters, and no hang (a minute's guard).
fn assert_refused_by_every_command(scene: &Path, prefix: &str, what: &str) {
    let dir = scene.parent().unwrap();
    let sol = dir.join("never.sol");
    let exr = dir.join("never.exr");
    let commands: [Vec<&str>; 3] = [
        vec!["info", s(scene)],
        vec!["solve", s(scene), "-o", s(&sol)],
        vec!["render", s(scene), "-o", s(&exr)],
    ];
    for args in commands {
        let out = trilux_or_hang(&args, Duration::from_secs(60));
        assert_refused(&out, prefix, what);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.chars().count() <= 1010,
            "{args:?}: {} chars",
            stderr.len()
        );
        assert!(out.stdout.is_empty() || args[0] == "info");
    }
    assert!(!sol.exists() && !exr.exists(), "no output left behind");
}

const HEAD: &str = r#"<scene version="3.0.0">"#;

/// A sensor, so that `render` gets as far as the meshes.
const SENSOR: &str = r#"<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>"#;

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    let dir = folder("scene-deep");
    let text = format!(
        "{HEAD}\n{}{}</scene>",
        "<a>".repeat(10_000),
        "</a>".repeat(10_000)
    );
    let scene = write(&dir, "deep.xml", text);
    // <scene> is level 1 on line 1; levels 2.. start on line 2: level 65
    // is the 64th <a>, at column 1 + 63·3.
    let prefix = format!("{}:2:{}: ", s(&scene), 1 + 63 * 3);
    assert_refused_by_every_command(&scene, &prefix, "elements nest more than 64 deep");
}

#[test]
fn exponential_defaults_are_bounded() {
    let dir = folder("scene-laughs");
    let mut text = format!(
        "{HEAD}\n<default name=\"a0\" value=\"{}\"/>\n",
        "x".repeat(64)
    );
    for i in 1..16 {
        text += &format!(
            "<default name=\"a{i}\" value=\"{}\"/>\n",
            format!("$a{}", i - 1).repeat(8)
        );
    }
    text += "</scene>\n";
    assert!(text.len() < 1600, "a 1.5 KB file");
    let scene = write(&dir, "laughs.xml", &text);
    // 64 · 8^k bytes passes 1 MiB at a5 (line 7).
    let prefix = format!("{}:7:", s(&scene));
    assert_refused_by_every_command(
        &scene,
        &prefix,
        "grows beyond 1 MiB when $a4 is substituted",
    );
}

#[test]
fn exponential_references_are_bounded() {
    let dir = folder("scene-refs");
    let mut text = format!("{HEAD}\n<bsdf type=\"diffuse\" id=\"b0\"/>\n");
    for i in 1..40 {
        text += &format!(
            "<bsdf type=\"blendbsdf\" id=\"b{i}\"><float name=\"weight\" value=\"0.5\"/><ref id=\"b{}\"/><ref id=\"b{}\"/></bsdf>\n",
            i - 1,
            i - 1
        );
    }
    text += "</scene>\n";
    let scene = write(&dir, "refs.xml", &text);
    assert_refused_by_every_command(
        &scene,
        s(&scene),
        "references expand the scene to more than 1000000 elements",
    );
    let cycle = write(
        &dir,
        "cycle.xml",
        format!(
            "{HEAD}\n<bsdf type=\"twosided\" id=\"a\"><bsdf type=\"twosided\" id=\"b\"><ref id=\"a\"/></bsdf></bsdf>\n</scene>"
        ),
    );
    assert_refused_by_every_command(
        &cycle,
        &format!("{}:2:", s(&cycle)),
        "reference cycle: a → b → a",
    );
}

#[test]
fn inputs_that_never_end_or_are_too_large_are_refused_unread() {
    let dir = folder("scene-endless");
    let fifo = dir.join("endless.xml");
    mkfifo(&fifo);
    assert_refused_by_every_command(
        &fifo,
        &format!("{}: cannot read the scene file", s(&fifo)),
        "it is a FIFO, not a regular file",
    );
    let mesh_fifo = dir.join("endless.obj");
    mkfifo(&mesh_fifo);
    let scene = write(
        &dir,
        "mesh.xml",
        format!(
            "{HEAD}\n<shape type=\"obj\"><string name=\"filename\" value=\"endless.obj\"/></shape>\n{SENSOR}</scene>"
        ),
    );
    assert_refused_by_every_command(
        &scene,
        &format!("{}:2:", s(&scene)),
        "it is a FIFO, not a regular file",
    );
    // Sparse files: large, but no disk space used.
    let big_obj = std::fs::File::create(dir.join("big.obj")).unwrap();
    big_obj.set_len(300 << 20).unwrap();
    let scene = write(
        &dir,
        "big-mesh.xml",
        format!(
            "{HEAD}\n<shape type=\"obj\"><string name=\"filename\" value=\"big.obj\"/></shape>\n{SENSOR}</scene>"
        ),
    );
    assert_refused_by_every_command(
        &scene,
        &format!("{}:2:", s(&scene)),
        "it is 300 MiB or more, and the limit is 256 MiB",
    );
    // 4.1 million one-line triangles in 33 MB: refused before parsing.
    let mut many = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_vec();
    many.extend(b"f 1 2 3\n".repeat(4_100_000));
    write(&dir, "many.obj", many);
    let scene = write(
        &dir,
        "many-mesh.xml",
        format!(
            "{HEAD}\n<shape type=\"obj\"><string name=\"filename\" value=\"many.obj\"/></shape>\n{SENSOR}</scene>"
        ),
    );
    assert_refused_by_every_command(
        &scene,
        &format!("{}:2:", s(&scene)),
        "has 4100000 triangles and 3 vertices; the limits are 4000000 and 12000000",
    );
    let big_scene = dir.join("big.xml");
    std::fs::File::create(&big_scene)
        .unwrap()
        .set_len(65 << 20)
        .unwrap();
    assert_refused_by_every_command(&big_scene, s(&big_scene), "the limit is 64 MiB");
}

#[test]
fn other_encodings_are_located() {
    let dir = folder("scene-encoding");
    let utf16: Vec<u8> = "\u{feff}<scene version=\"3.0.0\"/>"
        .encode_utf16()
        .flat_map(u16::to_le_bytes)
        .collect();
    let scene = write(&dir, "utf16.xml", utf16);
    assert_refused_by_every_command(
        &scene,
        &format!("{}:1:1: ", s(&scene)),
        "the file is UTF-16",
    );
    let scene = write(
        &dir,
        "latin1.xml",
        b"<scene version=\"3.0.0\">\n<!-- caf\xE9 -->\n</scene>",
    );
    assert_refused_by_every_command(
        &scene,
        &format!("{}:2:9: ", s(&scene)),
        "byte 0xE9 is not UTF-8",
    );
}

#[test]
fn malformed_versions_are_refused() {
    let dir = folder("scene-version");
    for v in ["3.x.y", "3", "3.0", "3.0.0.0", "+3.0.0", ""] {
        let scene = write(&dir, "v.xml", format!("<scene version=\"{v}\"/>"));
        assert_refused_by_every_command(&scene, &format!("{}:1:", s(&scene)), "scene version");
    }
}

#[test]
fn a_megabyte_value_is_not_echoed_whole() {
    let dir = folder("scene-long-value");
    let value = "x".repeat(5 << 20);
    let scene = write(
        &dir,
        "long.xml",
        format!("{HEAD}\n<shape type=\"{value}\"/>\n</scene>"),
    );
    assert_refused_by_every_command(&scene, &format!("{}:2:", s(&scene)), "unknown shape plugin");
    // And on the command line (as long as one argument may be): a usage
    // error of one short line and a hint.
    let value = "x".repeat(120_000);
    let out = trilux(&["render", s(&scene), "--lookat", &value]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr.len() < 2000, "{} bytes", stderr.len());
    assert!(
        stderr.contains("is not a comma-separated list of numbers"),
        "{stderr}"
    );
}

#[test]
fn misleading_messages_say_what_is_wrong() {
    let dir = folder("scene-messages");
    let cases = [
        (
            "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"1e160\"/></transform></shape>",
            "beyond the coordinate limit",
        ),
        (
            "<sensor type=\"perspective\"><transform name=\"to_world\"><lookat origin=\"4e200, 0, 0\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>",
            "beyond the coordinate limit",
        ),
    ];
    for (body, what) in cases {
        let scene = write(&dir, "m.xml", format!("{HEAD}\n{body}\n</scene>"));
        assert_refused_by_every_command(&scene, &format!("{}:2:", s(&scene)), what);
    }
}

/// `FILE:LINE:COL: ` at the start of `stderr` after "error: ".
fn located_at(stderr: &str, file: &str) -> bool {
    let Some(rest) = stderr.strip_prefix(&format!("error: {file}:")) else {
        return false;
    };
    let mut parts = rest.splitn(3, ':');
    let number =
        |p: Option<&str>| p.is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    number(parts.next()) && number(parts.next()) && parts.next().is_some_and(|r| r.starts_with(' '))
}

#[test]
fn every_scene_error_from_every_command_is_located() {
    let dir = folder("scene-located");
    write(&dir, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    write(
        &dir,
        "far.obj",
        "v 0 0 0\nv 1e30 0 0\nv 0 1e30 0\nf 1 2 3\n",
    );
    write(&dir, "index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    write(
        &dir,
        "nan.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nf 1//1 2//1 3//1\n",
    );
    let ply_head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    write(
        &dir,
        "flat.ply",
        format!("{ply_head}0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"),
    );
    write(
        &dir,
        "index.ply",
        format!("{ply_head}0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n"),
    );
    write(
        &dir,
        "short.ply",
        format!("{ply_head}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
    );
    let obj =
        |f: &str| format!("<shape type=\"obj\"><string name=\"filename\" value=\"{f}\"/></shape>");
    let ply =
        |f: &str| format!("<shape type=\"ply\"><string name=\"filename\" value=\"{f}\"/></shape>");
    let closed = "<shape type=\"cube\"><boolean name=\"flip_normals\" value=\"true\"/><bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"1\"/></bsdf><emitter type=\"area\"/></shape>";
    // A flat mesh loads (left out, as Mitsuba never hits it); an emitting
    // one is refused, as in Mitsuba.
    let lit = |body: String| body.replace("</shape>", "<emitter type=\"area\"/></shape>");
    let cases: Vec<(String, bool)> = vec![
        (lit(obj("flat.obj")), true),
        (obj("far.obj"), true),
        (obj("index.obj"), true),
        (obj("nan.obj"), true),
        (obj("missing.obj"), true),
        (lit(ply("flat.ply")), true),
        (ply("index.ply"), true),
        (ply("short.ply"), true),
        (ply("missing.ply"), true),
        ("<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"400:0.5, 500:1e400\"/></bsdf></shape>".into(), true),
        ("<shape type=\"rectangle\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1e300, 0, 0\"/></emitter></shape>".into(), true),
        ("<shape type=\"sphere\"><float name=\"radius\" value=\"1e-300\"/></shape>".into(), true),
        ("<shape type=\"rectangle\"><bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"-1\"/></bsdf></shape>".into(), true),
        ("<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"1e-8\"/></transform></shape>".into(), true),
        (closed.into(), false),
    ];
    for (k, (body, info_refuses)) in cases.iter().enumerate() {
        let scene = write(
            &dir,
            &format!("case{k}.xml"),
            format!("{HEAD}\n{SENSOR}\n{body}\n</scene>\n"),
        );
        let sol = dir.join("x.sol");
        let exr = dir.join("x.exr");
        let mut commands = vec![
            vec!["solve", s(&scene), "-o", s(&sol), "--quality", "draft"],
            vec!["render", s(&scene), "-o", s(&exr), "--quality", "draft"],
        ];
        if *info_refuses {
            commands.push(vec!["info", s(&scene)]);
        }
        for args in commands {
            let out = trilux(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{body}: {args:?}: {stderr}");
            assert_eq!(stderr.lines().count(), 1, "{stderr}");
            assert!(located_at(&stderr, s(&scene)), "{body}: {args:?}: {stderr}");
        }
        assert!(!sol.exists() && !exr.exists());
    }
}

#[test]
fn deep_reference_chains_are_not_called_cycles() {
    let dir = folder("scene-ref-depth");
    let mut text = format!("{HEAD}\n<bsdf type=\"diffuse\" id=\"b0\"/>\n");
    for i in 1..70 {
        text += &format!(
            "<bsdf type=\"twosided\" id=\"b{i}\"><ref id=\"b{}\"/></bsdf>\n",
            i - 1
        );
    }
    text += "</scene>\n";
    let scene = write(&dir, "chain.xml", &text);
    assert_refused_by_every_command(
        &scene,
        s(&scene),
        "elements nest more than 64 deep once references are expanded",
    );
    let out = trilux(&["info", s(&scene)]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("cycle"));
}

/// Runs the binary and checks a refusal (status `code`, one line for
/// status 1) that does not come from reading the mesh.
fn assert_refused_before_meshes(args: &[&str], code: i32, what: &str) {
    let out = trilux(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    if code == 1 {
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
    assert!(
        stderr.contains(what),
        "{args:?}: {stderr:?} should say {what:?}"
    );
    assert!(
        !stderr.contains("no-such-mesh"),
        "{args:?}: the mesh was read first: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn arguments_camera_film_and_outputs_are_checked_before_meshes_or_solving() {
    let dir = folder("scene-checks-first");
    let mesh = "<shape type=\"obj\"><string name=\"filename\" value=\"no-such-mesh.obj\"/></shape>";
    let with_sensor = write(
        &dir,
        "with.xml",
        format!("{HEAD}\n{SENSOR}\n{mesh}\n</scene>\n"),
    );
    let without = write(&dir, "without.xml", format!("{HEAD}\n{mesh}\n</scene>\n"));
    let big_film = write(
        &dir,
        "film.xml",
        format!(
            "{HEAD}\n<sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"100000\"/><integer name=\"height\" value=\"100000\"/></film></sensor>\n{mesh}\n</scene>\n"
        ),
    );
    let exr = dir.join("x.exr");
    let (w, wo, film, x) = (s(&with_sensor), s(&without), s(&big_film), s(&exr));
    // Usage errors (status 2), before any file is read.
    assert_refused_before_meshes(&["render", w, "-o", x, "--width", "0"], 2, "--width");
    assert_refused_before_meshes(
        &["render", w, "-o", x, "--lookat", "1,2,3"],
        2,
        "6 or 9 numbers",
    );
    assert_refused_before_meshes(&["render", w, "-o", x, "--spp", "0"], 2, "--spp");
    assert_refused_before_meshes(
        &[
            "render",
            w,
            "-o",
            x,
            "--width",
            "4294967295",
            "--height",
            "4294967295",
        ],
        2,
        "must lie in 1..=32768",
    );
    assert_refused_before_meshes(&["solve", w, "-o", x, "--threads", "0"], 2, "--threads");
    // The outputs, the sensor and the film (status 1), before the mesh.
    let missing = dir.join("missing").join("x.exr");
    assert_refused_before_meshes(&["render", w, "-o", s(&missing)], 1, "does not exist");
    assert_refused_before_meshes(&["render", wo, "-o", x], 1, "the scene has no <sensor>");
    assert_refused_before_meshes(
        &[
            "render", w, "-o", x, "--width", "30000", "--height", "30000",
        ],
        1,
        "film size 30000 × 30000 (900000000 pixels, about 50.3 GiB of memory) is beyond the limits",
    );
    assert_refused_before_meshes(&["render", film, "-o", x], 1, &format!("{film}:2:"));
    assert_refused_before_meshes(
        &["render", w, "-o", x, "--lookat", "1,2,3,1,2,3"],
        1,
        "invalid camera",
    );
    assert!(!exr.exists());
}

/// A far clip plane that would cut the scene is refused at the `<sensor>`
/// (trilux renders without one), before the solve; one beyond every
/// corner of the scene renders.
#[test]
fn a_far_clip_plane_cutting_the_scene_is_refused_at_the_sensor() {
    let dir = folder("scene-far-clip");
    let scene = |far: &str| {
        format!(
            "{HEAD}\n<sensor type=\"perspective\"><float name=\"far_clip\" value=\"{far}\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform><film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film></sensor>\n<shape type=\"cube\"><emitter type=\"area\"/></shape>\n</scene>\n"
        )
    };
    // The cube's far corners are 6 deep.
    let cut = write(&dir, "cut.xml", scene("5.5"));
    let exr = dir.join("cut.exr");
    let out = trilux(&["render", s(&cut), "-o", s(&exr), "--quality", "draft"]);
    assert_refused(
        &out,
        &format!("{}:2:1: ", s(&cut)),
        "far_clip 5.5 would cut the scene",
    );
    assert!(!exr.exists());
    let whole = write(&dir, "whole.xml", scene("6.5"));
    let exr = dir.join("whole.exr");
    let out = trilux(&["render", s(&whole), "-o", s(&exr), "--quality", "draft"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(exr.exists());
}

#[test]
fn a_sample_count_above_the_maximum_is_located() {
    use common::hostile::furnace;
    let dir = folder("scene-spp");
    // furnace()'s sampler is on line 5; its `<integer>` at column 33.
    let text = furnace("0.5", "1.0", 1.0);
    let too_many = text.replace(
        r#"name="sample_count" value="4""#,
        r#"name="sample_count" value="65537""#,
    );
    assert_ne!(too_many, text, "the sample count was replaced");
    let scene = write(&dir, "spp.xml", too_many);
    assert_refused_by_every_command(&scene, &format!("{}:5:", s(&scene)), "sample_count 65537");
    // 65 536 = 2^16, the sequence's length, is still accepted.
    let at_limit = text.replace(
        r#"name="sample_count" value="4""#,
        r#"name="sample_count" value="65536""#,
    );
    let scene = write(&dir, "spp-max.xml", at_limit);
    let out = trilux(&["info", s(&scene)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("65536 spp"));
}

#[test]
fn a_grayscale_jpeg_texture_is_accepted() {
    // Its texel values are checked in trilux-scene's tests/gltf.rs.
    let dir = folder("scene-grey-jpeg");
    let jpeg = Path::new(env!("CARGO_MANIFEST_DIR")).join("../trilux-scene/tests/data/grey192.jpg");
    std::fs::copy(jpeg, dir.join("grey.jpg")).unwrap();
    let texture = r#"<texture type="bitmap" name="reflectance"><string name="filename" value="grey.jpg"/></texture>"#;
    let scene = write(
        &dir,
        "grey.xml",
        format!(
            "{HEAD}\n{SENSOR}\n<shape type=\"rectangle\"><bsdf type=\"diffuse\">{texture}</bsdf></shape>\n</scene>\n"
        ),
    );
    let out = trilux(&["info", s(&scene)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("1 texture"));
    let exr = dir.join("grey.exr");
    let out = trilux(&["render", s(&scene), "--quality", "draft", "-o", s(&exr)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(exr.is_file());
}
