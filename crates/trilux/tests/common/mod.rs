//! Helpers shared by the binary's integration tests.
#![allow(dead_code)] // each test binary uses some of them

pub mod hostile;
pub mod serialized;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `trilux` binary with `args`.
pub fn trilux(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trilux"))
        .args(args)
        .output()
        .expect("the trilux binary runs")
}

/// The path of a bundled scene (`scenes/NAME`), as a string for the
/// command line.
pub fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// A fresh, empty folder for one test's files.
pub fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp folder");
    dir
}

/// `GET path` from the local server on `port`: (status line, body). A
/// server that never answers fails the test after a minute instead of
/// hanging it.
pub fn http_get(port: u16, path: &str) -> (String, Vec<u8>) {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(std::time::Duration::from_secs(60)))
        .unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: localhost\r\n\r\n").unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&all[..split]).into_owned();
    (
        head.lines().next().unwrap().to_string(),
        all[split + 4..].to_vec(),
    )
}
