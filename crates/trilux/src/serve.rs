//! `trilux bake --open`: the baked file in docs/viewer, served on
//! localhost until the command is stopped.
//!
//! The viewer's files are built into the binary (they are committed,
//! three.js vendored), so an installed `trilux` needs no source tree. The
//! server answers `GET` (and `HEAD`) for those files and `/model.glb` on
//! 127.0.0.1 only: a walkthrough for the person at this machine, not a web
//! server. Each connection is answered on its own thread, at most
//! [`MAX_CONNECTIONS`] at once, each read bounded in time
//! ([`READ_TIMEOUT`]) and size ([`MAX_REQUEST_BYTES`]), so one idle or
//! half-sent request blocks nobody else. The port is bound before the
//! solve ([`listen`]), so a port in use is refused before any work.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use anyhow::{Context, Result};

/// A file the server sends: path, content type, bytes.
type Served = (&'static str, &'static str, &'static [u8]);

/// Builds the table of the viewer's files from paths below docs/viewer
/// (through the link viewer/, so that the package holds them).
macro_rules! viewer_files {
    ($(($path:literal, $kind:expr)),* $(,)?) => {
        [$((
            concat!("/", $path),
            $kind,
            include_bytes!(concat!("../viewer/", $path)).as_slice(),
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

/// Longest request head read, newlines or not.
pub const MAX_REQUEST_BYTES: u64 = 16 * 1024;

/// Connections answered at once; more wait in the listener's backlog.
pub const MAX_CONNECTIONS: usize = 16;

/// How long a connection may stay silent while its request is read, and
/// how long a reply may wait for the reader.
pub const READ_TIMEOUT: Duration = Duration::from_secs(10);

/// Binds 127.0.0.1:`port` (0: any free one), before any work.
pub fn listen(port: u16) -> Result<TcpListener> {
    TcpListener::bind(("127.0.0.1", port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{port}"))
}

/// Serves the viewer with `glb` as `/model.glb` on `listener`; prints the
/// address; returns only on an error.
pub fn serve(listener: TcpListener, glb: &[u8]) -> Result<()> {
    let port = listener.local_addr()?.port();
    crate::streams::print(&format!(
        "viewer: http://127.0.0.1:{port}/index.html?file=/model.glb (Ctrl-C stops it)\n"
    ))?;
    let busy = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        // A failed connection (a closed tab) does not stop the server.
        for stream in listener.incoming().flatten() {
            while busy.load(Ordering::Acquire) >= MAX_CONNECTIONS {
                std::thread::sleep(Duration::from_millis(5));
            }
            busy.fetch_add(1, Ordering::AcqRel);
            let busy = &busy;
            scope.spawn(move || {
                let _ = answer(stream, glb);
                busy.fetch_sub(1, Ordering::AcqRel);
            });
        }
    });
    Ok(())
}

/// Reads one request (at most [`MAX_REQUEST_BYTES`], each read within
/// [`READ_TIMEOUT`]) and answers it.
fn answer(stream: TcpStream, glb: &[u8]) -> std::io::Result<()> {
    stream.set_read_timeout(Some(READ_TIMEOUT))?;
    stream.set_write_timeout(Some(READ_TIMEOUT))?;
    let mut reader = BufReader::new(stream.try_clone()?.take(MAX_REQUEST_BYTES));
    let mut head = String::new();
    let mut line = String::new();
    while reader.read_line(&mut line)? > 0 {
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
