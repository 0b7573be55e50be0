//! The binary tree over the primitives' boxes: PLOC (Meister and Bittner,
//! "Parallel Locally-Ordered Clustering for Bounding Volume Hierarchy
//! Construction", 2018) exactly as obvhs 0.4 builds it serially (boxes in
//! the 64-bit Morton order of their centres; each node paired with the
//! neighbour within 6 places whose union has the least surface area, 1
//! place in the first two passes; nodes that choose each other merge),
//! with a bound on its work.
//!
//! A pass over c nodes costs c, and on ordinary scenes the passes shrink
//! geometrically: the passes of the repository's scenes visit 2 to 3
//! nodes a primitive in all. But when the neighbours' unions only grow
//! along the order, every node chooses the same side and only the ends of
//! a run agree: coincident triangles (all ties) and a fan of slivers
//! sharing one vertex (a polygon of a million vertices) merged a handful
//! of nodes a pass, and their n passes of about n nodes took minutes. So
//! once the passes have visited [`WORK_PER_PRIMITIVE`] nodes a primitive,
//! every later pass merges the nodes two by two in order, halving them:
//! the build visits at most (`WORK_PER_PRIMITIVE` + 2) · n nodes whatever
//! the boxes. Below that budget the tree is obvhs's own, node for node
//! (tested against it).

use glam::DVec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::{Bvh2, DEFAULT_MAX_STACK_DEPTH};
use obvhs::ploc::morton::morton_encode_u64_unorm;
use rdst::{RadixKey, RadixSort};

/// Nodes the passes may visit, per primitive, before every pass merges
/// neighbours two by two (module docs).
pub(crate) const WORK_PER_PRIMITIVE: usize = 16;

/// How far along the order a node looks for its partner (obvhs's
/// `PlocSearchDistance::Low`).
const SEARCH: usize = 6;

/// Passes that look only at the next node (obvhs's
/// `search_depth_threshold`).
const NARROW_PASSES: usize = 2;

/// The tree over `boxes` (leaf i holds primitive i), and the nodes its
/// passes visited.
pub(crate) fn build(boxes: &[Aabb]) -> (Bvh2, usize) {
    let n = boxes.len();
    let mut bvh = Bvh2::zeroed(n);
    bvh.reset_for_reuse(n, Some((0..n as u32).collect()));
    if n == 0 {
        return (bvh, 0);
    }
    let mut total = Aabb::empty();
    let leaves: Vec<Bvh2Node> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| {
            total.extend(b.min);
            total.extend(b.max);
            Bvh2Node::new(*b, 1, i as u32)
        })
        .collect();
    let mut current = morton_order(&leaves, &total);
    let mut next = vec![Bvh2Node::default(); n];
    let mut merge = vec![0i8; n];
    let mut cache = [[0f32; SEARCH]; SEARCH];
    let mut insert = 2 * n - 1;
    bvh.nodes.resize(insert, Bvh2Node::default());
    let (mut passes, mut count, mut visits) = (0, n, 0);
    while count > 1 {
        visits += count;
        let nodes = &current[..count];
        let merge = &mut merge[..count];
        if visits > WORK_PER_PRIMITIVE * n {
            for (i, m) in merge.iter_mut().enumerate() {
                *m = if i % 2 == 0 { 1 } else { -1 };
            }
            merge[count - 1] = -1;
        } else if passes < NARROW_PASSES {
            let mut last = f32::INFINITY;
            for i in 0..count - 1 {
                let cost = nodes[i].aabb().union(nodes[i + 1].aabb()).half_area();
                merge[i] = if last < cost { -1 } else { 1 };
                last = cost;
            }
            merge[count - 1] = -1;
        } else {
            for (i, m) in merge.iter_mut().enumerate() {
                *m = best_partner(&mut cache, i, nodes);
            }
        }
        let mut kept = 0;
        for i in 0..count {
            let j = (i as i64 + i64::from(merge[i])) as usize;
            if j as i64 + i64::from(merge[j]) != i as i64 {
                next[kept] = nodes[i];
                kept += 1;
                continue;
            }
            if j > i {
                continue;
            }
            let (left, right) = (nodes[i], nodes[j]);
            insert -= 2;
            bvh.nodes[insert] = left;
            bvh.nodes[insert + 1] = right;
            next[kept] = Bvh2Node::new(left.aabb().union(right.aabb()), 0, insert as u32);
            kept += 1;
        }
        std::mem::swap(&mut current, &mut next);
        count = kept;
        passes += 1;
    }
    bvh.nodes[0] = current[0];
    bvh.max_depth = DEFAULT_MAX_STACK_DEPTH.max(passes + 1);
    bvh.children_are_ordered_after_parents = true;
    (bvh, visits)
}

/// A leaf's Morton code and index (obvhs's `Morton64`, whose sort this
/// repeats: ties keep the order that sort gives them).
#[derive(Clone, Copy)]
struct Morton {
    code: u64,
    index: u64,
}

impl RadixKey for Morton {
    const LEVELS: usize = 8;

    #[inline(always)]
    fn get_level(&self, level: usize) -> u8 {
        self.code.get_level(level)
    }
}

/// The leaves in the Morton order of their centres in `total`.
fn morton_order(leaves: &[Bvh2Node], total: &Aabb) -> Vec<Bvh2Node> {
    let scale: DVec3 = 1.0 / total.diagonal().as_dvec3();
    let offset = -total.min.as_dvec3() * scale;
    let mut mortons: Vec<Morton> = leaves
        .iter()
        .enumerate()
        .map(|(index, leaf)| Morton {
            code: morton_encode_u64_unorm(leaf.aabb().center().as_dvec3() * scale + offset),
            index: index as u64,
        })
        .collect();
    if mortons.len() <= 250_000 {
        mortons.sort_unstable_by_key(|m| m.code);
    } else {
        mortons.radix_sort_unstable();
    }
    mortons.iter().map(|m| leaves[m.index as usize]).collect()
}

/// The offset of node `index`'s partner within [`SEARCH`] places: the
/// least union area, the farthest right among equals. `cache[i % S][j % S]`
/// holds the cost of (i, j) computed when i < j was visited (obvhs's
/// `SearchCache`).
fn best_partner(cache: &mut [[f32; SEARCH]; SEARCH], index: usize, nodes: &[Bvh2Node]) -> i8 {
    let mut best = (index, f32::INFINITY);
    let begin = index - SEARCH.min(index);
    let end = (index + SEARCH + 1).min(nodes.len());
    for other in begin..index {
        let area = cache[other % SEARCH][index % SEARCH];
        if area <= best.1 {
            best = (other, area);
        }
    }
    let ours = nodes[index].aabb();
    for other in index + 1..end {
        let cost = ours.union(nodes[other].aabb()).half_area();
        cache[index % SEARCH][other % SEARCH] = cost;
        if cost <= best.1 {
            best = (other, cost);
        }
    }
    (best.0 as i64 - index as i64) as i8
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;
    use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};

    fn tri_box(v: [[f32; 3]; 3]) -> Aabb {
        let mut b = Aabb::empty();
        for p in v {
            b.extend(Vec3A::from(p));
        }
        // Padded as the BVH pads them (a flat box has no area).
        let pad = Vec3A::splat(1e-4);
        Aabb::new(b.min - pad, b.max + pad)
    }

    /// A sheet of `2 · side²` triangles, wavy with amplitude `wave` (flat
    /// at 0: every box alike).
    fn sheet(side: usize, wave: f32) -> Vec<Aabb> {
        let h = |i: usize, j: usize| ((i as f32 * 0.37).sin() + (j as f32 * 0.23).cos()) * wave;
        let p = |i: usize, j: usize| [i as f32, j as f32, h(i, j)];
        let mut out = Vec::new();
        for j in 0..side {
            for i in 0..side {
                out.push(tri_box([p(i, j), p(i + 1, j), p(i + 1, j + 1)]));
                out.push(tri_box([p(i, j), p(i + 1, j + 1), p(i, j + 1)]));
            }
        }
        out
    }

    /// The fan of a polygon of `n` vertices on the unit circle from its
    /// first vertex (how OBJ polygons are triangulated).
    fn fan(n: usize) -> Vec<Aabb> {
        let v = |i: usize| {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            [a.cos(), a.sin(), 0.0]
        };
        (1..n - 1)
            .map(|i| tri_box([v(0), v(i), v(i + 1)]))
            .collect()
    }

    fn obvhs_tree(boxes: &[Aabb]) -> Bvh2 {
        PlocBuilder::with_capacity(boxes.len()).build(
            PlocSearchDistance::Low,
            boxes,
            (0..boxes.len() as u32).collect(),
            SortPrecision::U64,
            NARROW_PASSES,
        )
    }

    fn same_tree(a: &Bvh2, b: &Bvh2) -> bool {
        a.nodes.len() == b.nodes.len()
            && a.max_depth == b.max_depth
            && a.primitive_indices == b.primitive_indices
            && a.nodes.iter().zip(&b.nodes).all(|(x, y)| {
                x.aabb().min == y.aabb().min
                    && x.aabb().max == y.aabb().max
                    && x.prim_count == y.prim_count
                    && x.first_index == y.first_index
            })
    }

    /// Every primitive in exactly one leaf, every leaf one primitive.
    fn assert_valid(t: &Bvh2, n: usize) {
        let mut seen = vec![false; n];
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = &t.nodes[i];
            if node.prim_count > 0 {
                assert_eq!(node.prim_count, 1);
                let p = t.primitive_indices[node.first_index as usize] as usize;
                assert!(!seen[p], "primitive {p} twice");
                seen[p] = true;
            } else {
                stack.push(node.first_index as usize);
                stack.push(node.first_index as usize + 1);
            }
        }
        assert!(seen.iter().all(|&s| s), "every primitive in a leaf");
    }

    /// Ordinary boxes stay within the budget, and the tree is obvhs's,
    /// both below and above the size where the sort turns radix.
    #[test]
    fn ordinary_trees_are_obvhs_trees() {
        for (side, wave) in [(40, 0.3), (360, 0.3), (40, 0.0), (320, 0.0)] {
            let boxes = sheet(side, wave);
            let (ours, visits) = build(&boxes);
            let n = boxes.len();
            eprintln!(
                "{n} primitives: {:.2} visits each",
                visits as f64 / n as f64
            );
            assert!(visits <= 4 * n, "{visits} visits for {n}");
            assert!(same_tree(&ours, &obvhs_tree(&boxes)), "{n} primitives");
            assert_valid(&ours, n);
        }
    }

    /// A fan of slivers and coincident copies of one triangle cost work
    /// proportional to their number (4 times as many, about 4 times the
    /// visits; obvhs's passes visited about n²/2), and still make valid
    /// trees.
    #[test]
    fn fans_and_coincident_boxes_cost_linear_work() {
        let copies = |n: usize| vec![tri_box([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]); n];
        let fans = |n: usize| fan(n + 2);
        for (what, boxes) in [("fan", fans as fn(usize) -> Vec<Aabb>), ("copies", copies)] {
            let work = |n: usize| {
                let b = boxes(n);
                let (tree, visits) = build(&b);
                assert_valid(&tree, n);
                assert!(visits <= (WORK_PER_PRIMITIVE + 2) * n, "{what}: {visits}");
                visits as f64
            };
            let (small, large) = (work(20_000), work(80_000));
            let ratio = large / small;
            eprintln!("{what}: {small} and {large} visits");
            assert!((3.8..4.2).contains(&ratio), "{what}: ×{ratio} for ×4");
        }
    }
}
