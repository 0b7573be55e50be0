//! The two sides of a surface: [`Side`] and per-side storage, [`Sided`].
//!
//! Mitsuba 3's surfaces are one-sided: a `diffuse` or `roughconductor`
//! BSDF is black from the back and an area emitter emits on its front
//! only; `twosided` makes the back reflect too. The geometry (faces of
//! input surfaces) and the reflectance models (the lobe on each side) both
//! speak of sides, with this one type.

use std::ops::{Index, IndexMut};

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Which side of a surface or element light leaves or arrives on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Side {
    /// The side the (geometric, after `flip_normals`) normal points to.
    Front,
    /// The other side.
    Back,
}

impl Side {
    /// Both sides, front first.
    pub const BOTH: [Side; 2] = [Side::Front, Side::Back];

    /// +1 for the front, −1 for the back: turns the front normal into this
    /// side's.
    #[inline]
    pub fn sign(self) -> f64 {
        match self {
            Side::Front => 1.0,
            Side::Back => -1.0,
        }
    }

    /// True for the back.
    #[inline]
    pub fn is_back(self) -> bool {
        self == Side::Back
    }

    /// The back when `back` is true.
    #[inline]
    pub fn from_back(back: bool) -> Side {
        if back { Side::Back } else { Side::Front }
    }

    /// The side a direction in a local frame (z = front normal) lies on;
    /// `None` exactly in the tangent plane.
    #[inline]
    pub fn of_local(w: DVec3) -> Option<Side> {
        if w.z > 0.0 {
            Some(Side::Front)
        } else if w.z < 0.0 {
            Some(Side::Back)
        } else {
            None
        }
    }
}

/// A pair of values, one per side (for example one per-element array for
/// each side of every element).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Sided<T> {
    /// The front's value.
    pub front: T,
    /// The back's value.
    pub back: T,
}

impl<T> Sided<T> {
    /// Both values made by `f`.
    pub fn from_fn(mut f: impl FnMut(Side) -> T) -> Self {
        Sided {
            front: f(Side::Front),
            back: f(Side::Back),
        }
    }

    /// Both values with their sides, front first.
    pub fn iter(&self) -> impl Iterator<Item = (Side, &T)> {
        [(Side::Front, &self.front), (Side::Back, &self.back)].into_iter()
    }
}

impl<T> Index<Side> for Sided<T> {
    type Output = T;
    #[inline]
    fn index(&self, side: Side) -> &T {
        match side {
            Side::Front => &self.front,
            Side::Back => &self.back,
        }
    }
}

impl<T> IndexMut<Side> for Sided<T> {
    #[inline]
    fn index_mut(&mut self, side: Side) -> &mut T {
        match side {
            Side::Front => &mut self.front,
            Side::Back => &mut self.back,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_directions_lie_on_the_side_of_their_z() {
        assert_eq!(
            Side::of_local(DVec3::new(0.3, -0.2, 0.1)),
            Some(Side::Front)
        );
        assert_eq!(
            Side::of_local(DVec3::new(0.3, -0.2, -0.1)),
            Some(Side::Back)
        );
        assert_eq!(Side::of_local(DVec3::new(1.0, 0.0, 0.0)), None);
        for side in Side::BOTH {
            assert_eq!(Side::from_back(side.is_back()), side);
            assert_eq!(side.sign() < 0.0, side.is_back());
        }
    }

    #[test]
    fn sided_values_are_indexed_by_their_side() {
        let mut s = Sided::from_fn(|side| side.sign());
        assert_eq!((s[Side::Front], s[Side::Back]), (1.0, -1.0));
        s[Side::Back] = 5.0;
        assert_eq!(s.back, 5.0);
        let sides: Vec<Side> = s.iter().map(|(side, _)| side).collect();
        assert_eq!(sides, Side::BOTH);
    }
}
