//! What `cargo xtask viewer` does with pictures: PNG values, their means
//! and differences, and the node scripts of docs/viewer that make them.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::golden::root;

/// A PNG's RGB values in [0, 1].
pub(crate) fn png_values(path: &Path) -> Result<Vec<f64>> {
    let file = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info()?;
    let mut buf = vec![0; reader.output_buffer_size().context("PNG size")?];
    let info = reader.next_frame(&mut buf)?;
    let channels = info.color_type.samples();
    if channels < 3 {
        bail!("{}: not an RGB PNG", path.display());
    }
    let pixels = &buf[..info.buffer_size()];
    Ok(pixels
        .chunks(channels)
        .flat_map(|p| &p[..3])
        .map(|&v| f64::from(v) / 255.0)
        .collect())
}

/// (preview mean, viewer mean, RMSE between them) of two PNGs of one size.
pub(crate) fn png_compare(preview: &Path, viewer: &Path) -> Result<(f64, f64, f64)> {
    let (p, v) = (png_values(preview)?, png_values(viewer)?);
    if p.len() != v.len() || p.is_empty() {
        bail!(
            "{} and {} differ in size",
            preview.display(),
            viewer.display()
        );
    }
    let n = p.len() as f64;
    let mean = |x: &[f64]| x.iter().sum::<f64>() / n;
    let sq: f64 = p.iter().zip(&v).map(|(a, b)| (a - b) * (a - b)).sum();
    Ok((mean(&p), mean(&v), (sq / n).sqrt()))
}

pub(crate) fn node(script: &str, args: &[String]) -> Result<()> {
    let script = root().join("docs/viewer").join(script);
    eprintln!("xtask: node {} {}", script.display(), args.join(" "));
    let status = Command::new("node")
        .arg(&script)
        .args(args)
        .status()
        .context(
            "could not start node (docs/viewer/scripts/ci.sh installs what the viewer needs)",
        )?;
    if !status.success() {
        bail!("node {} failed ({status})", script.display());
    }
    Ok(())
}

pub(crate) fn png_size(path: &Path) -> Result<(u32, u32)> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path)?));
    let info = decoder.read_info()?;
    Ok((info.info().width, info.info().height))
}

/// A node script's standard output (its standard error passed through).
pub(crate) fn node_output(script: &str, args: &[String]) -> Result<String> {
    let script = root().join("docs/viewer").join(script);
    eprintln!("xtask: node {} {}", script.display(), args.join(" "));
    let out = Command::new("node")
        .arg(&script)
        .args(args)
        .stderr(std::process::Stdio::inherit())
        .output()
        .context("could not start node")?;
    if !out.status.success() {
        bail!("node {} failed ({})", script.display(), out.status);
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Means of two PNGs of one size over the pixels where `mask` (a third)
/// is white (every channel above one half); `None` when it has none.
pub(crate) fn masked_means(a: &Path, b: &Path, mask: &Path) -> Result<Option<(f64, f64)>> {
    let (a, b, m) = (png_values(a)?, png_values(b)?, png_values(mask)?);
    if a.len() != b.len() || a.len() != m.len() {
        bail!(
            "{}: the pictures and the mask differ in size",
            mask.display()
        );
    }
    let (mut sa, mut sb, mut n) = (0.0, 0.0, 0usize);
    for ((pa, pb), pm) in a.chunks(3).zip(b.chunks(3)).zip(m.chunks(3)) {
        if pm.iter().all(|&x| x > 0.5) {
            sa += pa.iter().sum::<f64>();
            sb += pb.iter().sum::<f64>();
            n += 3;
        }
    }
    Ok((n > 0).then(|| (sa / n as f64, sb / n as f64)))
}
