//! Interactions and their hierarchies (paper §3.2, Fig. 2, 3 and 8).
//!
//! An interaction IJ is the light leaving element I towards element J: its
//! radiance L, unshot radiance δL and gathered radiance L^G. Each root
//! interaction (a pair of input-surface sides that exchange light) owns a
//! hierarchy of nodes in one arena. A node has at most one set of four
//! children, made by splitting its sender element (`From`) or its receiver
//! element (`To`): when refinement later asks for the other side, it
//! descends through the existing children first, so a point pair always has
//! exactly one path down (which keeps push-pull and the renderer's lookup
//! exact; docs/solver.md, "One split side per node").
//!
//! Every node caches its throughput T = A_I F_{I→J} V (paper §4.6). A split
//! node's T is redefined as the sum of its children's, so that pulling with
//! flux weights T_c / Σ T_c conserves flux exactly (paper §5.6 prints area
//! weights, which are only the far-field limit; docs/solver.md).

use serde::{Deserialize, Serialize};
use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, FaceId, SurfaceCoord};

use crate::throughput::Throughput;

/// Marks "no children".
pub(crate) const NO_CHILD: u32 = u32::MAX;

/// Which element of a node its children split.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Split {
    /// A leaf.
    None,
    /// Children I_m J: the sender element was split.
    From,
    /// Children I J_m: the receiver element was split.
    To,
}

/// One node IJ of an interaction hierarchy.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) struct Node<const N: usize> {
    /// Sender element I.
    pub from: ElementId,
    /// Receiver element J.
    pub to: ElementId,
    /// Index of the first of four consecutive children, or [`NO_CHILD`].
    pub first_child: u32,
    /// Which element the children split.
    pub split: Split,
    /// T = A_I F_{I→J} V (the sum over children once split).
    pub t: f64,
    /// Visible fraction measured for this node's own elements.
    pub v: f64,
    /// The spread of the point form factor F(y → I) over y in J for this
    /// node's own elements (the stage-2 oracle's form-factor error; kept
    /// so that refinement need not look it up again). Not saved: a loaded
    /// solution never refines.
    #[serde(skip)]
    pub spread: f64,
    /// Current radiance estimate L_IJ.
    pub radiance: Spectrum<N>,
    /// Unshot radiance δL_IJ.
    pub unshot: Spectrum<N>,
    /// Radiance gathered during shots, not yet pushed (L^G).
    pub gathered: Spectrum<N>,
}

/// The hierarchy of one root interaction between two sides.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) struct Hierarchy<const N: usize> {
    /// The sending face.
    pub from: FaceId,
    /// The receiving face.
    pub to: FaceId,
    /// Node arena; node 0 is the root.
    pub nodes: Vec<Node<N>>,
    /// Unshot flux of the whole hierarchy (the selection key δΦ, kept current
    /// as energy arrives: paper Eq. 6 in its exact flux form).
    pub unshot_flux: Spectrum<N>,
    /// True while the root's throughput is not made yet: it is made when
    /// light first arrives at the sender face (`RefineContext::nodes_for`),
    /// so that setup traces no shadow rays for root pairs that never carry
    /// light (docs/solver.md, "Lazy root throughputs"). A pending root
    /// has T = 0 and radiance 0. Not saved: a saved root is made or dark.
    #[serde(skip)]
    pub pending: bool,
}

impl<const N: usize> Hierarchy<N> {
    /// A hierarchy with only its root node.
    pub fn new(from: FaceId, to: FaceId, i: ElementId, j: ElementId, t: Throughput) -> Self {
        Hierarchy {
            from,
            to,
            nodes: vec![Node {
                from: i,
                to: j,
                first_child: NO_CHILD,
                split: Split::None,
                t: t.t,
                v: t.v,
                spread: t.spread,
                radiance: Spectrum::zero(),
                unshot: Spectrum::zero(),
                gathered: Spectrum::zero(),
            }],
            unshot_flux: Spectrum::zero(),
            pending: false,
        }
    }

    /// A hierarchy whose root throughput is made later
    /// ([`Hierarchy::make_root`]).
    pub fn pending(from: FaceId, to: FaceId, i: ElementId, j: ElementId) -> Self {
        let mut h = Hierarchy::new(from, to, i, j, Throughput::default());
        h.pending = true;
        h
    }

    /// Gives a pending root its throughput (before any energy reaches it).
    pub fn make_root(&mut self, t: Throughput) {
        debug_assert!(self.pending && self.nodes.len() == 1);
        let root = &mut self.nodes[0];
        (root.t, root.v, root.spread) = (t.t, t.v, t.spread);
        self.pending = false;
    }

    /// True for a side's interaction with itself (a concave surface lighting
    /// itself: paper §5.2's secondary interactions).
    pub fn is_self(&self) -> bool {
        self.from == self.to
    }

    /// The four children of node `n`, if split.
    pub fn children(&self, n: u32) -> Option<[u32; 4]> {
        let f = self.nodes[n as usize].first_child;
        (f != NO_CHILD).then(|| [f, f + 1, f + 2, f + 3])
    }

    /// Splits leaf `n` on `side` into children with the given elements and
    /// throughputs. Pending energy (δL and L^G) is rescaled by T_old / T_new
    /// so that its flux π T (δL + L^G) is unchanged; returns the flux that
    /// could not be kept because the children carry no throughput at all.
    pub fn split(
        &mut self,
        n: u32,
        side: Split,
        elements: [(ElementId, ElementId); 4],
        throughputs: [Throughput; 4],
    ) -> Spectrum<N> {
        let first = self.nodes.len() as u32;
        let parent = self.nodes[n as usize].clone();
        let t_new: f64 = throughputs.iter().map(|t| t.t).sum();
        let mut lost = Spectrum::zero();
        let scale = if t_new > 0.0 {
            parent.t / t_new
        } else {
            lost = (parent.unshot + parent.gathered) * (std::f64::consts::PI * parent.t);
            0.0
        };
        for (&(a, b), th) in elements.iter().zip(throughputs.iter()) {
            self.nodes.push(Node {
                from: a,
                to: b,
                first_child: NO_CHILD,
                split: Split::None,
                t: th.t,
                v: th.v,
                spread: th.spread,
                radiance: parent.radiance,
                unshot: parent.unshot * scale,
                gathered: Spectrum::zero(),
            });
        }
        let p = &mut self.nodes[n as usize];
        p.first_child = first;
        p.split = side;
        p.gathered *= scale;
        p.unshot *= scale;
        p.t = t_new;
        lost
    }

    /// Lazy push-pull of the whole hierarchy (paper §4.4): gathered radiance
    /// is pushed down unchanged into L and δL of the leaves, then parents are
    /// the flux-weighted averages of their children.
    pub fn push_pull(&mut self) {
        self.push_pull_rec(0, Spectrum::zero());
    }

    fn push_pull_rec(&mut self, n: u32, from_above: Spectrum<N>) -> (Spectrum<N>, Spectrum<N>) {
        let down = from_above + self.nodes[n as usize].gathered;
        self.nodes[n as usize].gathered = Spectrum::zero();
        match self.children(n) {
            None => {
                let node = &mut self.nodes[n as usize];
                node.radiance += down;
                node.unshot += down;
                (node.radiance, node.unshot)
            }
            Some(children) => {
                let pulled = children.map(|c| self.push_pull_rec(c, down));
                // Children split since this node was may have changed their
                // T: the node's T is again the sum of its children's.
                let total: f64 = children.iter().map(|&c| self.nodes[c as usize].t).sum();
                let mut l = Spectrum::zero();
                let mut dl = Spectrum::zero();
                for (c, (cl, cdl)) in children.into_iter().zip(pulled) {
                    let w = if total > 0.0 {
                        self.nodes[c as usize].t / total
                    } else {
                        0.25
                    };
                    l += cl * w;
                    dl += cdl * w;
                }
                let node = &mut self.nodes[n as usize];
                node.radiance = l;
                node.unshot = dl;
                node.t = total;
                (l, dl)
            }
        }
    }

    /// Sets δL to zero over the whole hierarchy (it has just shot).
    pub fn clear_unshot(&mut self) {
        for node in &mut self.nodes {
            node.unshot = Spectrum::zero();
        }
    }

    /// The deepest node whose elements contain the element pair (i, j).
    pub fn node_for(&self, forest: &ElementForest, i: ElementId, j: ElementId) -> u32 {
        let mut n = 0u32;
        loop {
            let node = &self.nodes[n as usize];
            let Some(children) = self.children(n) else {
                return n;
            };
            let next = children.into_iter().find(|&c| {
                let child = &self.nodes[c as usize];
                match node.split {
                    Split::From => is_within(forest, i, child.from),
                    Split::To => is_within(forest, j, child.to),
                    Split::None => false,
                }
            });
            match next {
                Some(c) => n = c,
                None => return n,
            }
        }
    }

    /// Radiance leaving the point `x` of the sender side towards the point
    /// `y` of the receiver side: the leaf (deepest node) whose elements
    /// contain both (paper §4.5, Fig. 11c).
    pub fn radiance_at(
        &self,
        forest: &ElementForest,
        x: SurfaceCoord,
        y: SurfaceCoord,
    ) -> Spectrum<N> {
        let mut n = 0u32;
        loop {
            let node = &self.nodes[n as usize];
            let Some(children) = self.children(n) else {
                return node.radiance;
            };
            let next = children.into_iter().find(|&c| {
                let child = &self.nodes[c as usize];
                match node.split {
                    Split::From => forest.element_contains(child.from, x),
                    Split::To => forest.element_contains(child.to, y),
                    Split::None => false,
                }
            });
            match next {
                // A child whose elements were found not to see each other
                // never received light; the caller only asks about points
                // that do see each other, so the parent's value is the
                // better estimate there.
                Some(c) if self.nodes[c as usize].t > 0.0 => n = c,
                _ => return node.radiance,
            }
        }
    }
}

/// True when element `e` is `ancestor` or lies below it.
pub(crate) fn is_within(forest: &ElementForest, e: ElementId, ancestor: ElementId) -> bool {
    let target = forest.element(ancestor).depth;
    let mut cur = e;
    loop {
        if cur == ancestor {
            return true;
        }
        let el = forest.element(cur);
        if el.depth <= target {
            return false;
        }
        match el.parent {
            Some(p) => cur = p,
            None => return false,
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn spectrum(v: f64) -> Spectrum<3> {
        Spectrum::splat(v)
    }

    fn flux_of_pending(h: &Hierarchy<3>) -> f64 {
        // π Σ T (δL + L^G) counted at the leaves after a push, the way a
        // shot sends it: push-pull first, then sum over leaves.
        let mut h = h.clone();
        h.push_pull();
        (0..h.nodes.len() as u32)
            .filter(|&n| h.children(n).is_none())
            .map(|n| std::f64::consts::PI * h.nodes[n as usize].t * h.nodes[n as usize].unshot[0])
            .sum()
    }

    proptest! {
        /// Splitting a node (with energy pending on it) and pushing and
        /// pulling keep the flux π Σ T δL exactly (flux-weighted pull,
        /// rescaling at the split), and the root's δL after the pull is the
        /// flux-weighted average of the leaves.
        #[test]
        fn split_and_push_pull_conserve_flux(
            t_root in 0.1..2.0f64,
            t_children in proptest::collection::vec(0.01..1.0f64, 4),
            pending in 0.0..10.0f64,
            gathered_child in 0.0..5.0f64,
            split_from in any::<bool>(),
        ) {
            let e = ElementId(0);
            let mut h = Hierarchy::<3>::new(FaceId(0), FaceId(1), e, e, Throughput { t: t_root, v: 1.0, f: 0.1, spread: 0.0 });
            h.nodes[0].gathered = spectrum(pending);
            let before = std::f64::consts::PI * t_root * pending;
            let th: Vec<Throughput> = t_children.iter().map(|&t| Throughput { t, v: 1.0, f: 0.1, spread: 0.0 }).collect();
            let lost = h.split(
                0,
                if split_from { Split::From } else { Split::To },
                [(e, e); 4],
                [th[0], th[1], th[2], th[3]],
            );
            prop_assert!(lost.is_black());
            // Energy arriving later on one child adds its own flux.
            let c = h.children(0).expect("split")[1];
            h.nodes[c as usize].gathered = spectrum(gathered_child);
            let added = std::f64::consts::PI * t_children[1] * gathered_child;
            let after = flux_of_pending(&h);
            prop_assert!((after - before - added).abs() <= 1e-9 * (before + added).max(1.0));
            let mut pulled = h.clone();
            pulled.push_pull();
            let total_t: f64 = t_children.iter().sum();
            prop_assert!((pulled.nodes[0].t - total_t).abs() <= 1e-12 * total_t);
            let avg = std::f64::consts::PI * pulled.nodes[0].t * pulled.nodes[0].unshot[0];
            prop_assert!((avg - after).abs() <= 1e-9 * after.max(1.0));
        }
    }
}
