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

use glam::{DVec2, DVec3};
use trilux_geometry::{ElementId, FormFactorOptions, SceneGeometry};

/// One element seen from one of its sides.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct SidedElement {
    /// The element.
    pub element: ElementId,
    /// Its back face rather than its front.
    pub back: bool,
}

impl SidedElement {
    fn key(self) -> u64 {
        (u64::from(self.element.0) << 1) | u64::from(self.back)
    }
}

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

const SHARDS: usize = 64;

/// A bounded, thread-safe cache of throughputs keyed by ordered sided pairs.
pub(crate) struct ThroughputCache {
    shards: Vec<RwLock<HashMap<u64, Throughput>>>,
    per_shard_cap: usize,
}

impl ThroughputCache {
    /// A cache holding at most about `capacity` pairs.
    pub fn new(capacity: usize) -> Self {
        ThroughputCache {
            shards: (0..SHARDS).map(|_| RwLock::new(HashMap::new())).collect(),
            per_shard_cap: (capacity / SHARDS).max(16),
        }
    }

    fn key(a: SidedElement, b: SidedElement) -> u64 {
        // Ordered: T is symmetric but the spread belongs to the first.
        (a.key() << 32) | b.key()
    }

    fn shard(key: u64) -> usize {
        // Fibonacci hashing spreads neighbouring ids over the shards.
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 58) as usize % SHARDS
    }

    /// The cached throughput of a pair, if any.
    pub fn get(&self, a: SidedElement, b: SidedElement) -> Option<Throughput> {
        let key = Self::key(a, b);
        let shard = self.shards[Self::shard(key)].read().ok()?;
        shard.get(&key).copied()
    }

    /// Stores a throughput; clears the shard when it is full (a simple bound
    /// that keeps memory O(capacity) whatever the scene).
    pub fn insert(&self, a: SidedElement, b: SidedElement, t: Throughput) {
        let key = Self::key(a, b);
        if let Ok(mut shard) = self.shards[Self::shard(key)].write() {
            if shard.len() >= self.per_shard_cap {
                shard.clear();
            }
            shard.insert(key, t);
        }
    }
}

/// F_{i→j} between the given faces of two elements, unoccluded.
///
/// Front to front is the geometry layer's accurate estimate (Lambert's
/// closed form with adaptive cubature). When a back face is involved (a
/// `twosided` material) the kernel cos θ_i cos θ_j / (π r²) is integrated with
/// the faces' normals on a stratified 8×8 × 8×8 grid of point pairs: a
/// deterministic estimate good to about a percent away from shared edges.
pub(crate) fn sided_form_factor(
    geom: &SceneGeometry,
    i: SidedElement,
    j: SidedElement,
    ff_options: &FormFactorOptions,
) -> (f64, f64) {
    if !i.back && !j.back {
        let ff = geom.form_factor_with(i.element, j.element, ff_options);
        return (ff.value, ff.spread);
    }
    const G: usize = 8;
    let grid = |e: ElementId, back: bool| -> Vec<(DVec3, DVec3, f64)> {
        let mut pts = Vec::with_capacity(G * G);
        for a in 0..G {
            for b in 0..G {
                let u = DVec2::new((a as f64 + 0.5) / G as f64, (b as f64 + 0.5) / G as f64);
                let s = geom.sample_element(e, u);
                let n = if back { -s.normal } else { s.normal };
                pts.push((s.point, n, 1.0 / s.pdf_area.max(1e-300)));
            }
        }
        pts
    };
    let (pi, pj) = (grid(i.element, i.back), grid(j.element, j.back));
    let mut sum = 0.0;
    let mut weight_i = 0.0;
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &(x, nx, wx) in &pi {
        weight_i += wx;
        let mut inner = 0.0;
        for &(y, ny, wy) in &pj {
            let d = y - x;
            let r2 = d.length_squared();
            if r2 <= 0.0 {
                continue;
            }
            let c1 = nx.dot(d);
            let c2 = -ny.dot(d);
            if c1 > 0.0 && c2 > 0.0 {
                inner += wy * c1 * c2 / (std::f64::consts::PI * r2 * r2);
            }
        }
        let point = (inner / pj.len() as f64).min(1.0);
        lo = lo.min(point);
        hi = hi.max(point);
        sum += wx * point;
    }
    let spread = if hi >= lo { hi - lo } else { 0.0 };
    if weight_i > 0.0 {
        let f = sum / weight_i;
        if f.is_finite() {
            (f.clamp(0.0, 1.0), spread)
        } else {
            (0.0, 0.0)
        }
    } else {
        (0.0, 0.0)
    }
}

/// Computes T_ij = A_i F_{i→j} V_ij for the given faces, without the cache
/// (`i` is the receiver: the spread is measured over it).
pub(crate) fn compute_throughput(
    geom: &SceneGeometry,
    i: SidedElement,
    j: SidedElement,
    visibility_samples: u32,
    ff_options: &FormFactorOptions,
) -> Throughput {
    let (f, spread) = sided_form_factor(geom, i, j, ff_options);
    if !(f.is_finite() && f > 0.0) {
        return Throughput::default();
    }
    // Coarse pairs decide a lot of transport from one number: give them
    // more shadow rays (×16 for whole input surfaces, ×4 one or two levels
    // down).
    let depth = geom.element(i.element).depth + geom.element(j.element).depth;
    let samples = match depth {
        0 | 1 => visibility_samples * 16,
        2 | 3 => visibility_samples * 4,
        _ => visibility_samples,
    };
    let v = geom.visibility(i.element, j.element, samples);
    let area = geom.element(i.element).area;
    let t = area * f * v;
    if t.is_finite() && t > 0.0 {
        Throughput { t, v, f, spread }
    } else {
        Throughput {
            t: 0.0,
            v,
            f,
            spread,
        }
    }
}
