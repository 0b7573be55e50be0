//! The cluster hierarchy above the input surfaces (Smits, Arvo & Greenberg
//! 1994, "A clustering algorithm for radiosity in complex environments";
//! docs/solver.md, "Clustering").
//!
//! A binary tree of bounding volumes over the input surfaces, built once
//! per solve by median splits of the surfaces' bounding-box centres along
//! the longest axis of their extent (O(k log k) for k input surfaces).
//! Every leaf is one input surface, so the element trees of the paper hang
//! below the leaves unchanged. Each cluster keeps the bounding sphere of
//! its members' bounds (what the far test of `cluster_transport` uses) and
//! the contiguous range of its member surfaces in the tree's order.

use glam::DVec3;
use trilux_geometry::{Bounds, Geometry, SurfaceId};

/// Index of a cluster in its tree; the root is 0.
pub(crate) type ClusterId = u32;

/// One node of the cluster hierarchy.
#[derive(Clone, Debug)]
pub(crate) struct Cluster {
    /// Centre of the bounding sphere (the bounds' centre).
    pub centre: DVec3,
    /// Radius of the bounding sphere (half the bounds' diagonal).
    pub radius: f64,
    /// The members, as a range of [`ClusterTree::members`].
    pub first: u32,
    /// Number of member surfaces.
    pub count: u32,
    /// The two children, or `None` for a leaf (one input surface).
    pub children: Option<[ClusterId; 2]>,
}

/// The hierarchy of clusters over every input surface.
#[derive(Clone, Debug)]
pub(crate) struct ClusterTree {
    /// Node arena; node 0 is the root (every surface).
    pub nodes: Vec<Cluster>,
    /// Member surfaces in tree order: cluster c holds
    /// `members[first..first + count]`.
    pub members: Vec<SurfaceId>,
    /// The leaf cluster of every surface.
    pub leaf_of: Vec<ClusterId>,
    /// The parent of every cluster (`u32::MAX` for the root).
    pub parent: Vec<ClusterId>,
}

impl ClusterTree {
    /// Builds the tree over every input surface of `geometry`.
    pub fn build(geometry: &Geometry) -> ClusterTree {
        let surfaces = geometry.surfaces();
        let mut members: Vec<SurfaceId> = (0..surfaces.len() as u32).map(SurfaceId).collect();
        let mut tree = ClusterTree {
            nodes: Vec::with_capacity(2 * surfaces.len()),
            members: Vec::new(),
            leaf_of: vec![0; surfaces.len()],
            parent: Vec::with_capacity(2 * surfaces.len()),
        };
        if !members.is_empty() {
            let bounds_of = |s: SurfaceId| surfaces[s.index()].bounds;
            tree.build_rec(&mut members, 0, &bounds_of, u32::MAX);
        }
        tree.members = members;
        tree
    }

    fn build_rec(
        &mut self,
        members: &mut [SurfaceId],
        first: u32,
        bounds_of: &impl Fn(SurfaceId) -> Bounds,
        parent: ClusterId,
    ) -> ClusterId {
        let bounds = members
            .iter()
            .fold(Bounds::EMPTY, |b, &s| b.union(bounds_of(s)));
        let id = self.nodes.len() as ClusterId;
        self.nodes.push(Cluster {
            centre: bounds.centre(),
            radius: 0.5 * bounds.diagonal().length(),
            first,
            count: members.len() as u32,
            children: None,
        });
        self.parent.push(parent);
        if members.len() == 1 {
            self.leaf_of[members[0].index()] = id;
            return id;
        }
        // Median split of the centres along their longest extent.
        let centres = members
            .iter()
            .fold(Bounds::EMPTY, |b, &s| b.with_point(bounds_of(s).centre()));
        let d = centres.diagonal();
        let axis = if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        };
        let key = |s: &SurfaceId| bounds_of(*s).centre()[axis];
        let mid = members.len() / 2;
        members.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        let (lo, hi) = members.split_at_mut(mid);
        let a = self.build_rec(lo, first, bounds_of, id);
        let b = self.build_rec(hi, first + mid as u32, bounds_of, id);
        self.nodes[id as usize].children = Some([a, b]);
        id
    }

    /// The member surfaces of cluster `c`.
    pub fn members_of(&self, c: ClusterId) -> &[SurfaceId] {
        let n = &self.nodes[c as usize];
        &self.members[n.first as usize..(n.first + n.count) as usize]
    }

    /// True when `surface` is a member of cluster `c`.
    pub fn contains(&self, c: ClusterId, surface: SurfaceId) -> bool {
        let mut cur = self.leaf_of.get(surface.index()).copied();
        while let Some(x) = cur {
            if x == c {
                return true;
            }
            cur = self
                .parent
                .get(x as usize)
                .copied()
                .filter(|&p| p != u32::MAX);
        }
        false
    }

    /// The clusters containing `surface`, from its leaf up to the root.
    pub fn ancestors(&self, surface: SurfaceId) -> impl Iterator<Item = ClusterId> + '_ {
        let mut cur = self.leaf_of.get(surface.index()).copied();
        std::iter::from_fn(move || {
            let x = cur?;
            cur = self
                .parent
                .get(x as usize)
                .copied()
                .filter(|&p| p != u32::MAX);
            Some(x)
        })
    }

    /// An upper bound of the throughput T = A_a F_{a→b} (unoccluded)
    /// between input surfaces `a` and `b` of areas `area_a`, `area_b`,
    /// from their leaves' bounding spheres: seen from any point of a's
    /// sphere, b's sphere lies in a cone of half-angle α with sin α ≤
    /// r_b / (d − r_a), and a point form factor into such a cone is at
    /// most sin² α; by reciprocity the same from b's side, and T ≤ min
    /// of the two areas. No shadow rays and no cubature: it lets the
    /// final gather dismiss a pair by the flux it can carry before
    /// tracing it.
    pub fn throughput_bound(&self, a: SurfaceId, area_a: f64, b: SurfaceId, area_b: f64) -> f64 {
        let sphere = |s: SurfaceId| &self.nodes[self.leaf_of[s.index()] as usize];
        let (sa, sb) = (sphere(a), sphere(b));
        let d = (sa.centre - sb.centre).length();
        let mut t = area_a.min(area_b);
        let from_a = d - sa.radius;
        if from_a > sb.radius {
            t = t.min(area_a * (sb.radius / from_a).powi(2));
        }
        let from_b = d - sb.radius;
        if from_b > sa.radius {
            t = t.min(area_b * (sa.radius / from_b).powi(2));
        }
        t
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Cluster>()
            + (self.members.capacity() + self.leaf_of.capacity() + self.parent.capacity()) * 4
    }
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, DVec3};
    use trilux_geometry::{Shape, ShapeKind};

    use super::*;

    #[test]
    fn every_surface_is_in_exactly_one_leaf_and_in_its_ancestors() {
        let shapes: Vec<Shape> = (0..7)
            .map(|i| Shape {
                kind: ShapeKind::Cube,
                world_from_object: DMat4::from_translation(DVec3::new(3.0 * i as f64, 0.0, 0.0))
                    * DMat4::from_scale(DVec3::splat(0.5)),
                flip_normals: false,
            })
            .collect();
        let g = Geometry::build(&shapes).expect("geometry");
        let t = ClusterTree::build(&g);
        let k = g.surfaces().len();
        assert_eq!(t.members.len(), k);
        assert_eq!(t.nodes[0].count as usize, k);
        assert_eq!(t.nodes.len(), 2 * k - 1);
        for s in 0..k as u32 {
            let leaf = t.leaf_of[s as usize];
            assert_eq!(t.members_of(leaf), &[SurfaceId(s)]);
            for c in t.ancestors(SurfaceId(s)) {
                assert!(t.members_of(c).contains(&SurfaceId(s)));
                assert!(t.contains(c, SurfaceId(s)));
                // The bounding sphere contains the member's bounds.
                let b = g.surface(SurfaceId(s)).bounds;
                let n = &t.nodes[c as usize];
                for p in [b.min, b.max] {
                    assert!((p - n.centre).length() <= n.radius * (1.0 + 1e-9));
                }
            }
            assert_eq!(t.ancestors(SurfaceId(s)).last(), Some(0));
        }
    }

    /// The bound is above T = A_a F_{a→b} from the geometry crate's
    /// form factor (cubature to 1e-4), for random pairs of small and large
    /// squares, near and far, facing or tilted.
    #[test]
    fn throughput_bound_is_above_the_form_factor() {
        use trilux_geometry::{ElementForest, FaceElement, FormFactorOptions, Side, form_factor};
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let opts = FormFactorOptions {
            rel_tol: 1e-4,
            max_depth: 8,
            samples: 256,
        };
        let mut tight = 0.0f64;
        for _ in 0..300 {
            let square = |centre: DVec3, size: f64, rx: f64, ry: f64| Shape {
                kind: ShapeKind::Rectangle,
                world_from_object: DMat4::from_translation(centre)
                    * DMat4::from_rotation_x(rx)
                    * DMat4::from_rotation_y(ry)
                    * DMat4::from_scale(DVec3::splat(size)),
                flip_normals: false,
            };
            let a = square(DVec3::ZERO, 0.1 + rnd(), 0.0, 0.0);
            let offset = DVec3::new(rnd() - 0.5, rnd() - 0.5, 0.2 + 4.0 * rnd());
            // Facing a (rotated by π about x), tilted by up to ±1 rad.
            let b = square(
                offset,
                0.1 + rnd(),
                std::f64::consts::PI + rnd() - 0.5,
                rnd() - 0.5,
            );
            let g = Geometry::build(&[a, b]).expect("geometry");
            let forest = ElementForest::new(std::sync::Arc::new(g));
            let g = forest.geometry();
            let (ra, rb) = (forest.root(SurfaceId(0)), forest.root(SurfaceId(1)));
            let fa = FaceElement::new(ra, Side::Front);
            let fb = FaceElement::new(rb, Side::Front);
            let (area_a, area_b) = (forest.element(ra).area, forest.element(rb).area);
            let t = area_a * form_factor(&forest, fa, fb, &opts).value;
            let bound =
                ClusterTree::build(g).throughput_bound(SurfaceId(0), area_a, SurfaceId(1), area_b);
            assert!(t <= bound * (1.0 + 1e-3), "T {t} above its bound {bound}");
            tight = tight.max(t / bound);
        }
        // The bound is not vacuous: some pair comes within a factor 4.
        assert!(tight > 0.25, "loosest bound ratio {tight}");
    }
}
