//! `trilux bake --open`: the baked file in docs/viewer, served on
//! localhost until the command is stopped.
//!
//! The viewer's files are built into the binary (they are committed,
//! three.js vendored), so an installed `trilux` needs no source tree. The
//! server answers `GET` (and `HEAD`) for those files and `/model.glb`, one
//! connection at a time, on 127.0.0.1 only: a walkthrough for the person
//! at this machine, not a web server.

use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};

use anyhow::{Context, Result};

/// A file the server sends: path, content type, bytes.
type Served = (&'static str, &'static str, &'static [u8]);

/// Builds the table of the viewer's files from paths below docs/viewer.
macro_rules! viewer_files {
    ($(($path:literal, $kind:expr)),* $(,)?) => {
        [$((
            concat!("/", $path),
            $kind,
            include_bytes!(concat!("../../../docs/viewer/", $path)).as_slice(),
        )),*]
    };
}

const JS: &str = "text/javascript; charset=utf-8";

/// The viewer's files.
const VIEWER: [Served; 9] = viewer_files![
    ("index.html", "text/html; charset=utf-8"),
    ("viewer.js", JS),
    ("vendor/three/build/three.module.js", JS),
    ("vendor/three/build/three.core.js", JS),
    ("vendor/three/examples/jsm/controls/OrbitControls.js", JS),
    (
        "vendor/three/examples/jsm/controls/PointerLockControls.js",
        JS
    ),
    ("vendor/three/examples/jsm/loaders/GLTFLoader.js", JS),
    ("vendor/three/examples/jsm/utils/BufferGeometryUtils.js", JS),
    ("vendor/three/examples/jsm/utils/SkeletonUtils.js", JS),
];

/// Longest request head read.
const MAX_REQUEST_BYTES: usize = 16 * 1024;

/// Serves the viewer with `glb` as `/model.glb` on 127.0.0.1 (`port` 0:
/// any free one); prints the address; returns only on an error.
pub fn serve(glb: &[u8], port: u16) -> Result<()> {
    let listener = TcpListener::bind(("127.0.0.1", port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{port}"))?;
    let port = listener.local_addr()?.port();
    crate::streams::print(&format!(
        "viewer: http://127.0.0.1:{port}/index.html?file=/model.glb (Ctrl-C stops it)\n"
    ))?;
    // A failed connection (a closed tab) does not stop the server.
    for stream in listener.incoming().flatten() {
        let _ = answer(stream, glb);
    }
    Ok(())
}

/// Reads one request and answers it.
fn answer(stream: TcpStream, glb: &[u8]) -> std::io::Result<()> {
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut head = String::new();
    let mut line = String::new();
    while reader.read_line(&mut line)? > 0 && head.len() < MAX_REQUEST_BYTES {
        if line == "\r\n" || line == "\n" {
            break;
        }
        head.push_str(&line);
        line.clear();
    }
    let mut words = head.split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    let path = target.split(['?', '#']).next().unwrap_or("");
    let path = if path == "/" { "/index.html" } else { path };
    let found = match path {
        "/model.glb" => Some(("model/gltf-binary", glb)),
        _ => VIEWER
            .iter()
            .find(|(p, _, _)| *p == path)
            .map(|(_, kind, bytes)| (*kind, *bytes)),
    };
    let mut out = stream;
    match (method, found) {
        ("GET" | "HEAD", Some((kind, body))) => {
            write!(
                out,
                "HTTP/1.1 200 OK\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
                body.len()
            )?;
            if method == "GET" {
                out.write_all(body)?;
            }
        }
        ("GET" | "HEAD", None) => out.write_all(
            b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
        )?,
        _ => out.write_all(
            b"HTTP/1.1 405 Method Not Allowed\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
        )?,
    }
    out.flush()
}
