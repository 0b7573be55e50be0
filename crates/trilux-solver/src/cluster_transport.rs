//! Transport between input surfaces and clusters of distant input surfaces
//! (docs/solver.md, "Clustering").
//!
//! **The cut.** For every face that sends light, a cut through the cluster
//! hierarchy (`cluster`) is made once, before the first shot, by
//! descending from the root (Smits, Arvo & Greenberg 1994, §3: links are
//! made as high as an error bound allows). A cluster C is *far* from a
//! face A, with bounding spheres (c_A, r_A) and (c_C, r_C) and
//! d = |c_C − c_A|, when
//!
//! r_C ≤ θ (d − r_A) and r_A ≤ θ_A d,
//!
//! i.e. C subtends less than θ (`SolverSettings::cluster_angle`) seen
//! from any point of A, and A
//! less than [`SENDER_ANGLE`] from C. Far clusters get one *far block* of
//! the cut; clusters that are not far are opened, down to single surfaces,
//! whose faces become *near* partners of A (then tested exactly for
//! whether they can exchange light, `faces::eligible_among`, and refined
//! by the paper's algorithm from their roots, as every pair was before).
//! The blocks and the near faces partition everything A can light, so no
//! transfer is counted twice. Cut sizes are O(log k) far blocks plus the
//! near faces, so the cuts of all faces take O(k log k) memory and the
//! k² root pairs are never enumerated.
//!
//! **A far link** carries the light of A's root towards every member face
//! of C at once. For member face f (the side of f's surface that A's
//! centre is in front of), T_Af = A_A F̂(A → f) V_AC, with F̂ the
//! point-to-disc form factor (HSA91) from A's four quadrant centres,
//! averaged, to a disc of f's exposed area at f's centre, and V_AC the visible fraction
//! between A and the cluster as a whole, from [`CLUSTER_RAYS`] stratified
//! segments from A to points of C's members (area-weighted; a segment with
//! a buried end counts as blocked, as in `Visibility`). Each member then
//! receives an ordinary pair link i → root(f), except faces that see only
//! their own shape (the inside of a closed box, [`is_enclosed`]), which a
//! cluster-wide visible fraction cannot tell from the outside, so that the receiving side
//! (Lambertian share, three-point links into glossy hierarchies, the
//! ledger) is the paper's, unchanged.
//!
//! **Glossy far fields** (Christensen, Lischinski, Stollnitz & Salesin
//! 1997: clusters as points with directional distributions of outgoing
//! radiance). A glossy face keeps stored hierarchies (three-point
//! transport) only with its near partners. Towards each far block C it
//! keeps one radiance L_AC, the radiance A reflects towards C's direction,
//! averaged over A's exposed area: the face seen as a point from C, with
//! one direction per block of its cut (the cut's blocks are the bins of
//! the directional distribution, each narrower than θ). Light
//! arriving at element j of A from i adds
//! ΔL_AC = π fr(i→j→C) T_ij δL_i / A_A (Eq. 4–5 with F_jC ≈ F_AC for a far
//! C), whose flux π T_AC ΔL_AC is exactly what its later shot delivers
//! (T_AC = Σ_f T_Af). A far field is one source for shooting, whatever the
//! number of far receivers.

use std::f64::consts::PI;
use std::sync::OnceLock;

use glam::{DVec2, DVec3};
use trilux_color::Spectrum;
use trilux_geometry::{
    BurialMap, ElementForest, ElementId, FaceElement, FaceId, PerFace, Side, Sided, SurfaceId,
};

use crate::cluster::{ClusterId, ClusterTree};
use crate::link::PairLink;

/// The largest θ of an emitter's cut (see [`cut_angle`]).
pub(crate) const EMITTER_FAR_ANGLE: f64 = 0.1;

/// θ_A: the largest angle a sender may subtend from a far cluster (its
/// light is taken from its centre).
pub(crate) const SENDER_ANGLE: f64 = 0.35;

/// Shadow segments per far block.
pub(crate) const CLUSTER_RAYS: u32 = 16;

/// One far block of a face's cut: a cluster and the visible fraction
/// between the face and it (traced once, when first needed).
#[derive(Debug, Default)]
pub(crate) struct FarBlock {
    /// The far cluster.
    pub cluster: ClusterId,
    /// V_AC, made on first use.
    pub visibility: OnceLock<f64>,
}

impl Clone for FarBlock {
    fn clone(&self) -> Self {
        let visibility = OnceLock::new();
        if let Some(&v) = self.visibility.get() {
            let _ = visibility.set(v);
        }
        FarBlock {
            cluster: self.cluster,
            visibility,
        }
    }
}

/// A face's cut: near partner candidates and far blocks.
#[derive(Clone, Debug, Default)]
pub(crate) struct Cut {
    /// Faces to test exactly and refine from their roots.
    pub near: Vec<FaceId>,
    /// Far clusters.
    pub far: Vec<FarBlock>,
}

/// Everything clustering reads: the tree, every face's cut (empty far
/// lists when clustering is off) and which faces are enclosed.
#[derive(Clone, Debug)]
pub(crate) struct Clusters {
    pub tree: ClusterTree,
    pub cuts: PerFace<Cut>,
    /// Faces that see only their own shape (the inside of a closed box):
    /// no far link reaches them. A far link's visible fraction is one
    /// number for the whole cluster, which cannot tell the outside of a
    /// box from its inside.
    pub enclosed: PerFace<bool>,
    /// Face elements that a crossing cuts off in part
    /// (`trilux_geometry::crossing`; not a matter of clustering, but read
    /// by refinement beside it).
    pub partly_cut: Sided<Vec<bool>>,
    /// The ends of far blocks' shadow segments.
    pub points: FarPoints,
}

/// Directions (about a face's normal) of the enclosure probe: the normal
/// and two rings of 8 at 35° and 70°.
fn probe_directions(n: DVec3) -> impl Iterator<Item = DVec3> {
    let (t, b) = n.any_orthonormal_pair();
    std::iter::once(n).chain([35f64, 70.0].into_iter().flat_map(move |deg| {
        let (sin, cos) = deg.to_radians().sin_cos();
        (0..8).map(move |k| {
            let phi = f64::from(k) * std::f64::consts::FRAC_PI_4 + deg.to_radians();
            cos * n + sin * (phi.cos() * t + phi.sin() * b)
        })
    }))
}

/// True when every probe ray from the centre and the four quadrant centres
/// of face `f`'s root, into its hemisphere, meets its own shape (the
/// inside of a closed solid).
pub(crate) fn is_enclosed(forest: &ElementForest, f: FaceId) -> bool {
    let geom = forest.geometry();
    let surface = geom.surface(f.surface());
    let root = forest.root(f.surface());
    let eps = 1e-7 * geom.extent();
    [
        (0.5, 0.5),
        (0.25, 0.25),
        (0.75, 0.25),
        (0.25, 0.75),
        (0.75, 0.75),
    ]
    .into_iter()
    .all(|(u, v)| {
        let p = forest.sample_element(root, DVec2::new(u, v));
        let n = p.normal * f.side().sign();
        probe_directions(n).all(|d| {
            let ray = trilux_geometry::Ray {
                origin: p.point + n * eps,
                dir: d,
            };
            let own = surface.shape;
            geom.intersect(&ray, f64::INFINITY).is_some_and(|h| {
                let shape = geom.surface(h.surface).shape;
                // A shape coincident with the own one (a box's bottom
                // on the floor) may be met first at the same distance.
                shape == own
                    || geom
                        .intersect_ignoring(&ray, h.t + 1e-6 * geom.extent(), shape)
                        .is_some_and(|g| geom.surface(g.surface).shape == own)
            })
        })
    })
}

impl Clusters {
    /// Bytes held (tree, cuts and the far blocks' segment ends).
    pub fn bytes(&self) -> usize {
        self.tree.bytes()
            + self.points.by_surface.capacity()
                * std::mem::size_of::<[FarPoint; 2 * CLUSTER_RAYS as usize]>()
            + self
                .cuts
                .values()
                .map(|c| {
                    c.near.capacity() * 4
                        + c.far.capacity() * std::mem::size_of::<FarBlock>()
                        + std::mem::size_of::<Cut>()
                })
                .sum::<usize>()
    }
}

/// The bounding sphere of an input surface.
fn sphere(forest: &ElementForest, s: SurfaceId) -> (DVec3, f64) {
    let b = forest.geometry().surface(s).bounds;
    (b.centre(), 0.5 * b.diagonal().length())
}

/// True when cluster `c` is far from a sender bounded by (`ca`, `ra`).
fn is_far(tree: &ClusterTree, c: ClusterId, ca: DVec3, ra: f64, angle: f64) -> bool {
    let n = &tree.nodes[c as usize];
    let d = (n.centre - ca).length();
    d > ra + n.radius && n.radius <= angle * (d - ra) && ra <= SENDER_ANGLE * d
}

/// θ for the cut of a face: `None` with clustering off; an emitter's at
/// most [`EMITTER_FAR_ANGLE`]: direct light is the largest transfer of a
/// scene, so its far links (whose relative error grows like the angle
/// squared) must be tighter (Smits et al.'s bound is the sender's flux
/// times the kernel's).
pub(crate) fn cut_angle(clustering: bool, theta: f64, emitter: bool) -> Option<f64> {
    match (clustering, emitter) {
        (false, _) => None,
        (true, true) => Some(theta.min(EMITTER_FAR_ANGLE)),
        (true, false) => Some(theta),
    }
}

/// The cut of face `a` (module docs) for θ = `angle` ([`cut_angle`]);
/// with `None` every other face is a near candidate.
pub(crate) fn cut_of(
    forest: &ElementForest,
    tree: &ClusterTree,
    a: FaceId,
    planar: Option<(DVec3, DVec3)>,
    angle: Option<f64>,
) -> Cut {
    let mut cut = Cut::default();
    let own = a.surface();
    let (ca, ra) = sphere(forest, own);
    if tree.nodes.is_empty() {
        return cut;
    }
    let mut stack: Vec<ClusterId> = vec![0];
    while let Some(c) = stack.pop() {
        let node = &tree.nodes[c as usize];
        // A cluster wholly behind a planar sender's face gets nothing.
        if let Some((p, n)) = planar
            && (node.centre - p).dot(n) < -node.radius
        {
            continue;
        }
        let holds_own = tree.contains(c, own);
        if !holds_own && angle.is_some_and(|angle| is_far(tree, c, ca, ra, angle)) {
            cut.far.push(FarBlock {
                cluster: c,
                visibility: OnceLock::new(),
            });
            continue;
        }
        match node.children {
            Some(ch) => stack.extend(ch),
            None => {
                let s = tree.members_of(c)[0];
                if s != own {
                    cut.near.push(FaceId::new(s, Side::Front));
                    cut.near.push(FaceId::new(s, Side::Back));
                }
            }
        }
    }
    cut.near.sort_unstable_by_key(|f| f.index());
    cut
}

/// What far links read.
#[derive(Clone, Copy)]
pub(crate) struct FarContext<'a> {
    pub forest: &'a ElementForest,
    pub tree: &'a ClusterTree,
    pub exposed_area: &'a Sided<Vec<f64>>,
    pub burial: Option<&'a BurialMap>,
    pub enclosed: &'a PerFace<bool>,
    pub points: &'a FarPoints,
}

/// One end of a far block's shadow segment, with whether it lies on a
/// buried part of either face of its surface.
#[derive(Clone, Copy, Debug, Default)]
struct FarPoint {
    point: DVec3,
    /// Buried on the front face, on the back face.
    buried: [bool; 2],
}

impl FarPoint {
    /// The point of element `e` at `u`, as `Visibility` samples it.
    fn sample(forest: &ElementForest, burial: Option<&BurialMap>, e: ElementId, u: DVec2) -> Self {
        let x = forest.sample_element(e, u);
        let surface = forest.element(e).surface;
        FarPoint {
            point: x.point,
            buried: Side::BOTH.map(|side| {
                burial.is_some_and(|b| b.is_buried(FaceId::new(surface, side), x.coord))
            }),
        }
    }

    fn is_buried(&self, side: Side) -> bool {
        self.buried[usize::from(side.is_back())]
    }
}

/// Per input surface, the ends of the far blocks' shadow segments
/// ([`FarContext::visibility`]). Segment k starts at the sender's point
/// `r2(k, ½)` and ends at a member's point `r2(k, ¼)`: both depend only on
/// the surface and k, so they are sampled once per surface here instead
/// of once per far block (a face has hundreds of blocks in an interior, and
/// sampling a mesh chart cost as much as tracing the segment). The
/// segments are the same as sampling each time, bit for bit.
#[derive(Clone, Debug, Default)]
pub(crate) struct FarPoints {
    /// Per surface: the sender points, then the member points.
    by_surface: Vec<[FarPoint; 2 * CLUSTER_RAYS as usize]>,
}

impl FarPoints {
    /// The points of every input surface of `forest`, or none when no
    /// face has a far block (`any_far` false: clustering off, or a scene
    /// too small for distant clusters).
    pub fn new(forest: &ElementForest, burial: Option<&BurialMap>, any_far: bool) -> Self {
        use rayon::prelude::*;
        if !any_far {
            return FarPoints::default();
        }
        let count = forest.geometry().surfaces().len() as u32;
        let by_surface = (0..count)
            .into_par_iter()
            .map(|s| {
                let root = forest.root(SurfaceId(s));
                let point = |u: DVec2| FarPoint::sample(forest, burial, root, u);
                let n = CLUSTER_RAYS;
                std::array::from_fn(|i| {
                    let k = i as u32;
                    if k < n {
                        point(r2(k, 0.5))
                    } else {
                        point(r2(k - n, 0.25))
                    }
                })
            })
            .collect();
        FarPoints { by_surface }
    }

    /// Segment k's start on `surface` (as a sender) and end on it (as a
    /// member).
    fn sender(&self, surface: SurfaceId, k: u32) -> Option<&FarPoint> {
        self.by_surface.get(surface.index())?.get(k as usize)
    }

    fn member(&self, surface: SurfaceId, k: u32) -> Option<&FarPoint> {
        self.by_surface
            .get(surface.index())?
            .get((CLUSTER_RAYS + k) as usize)
    }
}

/// One member face of a far block as a sender sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FarMember {
    /// The receiving face.
    pub face: FaceId,
    /// T_Af without the visible fraction: A_A F̂(A → f).
    pub t_open: f64,
}

/// Point-to-disc form factor from a point with normal `na` to a disc of
/// area `area_b` at `pb` with normal `nb` (one-sided: 0 unless both face
/// each other).
fn disc(pa: DVec3, na: DVec3, pb: DVec3, nb: DVec3, area_b: f64) -> f64 {
    let d = pb - pa;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return 0.0;
    }
    let r = r2.sqrt();
    let (ca, cb) = (na.dot(d) / r, -nb.dot(d) / r);
    if ca <= 0.0 || cb <= 0.0 {
        return 0.0;
    }
    (area_b * ca * cb / (PI * r2 + area_b)).min(1.0)
}

impl FarContext<'_> {
    /// The member faces of cluster `c` that sender `a` (a face element)
    /// can light, each with its unoccluded throughput; calls `f` per
    /// member.
    pub fn members(&self, a: FaceElement, c: ClusterId, mut f: impl FnMut(FarMember)) {
        let ea = self.forest.element(a.element);
        let aa = self.exposed_area[a.side][a.element.index()];
        if aa <= 0.0 {
            return;
        }
        // The sender's four quadrant centres (its midpoint rule): a centre
        // alone misjudges receivers seen near grazing.
        let quads = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)].map(|(u, v)| {
            let p = self.forest.sample_element(a.element, DVec2::new(u, v));
            (p.point, p.normal * a.side.sign())
        });
        for &s in self.tree.members_of(c) {
            let root = self.forest.root(s);
            let er = self.forest.element(root);
            // The side of s that faces A's centre.
            let side = Side::from_back((ea.centre - er.centre).dot(er.normal) < 0.0);
            if self.enclosed[FaceId::new(s, side)] {
                continue;
            }
            let area = self.exposed_area[side][root.index()];
            if area <= 0.0 {
                continue;
            }
            let nf = er.normal * side.sign();
            let ff = 0.25
                * quads
                    .iter()
                    .map(|&(p, n)| disc(p, n, er.centre, nf, area))
                    .sum::<f64>();
            if ff > 0.0 {
                f(FarMember {
                    face: FaceId::new(s, side),
                    t_open: aa * ff,
                });
            }
        }
    }

    /// The visible fraction between sender `a` and cluster `c`: segments
    /// from stratified points of `a` to points of the members that `a`
    /// lights, chosen in proportion to their unoccluded throughput.
    pub fn visibility(&self, a: FaceElement, c: ClusterId) -> f64 {
        let mut members: Vec<(FaceId, f64)> = Vec::new();
        let mut total = 0.0;
        self.members(a, c, |m| {
            total += m.t_open;
            members.push((m.face, total));
        });
        if total <= 0.0 {
            return 0.0;
        }
        let geom = self.forest.geometry();
        let (mut seen, mut count) = (0.0, 0u32);
        let mut hint = None;
        for k in 0..CLUSTER_RAYS {
            let pick = (f64::from(k) + 0.5) / f64::from(CLUSTER_RAYS) * total;
            let m = members
                .partition_point(|&(_, cum)| cum < pick)
                .min(members.len() - 1);
            let face = members[m].0;
            let (x, y) = self.segment(a, face, k);
            count += 1;
            if !(x.is_buried(a.side) || y.is_buried(face.side())) {
                seen += geom.transmittance_hint(x.point, y.point, &mut hint);
            }
        }
        seen / f64::from(count.max(1))
    }

    /// Segment k from sender `a` to member face `to`: from `a`'s point
    /// `r2(k, ½)` to the member's `r2(k, ¼)`, stored per surface
    /// ([`FarPoints`]) for a sender that is a whole surface, else sampled.
    fn segment(&self, a: FaceElement, to: FaceId, k: u32) -> (FarPoint, FarPoint) {
        let sample = |e: ElementId, u: DVec2| FarPoint::sample(self.forest, self.burial, e, u);
        let a_surface = self.forest.element(a.element).surface;
        let a_root = self.forest.root(a_surface) == a.element;
        let x = match self.points.sender(a_surface, k).filter(|_| a_root) {
            Some(x) => *x,
            None => sample(a.element, r2(k, 0.5)),
        };
        let y = match self.points.member(to.surface(), k) {
            Some(y) => *y,
            None => sample(self.forest.root(to.surface()), r2(k, 0.25)),
        };
        (x, y)
    }

    /// V of far block `block` of sender `a`, traced on first use.
    pub fn block_visibility(&self, a: FaceElement, block: &FarBlock) -> f64 {
        *block
            .visibility
            .get_or_init(|| self.visibility(a, block.cluster))
    }
}

/// The pair links from sender `a` to the members of every far block, in
/// parallel over blocks: i = a's element, j = the member's root, T = T_Af,
/// δL = `unshot(block index)`.
pub(crate) fn far_links<const N: usize>(
    ctx: &FarContext<'_>,
    a: FaceElement,
    blocks: &[FarBlock],
    unshot: impl Fn(usize) -> Spectrum<N> + Sync,
) -> Vec<PairLink<N>> {
    use rayon::prelude::*;
    blocks
        .par_iter()
        .enumerate()
        .flat_map_iter(|(b, block)| {
            let dl = unshot(b);
            let mut out = Vec::new();
            if dl.is_black() {
                return out;
            }
            let v = ctx.block_visibility(a, block);
            if v <= 0.0 {
                return out;
            }
            ctx.members(a, block.cluster, |m| {
                out.push(PairLink {
                    i: a.element,
                    j: ctx.forest.root(m.face.surface()),
                    face: m.face,
                    t: m.t_open * v,
                    unshot: dl,
                });
            });
            out
        })
        .collect()
}

/// The k-th point of the R2 low-discrepancy sequence (Roberts 2018),
/// offset by `shift`.
pub(crate) fn r2(k: u32, shift: f64) -> DVec2 {
    const G: f64 = 1.324_717_957_244_746;
    let (a1, a2) = (1.0 / G, 1.0 / (G * G));
    let k = f64::from(k);
    DVec2::new((shift + a1 * k).fract(), (shift + a2 * k).fract())
}

/// A glossy face's far field (module docs): one radiance per far block.
#[derive(Clone, Debug)]
pub(crate) struct FarField<const N: usize> {
    /// The sending face.
    pub face: FaceId,
    /// Per far block of the face's cut, in the cut's order.
    pub blocks: Vec<FarRadiance<N>>,
    /// Unshot flux Σ π T_AC δL_AC (the selection key).
    pub unshot_flux: Spectrum<N>,
    /// Whether the blocks' T_AC are made ([`FarField::trace`]).
    pub traced: bool,
}

/// The light a glossy face sends towards one far cluster.
#[derive(Clone, Debug)]
pub(crate) struct FarRadiance<const N: usize> {
    /// The far cluster.
    pub cluster: ClusterId,
    /// T_AC = Σ over its members of T_Af (0 until the field is traced).
    pub t: f64,
    /// Unit direction from the face's centre to the cluster's centre.
    pub direction: DVec3,
    /// Radiance L_AC sent so far (reflected).
    pub radiance: Spectrum<N>,
    /// Unshot radiance δL_AC.
    pub unshot: Spectrum<N>,
}

impl<const N: usize> FarField<N> {
    /// The far field of `face` over its cut's far blocks, dark and not
    /// yet traced: most glossy faces of an interior (the charts of a
    /// chair's metal legs) never receive light in a solve, and their
    /// blocks' visible fractions were most of its preparation.
    pub fn new(forest: &ElementForest, tree: &ClusterTree, face: FaceId, cut: &Cut) -> Self {
        let centre = forest.element(forest.root(face.surface())).centre;
        let blocks = cut
            .far
            .iter()
            .map(|b| FarRadiance {
                cluster: b.cluster,
                t: 0.0,
                direction: (tree.nodes[b.cluster as usize].centre - centre).normalize_or_zero(),
                radiance: Spectrum::zero(),
                unshot: Spectrum::zero(),
            })
            .collect();
        FarField {
            face,
            blocks,
            unshot_flux: Spectrum::zero(),
            traced: false,
        }
    }

    /// Makes every block's T_AC = V_AC Σ T_Af (its visible fraction traced
    /// once, shared with the face's Lambertian far links): done when
    /// light first arrives at the face, before anything reads T_AC.
    pub fn trace(&mut self, ctx: &FarContext<'_>, cut: &Cut) {
        let a = self.face.of(ctx.forest.root(self.face.surface()));
        for (r, b) in self.blocks.iter_mut().zip(&cut.far) {
            let v = ctx.block_visibility(a, b);
            let mut t = 0.0;
            ctx.members(a, b.cluster, |m| t += m.t_open * v);
            r.t = t;
        }
        self.traced = true;
    }
}

/// The far fields of every glossy face, `None` for the others.
pub(crate) type FarFields<const N: usize> = PerFace<Option<FarField<N>>>;

/// The far block of a cut that contains surface `s` (at most one: the
/// blocks are disjoint), as an index into the cut's far list.
pub(crate) fn block_of(tree: &ClusterTree, cut: &Cut, s: SurfaceId) -> Option<usize> {
    cut.far.iter().position(|b| tree.contains(b.cluster, s))
}

#[cfg(test)]
mod tests {
    //! The cut against its defining property: for every face, its near
    //! faces and far blocks partition the other input surfaces (each met
    //! exactly once, through both its faces when near or through one far
    //! block), except those wholly behind a planar face.
    #![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

    use glam::DVec3;

    use super::*;
    use crate::test_scenes as ts;

    /// A 5 × 5 grid of small squares on the floor, facing up, under a
    /// 3 × 3 grid of small squares at height 1, facing down: far enough
    /// apart that clusters of them are far from each other.
    fn grids() -> crate::setup::Setup<3> {
        grids_sized(0.1, false)
    }

    /// [`grids`], and with `blockers` four squares 0.3 wide halfway up
    /// (facing up, at odd coordinates), which hide some far blocks in part.
    fn grids_with(blockers: bool) -> crate::setup::Setup<3> {
        grids_sized(0.1, blockers)
    }

    /// The grids with squares `size` wide (0.6: close enough that which
    /// of them are far depends on θ between 0.1 and 1).
    fn grids_sized(size: f64, blockers: bool) -> crate::setup::Setup<3> {
        let mut shapes = Vec::new();
        for a in 0..5 {
            for b in 0..5 {
                let c = DVec3::new(f64::from(a), f64::from(b), 0.0);
                shapes.push(ts::square(c, size, false));
            }
        }
        for a in 0..3 {
            for b in 0..3 {
                let c = DVec3::new(2.0 * f64::from(a), 2.0 * f64::from(b), 1.0);
                shapes.push(ts::square(c, size, true));
            }
        }
        for a in (0..2).filter(|_| blockers) {
            for b in 0..2 {
                let c = DVec3::new(2.0 * f64::from(a) + 1.0, 2.0 * f64::from(b) + 1.0, 0.5);
                shapes.push(ts::square(c, 0.3, false));
            }
        }
        let n = shapes.len();
        ts::setup(
            &shapes,
            &vec![ts::diffuse(0.5); n],
            &vec![None; n],
            ts::settings(1),
        )
    }

    /// How many times the cut of face `a` meets every input surface: once
    /// per near face (both faces of a near surface are listed), once per
    /// far block holding it.
    fn coverage(
        forest: &ElementForest,
        tree: &ClusterTree,
        a: FaceId,
        angle: Option<f64>,
    ) -> (Vec<u32>, usize) {
        let root = forest.element(forest.root(a.surface()));
        let planar = Some((root.centre, root.normal * a.side().sign()));
        let cut = cut_of(forest, tree, a, planar, angle);
        let mut count = vec![0u32; forest.geometry().surfaces().len()];
        for f in &cut.near {
            if f.side() == Side::Front {
                count[f.surface().index()] += 1;
            }
            assert!(cut.near.contains(&FaceId::new(
                f.surface(),
                Side::from_back(!f.side().is_back())
            )));
        }
        for b in &cut.far {
            for s in tree.members_of(b.cluster) {
                count[s.index()] += 1;
            }
        }
        (count, cut.far.len())
    }

    /// Every face of the floor grid (whose front sees everything above or
    /// beside it) meets every other surface exactly once and never its
    /// own, at every θ; with clustering on, some of them through far
    /// blocks. A looser θ only makes more far (a near face at θ' > θ is near
    /// at θ), so the near sets are nested; with squares 0.6 wide they
    /// shrink as θ grows.
    #[test]
    fn near_faces_and_far_blocks_partition_the_other_surfaces() {
        let angles = [None, Some(0.1), Some(0.25), Some(0.5), Some(1.0)];
        for size in [0.1, 0.6] {
            let setup = grids_sized(size, false);
            let forest = setup.forest();
            let tree = &setup.clusters.tree;
            let (mut far_blocks, mut shrank) = (0, 0);
            for s in 0..25 {
                let a = ts::front(s);
                let mut tighter: Option<Vec<FaceId>> = None;
                for angle in angles {
                    let (count, far) = coverage(forest, tree, a, angle);
                    for (t, &c) in count.iter().enumerate() {
                        let expected = u32::from(t != s as usize);
                        assert_eq!(c, expected, "face {s}, surface {t}, θ {angle:?}");
                    }
                    if angle.is_some() {
                        far_blocks += far;
                    } else {
                        assert_eq!(far, 0, "no far blocks without clustering");
                    }
                    let near = near_of(forest, tree, a, angle);
                    if let Some(w) = &tighter {
                        assert!(
                            near.iter().all(|f| w.contains(f)),
                            "size {size}, face {s}: near at θ {angle:?} not within the tighter θ's"
                        );
                        shrank +=
                            usize::from(near.len() < w.len() && angle.is_some_and(|a| a > 0.1));
                    }
                    tighter = Some(near);
                }
            }
            assert!(far_blocks > 0, "the scene exercises far blocks");
            if size > 0.5 {
                assert!(shrank > 0, "a looser θ leaves fewer near faces");
            }
        }
    }

    /// The near faces of `a`'s cut at θ = `angle`.
    fn near_of(
        forest: &ElementForest,
        tree: &ClusterTree,
        a: FaceId,
        angle: Option<f64>,
    ) -> Vec<FaceId> {
        let root = forest.element(forest.root(a.surface()));
        let planar = Some((root.centre, root.normal * a.side().sign()));
        cut_of(forest, tree, a, planar, angle).near
    }

    /// A planar face gets no near partner wholly behind it: the back of a
    /// floor square (facing down) meets every other floor square (in its
    /// plane) exactly once, and a square above at most once, only through a
    /// far block whose cluster is not wholly behind it.
    #[test]
    fn surfaces_behind_a_planar_face_are_left_out() {
        let setup = grids();
        let forest = setup.forest();
        let tree = &setup.clusters.tree;
        let theta = crate::settings::DEFAULT_CLUSTER_ANGLE;
        for s in 0..25u32 {
            let a = FaceId::new(trilux_geometry::SurfaceId(s), Side::Back);
            let (count, _) = coverage(forest, tree, a, Some(theta));
            let near = near_of(forest, tree, a, Some(theta));
            for (t, &c) in count.iter().enumerate() {
                if t < 25 {
                    assert_eq!(c, u32::from(t != s as usize), "face {s} back, surface {t}");
                } else {
                    assert!(c <= 1, "face {s} back, surface {t}");
                    assert!(near.iter().all(|f| f.surface().index() != t));
                }
            }
        }
    }

    /// The stored segment ends are the points sampling gives, every far
    /// block's segments are the sampled ones, and so is its visible
    /// fraction, bit for bit (partly hidden blocks among them).
    #[test]
    fn stored_segment_ends_trace_the_sampled_segments() {
        let setup = grids_with(true);
        let cache = crate::throughput::ThroughputCache::new(16);
        let stored = setup.refine_context(&cache).far();
        assert!(
            !stored.points.by_surface.is_empty(),
            "clustering stores points"
        );
        let none = FarPoints::default();
        let sampled = FarContext {
            points: &none,
            ..stored
        };
        let forest = setup.forest();
        for s in 0..forest.geometry().surfaces().len() as u32 {
            let s = SurfaceId(s);
            for k in 0..CLUSTER_RAYS {
                let x = forest.sample_surface(s, r2(k, 0.5)).point;
                let y = forest.sample_surface(s, r2(k, 0.25)).point;
                assert_eq!(stored.points.sender(s, k).map(|p| p.point), Some(x));
                assert_eq!(stored.points.member(s, k).map(|p| p.point), Some(y));
            }
        }
        let tree = &setup.clusters.tree;
        let (mut blocks, mut partial) = (0, 0);
        for (face, cut) in setup.clusters.cuts.iter() {
            let a = face.of(setup.forest().root(face.surface()));
            for b in &cut.far {
                let (v, w) = (
                    stored.visibility(a, b.cluster),
                    sampled.visibility(a, b.cluster),
                );
                assert_eq!(
                    v.to_bits(),
                    w.to_bits(),
                    "face {face:?}, cluster {}",
                    b.cluster
                );
                assert!((0.0..=1.0).contains(&v));
                for &m in tree.members_of(b.cluster) {
                    let to = FaceId::new(m, Side::Front);
                    for k in 0..CLUSTER_RAYS {
                        let (p, q) = (stored.segment(a, to, k), sampled.segment(a, to, k));
                        assert_eq!((p.0.point, p.1.point), (q.0.point, q.1.point));
                        assert_eq!((p.0.buried, p.1.buried), (q.0.buried, q.1.buried));
                    }
                }
                blocks += 1;
                partial += u32::from(v > 0.0 && v < 1.0);
            }
        }
        assert!(blocks > 0, "the scene has far blocks");
        assert!(partial > 0, "some far block is partly hidden");
    }
}
