//! Helpers shared by the binary's integration tests.
#![allow(dead_code)] // each test binary uses some of them

pub mod hostile;
pub mod serialized;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A file under the repository's `tests/` folder.
pub fn test_file(name: &str) -> String {
    format!("{}/../../tests/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// `trilux render FILE -o OUT EXTRA…`, which must succeed, and its image.
pub fn render(file: &str, extra: &[&str], out: &Path) -> trilux_render::Image {
    let mut args = vec!["render", file, "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let run = trilux(&args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    trilux_render::Image::read_exr(out).unwrap()
}

/// `trilux solve FILE -o SOLUTION`, which must succeed.
pub fn solve(file: &str, solution: &Path) {
    let run = trilux(&["solve", file, "-o", solution.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// The `mean_rgb` of a Mitsuba reference's JSON (`scenes/NAME`), as the
/// scenes' make_references.py scripts write it.
pub fn reference_rgb(name: &str) -> [f64; 3] {
    let text = std::fs::read_to_string(scene(name)).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    std::array::from_fn(|c| v["mean_rgb"][c].as_f64().unwrap())
}

/// The mean over an image's pixels per channel (R, G, B).
pub fn mean_rgb(image: &trilux_render::Image) -> [f64; 3] {
    let px = image.pixels();
    let mut m = [0.0; 3];
    for p in px {
        for (c, mc) in m.iter_mut().enumerate() {
            *mc += f64::from(p[c]) / px.len() as f64;
        }
    }
    m
}

/// The render options that choose an estimator by the name the scene
/// tests use: `preview` is `--preview`, any other `--gather NAME`.
pub fn gather_args(gather: &str) -> Vec<&str> {
    if gather == "preview" {
        vec!["--preview"]
    } else {
        vec!["--gather", gather]
    }
}

/// The mean over an image's pixels of R + G + B (the figure the scenes'
/// Mitsuba references store as their `mean_rgb` summed).
pub fn mean_rgb_sum(image: &trilux_render::Image) -> f64 {
    mean_rgb(image).iter().sum()
}

/// A thin slab's transmittance (1 − r)² / (1 − r²) at cos θ_i = `c`, r
/// the unpolarised Fresnel reflectance of one interface of relative index
/// `eta` by Snell's law and the Fresnel equations: the closed form the
/// pane-of-glass tests hold trilux to.
pub fn slab_transmittance(c: f64, eta: f64) -> f64 {
    let s = (1.0 - c * c).sqrt() / eta;
    let ct = (1.0 - s * s).sqrt();
    let rs = ((c - eta * ct) / (c + eta * ct)).powi(2);
    let rp = ((ct - eta * c) / (ct + eta * c)).powi(2);
    let r = 0.5 * (rs + rp);
    (1.0 - r) * (1.0 - r) / (1.0 - r * r)
}

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
