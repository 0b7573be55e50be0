//! Axis-aligned bounding boxes in f64.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// An axis-aligned box. An empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

impl Bounds {
    /// The empty box (the identity of [`Bounds::union`]).
    pub const EMPTY: Bounds = Bounds {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The smallest box containing all `points`.
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Bounds {
        points
            .into_iter()
            .fold(Bounds::EMPTY, |b, p| b.with_point(p))
    }

    /// This box grown to contain `p`.
    #[inline]
    pub fn with_point(self, p: DVec3) -> Bounds {
        Bounds {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(self, o: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// True if the box contains no point.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// `max - min` (zero for an empty box).
    pub fn diagonal(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// The centre of the box.
    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// The box grown by `d` on every side.
    pub fn padded(&self, d: f64) -> Bounds {
        Bounds {
            min: self.min - DVec3::splat(d),
            max: self.max + DVec3::splat(d),
        }
    }

    /// True if `p` lies inside or on the box.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}
