//! The range of coordinates the float pipeline holds without the result
//! depending on the scene's units (docs/limits.md).
//!
//! Geometry is f64, but the BVH is obvhs's, in f32: its surface-area
//! heuristic overflows f32 (3.4e38) for boxes around 1e19 across, and it
//! treats every box whose exit lies within 1e-4 (absolute) of the ray
//! origin as behind it, which the traversal answers by starting f32 rays a
//! little before the scene; below about 1e-8 across the f32 rounding of
//! that start is as large as the scene. Ray offsets are relative
//! ([`crate::RAY_EPSILON`] × the largest coordinate), so a scene far from
//! the origin compared with its size loses precision in its offsets.
//! Within these limits a scene renders the same whatever its unit (the
//! binary's test `unit_range` renders one at both ends).

/// Largest absolute coordinate of any point of a shape (1e15).
pub const MAX_COORDINATE: f64 = 1e15;

/// Smallest scene: the diagonal of the bounding box of every shape (1e-6).
pub const MIN_SCENE_SIZE: f64 = 1e-6;

/// Largest ratio of the scene's largest absolute coordinate to its size
/// (1e5): a scene of size 1 may lie up to 1e5 from the origin. Its ray
/// offsets are then 1e-4 of its size; at ten times that, light leaks
/// through corners (a closed box 3e6 from the origin renders 0.3 % dark).
pub const MAX_OFFSET_RATIO: f64 = 1e5;

/// Why a point beyond the coordinate limit is refused, for messages.
pub fn beyond(coordinate: f64) -> String {
    format!(
        "coordinate {coordinate:e} is beyond the coordinate limit ±{MAX_COORDINATE:e} (docs/limits.md)"
    )
}

/// True when `coordinate` is a number within ±[`MAX_COORDINATE`] (false
/// for NaN).
pub fn within(coordinate: f64) -> bool {
    coordinate.abs() <= MAX_COORDINATE
}
