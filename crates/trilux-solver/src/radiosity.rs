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

#[cfg(test)]
mod tests {
    //! Push-pull against what it must conserve: gathered radiance pushed
    //! down and pulled up by exposed area gives every parent the
    //! exposed-area-weighted average of its leaves (so flux π A L is
    //! unchanged), and a uniform field stays uniform.
    #![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic

    use glam::DVec3;

    use super::*;
    use crate::test_scenes as ts;

    /// One unit square subdivided to depth 2, with its forest.
    fn square_forest() -> crate::setup::Setup<3> {
        ts::setup(
            &[ts::square(DVec3::ZERO, 1.0, false)],
            &[ts::diffuse(0.5)],
            &[None],
            ts::settings(2),
        )
    }

    fn close(a: Spectrum<3>, b: Spectrum<3>) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-12 * b[k].abs().max(1.0))
    }

    /// Radiance gathered at the root only: after push-pull every element,
    /// leaves and parents, holds it, in L and in δL.
    #[test]
    fn a_uniform_field_stays_uniform() {
        let setup = square_forest();
        let forest = setup.forest();
        let root = forest.root(ts::front(0).surface());
        let mut field = ElementRadiance::<3>::new(forest.element_count());
        let l = Spectrum::new([1.0, 2.0, 3.0]);
        field.gathered[Side::Front][root.index()] = l;
        let area = &setup.exposed_area[Side::Front];
        field.push_pull(forest, root, Side::Front, area, None);
        for e in 0..forest.element_count() {
            assert!(close(field.radiance[Side::Front][e], l), "element {e}");
            assert!(close(field.unshot[Side::Front][e], l), "element {e}");
            assert!(field.gathered[Side::Front][e].is_black());
        }
    }

    /// Radiance gathered at three levels, with uneven exposed areas (a
    /// partly buried face: each leaf exposed in part, each parent the sum
    /// of its children, as `setup` makes them): every leaf holds the sum
    /// of what was gathered on it and its ancestors, and every parent the
    /// exposed-area-weighted average of its leaves, so the flux Σ A L over
    /// the leaves equals the root's A L.
    #[test]
    fn push_pull_returns_the_exposed_area_weighted_average() {
        let setup = square_forest();
        let forest = setup.forest();
        let root = forest.root(ts::front(0).surface());
        let child = forest.element(root).children().unwrap()[1];
        let leaf = forest.element(child).children().unwrap()[2];
        // Exposed share of each leaf: 0.1 … 0.85, in a fixed order.
        let mut area = vec![0.0; forest.element_count()];
        let leaves = ts::leaves(forest, root);
        for (k, &e) in leaves.iter().enumerate() {
            area[e.index()] = forest.element(e).area * (0.1 + 0.05 * k as f64);
        }
        fn sum_up(forest: &ElementForest, e: ElementId, area: &mut [f64]) -> f64 {
            if let Some(c) = forest.element(e).children() {
                area[e.index()] = c.iter().map(|&c| sum_up(forest, c, area)).sum();
            }
            area[e.index()]
        }
        sum_up(forest, root, &mut area);
        let (g0, g1, g2) = (
            Spectrum::new([1.0, 0.5, 0.25]),
            Spectrum::new([2.0, 0.0, 1.0]),
            Spectrum::new([0.0, 4.0, 8.0]),
        );
        let mut field = ElementRadiance::<3>::new(forest.element_count());
        let s = Side::Front;
        field.gathered[s][root.index()] = g0;
        field.gathered[s][child.index()] = g1;
        field.gathered[s][leaf.index()] = g2;
        field.push_pull(forest, root, s, &area, None);
        // Leaves: the sum of the gathered radiance on their path.
        let under_child = ts::leaves(forest, child);
        let expected_leaf = |e: ElementId| {
            let mut l = g0;
            if under_child.contains(&e) {
                l += g1;
            }
            if e == leaf {
                l += g2;
            }
            l
        };
        let mut flux = Spectrum::<3>::zero();
        for &e in &leaves {
            let l = field.radiance[s][e.index()];
            assert!(close(l, expected_leaf(e)), "leaf {e:?}");
            flux += l * area[e.index()];
        }
        // Every parent: the exposed-area-weighted average of its leaves.
        for e in [root, child] {
            let mut sum = Spectrum::<3>::zero();
            for x in ts::leaves(forest, e) {
                sum += expected_leaf(x) * area[x.index()];
            }
            let average = sum * (1.0 / area[e.index()]);
            assert!(close(field.radiance[s][e.index()], average), "parent {e:?}");
            assert!(close(field.unshot[s][e.index()], average), "parent {e:?}");
        }
        assert!(close(
            field.radiance[s][root.index()] * area[root.index()],
            flux
        ));
    }
}
