//! The next source and the residual, without a pass over every source.
//!
//! Progressive refinement shoots the source of greatest unshot flux δΦ
//! (Southwell's order, paper §4) and stops on the residual Σ δΦ. A room
//! with a thousand boxes has about a hundred thousand sources (faces,
//! stored hierarchies, far fields, waiting glossy light), and a shot
//! changes a few hundred of them; a pass over all of them after every shot
//! was a quarter of its solve, on one thread while the others waited.
//!
//! Here each kind of source keeps a tree over blocks of [`BLOCK`]
//! consecutive sources; a node holds its range's greatest key (the band
//! sum of δΦ), the first source that has it, and the range's flux. The
//! mutations of a shot mark their sources ([`SourceQueue::touch`]); before
//! the next choice only the marked blocks are summed again and their
//! paths to the root mended ([`SourceQueue::refresh`]). The choice is the
//! pass's exactly (the first source of the greatest positive key, kinds
//! in the pass's order); the residual is the same sum grouped otherwise,
//! equal to rounding.

use trilux_color::Spectrum;
use trilux_geometry::FaceId;

/// A light source for shooting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Source {
    /// The two-point tree of a face.
    Radiosity(FaceId),
    /// A stored interaction hierarchy.
    Stored(u32),
    /// A glossy face's far field (`cluster_transport`).
    Far(FaceId),
    /// A light without area (`lights`), by its index.
    Light(u32),
    /// The glossy light waiting at a face (`deferred`).
    Deferred(FaceId),
}

/// Sources per block of a tree's leaves.
const BLOCK: usize = 32;

/// The kinds of source, in the order that breaks ties between equal keys.
const KINDS: usize = 5;

/// A node: the greatest positive key of its range and where (`u32::MAX`:
/// none), and its flux.
#[derive(Clone, Copy)]
struct Node<const N: usize> {
    best: f64,
    at: u32,
    sum: Spectrum<N>,
}

impl<const N: usize> Node<N> {
    const EMPTY: Self = Node {
        best: 0.0,
        at: u32::MAX,
        sum: Spectrum::zero(),
    };

    /// Two neighbouring ranges as one; the left wins a tie.
    fn join(l: Self, r: Self) -> Self {
        let (best, at) = if r.best > l.best {
            (r.best, r.at)
        } else {
            (l.best, l.at)
        };
        Node {
            best,
            at,
            sum: l.sum + r.sum,
        }
    }
}

/// One kind's tree: a binary heap of nodes over its blocks.
#[derive(Default)]
struct KeyTree<const N: usize> {
    len: usize,
    width: usize,
    nodes: Vec<Node<N>>,
    dirty: Vec<bool>,
    pending: Vec<u32>,
}

impl<const N: usize> KeyTree<N> {
    /// `len` sources, every block marked (the first refresh builds it).
    fn new(len: usize) -> Self {
        let blocks = len.div_ceil(BLOCK);
        let width = blocks.next_power_of_two();
        KeyTree {
            len,
            width,
            nodes: vec![Node::EMPTY; 2 * width],
            dirty: vec![true; blocks],
            pending: (0..blocks as u32).collect(),
        }
    }

    fn touch(&mut self, i: usize) {
        let b = i / BLOCK;
        if let Some(d) = self.dirty.get_mut(b)
            && !*d
        {
            *d = true;
            self.pending.push(b as u32);
        }
    }

    /// Sums the marked blocks again from `flux` and mends their paths.
    fn refresh(&mut self, flux: impl Fn(usize) -> Spectrum<N>) {
        // Taken and put back, so that its allocation serves every shot.
        let mut pending = std::mem::take(&mut self.pending);
        for &b in &pending {
            let b = b as usize;
            self.dirty[b] = false;
            let mut leaf = Node::EMPTY;
            for i in b * BLOCK..((b + 1) * BLOCK).min(self.len) {
                let f = flux(i);
                leaf.sum += f;
                let key = f.sum();
                if key > leaf.best {
                    (leaf.best, leaf.at) = (key, i as u32);
                }
            }
            let mut n = self.width + b;
            self.nodes[n] = leaf;
            while n > 1 {
                n /= 2;
                self.nodes[n] = Node::join(self.nodes[2 * n], self.nodes[2 * n + 1]);
            }
        }
        pending.clear();
        self.pending = pending;
    }

    fn root(&self) -> Node<N> {
        self.nodes.get(1).copied().unwrap_or(Node::EMPTY)
    }

    fn bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node<N>>()
            + self.dirty.capacity()
            + self.pending.capacity() * 4
    }
}

/// The sources' keys by kind (module docs).
#[derive(Default)]
pub(crate) struct SourceQueue<const N: usize> {
    trees: [KeyTree<N>; KINDS],
}

/// Kind and index of a source.
fn slot(s: Source) -> (usize, usize) {
    match s {
        Source::Light(k) => (0, k as usize),
        Source::Radiosity(f) => (1, f.index()),
        Source::Stored(h) => (2, h as usize),
        Source::Deferred(f) => (3, f.index()),
        Source::Far(f) => (4, f.index()),
    }
}

/// The source of kind `kind` and index `i` (`slot`'s inverse).
fn source(kind: usize, i: u32) -> Source {
    match kind {
        0 => Source::Light(i),
        1 => Source::Radiosity(FaceId(i)),
        2 => Source::Stored(i),
        3 => Source::Deferred(FaceId(i)),
        _ => Source::Far(FaceId(i)),
    }
}

impl<const N: usize> SourceQueue<N> {
    /// A queue over `lights` lights without area, `faces` faces and
    /// `hierarchies` stored hierarchies, to be built by the first refresh.
    pub fn new(lights: usize, faces: usize, hierarchies: usize) -> Self {
        SourceQueue {
            trees: [
                KeyTree::new(lights),
                KeyTree::new(faces),
                KeyTree::new(hierarchies),
                KeyTree::new(faces),
                KeyTree::new(faces),
            ],
        }
    }

    /// Marks `s`: its unshot flux changed.
    pub fn touch(&mut self, s: Source) {
        let (kind, i) = slot(s);
        self.trees[kind].touch(i);
    }

    /// Reads every marked block's sources again through `flux`.
    pub fn refresh(&mut self, flux: impl Fn(Source) -> Spectrum<N>) {
        for (kind, tree) in self.trees.iter_mut().enumerate() {
            tree.refresh(|i| flux(source(kind, i as u32)));
        }
    }

    /// The source of greatest positive key, if any, and the residual
    /// (as of the last refresh).
    pub fn next_and_residual(&self) -> (Option<Source>, Spectrum<N>) {
        let roots = self.trees.each_ref().map(KeyTree::root);
        let mut best: Option<(Source, f64)> = None;
        for (kind, r) in roots.iter().enumerate() {
            if r.at != u32::MAX && best.is_none_or(|(_, f)| r.best > f) {
                best = Some((source(kind, r.at), r.best));
            }
        }
        let [light, face, stored, deferred, far] = roots.map(|r| r.sum);
        (best.map(|(s, _)| s), face + stored + far + light + deferred)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.trees.iter().map(KeyTree::bytes).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a pass over every source: the same choice (first of the
    /// greatest positive key) and the same residual to rounding, after
    /// random changes marked one by one.
    #[test]
    fn the_queue_chooses_as_a_pass_does() {
        let (lights, faces, hierarchies) = (3, 70, 1000);
        let mut keys: Vec<Vec<f64>> = [lights, faces, hierarchies, faces, faces]
            .iter()
            .map(|&n| vec![0.0; n])
            .collect();
        let mut q = SourceQueue::<1>::new(lights, faces, hierarchies);
        let mut seed = 12345u64;
        let mut rand = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for round in 0..300 {
            for _ in 0..(1 + round % 17) {
                let kind = (rand() * 5.0) as usize;
                let i = (rand() * keys[kind].len() as f64) as usize;
                // Some ties and some zeros.
                let v = match (rand() * 4.0) as u32 {
                    0 => 0.0,
                    1 => 0.5,
                    _ => rand(),
                };
                keys[kind][i] = v;
                q.touch(source(kind, i as u32));
            }
            q.refresh(|s| {
                let (k, i) = slot(s);
                Spectrum::splat(keys[k][i])
            });
            let mut best: Option<(Source, f64)> = None;
            let mut total = 0.0;
            for (kind, ks) in keys.iter().enumerate() {
                for (i, &v) in ks.iter().enumerate() {
                    total += v;
                    if v > 0.0 && best.is_none_or(|(_, f)| v > f) {
                        best = Some((source(kind, i as u32), v));
                    }
                }
            }
            let (next, residual) = q.next_and_residual();
            assert_eq!(next, best.map(|(s, _)| s), "round {round}");
            assert!((residual.sum() - total).abs() <= 1e-12 * total.max(1.0));
        }
    }
}
