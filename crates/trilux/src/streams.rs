//! The command's standard streams, written without panicking.
//!
//! `println!` and `eprintln!` panic when the write fails (exit 101): stdout
//! on a full disk (`> /dev/full`), a pipe whose reader has gone
//! (`trilux info | head -c 10`), stderr on a full disk. Here every write is
//! checked:
//! - stdout on a closed pipe ends the output quietly and the command keeps
//!   its status: the reader chose to read no more, so what it did read is
//!   correct, and the command's work (files written, a scene checked) is
//!   done (status 0, as `head` users expect; a failing command still
//!   fails with 1).
//! - any other failure of stdout (a full disk) is an error: the output the
//!   user asked for is lost, status 1.
//! - stderr is written at best: when the error line itself cannot be
//!   written there is nowhere left to say so, and the status (1) still says
//!   the command failed.

use std::io::{ErrorKind, Write};

use anyhow::{Result, anyhow};

/// Writes `text` to stdout and flushes it; a reader that has gone (a
/// closed pipe) is not an error (module docs).
pub fn print(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != ErrorKind::BrokenPipe => {
            Err(anyhow!("cannot write to the standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// Writes one line to stderr, at best (module docs).
pub fn eprint_line(line: &str) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "{line}");
}
