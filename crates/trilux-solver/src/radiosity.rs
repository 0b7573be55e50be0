//! Two-point radiance of Lambertian parts (docs/architecture.md, "Two-point
//! and stored transport").
//!
//! A Lambertian surface sends the same radiance in every direction, so its
//! outgoing light is one spectrum per element and side, exactly as in
//! hierarchical radiosity: L (reflected radiance, emission excluded), δL
//! (unshot, emission included) and L^G (gathered during shots, not yet
//! pushed). The element trees are pushed and pulled lazily, only when a side
//! is about to shoot (paper §4.4).

use trilux_color::Spectrum;
use trilux_geometry::{ElementForest, ElementId, Side, Sided};

use crate::textures::ElementTextures;

/// What one push-pull reads.
#[derive(Clone, Copy)]
struct Down<'a, const N: usize> {
    forest: &'a ElementForest,
    side: Side,
    exposed_area: &'a [f64],
    textures: Option<&'a ElementTextures<N>>,
}

/// Per-element radiance of the two faces of every element.
#[derive(Clone, Debug)]
pub(crate) struct ElementRadiance<const N: usize> {
    /// Reflected outgoing radiance L, per side and element.
    pub radiance: Sided<Vec<Spectrum<N>>>,
    /// Unshot radiance δL.
    pub unshot: Sided<Vec<Spectrum<N>>>,
    /// Gathered radiance L^G waiting to be pushed.
    pub gathered: Sided<Vec<Spectrum<N>>>,
}

impl<const N: usize> ElementRadiance<N> {
    /// All zero for `elements` elements.
    pub fn new(elements: usize) -> Self {
        let z = |_| vec![Spectrum::zero(); elements];
        ElementRadiance {
            radiance: Sided::from_fn(z),
            unshot: Sided::from_fn(z),
            gathered: Sided::from_fn(z),
        }
    }

    /// Push-pull of one side's tree under `root` (HSA91; paper §3.2.4 and
    /// §4.4): gathered radiance goes down unchanged and lands in L and δL at
    /// the leaves; parents become the average of their children weighted by
    /// their exposed areas `exposed_area` (element area × exposed share, see
    /// `trilux_geometry::burial`). For Lambertian radiance that area weight
    /// *is* the flux weight (flux = π A L whatever the orientation), so
    /// pulling over curved, non-coplanar children conserves flux exactly.
    /// On a textured face the gathered radiance is scaled by ρ_d(child) /
    /// ρ_d(parent) on its way down (`textures`: the irradiance is pushed).
    pub fn push_pull(
        &mut self,
        forest: &ElementForest,
        root: ElementId,
        side: Side,
        exposed_area: &[f64],
        textures: Option<&ElementTextures<N>>,
    ) {
        let down = Down {
            forest,
            side,
            exposed_area,
            textures,
        };
        self.push_pull_rec(&down, root, Spectrum::zero());
    }

    fn push_pull_rec(
        &mut self,
        down_ctx: &Down<'_, N>,
        e: ElementId,
        from_above: Spectrum<N>,
    ) -> (Spectrum<N>, Spectrum<N>) {
        let Down {
            forest,
            side: s,
            exposed_area,
            textures,
        } = *down_ctx;
        let i = e.index();
        let down = from_above + self.gathered[s][i];
        self.gathered[s][i] = Spectrum::zero();
        match forest.element(e).children() {
            None => {
                self.radiance[s][i] += down;
                self.unshot[s][i] += down;
                (self.radiance[s][i], self.unshot[s][i])
            }
            Some(children) => {
                let area = exposed_area[i];
                let mut l = Spectrum::zero();
                let mut dl = Spectrum::zero();
                for c in children {
                    let w = if area > 0.0 {
                        exposed_area[c.index()] / area
                    } else {
                        0.0
                    };
                    let pushed = match textures {
                        Some(t) => down * t.push_ratio(s, e, c),
                        None => down,
                    };
                    let (cl, cdl) = self.push_pull_rec(down_ctx, c, pushed);
                    l += cl * w;
                    dl += cdl * w;
                }
                self.radiance[s][i] = l;
                self.unshot[s][i] = dl;
                (l, dl)
            }
        }
    }

    /// Sets δL to zero over one side's tree (the side has just shot).
    pub fn clear_unshot(&mut self, forest: &ElementForest, root: ElementId, side: Side) {
        let mut stack = vec![root];
        while let Some(e) = stack.pop() {
            self.unshot[side][e.index()] = Spectrum::zero();
            if let Some(children) = forest.element(e).children() {
                stack.extend(children);
            }
        }
    }
}
