//! Ray queries: closest hit and occlusion over the whole scene.
//!
//! # Structure
//!
//! One wide BVH ([`wide`]) over all primitives: mesh triangles, the two
//! triangles of every planar quad, and one primitive per disk, sphere and
//! cylinder. The binary tree is obvhs's PLOC with a bound on its work
//! ([`ploc`]), then obvhs's reinsertion, over the primitives' boxes padded
//! by 4·10⁻⁶ × the scene's extent; this module collapses it into nodes of
//! eight children with f32 boxes, and leaves of up to four primitives
//! stored as one [`Tri4`].
//!
//! A query ray is f64 (origin, non-unit direction, t in units of that
//! direction). It is traversed as an f32 ray ([`traverse`]: nearest child
//! first for closest hits, first hit ends an occlusion query), clipped in
//! f64 to the scene's box when it starts far outside; each leaf is tested
//! four triangles at once in f32 ([`tri4`]), and only the lanes that test
//! cannot decide are tested in f64 ([`triangle`], [`analytic`]), which
//! gives every closest hit, its t and barycentric coordinates. The f32
//! stages only ever decide what the f64 tests would decide the same way,
//! with stated error bounds (in [`traverse`] and [`tri4`]), so the answers
//! are the f64 tests' own: those of brute force over every primitive.
//!
//! # Robustness
//!
//! - **Shared edges.** Triangles (mesh triangles and the halves of quads, so
//!   also the six faces of a cube, whose corners are shared bit-for-bit)
//!   use the watertight test of Woop, Benthin and Wald (JCGT 2013) in f64:
//!   a ray through an edge or vertex hits at least one of the triangles
//!   that share it.
//! - **Analytic shapes** are intersected exactly, in object space
//!   ([`analytic`]).
//! - **Self-intersection** is the caller's: every query takes the ray
//!   interval (tmin, tmax), and [`crate::Geometry`] sets tmin from its
//!   relative epsilon ([`crate::RAY_EPSILON`]); f64 hits keep that epsilon
//!   valid.
//!
//! This module knows primitives only; [`crate::Geometry`] turns a
//! [`PrimHit`] into a hit on an input surface.

mod analytic;
mod ploc;
mod traverse;
mod tri4;
mod triangle;
mod wide;

/// Counters of traversal work on this thread (nodes, leaves, f64 hits, f64
/// misses), for tuning: `--features trace-stats`.
#[cfg(feature = "trace-stats")]
pub mod stats {
    thread_local! {
        static STATS: std::cell::Cell<[u64; 4]> = const { std::cell::Cell::new([0; 4]) };
    }

    /// The counts since the last call, on this thread.
    pub fn take() -> [u64; 4] {
        STATS.with(|c| c.replace([0; 4]))
    }

    pub(crate) fn bump(i: usize) {
        STATS.with(|c| {
            let mut v = c.get();
            v[i] += 1;
            c.set(v);
        })
    }
}

/// Counts traversal work with `--features trace-stats`, else nothing.
macro_rules! bump {
    ($i:expr) => {
        #[cfg(feature = "trace-stats")]
        $crate::bvh::stats::bump($i);
    };
}
use bump;

pub(crate) use analytic::{Analytic, AnalyticKind};

use glam::{DVec2, DVec3};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use rayon::prelude::*;

use crate::bounds::Bounds;
use traverse::BoxRay;
use tri4::{Ray4, Span4, Tri4};
use triangle::{RayPre, intersect_triangle};
use wide::{LEAF_SIZE, WideBvh, leaf_parts};

/// What a triangle primitive belongs to.
#[derive(Clone, Copy, Debug)]
pub(crate) enum TriOwner {
    Mesh {
        mesh: u32,
        tri: u32,
    },
    /// Half of a planar quad (p00, p10, p11, p01): the triangle
    /// (p00, p10, p11) or, if `second`, (p00, p11, p01); `affine` if the
    /// quad is a parallelogram.
    Quad {
        second: bool,
        affine: bool,
    },
}

/// A primitive of the BVH, with the scene shape it belongs to (so that a
/// query can ignore one shape).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    /// A triangle of a mesh or half of a planar quad, with what a hit on it
    /// needs (kept here so that a hit reads nothing else for them).
    Tri {
        v: [DVec3; 3],
        /// Front-side unit geometric normal of the input surface.
        normal: DVec3,
        /// The input surface it lies on.
        surface: u32,
        owner: TriOwner,
        shape: u32,
    },
    /// A disk, sphere or cylinder: an index into the analytic shapes.
    Analytic { index: u32, shape: u32 },
}

impl Prim {
    pub(crate) fn shape(&self) -> u32 {
        match *self {
            Prim::Tri { shape, .. } | Prim::Analytic { shape, .. } => shape,
        }
    }
}

/// Which primitive a closest-hit search found, and where.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimHit {
    /// Index of the primitive (BVH order).
    pub prim: usize,
    /// Ray parameter, in units of the query's direction.
    pub t: f64,
    /// Barycentrics (b1, b2) for triangles, zero for analytic shapes.
    pub bary: DVec2,
}

/// Size and build time of a scene's BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct BvhStats {
    /// Inner nodes (eight children each).
    pub nodes: usize,
    /// Leaves (up to four primitives each).
    pub leaves: usize,
    /// Longest root-to-leaf path, in inner nodes.
    pub depth: usize,
    /// Wall-clock seconds of the build (binary tree, collapse, leaves).
    pub build_seconds: f64,
}

/// The BVH and the primitives it holds.
#[derive(Clone, Debug)]
pub(crate) struct Bvh {
    wide: WideBvh,
    /// Primitives in leaf order.
    prims: Vec<Prim>,
    analytic: Vec<Analytic>,
    /// Box padding: 4e-6 × the scene's extent.
    pad: f64,
    /// The scene's box, to which rays are clipped before traversal.
    bounds: Bounds,
    /// The scene's largest absolute coordinate.
    extent: f64,
    /// Coordinates beyond f32's range: every query tests every primitive.
    brute: bool,
    /// Wall-clock seconds the build took.
    seconds: f64,
}

/// A query's ray with its length and largest absolute origin coordinate
/// (which the caller needs too, for the ray epsilon).
#[derive(Clone, Copy, Debug)]
pub(crate) struct QueryRay {
    pub o: DVec3,
    pub d: DVec3,
    pub len: f64,
    pub omax: f64,
}

impl QueryRay {
    /// `None` unless `o` is finite and `d` finite and non-zero.
    #[inline(always)]
    pub(crate) fn new(o: DVec3, d: DVec3) -> Option<QueryRay> {
        let len = d.length();
        let omax = o.abs().max_element();
        (len > 0.0 && len.is_finite() && omax.is_finite()).then_some(QueryRay { o, d, len, omax })
    }
}

/// A ray clipped to the scene's box, ready for traversal.
struct Traversal {
    ray: BoxRay,
    /// f64 ray parameter where the f32 ray starts.
    start: f64,
    /// |d|: f32 distances are (t − start) · len.
    len: f64,
    /// f32 distance where the clipped ray ends.
    tmax: f32,
}

impl Traversal {
    /// The f32 distance of f64 parameter t, rounded up.
    #[inline(always)]
    fn distance(&self, t: f64) -> f32 {
        (((t - self.start) * self.len) as f32).next_up()
    }
}

impl Bvh {
    /// Builds the BVH over `prims` (module docs), with boxes padded by
    /// 4e-6 × `extent`.
    pub(crate) fn build(
        prims: Vec<Prim>,
        analytic: Vec<Analytic>,
        bounds: Bounds,
        extent: f64,
    ) -> Bvh {
        let started = std::time::Instant::now();
        let pad = 4e-6 * extent;
        let boxes: Vec<Aabb> = prims
            .par_iter()
            .map(|p| {
                let b = match p {
                    Prim::Tri { v, .. } => Bounds::from_points(*v),
                    Prim::Analytic { index, .. } => analytic[*index as usize].bounds(),
                }
                .padded(pad);
                f32_box(&b)
            })
            .collect();
        let (mut bvh2, visits) = ploc::build(&boxes);
        // Reinsertion searches the tree from the top for each node it
        // moves; on the boxes that exhausted PLOC's budget (coincident
        // triangles, fans of slivers: boxes that all overlap) that search
        // prunes nothing, so it is left out there.
        if visits <= ploc::WORK_PER_PRIMITIVE * boxes.len() {
            ReinsertionOptimizer::default().run(&mut bvh2, 0.02, None);
        }
        // PLOC leaves hold one primitive each; anything else, and scenes
        // whose scale f32's range does not suit ([`tri4`]), fall back to
        // testing everything.
        let brute = !(1e-6..=1e15).contains(&extent)
            || bvh2
                .nodes
                .iter()
                .any(|n| n.is_leaf() && n.prim_count as usize > LEAF_SIZE);
        let mut wide = if brute || prims.is_empty() {
            WideBvh {
                root: wide::EMPTY,
                ..Default::default()
            }
        } else {
            WideBvh::collapse(&bvh2, |ids| {
                let mut lanes = [None; 4];
                for (lane, &id) in ids.iter().enumerate() {
                    if let Prim::Tri { v, .. } = prims[id as usize] {
                        lanes[lane] = Some(v);
                    }
                }
                Tri4::new(lanes)
            })
        };
        let prims = leaf_order(&mut wide, prims);
        Bvh {
            wide,
            prims,
            analytic,
            pad,
            bounds,
            extent,
            brute,
            seconds: started.elapsed().as_secs_f64(),
        }
    }

    /// Size and build time of the tree.
    pub(crate) fn stats(&self) -> BvhStats {
        BvhStats {
            nodes: self.wide.nodes.len(),
            leaves: self.wide.leaves.len(),
            depth: self.wide.depth,
            build_seconds: self.seconds,
        }
    }

    /// Number of primitives (triangles and analytic shapes).
    pub(crate) fn len(&self) -> usize {
        self.prims.len()
    }

    /// A primitive, by its index in BVH order.
    pub(crate) fn prim(&self, id: usize) -> &Prim {
        &self.prims[id]
    }

    /// The triangle primitives' vertices.
    pub(crate) fn triangles(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.prims.iter().filter_map(|p| match p {
            Prim::Tri { v, .. } => Some(*v),
            Prim::Analytic { .. } => None,
        })
    }

    /// An analytic shape.
    pub(crate) fn analytic(&self, index: u32) -> &Analytic {
        &self.analytic[index as usize]
    }

    #[inline]
    fn test_prim(&self, prim: &Prim, pre: &RayPre, tmin: f64, tmax: f64) -> Option<(f64, DVec2)> {
        let r = match prim {
            Prim::Tri { v, .. } => intersect_triangle(pre, v, tmin, tmax),
            Prim::Analytic { index, .. } => self.analytic[*index as usize]
                .intersect(pre.o, pre.d, tmin, tmax)
                .map(|t| (t, DVec2::ZERO)),
        };
        bump!(if r.is_some() { 2 } else { 3 });
        r
    }

    /// The f32 traversal of a ray; `None` if it misses the padded scene box
    /// or is not finite. A ray from within twice the scene's extent starts
    /// at its own origin (the error bound in [`traverse`] allows for that);
    /// one from farther away starts where it enters the box, in f64.
    fn traversal(&self, q: &QueryRay, tmin: f64, tmax: f64) -> Option<Traversal> {
        let (o, d, len) = (q.o, q.d, q.len);
        let (start, end) = if q.omax <= 2.0 * self.extent {
            (0.0, tmax)
        } else {
            self.clip(o, d, tmin, tmax)?
        };
        let t = Traversal {
            ray: BoxRay::new(o + start * d, d / len),
            start,
            len,
            tmax: 0.0,
        };
        Some(Traversal {
            tmax: t.distance(end),
            ..t
        })
    }

    /// The part of (tmin, tmax) within the padded scene box.
    fn clip(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
        let b = self.bounds.padded(2.0 * self.pad + 1e-300);
        let inv = 1.0 / d;
        let t1 = (b.min - o) * inv;
        let t2 = (b.max - o) * inv;
        let near = t1.min(t2);
        let far = t1.max(t2);
        // NaN (0 × ∞ for a zero direction component on a slab edge) counts
        // as unbounded.
        let tn = [near.x, near.y, near.z]
            .into_iter()
            .filter(|x| !x.is_nan())
            .fold(tmin.max(0.0), f64::max);
        let tf = [far.x, far.y, far.z]
            .into_iter()
            .filter(|x| !x.is_nan())
            .fold(tmax, f64::min);
        (tn <= tf).then_some((tn, tf))
    }

    /// The closest primitive hit in (tmin, tmax), ignoring the primitives of
    /// shape `skip`.
    pub(crate) fn closest(
        &self,
        q: &QueryRay,
        tmin: f64,
        tmax: f64,
        skip: Option<u32>,
    ) -> Option<PrimHit> {
        if self.brute {
            return self.brute_force(q.o, q.d, tmin, tmax, skip, false);
        }
        let tr = self.traversal(q, tmin, tmax)?;
        let pre = RayPre::new(q.o, q.d);
        let r4 = Ray4::new(&pre, q.omax + self.extent);
        let mut span = Span4::new(tmin, tmax);
        let mut best: Option<PrimHit> = None;
        let mut best_t = tmax;
        self.wide
            .traverse::<true>(&tr.ray, tr.tmax, |leaf, tmax32| {
                let (g, count) = leaf_parts(leaf);
                let leaf = &self.wide.leaves[g];
                let mut m = leaf.tri.classify::<false>(&r4, &span).test & ((1 << count) - 1);
                while m != 0 {
                    let id = leaf.ids[m.trailing_zeros() as usize];
                    m &= m - 1;
                    let prim = &self.prims[id as usize];
                    if skip == Some(prim.shape()) {
                        continue;
                    }
                    if let Some((t, bary)) = self.test_prim(prim, &pre, tmin, best_t) {
                        best_t = t;
                        best = Some(PrimHit {
                            prim: id as usize,
                            t,
                            bary,
                        });
                        *tmax32 = tr.distance(t);
                        span = span.with_max(t);
                    }
                }
                false
            });
        best
    }

    /// True if any primitive is hit in (tmin, tmax). Tries the primitive in
    /// `hint` (the last occluder found, for coherent segments) first, and
    /// stores the occluder it finds there.
    pub(crate) fn any(&self, q: &QueryRay, tmin: f64, tmax: f64, hint: &mut Option<u32>) -> bool {
        let pre = RayPre::new(q.o, q.d);
        if let Some(h) = *hint
            && let Some(prim) = self.prims.get(h as usize)
            && self.test_prim(prim, &pre, tmin, tmax).is_some()
        {
            return true;
        }
        if self.brute {
            let hit = self.brute_force(q.o, q.d, tmin, tmax, None, true);
            if let Some(h) = hit {
                *hint = Some(h.prim as u32);
            }
            return hit.is_some();
        }
        let Some(tr) = self.traversal(q, tmin, tmax) else {
            return false;
        };
        let r4 = Ray4::new(&pre, q.omax + self.extent);
        let span = Span4::new(tmin, tmax);
        let mut found = None;
        self.wide.traverse::<false>(&tr.ray, tr.tmax, |leaf, _| {
            let (g, count) = leaf_parts(leaf);
            let leaf = &self.wide.leaves[g];
            let lanes = leaf.tri.classify::<true>(&r4, &span);
            let valid = (1 << count) - 1;
            if lanes.hits & valid != 0 {
                found = Some(leaf.ids[(lanes.hits & valid).trailing_zeros() as usize]);
                return true;
            }
            let mut m = lanes.test & valid;
            while m != 0 {
                let id = leaf.ids[m.trailing_zeros() as usize];
                m &= m - 1;
                if self
                    .test_prim(&self.prims[id as usize], &pre, tmin, tmax)
                    .is_some()
                {
                    found = Some(id);
                    return true;
                }
            }
            false
        });
        if found.is_some() {
            *hint = found;
        }
        found.is_some()
    }

    /// The closest hit over every primitive, without the tree (the
    /// reference for tests).
    pub(crate) fn closest_brute_force(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
    ) -> Option<PrimHit> {
        self.brute_force(o, d, tmin, tmax, None, false)
    }

    /// The closest hit (or, if `any`, the first found) over every
    /// primitive not of shape `skip`.
    fn brute_force(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        skip: Option<u32>,
        any: bool,
    ) -> Option<PrimHit> {
        let pre = RayPre::new(o, d);
        let mut best: Option<PrimHit> = None;
        let mut best_t = tmax;
        for (i, p) in self.prims.iter().enumerate() {
            if skip == Some(p.shape()) {
                continue;
            }
            if let Some((t, bary)) = self.test_prim(p, &pre, tmin, best_t) {
                best_t = t;
                best = Some(PrimHit { prim: i, t, bary });
                if any {
                    break;
                }
            }
        }
        best
    }
}

/// The primitives reordered as the leaves hold them (so that a leaf's
/// primitives lie together in memory), with the leaves' indices renamed.
fn leaf_order(wide: &mut WideBvh, prims: Vec<Prim>) -> Vec<Prim> {
    let mut new_index = vec![u32::MAX; prims.len()];
    let mut out = Vec::with_capacity(prims.len());
    for leaf in &mut wide.leaves {
        for id in leaf.ids.iter_mut() {
            let slot = &mut new_index[*id as usize];
            if *slot == u32::MAX {
                *slot = out.len() as u32;
                out.push(prims[*id as usize]);
            }
            *id = *slot;
        }
    }
    // Primitives no leaf holds (none, unless the tree is empty or the
    // fallback tests everything) keep their place after the others.
    for (i, p) in prims.iter().enumerate() {
        if new_index[i] == u32::MAX {
            out.push(*p);
        }
    }
    out
}

/// The largest f32 not above `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// The smallest f32 not below `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// A binary tree over boxes for overlap queries (the contact search of
/// [`crate::contact`]): obvhs's PLOC tree as [`ploc`] builds it, without
/// the wide collapse that ray queries need.
pub(crate) struct BoxTree {
    tree: obvhs::bvh2::Bvh2,
}

impl BoxTree {
    /// The tree over `boxes` (the boxes rounded outwards to f32).
    pub(crate) fn new(boxes: &[Bounds]) -> BoxTree {
        let boxes: Vec<Aabb> = boxes.iter().map(f32_box).collect();
        BoxTree {
            tree: ploc::build(&boxes).0,
        }
    }

    /// Calls `visit` with the index of every box that overlaps `query`.
    pub(crate) fn overlapping(&self, query: &Bounds, mut visit: impl FnMut(usize)) {
        let tree = &self.tree;
        tree.aabb_traverse(f32_box(query), |t, node| {
            let node = &t.nodes[node as usize];
            let first = node.first_index as usize;
            for &p in &t.primitive_indices[first..first + node.prim_count as usize] {
                visit(p as usize);
            }
            true
        });
    }
}

/// A box rounded outwards to f32.
fn f32_box(b: &Bounds) -> Aabb {
    Aabb::new(
        b.min.to_array().map(round_down).into(),
        b.max.to_array().map(round_up).into(),
    )
}
