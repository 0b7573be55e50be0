//! Identifiers of input surfaces and elements: plain `u32` indices into the
//! arenas of [`crate::Geometry`] and [`crate::ElementForest`].

use serde::{Deserialize, Serialize};

/// Index of an input surface in [`crate::Geometry::surfaces`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct SurfaceId(pub u32);

impl SurfaceId {
    /// The index as a `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Index of an element (a node of an input surface's element tree) in the
/// element arena of an [`crate::ElementForest`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ElementId(pub u32);

impl ElementId {
    /// The index as a `usize`.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}
