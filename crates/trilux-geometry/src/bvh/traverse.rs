//! Traversal of the wide BVH by one f32 ray: SIMD slab tests of a node's
//! children ([`BoxRay::hit`]), a stack of (child, entry distance), and two
//! loops: ordered (nearest child first, entries beyond the current closest
//! hit skipped when popped) for closest hits, and unordered with early exit
//! for occlusion.
//!
//! # Robustness
//!
//! The f32 ray has a unit direction and starts either at the query's own
//! origin, when that lies within 2 × extent of the world origin in every
//! coordinate, or, in f64, where the ray enters the scene's box: in both
//! cases every point of the scene lies within D ≤ 3√3 · extent of the f32
//! origin. Each slab distance (p − o) / d carries a relative error of at
//! most 3u (u = 2⁻²⁴), and rounding the origin and direction moves the ray
//! by at most 2u · extent + u · D: together below 1.5·10⁻⁶ · extent, while
//! every box is padded by 4·10⁻⁶ · extent ([`super::Bvh`]). A box the f64
//! ray passes through is therefore always entered. Zero direction
//! components are replaced by 10⁻³⁰ (finite reciprocals: no 0 · ∞ = NaN in
//! the slab test; the ray moves by 10⁻³⁰ · D).

use glam::{DVec3, Vec4};

use super::wide::{EMPTY, LANES, LEAF, WIDTH, WideBvh, WideNode};

/// The f32 traversal ray: origin and reciprocal direction, splatted, and
/// which plane of each axis it meets first.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxRay {
    o: [Vec4; 3],
    inv: [Vec4; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl BoxRay {
    /// The ray from `o` along the unit direction `dn`.
    pub(crate) fn new(o: DVec3, dn: DVec3) -> BoxRay {
        let d = dn
            .as_vec3()
            .to_array()
            .map(|c| if c.abs() < 1e-30 { 1e-30 } else { c });
        let neg = d.map(|c| usize::from(c < 0.0));
        BoxRay {
            o: o.as_vec3().to_array().map(Vec4::splat),
            inv: d.map(|c| Vec4::splat(1.0 / c)),
            near: [neg[0], 2 + neg[1], 4 + neg[2]],
            far: [1 - neg[0], 3 - neg[1], 5 - neg[2]],
        }
    }

    /// The children of `n` that the ray meets within [0, `tmax`]: a bit
    /// mask, and their entry distances.
    #[inline(always)]
    pub(crate) fn hit(&self, n: &WideNode, tmax: f32) -> (u32, [f32; WIDTH]) {
        let mut mask = 0;
        let mut entry = [0.0; WIDTH];
        let tmax = Vec4::splat(tmax);
        for j in 0..LANES {
            let slab =
                |axis: usize, plane: usize| (n.planes[plane][j] - self.o[axis]) * self.inv[axis];
            let tn = slab(0, self.near[0])
                .max(slab(1, self.near[1]))
                .max(slab(2, self.near[2]))
                .max(Vec4::ZERO);
            let tf = slab(0, self.far[0])
                .min(slab(1, self.far[1]))
                .min(slab(2, self.far[2]))
                .min(tmax);
            mask |= tn.cmple(tf).bitmask() << (4 * j);
            entry[4 * j..4 * j + 4].copy_from_slice(&tn.to_array());
        }
        (mask, entry)
    }
}

/// A traversal stack of (entry distance bits << 32 | child): a fixed array,
/// spilling to the heap only for trees deeper than it allows.
struct Stack {
    fixed: [u64; 48],
    len: usize,
    spill: Vec<u64>,
}

impl Stack {
    #[inline(always)]
    fn new() -> Stack {
        Stack {
            fixed: [0; 48],
            len: 0,
            spill: Vec::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, e: u64) {
        if self.len < self.fixed.len() {
            self.fixed[self.len] = e;
            self.len += 1;
        } else {
            self.spill.push(e);
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<u64> {
        if let Some(e) = self.spill.pop() {
            return Some(e);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.fixed[self.len])
    }
}

#[inline(always)]
fn entry_key(t: f32, child: u32) -> u64 {
    (u64::from(t.to_bits()) << 32) | u64::from(child)
}

impl WideBvh {
    /// Visits the leaves the ray may hit within [0, `tmax`], nearest child
    /// first when `ORDERED`. `leaf(reference, tmax)` tests one leaf, may
    /// lower `tmax`, and returns true to stop.
    #[inline(always)]
    pub(crate) fn traverse<const ORDERED: bool>(
        &self,
        ray: &BoxRay,
        mut tmax: f32,
        mut leaf: impl FnMut(u32, &mut f32) -> bool,
    ) {
        if self.root == EMPTY {
            return;
        }
        let mut stack = Stack::new();
        let mut cur = self.root;
        loop {
            if cur & LEAF != 0 {
                super::bump!(1);
                if leaf(cur, &mut tmax) {
                    return;
                }
            } else {
                let node = &self.nodes[cur as usize];
                super::bump!(0);
                let (mask, entry) = ray.hit(node, tmax);
                if mask != 0 {
                    cur = if ORDERED {
                        push_ordered(&mut stack, node, mask, &entry)
                    } else {
                        push_unordered(&mut stack, node, mask, &entry)
                    };
                    continue;
                }
            }
            // Next: the top of the stack that still starts before tmax.
            loop {
                let Some(e) = stack.pop() else { return };
                if f32::from_bits((e >> 32) as u32) <= tmax {
                    cur = e as u32;
                    break;
                }
            }
        }
    }
}

/// Pushes the hit children but the nearest, farthest first; returns the
/// nearest.
#[inline(always)]
fn push_ordered(stack: &mut Stack, node: &WideNode, mask: u32, entry: &[f32; WIDTH]) -> u32 {
    if mask & (mask - 1) == 0 {
        return node.child[mask.trailing_zeros() as usize];
    }
    let mut keys = [0u64; WIDTH];
    let mut k = 0;
    let mut m = mask;
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        // Insertion sort, descending.
        let key = entry_key(entry[i], node.child[i]);
        let mut j = k;
        while j > 0 && keys[j - 1] < key {
            keys[j] = keys[j - 1];
            j -= 1;
        }
        keys[j] = key;
        k += 1;
    }
    for &key in &keys[..k - 1] {
        stack.push(key);
    }
    keys[k - 1] as u32
}

/// Pushes the hit children but the first; returns the first.
#[inline(always)]
fn push_unordered(stack: &mut Stack, node: &WideNode, mask: u32, entry: &[f32; WIDTH]) -> u32 {
    let first = mask.trailing_zeros() as usize;
    let mut m = mask & (mask - 1);
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        stack.push(entry_key(entry[i], node.child[i]));
    }
    node.child[first]
}
