//! The incidences of one shot's sub-pairs, shared by every hierarchy they
//! feed.
//!
//! Stage 2 refines a pair link (i, j) into every stored hierarchy leaving
//! j's face. When a link splits its sender i (or its element j), each
//! sub-pair (i_m, j) needs its own incidence (T_ij, the unshot radiance sent,
//! the direction of arrival, its sampled lobe), and before this table each
//! hierarchy of the face made the same incidences again: a glossy face
//! with a dozen near partners computed each one a dozen times. The table
//! lives for one shot (the unshot radiance changes between shots) and is
//! shared by the shot's parallel tasks.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use trilux_geometry::FaceElement;

use crate::shards::Padded;
use crate::throughput::BuildKeyHasher;

/// Shards of the table: enough that two to a few dozen threads rarely
/// want the same one at once (each on its own cache lines).
const SHARDS: usize = 128;

/// One shard: incidences by i's key · 2³² + j's key (each 2 × element +
/// side; element ids stay far below 2³¹, whose forest would need hundreds
/// of gigabytes), hashed as the throughput cache hashes its keys. i's side
/// counts: a flush of deferred glossy light (`deferred`) refines links
/// from both sides of one surface in the same pass.
type Table<T> = HashMap<u64, Option<Arc<T>>, BuildKeyHasher>;

/// One shot's incidences `T` (stage 2's `Incidence`) by (i, j and their
/// sides); `None` records a sub-pair that carries no light.
pub(crate) struct IncidenceMemo<T> {
    shards: Vec<Padded<Mutex<Table<T>>>>,
}

impl<T> IncidenceMemo<T> {
    /// An empty table.
    pub fn new() -> Self {
        IncidenceMemo {
            shards: (0..SHARDS)
                .map(|_| Padded(Mutex::new(Table::default())))
                .collect(),
        }
    }

    /// The incidence of (i, j), made by `make` the first time it is asked
    /// for, looked up in the task's `local` front first (a hierarchy asks
    /// for the same (i, j) once per receiver node of j, and the shared
    /// table's lock and reference count are atomics that both cores
    /// write). (Two threads asking at once may both make it; they make
    /// the same value, and the first stored is kept.)
    pub fn get_or_make(
        &self,
        local: &mut LocalMemo<T>,
        i: FaceElement,
        j: FaceElement,
        make: impl FnOnce() -> Option<T>,
    ) -> Option<Arc<T>> {
        let key = (i.key() << 32) | j.key();
        if let Some(found) = local.0.get(&key) {
            return found.clone();
        }
        let got = self.shared(key, make);
        local.0.insert(key, got.clone());
        got
    }

    fn shared(&self, key: u64, make: impl FnOnce() -> Option<T>) -> Option<Arc<T>> {
        let shard = &self.shards[(key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 57) as usize % SHARDS];
        if let Some(found) = shard.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return found;
        }
        let made = make().map(Arc::new);
        match shard.lock() {
            Ok(mut m) => m.entry(key).or_insert(made).clone(),
            Err(_) => made,
        }
    }
}

/// One task's incidences already asked for (lives as long as the task).
pub(crate) struct LocalMemo<T>(Table<T>);

impl<T> Default for LocalMemo<T> {
    fn default() -> Self {
        LocalMemo(Table::default())
    }
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use trilux_geometry::{ElementId, FaceElement, Side};

    use super::{IncidenceMemo, LocalMemo};

    #[test]
    fn each_incidence_is_made_once_per_shot_whichever_task_asks() {
        let memo = IncidenceMemo::new();
        let (mut first, mut second) = (LocalMemo::default(), LocalMemo::default());
        let made = Cell::new(0);
        let make = |v: u32| {
            made.set(made.get() + 1);
            Some(v)
        };
        let j = FaceElement::new(ElementId(7), Side::Back);
        let i = |e: u32| FaceElement::new(ElementId(e), Side::Front);
        let a = memo.get_or_make(&mut first, i(3), j, || make(30));
        let again = memo.get_or_make(&mut first, i(3), j, || make(99));
        let other_task = memo.get_or_make(&mut second, i(3), j, || make(98));
        assert_eq!(
            (a.as_deref(), again.as_deref(), other_task.as_deref()),
            (Some(&30), Some(&30), Some(&30))
        );
        assert_eq!(made.get(), 1);
        // The other side of j, and another i, are other incidences.
        let front = FaceElement::new(ElementId(7), Side::Front);
        assert_eq!(
            memo.get_or_make(&mut first, i(3), front, || make(31))
                .as_deref(),
            Some(&31)
        );
        assert_eq!(
            memo.get_or_make(&mut second, i(4), j, || make(40))
                .as_deref(),
            Some(&40)
        );
        // So is the other side of i.
        let back = FaceElement::new(ElementId(3), Side::Back);
        assert_eq!(
            memo.get_or_make(&mut first, back, j, || make(32))
                .as_deref(),
            Some(&32)
        );
        // A sub-pair that carries no light is remembered as such.
        assert_eq!(memo.get_or_make(&mut first, i(5), j, || None), None);
        assert_eq!(memo.get_or_make(&mut second, i(5), j, || make(50)), None);
        assert_eq!(made.get(), 4);
    }
}
