//! A file's independent errors through the binary: every one reported in
//! one run, one located line each, at most 20 and a count of the rest,
//! exit 1, nothing written; an error that makes the rest meaningless
//! (malformed XML, a missing include) is still one line.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::{Path, PathBuf};

mod common;
use common::{folder, trilux};

/// Five top-level elements, each wrong in its own way: a colour of two
/// numbers, a parameter the shape does not take, a reference to no id, a
/// field of view out of range, an element trilux does not know.
const FIVE: [(&str, &str); 5] = [
    (
        "<bsdf type=\"diffuse\" id=\"a\">\n    <rgb name=\"reflectance\" value=\"0.5, 0.5\"/>\n</bsdf>",
        "<rgb> takes 1 or 3 numbers, found 2",
    ),
    (
        "<shape type=\"rectangle\">\n    <float name=\"radius\" value=\"1\"/>\n</shape>",
        "unknown parameter \"radius\" for <shape type=\"rectangle\">",
    ),
    (
        "<shape type=\"sphere\">\n    <ref id=\"nothing\"/>\n</shape>",
        "reference to unknown id \"nothing\"",
    ),
    (
        "<sensor type=\"perspective\">\n    <float name=\"fov\" value=\"200\"/>\n</sensor>",
        "fov must lie strictly between 0 and 180 degrees, found 200",
    ),
    (
        "<light type=\"point\"/>",
        "unsupported element <light> in <scene>",
    ),
];

/// A scene holding `elements`, with a valid lit cube first.
fn scene(elements: &[&str]) -> String {
    let mut text = String::from(
        "<scene version=\"3.0.0\">\n<shape type=\"cube\">\n    <emitter type=\"area\"/>\n</shape>\n",
    );
    for e in elements {
        text += e;
        text += "\n";
    }
    text + "</scene>\n"
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The binary's stderr for `args`, after checking it failed with status 1.
fn refused(args: &[&str]) -> String {
    let out = trilux(args);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    stderr
}

/// 1-based line and column of the first `needle` in `text`.
fn line_col(text: &str, needle: &str) -> (usize, usize) {
    let at = text.find(needle).unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |k| k + 1) + 1;
    (line, col)
}

/// Each of the five errors is reported, in file order, on its own line
/// naming the file, the line and column of the element or attribute at
/// fault (found in the text here) and the problem; and each line is the
/// one the same element gives alone, so that reporting them together
/// changes none of them.
#[test]
fn a_file_with_five_independent_errors_reports_all_five() {
    let dir = folder("errors-five");
    let elements: Vec<&str> = FIVE.iter().map(|(e, _)| *e).collect();
    let text = scene(&elements);
    let path = write(&dir, "five.xml", &text);
    let p = path.to_str().unwrap();
    let stderr = refused(&["info", p]);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 5, "{stderr}");
    // Where each error points: the attribute value, the parameter
    // element, the reference's id, the fov element, the unknown element.
    let places = [
        "0.5, 0.5",
        "<float name=\"radius\"",
        "nothing",
        "<float name=\"fov\"",
        "<light",
    ];
    for (k, (needle, (_, problem))) in places.iter().zip(FIVE).enumerate() {
        let (line, col) = line_col(&text, needle);
        let expected = format!("error: {p}:{line}:{col}: {problem}");
        assert!(
            lines[k].starts_with(&expected),
            "{k}: {} vs {expected}",
            lines[k]
        );
    }
    for (k, element) in elements.iter().enumerate() {
        let alone_text = scene(&[element]);
        let alone = write(&dir, "alone.xml", &alone_text);
        let err = refused(&["info", alone.to_str().unwrap()]);
        assert_eq!(err.lines().count(), 1, "{err}");
        let problem = err.trim_end().split_once(": ").unwrap().1;
        let problem = problem.split_once(": ").unwrap().1;
        let together = lines[k].split_once(": ").unwrap().1;
        assert_eq!(
            together.split_once(": ").unwrap().1,
            problem,
            "element {k} alone"
        );
    }
}

/// The command that would solve and render stops at the errors: nothing
/// is written.
#[test]
fn a_file_with_errors_starts_no_work_and_writes_nothing() {
    let dir = folder("errors-render");
    let elements: Vec<&str> = FIVE.iter().map(|(e, _)| *e).collect();
    let path = write(&dir, "five.xml", &scene(&elements));
    let out = dir.join("five.exr");
    let stderr = refused(&[
        "render",
        path.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(stderr.lines().count(), 5, "{stderr}");
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
}

/// 100 errors: the first 20 in file order, each its own line, then one
/// line counting the 80 left out.
#[test]
fn at_most_twenty_errors_are_reported_and_the_rest_counted() {
    let dir = folder("errors-bound");
    let unknown: Vec<String> = (0..100)
        .map(|i| format!("<shape type=\"nosuch{i}\"/>"))
        .collect();
    let elements: Vec<&str> = unknown.iter().map(String::as_str).collect();
    let path = write(&dir, "hundred.xml", &scene(&elements));
    let p = path.to_str().unwrap();
    let stderr = refused(&["info", p]);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 21, "{stderr}");
    for (i, line) in lines[..20].iter().enumerate() {
        // The scene's four first lines, then one shape a line.
        assert!(
            line.starts_with(&format!("error: {p}:{}:", i + 5)),
            "{line}"
        );
        assert!(line.contains(&format!("nosuch{i}\"")), "{line}");
    }
    assert_eq!(
        lines[20],
        format!("error: {p}: and 80 more errors (only the first 20 are reported)")
    );
}

/// Errors found by different stages (references, then parameters) are
/// reported in file order, and the 20 kept are the file's first 20, not
/// the first stage's.
#[test]
fn the_errors_kept_are_the_first_in_the_file_whatever_stage_finds_them() {
    let dir = folder("errors-order");
    let elements: Vec<String> = (0..40)
        .map(|i| {
            if i % 2 == 0 {
                format!("<shape type=\"sphere\">\n    <ref id=\"none{i}\"/>\n</shape>")
            } else {
                format!("<shape type=\"nosuch{i}\"/>")
            }
        })
        .collect();
    let refs: Vec<&str> = elements.iter().map(String::as_str).collect();
    let path = write(&dir, "mixed.xml", &scene(&refs));
    let stderr = refused(&["info", path.to_str().unwrap()]);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 21, "{stderr}");
    for (i, line) in lines[..20].iter().enumerate() {
        let what = if i % 2 == 0 { "none" } else { "nosuch" };
        assert!(line.contains(&format!("{what}{i}\"")), "{i}: {line}");
    }
    assert!(lines[20].ends_with("and 20 more errors (only the first 20 are reported)"));
}

/// A definition's error is reported once, however many shapes reference
/// it; an error in another shape is still reported beside it.
#[test]
fn a_failed_definition_is_reported_once() {
    let dir = folder("errors-definition");
    let user = "<shape type=\"sphere\">\n    <ref id=\"bad\"/>\n</shape>";
    let text = scene(&[
        "<bsdf type=\"diffuse\" id=\"bad\">\n    <float name=\"reflectance\" value=\"2\"/>\n</bsdf>",
        user,
        user,
        user,
        "<shape type=\"rectangle\">\n    <float name=\"radius\" value=\"1\"/>\n</shape>",
    ]);
    let path = write(&dir, "shared.xml", &text);
    let stderr = refused(&["info", path.to_str().unwrap()]);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 2, "{stderr}");
    assert!(lines[0].contains("reflectance"), "{stderr}");
    assert!(lines[1].contains("\"radius\""), "{stderr}");
}

/// Malformed XML makes the rest of the file meaningless: one line, though
/// the elements before it are wrong too; and so does a missing include.
#[test]
fn malformed_xml_and_a_missing_include_are_still_one_error() {
    let dir = folder("errors-fatal");
    let elements: Vec<&str> = FIVE.iter().map(|(e, _)| *e).collect();
    let mut broken = elements.clone();
    broken.push("<shape type=\"cube\">");
    let path = write(&dir, "broken.xml", &scene(&broken));
    let stderr = refused(&["info", path.to_str().unwrap()]);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    let mut included = elements.clone();
    included.insert(2, "<include filename=\"missing.xml\"/>");
    let path = write(&dir, "include.xml", &scene(&included));
    let stderr = refused(&["info", path.to_str().unwrap()]);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("missing.xml"), "{stderr}");
}

/// Three shapes naming missing mesh files: each reported, at its
/// `filename` parameter.
#[test]
fn every_missing_mesh_file_is_reported() {
    let dir = folder("errors-meshes");
    let shapes: Vec<String> = ["a.obj", "b.ply", "c.obj"]
        .iter()
        .map(|f| {
            let t = &f[2..];
            format!("<shape type=\"{t}\">\n    <string name=\"filename\" value=\"{f}\"/>\n</shape>")
        })
        .collect();
    let refs: Vec<&str> = shapes.iter().map(String::as_str).collect();
    let text = scene(&refs);
    let path = write(&dir, "meshes.xml", &text);
    let p = path.to_str().unwrap();
    let stderr = refused(&["info", p]);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 3, "{stderr}");
    for (line, f) in lines.iter().zip(["a.obj", "b.ply", "c.obj"]) {
        let (l, c) = line_col(&text, &format!("<string name=\"filename\" value=\"{f}\""));
        assert!(line.starts_with(&format!("error: {p}:{l}:{c}: ")), "{line}");
        assert!(line.contains(f), "{line}");
    }
}
