//! Corrupted solution files through the binary: a valid header
//! over a corrupted payload — a depth field that once made the reader
//! allocate gigabytes, a NaN, infinite or negative radiance that once
//! changed the image silently — truncated, extended or foreign files, and
//! a solution that is not a regular file, are each refused in one line
//! naming the file, with no image written.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::hostile::{fnv, furnace, s};
use common::{folder, trilux};

const HEADER: usize = 40;

/// The bytes with a header whose length and checksum fit the payload.
fn with_valid_header(mut bytes: Vec<u8>) -> Vec<u8> {
    let len = (bytes.len() - HEADER) as u64;
    let sum = fnv(&bytes[HEADER..]);
    bytes[24..32].copy_from_slice(&len.to_le_bytes());
    bytes[32..40].copy_from_slice(&sum.to_le_bytes());
    bytes
}

/// A solved furnace in its own folder `name` (each test has its own: the
/// tests of this file run in parallel, and `folder` empties the folder).
fn setup(name: &str) -> (PathBuf, PathBuf, Vec<u8>) {
    let dir = folder(name);
    let scene = dir.join("scene.xml");
    std::fs::write(&scene, furnace("0.5", "1.0", 1.0)).unwrap();
    let sol = dir.join("good.sol");
    let out = trilux(&["solve", s(&scene), "-o", s(&sol), "--quality", "draft"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&sol).unwrap();
    (dir, scene, bytes)
}

/// Renders `scene` from solution `bytes` and checks the refusal.
fn assert_solution_refused(dir: &Path, scene: &Path, bytes: &[u8], what: &str) {
    let sol = dir.join("bad.sol");
    std::fs::write(&sol, bytes).unwrap();
    let exr = dir.join("bad.exr");
    let out = trilux(&[
        "render",
        s(scene),
        "--solution",
        s(&sol),
        "-o",
        s(&exr),
        "--quality",
        "draft",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with(&format!("error: {}: ", s(&sol))),
        "{stderr}"
    );
    assert!(stderr.contains(what), "{stderr:?} should say {what:?}");
    assert!(!exr.exists());
}

#[test]
fn corrupted_payloads_under_valid_headers_are_refused() {
    let (dir, scene, good) = setup("solutions");
    let stats_len = u64::from_le_bytes(good[HEADER..HEADER + 8].try_into().unwrap()) as usize;
    let depths = HEADER + 8 + stats_len + 4;
    let mut deep = good.clone();
    deep[depths..depths + 4].copy_from_slice(&30u32.to_le_bytes());
    assert_solution_refused(
        &dir,
        &scene,
        &with_valid_header(deep),
        "element depth limits differ",
    );
    // The first radiance value: after the depths and the element count.
    let surfaces = u32::from_le_bytes(good[depths - 4..depths].try_into().unwrap()) as usize;
    let radiance = depths + 4 * surfaces + 8;
    for bad in [f32::NAN, f32::INFINITY, -1.0] {
        let mut b = good.clone();
        b[radiance..radiance + 4].copy_from_slice(&bad.to_le_bytes());
        assert_solution_refused(
            &dir,
            &scene,
            &with_valid_header(b),
            "corrupt radiance (negative or not finite)",
        );
    }
    let mut flipped = good.clone();
    flipped[radiance] ^= 0x40;
    assert_solution_refused(&dir, &scene, &flipped, "checksum mismatch");
    assert_solution_refused(
        &dir,
        &scene,
        &good[..good.len() - 3],
        "truncated or extended",
    );
    let mut extended = good.clone();
    extended.extend_from_slice(b"more");
    assert_solution_refused(&dir, &scene, &with_valid_header(extended), "trailing bytes");
    assert_solution_refused(&dir, &scene, b"TRILUXS\0", "truncated");
    assert_solution_refused(
        &dir,
        &scene,
        b"not a solution",
        "not a trilux solution file",
    );
}

#[test]
fn a_solution_that_is_not_a_regular_file_is_refused_unread() {
    let (dir, scene, _) = setup("solutions-irregular");
    let fifo = dir.join("fifo.sol");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let exr = dir.join("x.exr");
    let out = trilux(&[
        "render",
        s(&scene),
        "--solution",
        s(&fifo),
        "-o",
        s(&exr),
        "--quality",
        "draft",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("cannot read the solution file: it is a FIFO, not a regular file"),
        "{stderr}"
    );
    assert!(!exr.exists());
}
