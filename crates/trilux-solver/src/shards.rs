//! Shards of the tables a shot's threads share, each on its own cache
//! lines.
//!
//! Taking a lock writes its word. Shards packed side by side put several
//! lock words on one 64-byte line, so two threads locking *different*
//! shards still pass that line back and forth between their cores; in the
//! boxes-64 profile that transfer was most of the incidence table's time
//! (docs/results.md, "Scale"). 128 bytes, because the adjacent-line
//! prefetcher fetches lines in pairs.

use std::ops::Deref;

/// A value alone on its 128-byte block.
#[repr(align(128))]
pub(crate) struct Padded<T>(pub T);

impl<T> Deref for Padded<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::Padded;
    use std::sync::Mutex;

    #[test]
    fn neighbouring_shards_never_share_a_line() {
        let shards: Vec<Padded<Mutex<u64>>> = (0..4).map(|i| Padded(Mutex::new(i))).collect();
        for pair in shards.windows(2) {
            let a = &*pair[0] as *const Mutex<u64> as usize;
            let b = &*pair[1] as *const Mutex<u64> as usize;
            assert!(b - a >= 128 && a.is_multiple_of(128) && b.is_multiple_of(128));
        }
    }
}
