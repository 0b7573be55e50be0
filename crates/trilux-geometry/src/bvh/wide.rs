//! The wide BVH: nodes of [`WIDTH`] children whose f32 boxes are stored as
//! structures of arrays, so that one node is tested against a ray with a
//! few SIMD instructions (the layout of Embree's BVH4/BVH8, Wald et al.,
//! "Embree: a kernel framework for efficient CPU ray tracing", 2014), and
//! leaves of up to four primitives held as one [`Tri4`].
//!
//! The tree is obvhs's PLOC binary BVH (Meister and Bittner, "Parallel
//! Locally-Ordered Clustering for BVH Construction", 2018), improved by
//! reinsertion, then collapsed top-down: a node's children are the binary
//! subtrees left after repeatedly opening its largest child (by surface
//! area) until there are [`WIDTH`] of them or only leaves remain (as in
//! Ylitie et al.'s CWBVH collapse, without the quantisation: safe Rust has
//! no byte-to-float SIMD conversion, and f32 planes need none). A binary
//! subtree of at most four primitives becomes one leaf.

use glam::Vec4;
use obvhs::bvh2::Bvh2;

use super::tri4::Tri4;

/// Children per node, in lanes of four.
pub(crate) const LANES: usize = 2;
/// Children per node.
pub(crate) const WIDTH: usize = 4 * LANES;
/// Most primitives in a leaf (one [`Tri4`]).
pub(crate) const LEAF_SIZE: usize = 4;

/// A child reference with this bit set is a leaf: bits 29–30 hold its
/// primitive count minus one, bits 0–28 its group index.
pub(crate) const LEAF: u32 = 1 << 31;
const GROUP_MASK: u32 = (1 << 29) - 1;
/// An empty child slot (its box is empty, so it is never entered).
pub(crate) const EMPTY: u32 = u32::MAX;

/// The group and primitive count of a leaf reference.
#[inline(always)]
pub(crate) fn leaf_parts(r: u32) -> (usize, u32) {
    ((r & GROUP_MASK) as usize, ((r >> 29) & 3) + 1)
}

/// A node: `planes[2 * axis]` are the children's lower bounds on `axis`,
/// `planes[2 * axis + 1]` the upper ones, four children a lane group.
/// Empty slots have lower bound +∞ and upper bound −∞.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WideNode {
    pub planes: [[Vec4; LANES]; 6],
    pub child: [u32; WIDTH],
}

impl WideNode {
    fn empty() -> WideNode {
        let lo = [Vec4::INFINITY; LANES];
        let hi = [Vec4::NEG_INFINITY; LANES];
        WideNode {
            planes: [lo, hi, lo, hi, lo, hi],
            child: [EMPTY; WIDTH],
        }
    }

    fn set_child(&mut self, slot: usize, r: u32, min: [f32; 3], max: [f32; 3]) {
        let (lane, i) = (slot / 4, slot % 4);
        for axis in 0..3 {
            self.planes[2 * axis][lane][i] = min[axis];
            self.planes[2 * axis + 1][lane][i] = max[axis];
        }
        self.child[slot] = r;
    }
}

/// A leaf: up to four primitives' f32 triangles and their indices (into
/// the caller's list; lanes past the leaf's count repeat lane 0), side by
/// side in memory.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Leaf {
    pub tri: Tri4,
    pub ids: [u32; 4],
}

/// The collapsed tree: nodes and leaves.
#[derive(Clone, Debug, Default)]
pub(crate) struct WideBvh {
    pub nodes: Vec<WideNode>,
    /// The root: a node index, a leaf reference, or [`EMPTY`].
    pub root: u32,
    /// Leaves, in tree order.
    pub leaves: Vec<Leaf>,
    /// Longest root-to-leaf path, in nodes.
    pub depth: usize,
}

impl WideBvh {
    /// Collapses `bvh2` (whose leaves index `bvh2.primitive_indices`);
    /// `group` makes the [`Tri4`] of up to four primitive indices.
    pub(crate) fn collapse(bvh2: &Bvh2, mut group: impl FnMut(&[u32]) -> Tri4) -> WideBvh {
        let mut out = WideBvh {
            root: EMPTY,
            ..Default::default()
        };
        if bvh2.nodes.is_empty() {
            return out;
        }
        let counts = subtree_counts(bvh2);
        let mut leaf = |out: &mut WideBvh, b: usize| {
            let (prims, n) = subtree_prims(bvh2, b);
            let mut ids = [prims[0]; 4];
            ids[..n].copy_from_slice(&prims[..n]);
            out.leaves.push(Leaf {
                tri: group(&prims[..n]),
                ids,
            });
            LEAF | ((n as u32 - 1) << 29) | (out.leaves.len() as u32 - 1)
        };
        if counts[0] as usize <= LEAF_SIZE {
            out.root = leaf(&mut out, 0);
            out.depth = 0;
            return out;
        }
        out.root = 0;
        out.nodes.push(WideNode::empty());
        // (wide node to fill, binary node it stands for, its depth)
        let mut work = vec![(0usize, 0usize, 1usize)];
        while let Some((w, b, depth)) = work.pop() {
            out.depth = out.depth.max(depth);
            let (kids, n) = open(bvh2, b, &counts);
            let mut node = WideNode::empty();
            for (slot, &k) in kids[..n].iter().enumerate() {
                let r = if counts[k] as usize <= LEAF_SIZE {
                    leaf(&mut out, k)
                } else {
                    out.nodes.push(WideNode::empty());
                    let index = out.nodes.len() - 1;
                    work.push((index, k, depth + 1));
                    index as u32
                };
                let a = bvh2.nodes[k].aabb();
                node.set_child(slot, r, a.min.to_array(), a.max.to_array());
            }
            out.nodes[w] = node;
        }
        out
    }
}

/// Up to [`WIDTH`] binary subtrees under inner node `b`: its children, with
/// the largest one that is not to become a leaf opened until the node is
/// full.
fn open(bvh2: &Bvh2, b: usize, counts: &[u32]) -> ([usize; WIDTH], usize) {
    let first = bvh2.nodes[b].first_index as usize;
    let mut kids = [0; WIDTH];
    kids[0] = first;
    kids[1] = first + 1;
    let mut n = 2;
    while n < WIDTH {
        let mut best = None;
        let mut best_area = f32::NEG_INFINITY;
        for (i, &k) in kids[..n].iter().enumerate() {
            let node = &bvh2.nodes[k];
            let area = node.aabb().half_area();
            if !node.is_leaf() && counts[k] as usize > LEAF_SIZE && area > best_area {
                best = Some(i);
                best_area = area;
            }
        }
        let Some(i) = best else { break };
        let f = bvh2.nodes[kids[i]].first_index as usize;
        kids[i] = f;
        kids[n] = f + 1;
        n += 1;
    }
    (kids, n)
}

/// The number of primitives under every binary node (post-order, with an
/// explicit stack: degenerate input may make the tree deep).
fn subtree_counts(bvh2: &Bvh2) -> Vec<u32> {
    let n = bvh2.nodes.len();
    let mut counts = vec![0u32; n];
    let mut stack = vec![(0usize, false)];
    while let Some((b, done)) = stack.pop() {
        let node = &bvh2.nodes[b];
        if node.is_leaf() {
            counts[b] = node.prim_count;
        } else if done {
            let f = node.first_index as usize;
            counts[b] = counts[f] + counts[f + 1];
        } else {
            let f = node.first_index as usize;
            stack.push((b, true));
            stack.push((f, false));
            stack.push((f + 1, false));
        }
    }
    counts
}

/// The primitive indices under binary node `b`, which holds at most
/// [`LEAF_SIZE`] (so at most 2 × LEAF_SIZE − 1 nodes: a fixed stack).
fn subtree_prims(bvh2: &Bvh2, b: usize) -> ([u32; LEAF_SIZE], usize) {
    let mut out = [0; LEAF_SIZE];
    let mut n = 0;
    let mut stack = [0usize; 2 * LEAF_SIZE];
    stack[0] = b;
    let mut sp = 1;
    while sp > 0 {
        sp -= 1;
        let node = &bvh2.nodes[stack[sp]];
        if node.is_leaf() {
            let f = node.first_index as usize;
            for &p in &bvh2.primitive_indices[f..f + node.prim_count as usize] {
                if n < LEAF_SIZE {
                    out[n] = p;
                    n += 1;
                }
            }
        } else if sp + 2 <= stack.len() {
            let f = node.first_index as usize;
            stack[sp] = f + 1;
            stack[sp + 1] = f;
            sp += 2;
        }
    }
    (out, n)
}
