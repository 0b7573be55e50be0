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

/// A fresh, empty folder for one test's files.
pub fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp folder");
    dir
}
