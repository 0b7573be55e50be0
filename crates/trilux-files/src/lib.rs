//! # trilux-files — reading inputs and writing outputs without surprises
//!
//! Layer: the bottom, beside `trilux-color`; depends on nothing else in
//! trilux (only `thiserror`). Every crate that touches the file system goes
//! through it, so that every command has the same guarantees
//! (docs/limits.md):
//!
//! - [`read`]: an input is read only if it is a regular file (after
//!   following symbolic links) no larger than a stated limit, so that
//!   `/dev/zero`, a FIFO or a 100 GB file is an error, not an unbounded read.
//! - [`mod@write`]: outputs are planned before any work ([`Output::plan`]: the
//!   folder exists, the path is not a folder, symbolic links are followed
//!   to the file they name) and written all or none at the end
//!   ([`write_all`]): each regular file is staged in an exclusively created
//!   temporary file beside it and renamed over it only when every output is
//!   staged; FIFOs and character devices (`/dev/null`) are written through,
//!   never replaced.
//! - [`identity`]: whether two paths name the same file (hard links,
//!   symbolic links, `a/../b`, files that do not exist yet), so that a
//!   command can refuse an output that would overwrite one of its inputs.
//! - [`film`]: the largest film a render may allocate (pixels a side and
//!   in all), checked where a scene file or a command line sets one.
#![forbid(unsafe_code)]

pub mod film;
pub mod identity;
pub mod read;
pub mod write;

pub use identity::FileIdentity;
pub use read::{ReadError, read_limited};
pub use write::{Output, WriteError, write_all, write_one};

/// Units for the limits in messages: "64 MiB", "3.2 GiB", "512 bytes".
pub fn human_bytes(n: u64) -> String {
    const UNITS: [&str; 4] = ["KiB", "MiB", "GiB", "TiB"];
    if n < 1024 {
        return format!("{n} bytes");
    }
    let mut v = n as f64 / 1024.0;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if v.fract() == 0.0 {
        format!("{v} {}", UNITS[unit])
    } else {
        format!("{v:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn human_bytes_reads_well() {
        assert_eq!(super::human_bytes(10), "10 bytes");
        assert_eq!(super::human_bytes(64 << 20), "64 MiB");
        assert_eq!(super::human_bytes(3 << 29), "1.5 GiB");
    }
}
