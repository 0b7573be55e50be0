//! Closed and full standard streams through the binary: stdout on a full
//! disk is an error (status 1), stdout into a pipe whose reader has gone
//! ends the output quietly (status 0: the reader chose to stop), stderr
//! on a full disk still gives status 1, and never a panic (status 101).
//! `-o /dev/stdout` into a pipe writes the output through the pipe.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

mod common;
use common::folder;
use common::hostile::{assert_ok, furnace, s, trilux_streams_or_hang};

/// The hang guard: generous, not a speed figure.
const LIMIT: Duration = Duration::from_secs(60);

fn dev_full() -> Stdio {
    Stdio::from(File::options().write(true).open("/dev/full").unwrap())
}

/// The write end of a pipe whose read end is already closed.
fn closed_pipe() -> Stdio {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    Stdio::from(writer)
}

fn scene(name: &str) -> std::path::PathBuf {
    let dir = folder(name);
    let scene = dir.join("scene.xml");
    std::fs::write(&scene, furnace("0.5", "1.0", 1.0)).unwrap();
    scene
}

fn no_panic(stderr: &[u8], what: &str) {
    let stderr = String::from_utf8_lossy(stderr);
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
}

#[test]
fn stdout_on_a_full_disk_is_an_error() {
    let scene = scene("streams-full");
    for json in [false, true] {
        let mut args = vec!["info", s(&scene)];
        if json {
            args.push("--json");
        }
        let out = trilux_streams_or_hang(&args, dev_full(), Stdio::piped(), LIMIT);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "info {json}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.starts_with("error: cannot write to the standard output"),
            "{stderr}"
        );
    }
}

#[test]
fn a_bake_reporting_to_a_full_disk_fails_after_writing_its_file() {
    let scene = scene("streams-bake");
    let glb = scene.with_file_name("scene.glb");
    let args = ["bake", s(&scene), "--quality", "draft", "-o", s(&glb)];
    let out = trilux_streams_or_hang(&args, dev_full(), Stdio::piped(), LIMIT);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("error: cannot write to the standard output"),
        "{stderr}"
    );
    no_panic(&out.stderr, "bake");
    // The "wrote" line comes after the file: the file is whole.
    assert!(std::fs::read(&glb).unwrap().starts_with(b"glTF"));
}

#[test]
fn stdout_into_a_closed_pipe_ends_quietly() {
    let scene = scene("streams-pipe");
    for json in [false, true] {
        let mut args = vec!["info", s(&scene)];
        if json {
            args.push("--json");
        }
        let out = trilux_streams_or_hang(&args, closed_pipe(), Stdio::piped(), LIMIT);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "info {json}: {stderr}");
        assert!(stderr.is_empty(), "quietly: {stderr}");
    }
}

#[test]
fn an_error_that_cannot_be_written_still_fails() {
    let dir = folder("streams-stderr");
    let missing = dir.join("no-such-scene.xml");
    // Both streams full: nothing can be said, the status says it.
    let out = trilux_streams_or_hang(&["info", s(&missing)], dev_full(), dev_full(), LIMIT);
    assert_eq!(out.status.code(), Some(1));
    // A usage error too keeps clap's status.
    let out = trilux_streams_or_hang(&["info", "--no-such-option"], dev_full(), dev_full(), LIMIT);
    assert_eq!(out.status.code(), Some(2));
    // And stderr into a closed pipe.
    let out = trilux_streams_or_hang(&["info", s(&missing)], Stdio::null(), closed_pipe(), LIMIT);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn an_output_to_dev_stdout_goes_through_the_pipe() {
    let scene = scene("streams-dev-stdout");
    let mut child = Command::new(env!("CARGO_BIN_EXE_trilux"))
        .args([
            "solve",
            s(&scene),
            "--quality",
            "draft",
            "-o",
            "/dev/stdout",
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read it all while it runs (a solution is larger than a pipe holds),
    // killing the child if it has not ended within the hang guard.
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        stdout.read_to_end(&mut bytes).unwrap();
        bytes
    });
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            panic!("solve -o /dev/stdout had not ended after {LIMIT:?}: a hang");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let bytes = reader.join().unwrap();
    let out = child.wait_with_output().unwrap();
    assert_ok(&out);
    assert!(!bytes.is_empty(), "the solution came through the pipe");
    // What came through is a whole solution: a render reads it.
    let sol = scene.with_file_name("piped.sol");
    std::fs::write(&sol, &bytes).unwrap();
    let exr = scene.with_file_name("from-pipe.exr");
    let args = [
        "render",
        s(&scene),
        "--quality",
        "draft",
        "--solution",
        s(&sol),
        "-o",
        s(&exr),
    ];
    let out = trilux_streams_or_hang(&args, Stdio::piped(), Stdio::piped(), LIMIT);
    assert_ok(&out);
    assert!(Path::new(&exr).is_file());
    // No file was made under /proc/self/fd, nor beside the scene.
    assert!(!scene.with_file_name("stdout").exists());
}
