//! `trilux bake --open` and `trilux view`: a baked file in docs/viewer,
//! served on localhost until the command is stopped, and opened in the
//! system browser where there is one ([`open_browser`]).
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
const VIEWER: [Served; 11] = viewer_files![
    ("index.html", "text/html; charset=utf-8"),
    ("viewer.js", JS),
    ("walk.js", JS),
    ("glossy.js", JS),
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
/// address and, with `open`, opens it in the system browser; returns only
/// on an error.
pub fn serve(listener: TcpListener, glb: &[u8], open: bool) -> Result<()> {
    let port = listener.local_addr()?.port();
    let url = format!("http://127.0.0.1:{port}/index.html?file=/model.glb");
    crate::streams::print(&format!("viewer: {url} (Ctrl-C stops it)\n"))?;
    if open {
        match open_browser(&url) {
            Some(how) => {
                crate::streams::print(&format!("viewer: opened in the browser ({how})\n"))?
            }
            None => {
                let listed = match std::env::var("BROWSER") {
                    Ok(b) if !b.trim().is_empty() => "no command of $BROWSER started",
                    _ => "$BROWSER is not set",
                };
                crate::streams::eprint_line(&format!(
                    "warning: no browser to open ({listed} and {OPENER} is not on PATH): open {url} yourself"
                ));
            }
        }
    }
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

/// The platform's program that opens an address in the default browser.
const OPENER: &str = if cfg!(target_os = "macos") {
    "open"
} else if cfg!(windows) {
    "explorer.exe"
} else {
    "xdg-open"
};

/// Starts the system browser on `url`: each command of `$BROWSER` (a
/// `:`-separated list, as `man` and Python's `webbrowser` read it; `%s`
/// stands for the address, else it is appended) until one starts, else
/// [`OPENER`] from `PATH`. Returns the command started, or `None` when
/// there is none. The browser is not waited for (it may run for hours):
/// a thread reaps it.
pub fn open_browser(url: &str) -> Option<String> {
    let listed = std::env::var("BROWSER").unwrap_or_default();
    let mut commands: Vec<Vec<String>> = listed
        .split(':')
        .filter_map(|c| {
            let words: Vec<String> = c.split_whitespace().map(str::to_string).collect();
            (!words.is_empty()).then_some(words)
        })
        .map(|mut words| {
            if words.iter().any(|w| w.contains("%s")) {
                words.iter_mut().for_each(|w| *w = w.replace("%s", url));
            } else {
                words.push(url.to_string());
            }
            words
        })
        .collect();
    if let Some(opener) = on_path(OPENER) {
        commands.push(vec![opener.display().to_string(), url.to_string()]);
    }
    commands.into_iter().find_map(|words| {
        let mut child = std::process::Command::new(&words[0])
            .args(&words[1..])
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .spawn()
            .ok()?;
        std::thread::spawn(move || child.wait());
        Some(words[0].clone())
    })
}

/// `program` in one of `PATH`'s folders.
fn on_path(program: &str) -> Option<std::path::PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
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
