//! Helpers of the hostile-input tests (`hostile_*.rs`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A path as the `&str` the command line takes.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Writes `bytes` to `dir/name`.
pub fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write test file");
    p
}

/// Makes a FIFO: the stand-in for a device or an endless input (never a
/// real device).
pub fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success());
}

/// Runs the `trilux` binary with `args`, killing it if it has not ended
/// after `limit`: a guard against a hang (an input read forever, an
/// expansion without bound), not a speed figure, so `limit` is generous.
/// Its output is read once it ends, so it is for commands that print
/// little (a refusal's one line), not more than a pipe holds (64 KiB).
pub fn trilux_or_hang(args: &[&str], limit: Duration) -> Output {
    trilux_streams_or_hang(args, Stdio::piped(), Stdio::piped(), limit)
}

/// [`trilux_or_hang`] with the child's stdout and stderr as given (a
/// full device, a pipe whose reader has gone); the output holds only
/// what went to a `Stdio::piped()`.
pub fn trilux_streams_or_hang(
    args: &[&str],
    stdout: Stdio,
    stderr: Stdio,
    limit: Duration,
) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_trilux"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .spawn()
        .expect("the trilux binary runs");
    let start = Instant::now();
    while child
        .try_wait()
        .expect("the child can be waited on")
        .is_none()
    {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{args:?} had not ended after {limit:?}: a hang");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("the child's output")
}

/// One line `error: {prefix}...` containing `what`, status 1, no panic.
pub fn assert_refused(out: &Output, prefix: &str, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{what}: status; stderr {stderr}"
    );
    assert_eq!(stderr.lines().count(), 1, "{what}: one line: {stderr}");
    assert!(
        stderr.starts_with(&format!("error: {prefix}")),
        "{stderr:?} should start with error: {prefix}"
    );
    assert!(stderr.contains(what), "{stderr:?} should say {what:?}");
}

/// Success, with stderr shown otherwise.
pub fn assert_ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A closed box seen from inside, reflectance `rho`, radiance `le`, every
/// length times `scale`; 12 × 12 pixels, 4 samples. The `<emitter>` is on
/// line 9 at column 5, its radiance value at column 27.
pub fn furnace(rho: &str, le: &str, scale: f64) -> String {
    format!(
        r#"<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,0,{z}" target="0,0,{t}" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/></film>
  </sensor>
  <shape type="cube"><boolean name="flip_normals" value="true"/><transform name="to_world"><scale value="{scale:e}"/></transform>
    <emitter type="area"><float name="radiance" value="{le}"/></emitter>
    <bsdf type="diffuse"><float name="reflectance" value="{rho}"/></bsdf>
  </shape>
</scene>
"#,
        z = 0.5 * scale,
        t = -scale
    )
}

/// FNV-1a, the solution file's checksum.
pub fn fnv(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}
