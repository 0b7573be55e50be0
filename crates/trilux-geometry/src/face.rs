//! Faces: the two sides of an input surface, each with its own light.
//!
//! Mitsuba 3's surfaces are one-sided: a `diffuse` or `roughconductor`
//! BSDF is black from the back and an area emitter emits on its front only;
//! `twosided` makes the back reflect too. Every layer therefore speaks of
//! *faces*: (input surface, [`Side`]). This module is the one place that
//! says how a face is named ([`FaceId`]), how per-face data is stored
//! ([`PerFace`]) and how an element is seen from one of its sides
//! ([`FaceElement`]). [`Side`] and per-side storage ([`Sided`]) are
//! `trilux-frame`'s, shared with the reflectance models (`trilux-brdf`).

use std::ops::{Index, IndexMut};

use serde::{Deserialize, Serialize};

pub use trilux_frame::{Side, Sided};

use crate::ids::{ElementId, SurfaceId};

/// One face of an input surface, as a dense index: 2 × surface + (back).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct FaceId(pub u32);

impl FaceId {
    /// The face `side` of `surface`.
    #[inline]
    pub fn new(surface: SurfaceId, side: Side) -> FaceId {
        FaceId(2 * surface.0 + u32::from(side.is_back()))
    }

    /// Its input surface.
    #[inline]
    pub fn surface(self) -> SurfaceId {
        SurfaceId(self.0 / 2)
    }

    /// Its side.
    #[inline]
    pub fn side(self) -> Side {
        Side::from_back(self.0 & 1 == 1)
    }

    /// The index as a `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// An element of this face's surface, seen from this face's side.
    #[inline]
    pub fn of(self, element: ElementId) -> FaceElement {
        FaceElement::new(element, self.side())
    }
}

/// Data for every face of a scene, indexed by [`FaceId`] (both faces of
/// every input surface, in surface order).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PerFace<T>(Vec<T>);

impl<T> PerFace<T> {
    /// One value per face of `surfaces` input surfaces, made by `f`.
    pub fn from_fn(surfaces: usize, mut f: impl FnMut(FaceId) -> T) -> Self {
        PerFace((0..2 * surfaces as u32).map(|i| f(FaceId(i))).collect())
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when there are no faces.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The value of a face, if the id is in range.
    pub fn get(&self, face: FaceId) -> Option<&T> {
        self.0.get(face.index())
    }

    /// Every face with its value, in id order.
    pub fn iter(&self) -> impl Iterator<Item = (FaceId, &T)> {
        self.0
            .iter()
            .enumerate()
            .map(|(i, v)| (FaceId(i as u32), v))
    }

    /// Every value, in id order.
    pub fn values(&self) -> std::slice::Iter<'_, T> {
        self.0.iter()
    }

    /// Every value, mutably, in id order.
    pub fn values_mut(&mut self) -> std::slice::IterMut<'_, T> {
        self.0.iter_mut()
    }
}

/// Values in face-id order (two per input surface: front, back).
impl<T> From<Vec<T>> for PerFace<T> {
    fn from(values: Vec<T>) -> Self {
        debug_assert!(values.len().is_multiple_of(2), "two faces per surface");
        PerFace(values)
    }
}

impl<T> Index<FaceId> for PerFace<T> {
    type Output = T;
    #[inline]
    fn index(&self, face: FaceId) -> &T {
        &self.0[face.index()]
    }
}

impl<T> IndexMut<FaceId> for PerFace<T> {
    #[inline]
    fn index_mut(&mut self, face: FaceId) -> &mut T {
        &mut self.0[face.index()]
    }
}

impl<T> Index<FaceElement> for Sided<Vec<T>> {
    type Output = T;
    #[inline]
    fn index(&self, e: FaceElement) -> &T {
        &self[e.side][e.element.index()]
    }
}

impl<T> IndexMut<FaceElement> for Sided<Vec<T>> {
    #[inline]
    fn index_mut(&mut self, e: FaceElement) -> &mut T {
        &mut self[e.side][e.element.index()]
    }
}

/// An element seen from one of its sides: what form factors, visibility
/// and transport are computed between.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FaceElement {
    /// The element.
    pub element: ElementId,
    /// The side light leaves or arrives on.
    pub side: Side,
}

impl FaceElement {
    /// `element` seen from `side`.
    #[inline]
    pub fn new(element: ElementId, side: Side) -> FaceElement {
        FaceElement { element, side }
    }

    /// `element` seen from its front.
    #[inline]
    pub fn front(element: ElementId) -> FaceElement {
        FaceElement::new(element, Side::Front)
    }

    /// The same side of another element (a child, a parent).
    #[inline]
    pub fn with(self, element: ElementId) -> FaceElement {
        FaceElement::new(element, self.side)
    }

    /// A dense key: 2 × element + (back).
    #[inline]
    pub fn key(self) -> u64 {
        (u64::from(self.element.0) << 1) | u64::from(self.side.is_back())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_ids_round_trip() {
        for s in [0u32, 1, 7, 1 << 20] {
            for side in Side::BOTH {
                let f = FaceId::new(SurfaceId(s), side);
                assert_eq!(f.surface(), SurfaceId(s));
                assert_eq!(f.side(), side);
            }
        }
        assert_eq!(FaceId::new(SurfaceId(3), Side::Back).0, 7);
    }

    #[test]
    fn per_face_indexes_both_sides_of_every_surface() {
        let p = PerFace::from_fn(3, |f| (f.surface().0, f.side()));
        assert_eq!(p.len(), 6);
        assert_eq!(p[FaceId::new(SurfaceId(2), Side::Front)], (2, Side::Front));
        assert_eq!(p[FaceId::new(SurfaceId(1), Side::Back)], (1, Side::Back));
    }
}
