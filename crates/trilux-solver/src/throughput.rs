//! Geometric throughput of an element pair, T_ij = A_i F_{i→j} V_ij, cached.
//!
//! T is symmetric (reciprocity A_i F_ij = A_j F_ji), so one number serves
//! both directions: a link i→j transports flux π T_ij δL_i and gives j the
//! radiance ρ (T_ij / A_j) δL_i. The paper stores "a form factor multiplied
//! by a visibility term" in each interaction (§4.6); the solver keeps it on
//! stored interaction nodes and, for the transient pairs of Lambertian
//! senders, in this bounded cache so that later shots between the same
//! elements do not trace the same shadow rays again.

use std::collections::HashMap;
use std::sync::RwLock;

use trilux_geometry::{FaceElement, FormFactorOptions, Visibility, form_factor};

use crate::shards::Padded;

/// A throughput with the visible fraction it was made with.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Throughput {
    /// T = A_i F_{i→j} V (m²).
    pub t: f64,
    /// The visible fraction V in [0, 1].
    pub v: f64,
    /// The unoccluded form factor F_{i→j} from the first element of the
    /// pair (the receiver) to the second.
    pub f: f64,
    /// How much the point form factor F(x → second) varies over x in the
    /// first element (max − min): the receiver-side error of a transfer
    /// made at this level, the refinement oracle of stage 1.
    pub spread: f64,
}

/// The form-factor accuracy the solver asks for: relative tolerance 1e-2
/// on the adaptive cubature (the geometry crate's default is 1e-3). T also
/// carries a visible fraction from 16–256 shadow rays, whose noise is
/// larger; the degree-5 rules' actual error is far below the tolerance
/// (the furnace, whose visibility is exact, stays at 0.37 %), and the
/// solve is about a quarter faster (docs/results.md, "Solver").
const FORM_FACTOR_OPTIONS: FormFactorOptions = FormFactorOptions {
    rel_tol: 1e-2,
    max_depth: 4,
    samples: 64,
};

const SHARDS: usize = 64;

/// A hasher for the cache's u64 keys: a few multiplications instead of
/// SipHash, which dominated the solve's profile.
#[derive(Clone, Copy, Default)]
pub(crate) struct KeyHasher(u64);

impl std::hash::Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, k: u64) {
        // MurmurHash3's 64-bit finaliser: every bit of the key reaches the
        // top bits (which the table uses), independently of the shard index.
        let mut h = k ^ 0x5851_F42D_4C95_7F2D;
        h ^= h >> 33;
        h = h.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
        h ^= h >> 33;
        h = h.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
        h ^= h >> 33;
        self.0 = h;
    }
}

/// Builds [`KeyHasher`]s, for maps keyed by dense `u64` pair keys.
pub(crate) type BuildKeyHasher = std::hash::BuildHasherDefault<KeyHasher>;

type KeyMap = HashMap<u64, Throughput, BuildKeyHasher>;

/// A bounded, thread-safe cache of throughputs keyed by ordered sided pairs.
pub(crate) struct ThroughputCache {
    shards: Vec<Padded<RwLock<KeyMap>>>,
    per_shard_cap: usize,
}

impl ThroughputCache {
    /// A cache holding at most about `capacity` pairs.
    pub fn new(capacity: usize) -> Self {
        ThroughputCache {
            shards: (0..SHARDS)
                .map(|_| Padded(RwLock::new(KeyMap::default())))
                .collect(),
            per_shard_cap: (capacity / SHARDS).max(16),
        }
    }

    fn key(a: FaceElement, b: FaceElement) -> u64 {
        // Ordered: T is symmetric but the spread belongs to the first.
        (a.key() << 32) | b.key()
    }

    fn shard(key: u64) -> usize {
        // Fibonacci hashing spreads neighbouring ids over the shards.
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 58) as usize % SHARDS
    }

    /// The cached throughput of a pair, if any.
    pub fn get(&self, a: FaceElement, b: FaceElement) -> Option<Throughput> {
        let key = Self::key(a, b);
        let shard = self.shards[Self::shard(key)].read().ok()?;
        shard.get(&key).copied()
    }

    /// Bytes the cache holds now (entries × (key + value), with the hash
    /// table's load factor of about 8/7).
    pub fn bytes(&self) -> usize {
        let entries: usize = self
            .shards
            .iter()
            .filter_map(|s| s.read().ok().map(|s| s.capacity()))
            .sum();
        entries * (std::mem::size_of::<u64>() + std::mem::size_of::<Throughput>() + 1)
    }

    /// Stores a throughput; clears the shard when it is full (a simple bound
    /// that keeps memory O(capacity) whatever the scene).
    pub fn insert(&self, a: FaceElement, b: FaceElement, t: Throughput) {
        let key = Self::key(a, b);
        if let Ok(mut shard) = self.shards[Self::shard(key)].write() {
            if shard.len() >= self.per_shard_cap {
                shard.clear();
            }
            shard.insert(key, t);
        }
    }
}

/// Computes T_ij = A_i F_{i→j} V_ij for the given faces, without the cache
/// (`i` is the receiver: the spread is measured over it). With `visible`,
/// V = 1 without tracing (a pair inside a pair whose shadow rays all
/// passed).
pub(crate) fn compute_throughput(
    vis: &Visibility<'_>,
    i: FaceElement,
    j: FaceElement,
    visibility_samples: u32,
    visible: bool,
) -> Throughput {
    // Coarse pairs decide a lot of transport from one number: give them
    // more shadow rays (×16 for whole input surfaces, ×4 one or two levels
    // down).
    let forest = vis.forest();
    let depth = forest.element(i.element).depth + forest.element(j.element).depth;
    let samples = match depth {
        0 | 1 => visibility_samples * 16,
        2 | 3 => visibility_samples * 4,
        _ => visibility_samples,
    };
    throughput_with_rays(vis, i, j, samples, visible)
}

/// [`compute_throughput`] with exactly `rays` shadow rays, whatever the
/// pair's depth (a root pair reached after the solve's deadline:
/// docs/solver.md, "The deadline inside a shot").
pub(crate) fn throughput_with_rays(
    vis: &Visibility<'_>,
    i: FaceElement,
    j: FaceElement,
    rays: u32,
    visible: bool,
) -> Throughput {
    let forest = vis.forest();
    let ff = form_factor(forest, i, j, &FORM_FACTOR_OPTIONS);
    let (f, spread) = (ff.value, ff.spread);
    if !(f.is_finite() && f > 0.0) {
        return Throughput::default();
    }
    let v = if visible {
        1.0
    } else {
        vis.weighted(i, j, rays)
    };
    let area = forest.element(i.element).area;
    let t = area * f * v;
    Throughput {
        t: if t.is_finite() && t > 0.0 { t } else { 0.0 },
        v,
        f,
        spread,
    }
}
