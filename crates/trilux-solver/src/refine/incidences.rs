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

use trilux_geometry::{ElementId, FaceElement};

use crate::throughput::BuildKeyHasher;

/// Shards of the table: enough that two to a few dozen threads rarely
/// wait on one another.
const SHARDS: usize = 32;

/// One shard: incidences by i · 2³³ + j's key (2 × element + side;
/// element ids stay far below 2³¹, whose forest would need hundreds of
/// gigabytes), hashed as the throughput cache hashes its keys.
type Table<T> = HashMap<u64, Option<Arc<T>>, BuildKeyHasher>;

/// One shot's incidences `T` (stage 2's `Incidence`) by (i, j and j's
/// side); `None` records a sub-pair that carries no light.
pub(crate) struct IncidenceMemo<T> {
    shards: Vec<Mutex<Table<T>>>,
}

impl<T> IncidenceMemo<T> {
    /// An empty table.
    pub fn new() -> Self {
        IncidenceMemo {
            shards: (0..SHARDS).map(|_| Mutex::new(Table::default())).collect(),
        }
    }

    /// The incidence of (i, j), made by `make` the first time it is asked
    /// for. (Two threads asking at once may both make it; they make the
    /// same value, and the first stored is kept.)
    pub fn get_or_make(
        &self,
        i: ElementId,
        j: FaceElement,
        make: impl FnOnce() -> Option<T>,
    ) -> Option<Arc<T>> {
        let key = (u64::from(i.0) << 33) | j.key();
        let shard = &self.shards[(key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 59) as usize % SHARDS];
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
