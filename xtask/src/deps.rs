//! `cargo xtask deps`: every dependency a manifest declares is used.
//!
//! For each package (`crates/*` and `xtask`), each name under
//! `[dependencies]` must be named in `src/` (or `build.rs`), and each under
//! `[dev-dependencies]` in `src/`, `tests/`, `benches/` or `examples/`, as
//! `name::…`, `use name` or `extern crate name` (with `-` read as `_`).
//! A name only a build needs (a linker hook, a feature switch) goes in
//! [`ALLOWED`] with its reason.
//!
//! Why a text check and not cargo-machete or cargo-udeps: cargo-udeps needs
//! a nightly compiler, and cargo-machete, which does the same text search,
//! takes minutes to build from crates.io on every fresh CI machine; this
//! runs in milliseconds and is tested here. Like cargo-machete it can miss
//! an unused dependency whose name appears in a comment, never the reverse.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// Dependencies used without being named in code: (package, dependency,
/// why).
const ALLOWED: &[(&str, &str, &str)] = &[];

/// `cargo xtask deps`: checks every package's manifest.
pub fn main() -> Result<()> {
    let mut packages: Vec<PathBuf> = std::fs::read_dir("crates")
        .context("run from the workspace root: no crates/ directory")?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("Cargo.toml").is_file())
        .collect();
    packages.sort();
    packages.push(PathBuf::from("xtask"));
    let mut offences = Vec::new();
    for dir in &packages {
        offences.extend(check_package(dir)?);
    }
    for offence in &offences {
        println!("{offence}");
    }
    if !offences.is_empty() {
        bail!("deps: {} unused dependenc(ies)", offences.len());
    }
    println!("deps: every declared dependency is used");
    Ok(())
}

/// The unused dependencies of the package in `dir`, as `path:line: what`.
fn check_package(dir: &Path) -> Result<Vec<String>> {
    let manifest_path = dir.join("Cargo.toml");
    let manifest = std::fs::read_to_string(&manifest_path)
        .with_context(|| format!("reading {}", manifest_path.display()))?;
    let package = dir
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let read = |parts: &[&str]| -> Result<String> {
        let mut text = String::new();
        for part in parts {
            text.push_str(&read_sources(&dir.join(part))?);
        }
        Ok(text)
    };
    let main_code = read(&["src", "build.rs"])?;
    let all_code = main_code.clone() + &read(&["tests", "benches", "examples"])?;
    let mut offences = Vec::new();
    for dep in declared(&manifest) {
        if ALLOWED
            .iter()
            .any(|(p, d, _)| *p == package && *d == dep.name)
        {
            continue;
        }
        let (code, places) = match dep.section {
            Section::Normal => (&main_code, "src/"),
            Section::Dev => (&all_code, "src/, tests/, benches/ or examples/"),
        };
        if !names_crate(code, &dep.name.replace('-', "_")) {
            offences.push(format!(
                "{}:{}: {} `{}` is not used in {places}",
                manifest_path.display(),
                dep.line,
                dep.section.title(),
                dep.name
            ));
        }
    }
    Ok(offences)
}

/// The text of every `.rs` file under `path` (or `path` itself), or
/// nothing if it does not exist.
fn read_sources(path: &Path) -> Result<String> {
    let mut text = String::new();
    if path.is_file() {
        return std::fs::read_to_string(path)
            .with_context(|| format!("reading {}", path.display()));
    }
    if !path.is_dir() {
        return Ok(text);
    }
    let mut stack = vec![path.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in
            std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))?
        {
            let p = entry?.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                text.push_str(
                    &std::fs::read_to_string(&p)
                        .with_context(|| format!("reading {}", p.display()))?,
                );
                text.push('\n');
            }
        }
    }
    Ok(text)
}

/// Which table a dependency is declared in.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Section {
    Normal,
    Dev,
}

impl Section {
    fn title(self) -> &'static str {
        match self {
            Section::Normal => "[dependencies]",
            Section::Dev => "[dev-dependencies]",
        }
    }
}

/// A declared dependency.
#[derive(Debug, PartialEq)]
struct Dependency {
    name: String,
    section: Section,
    /// 1-based line of its declaration.
    line: usize,
}

/// The names under `[dependencies]` and `[dev-dependencies]` of a manifest
/// (`name = …`, `name.workspace = true`, `name = { … }`).
fn declared(manifest: &str) -> Vec<Dependency> {
    let mut found = Vec::new();
    let mut section = None;
    for (i, raw) in manifest.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.starts_with('[') {
            section = match line {
                "[dependencies]" => Some(Section::Normal),
                "[dev-dependencies]" => Some(Section::Dev),
                _ => None,
            };
            continue;
        }
        let Some(section) = section else { continue };
        let Some((key, _)) = line.split_once('=') else {
            continue;
        };
        let name = key
            .trim()
            .split('.')
            .next()
            .unwrap_or("")
            .trim()
            .trim_matches('"');
        if !name.is_empty() {
            found.push(Dependency {
                name: name.to_string(),
                section,
                line: i + 1,
            });
        }
    }
    found
}

/// True when `code` names the crate `ident` as a path's first segment
/// (`ident::`), in `use ident` or in `extern crate ident`.
fn names_crate(code: &str, ident: &str) -> bool {
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    code.match_indices(ident).any(|(at, _)| {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| is_ident(c) || c == ':' || c == '.')
            && !code[..at].ends_with("::")
        {
            return false;
        }
        // A leading `::ident::` is a crate path too; `a::ident::` is not.
        if code[..at].ends_with("::") {
            let head = &code[..at - 2];
            if head.chars().next_back().is_some_and(is_ident) {
                return false;
            }
        }
        let after = &code[at + ident.len()..];
        if after.starts_with("::") {
            return true;
        }
        if after.chars().next().is_some_and(is_ident) {
            return false;
        }
        let head = code[..at].trim_end();
        head.ends_with("use") || head.ends_with("extern crate")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifests_are_read_by_section() {
        let manifest = "[package]\nname = \"x\"\n\n[dependencies]\nglam.workspace = true\nserde = { version = \"1\" } # why\n\n[dev-dependencies]\nproptest = \"1\"\n\n[[bench]]\nname = \"b\"\n";
        let deps = declared(manifest);
        let names: Vec<_> = deps
            .iter()
            .map(|d| (d.name.as_str(), d.section, d.line))
            .collect();
        assert_eq!(
            names,
            vec![
                ("glam", Section::Normal, 5),
                ("serde", Section::Normal, 6),
                ("proptest", Section::Dev, 9)
            ]
        );
    }

    #[test]
    fn a_crate_is_named_only_as_a_path_head_or_a_use() {
        assert!(names_crate("let v = glam::DVec3::ZERO;", "glam"));
        assert!(names_crate("use serde_json;", "serde_json"));
        assert!(names_crate("use ::rayon::prelude::*;", "rayon"));
        assert!(names_crate("#[derive(thiserror::Error)]", "thiserror"));
        // A module of the same name inside another path, a longer name, a
        // field or a word in prose do not count.
        assert!(!names_crate("use crate::png::write;", "png"));
        assert!(!names_crate(
            "let a = self.png; let b = png_bytes();",
            "png"
        ));
        assert!(!names_crate("// writes a png file", "png"));
        assert!(!names_crate("use trilux_geometry::Side;", "geometry"));
    }
}
