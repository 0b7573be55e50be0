//! `cargo xtask package`: every publishable crate packaged as crates.io
//! would receive it, and each package built on its own from its `.crate`
//! (cargo's verification: a file outside the crate, a path dependency
//! without a version or a missing README fails here).

use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::run;

/// Sibling crates resolve from cargo's local overlay of the packages just
/// made. trilux-py (a Python extension module, published as a wheel) and
/// xtask are `publish = false`; `--workspace` would package them too, so
/// they are excluded by name. `--allow-dirty`: what is checked is the
/// crates, not whether the work tree is committed (CI runs in a clean
/// checkout; a local run may be mid-change).
pub fn main() -> Result<()> {
    forget_unpacked_overlay()?;
    run(
        "cargo",
        &[
            "package",
            "--workspace",
            "--allow-dirty",
            "--exclude",
            "trilux-py",
            "--exclude",
            "xtask",
        ],
    )
}

/// Cargo unpacks the overlay's `.crate` files into
/// `$CARGO_HOME/registry/src/-HASH/NAME-VERSION`, the hash depending only on
/// the checkout's path, and never unpacks a crate again once its folder is
/// there. The version stays 0.1.0 between commits, so on a machine that
/// packaged an earlier commit from the same path, verification would build
/// against that commit's sibling sources. Local registries' folders (their
/// names start with `-`; crates.io's start with its host) lose their trilux
/// crates first, so every run unpacks what it just packaged.
fn forget_unpacked_overlay() -> Result<()> {
    let Some(home) = cargo_home() else {
        return Ok(());
    };
    let Ok(registries) = std::fs::read_dir(home.join("registry/src")) else {
        return Ok(());
    };
    for registry in registries.flatten() {
        if !registry.file_name().to_string_lossy().starts_with('-') {
            continue;
        }
        for unpacked in std::fs::read_dir(registry.path())?.flatten() {
            if unpacked.file_name().to_string_lossy().starts_with("trilux") {
                let path = unpacked.path();
                std::fs::remove_dir_all(&path)
                    .with_context(|| format!("could not remove {}", path.display()))?;
            }
        }
    }
    Ok(())
}

/// `$CARGO_HOME`, or cargo's default `~/.cargo`.
fn cargo_home() -> Option<PathBuf> {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".cargo")))
}
