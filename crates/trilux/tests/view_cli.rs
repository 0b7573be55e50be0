//! `trilux view FILE.glb`: a wrong file is one located error line and
//! status 1 before anything is served, a usage error status 2; a good
//! file is served byte for byte with the viewer, and `--open` starts
//! `$BROWSER` on the printed address, or says in one line that there is
//! no browser and keeps serving. (docs/viewer/test/interior.test.mjs
//! loads a served bake in headless Chromium.)
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, ChildStderr, Command, Stdio};

use common::{folder, http_get, trilux};

/// A glTF binary (glTF 2.0 §4.4) of one JSON chunk, padded with spaces
/// to 4 bytes, its header's length `extra` bytes off the true one.
fn glb(json: &str, extra: i64) -> Vec<u8> {
    let mut chunk = json.as_bytes().to_vec();
    while !chunk.len().is_multiple_of(4) {
        chunk.push(b' ');
    }
    let total = 12 + 8 + chunk.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(u32::try_from(total as i64 + extra).unwrap().to_le_bytes());
    out.extend(u32::try_from(chunk.len()).unwrap().to_le_bytes());
    out.extend(b"JSON");
    out.extend(chunk);
    out
}

const ASSET: &str = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0}"#;

/// Runs `trilux view` on `bytes` written to `name` and expects one error
/// line naming the file and containing `what`, status 1, nothing served.
fn refused(dir: &Path, name: &str, bytes: &[u8], what: &str) {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let out = trilux(&["view", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{name}: {err}");
    assert_eq!(err.lines().count(), 1, "{name}: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(path.to_str().unwrap()), "{err}");
    assert!(err.contains(what), "{name}: {err} lacks {what}");
    assert!(out.stdout.is_empty(), "{name}: something was served");
}

#[test]
fn a_missing_or_malformed_file_is_one_located_line() {
    let dir = folder("view-refused");
    let missing = dir.join("missing.glb");
    let out = trilux(&["view", missing.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("missing.glb: cannot read"), "{err}");

    refused(&dir, "text.glb", b"not a model at all", "byte 0");
    refused(&dir, "scene.gltf", ASSET.as_bytes(), "byte 0");
    refused(&dir, "short.glb", b"glTF\x02\0", "byte 6");
    let mut v1 = glb(ASSET, 0);
    v1[4] = 1;
    refused(&dir, "v1.glb", &v1, "version 1");
    refused(&dir, "cut.glb", &glb(ASSET, 8), "byte 8");
    refused(
        &dir,
        "json.glb",
        &glb(r#"{"asset": {"version": "2.0""#, 0),
        "JSON chunk",
    );
    refused(
        &dir,
        "asset.glb",
        &glb(r#"{"scenes": []}"#, 0),
        "asset.version",
    );
    let mut bin_first = glb(ASSET, 0);
    bin_first[16..20].copy_from_slice(b"BIN\0");
    refused(&dir, "bin.glb", &bin_first, "not JSON");
}

#[test]
fn bad_arguments_are_usage_errors() {
    let dir = folder("view-usage");
    let path = dir.join("ok.glb");
    std::fs::write(&path, glb(ASSET, 0)).unwrap();
    let p = path.to_str().unwrap();
    for args in [
        vec!["view"],
        vec!["view", p, "--port", "http"],
        vec!["view", p, "--port", "70000"],
        vec!["view", p, "--bogus"],
        vec!["view", p, p],
    ] {
        let out = trilux(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

/// `trilux view` with `env` changes, its stderr piped; returns it with the
/// lines it printed on stdout up to and including the first that starts
/// with `last`, and its port.
fn serve(glb: &Path, open: bool, env: &[(&str, &str)], last: &str) -> (Child, Vec<String>, u16) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_trilux"));
    cmd.args(["view", glb.to_str().unwrap()]);
    if open {
        cmd.arg("--open");
    }
    cmd.env_remove("BROWSER");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = Vec::new();
    for line in BufReader::new(child.stdout.take().unwrap()).lines() {
        let line = line.unwrap();
        let done = line.starts_with(last);
        lines.push(line);
        if done {
            break;
        }
    }
    let port = lines[0]
        .split("127.0.0.1:")
        .nth(1)
        .and_then(|r| r.split('/').next())
        .unwrap()
        .parse()
        .unwrap();
    (child, lines, port)
}

fn first_line(stderr: ChildStderr) -> String {
    let mut line = String::new();
    BufReader::new(stderr).read_line(&mut line).unwrap();
    line.trim_end().to_string()
}

#[test]
fn a_good_file_is_served_as_it_is() {
    let dir = folder("view-serve");
    let path = dir.join("model.glb");
    let bytes = glb(ASSET, 0);
    std::fs::write(&path, &bytes).unwrap();
    let (mut child, lines, port) = serve(&path, false, &[], "viewer: ");
    assert_eq!(
        lines,
        [format!(
            "viewer: http://127.0.0.1:{port}/index.html?file=/model.glb (Ctrl-C stops it)"
        )]
    );
    let (status, model) = http_get(port, "/model.glb");
    assert!(status.contains("200"), "{status}");
    assert_eq!(model, bytes);
    let (status, page) = http_get(port, "/index.html?file=/model.glb");
    assert!(status.contains("200"), "{status}");
    assert!(String::from_utf8_lossy(&page).contains("viewer.js"));
    child.kill().unwrap();
    child.wait().unwrap();
}

/// `--open` starts `$BROWSER` with the printed address: the stand-in
/// browser writes what it was given to stderr.
#[test]
fn open_starts_the_browser_on_the_address() {
    let dir = folder("view-open");
    let path = dir.join("model.glb");
    std::fs::write(&path, glb(ASSET, 0)).unwrap();
    let browser = dir.join("browser.sh");
    std::fs::write(&browser, "#!/bin/sh\necho \"browser got $1\" >&2\n").unwrap();
    let chmod = Command::new("chmod")
        .args(["+x", browser.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(chmod.success());
    let env = [("BROWSER", browser.to_str().unwrap())];
    let (mut child, lines, port) = serve(&path, true, &env, "viewer: opened");
    let url = format!("http://127.0.0.1:{port}/index.html?file=/model.glb");
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert_eq!(
        lines[1],
        format!("viewer: opened in the browser ({})", browser.display())
    );
    let said = first_line(child.stderr.take().unwrap());
    assert_eq!(said, format!("browser got {url}"));
    child.kill().unwrap();
    child.wait().unwrap();
}

/// Without `$BROWSER` and without xdg-open on `PATH`, `--open` says so in
/// one line on stderr and serves all the same.
#[test]
fn open_without_a_browser_says_so_and_serves() {
    let dir = folder("view-no-browser");
    let path = dir.join("model.glb");
    let bytes = glb(ASSET, 0);
    std::fs::write(&path, &bytes).unwrap();
    let empty = dir.join("empty-path");
    std::fs::create_dir_all(&empty).unwrap();
    let env = [("PATH", empty.to_str().unwrap())];
    let (mut child, lines, port) = serve(&path, true, &env, "viewer: ");
    assert_eq!(lines.len(), 1, "{lines:?}");
    let said = first_line(child.stderr.take().unwrap());
    assert!(said.starts_with("warning: no browser to open"), "{said}");
    assert!(said.contains(&format!("127.0.0.1:{port}")), "{said}");
    let (status, model) = http_get(port, "/model.glb");
    assert!(status.contains("200"), "{status}");
    assert_eq!(model, bytes);
    child.kill().unwrap();
    child.wait().unwrap();
}

/// A `$BROWSER` none of whose commands starts is the same: one line, and
/// the server runs on.
#[test]
fn open_with_a_browser_that_does_not_start_says_so() {
    let dir = folder("view-bad-browser");
    let path = dir.join("model.glb");
    std::fs::write(&path, glb(ASSET, 0)).unwrap();
    let empty = dir.join("empty-path");
    std::fs::create_dir_all(&empty).unwrap();
    let missing = dir.join("no-such-browser");
    let env = [
        ("PATH", empty.to_str().unwrap()),
        ("BROWSER", missing.to_str().unwrap()),
    ];
    let (mut child, lines, port) = serve(&path, true, &env, "viewer: ");
    assert_eq!(lines.len(), 1, "{lines:?}");
    let said = first_line(child.stderr.take().unwrap());
    assert!(
        said.starts_with("warning: no browser to open (no command of $BROWSER started"),
        "{said}"
    );
    let (status, _) = http_get(port, "/index.html");
    assert!(status.contains("200"), "{status}");
    child.kill().unwrap();
    child.wait().unwrap();
}
