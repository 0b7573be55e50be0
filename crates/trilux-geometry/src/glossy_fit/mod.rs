//! The glossy (view-dependent) light leaving a surface point as a function
//! of the outgoing direction, L_g(x, ω_o), fitted from estimates towards a
//! set of directions over the point's hemisphere: order-2 real spherical
//! harmonics ([`sh`]) plus one spherical Gaussian lobe ([`lobe`]). One
//! definition for the two places that build it: the directional bake
//! (`trilux-bake`, per vertex) and the renderer's preview (`trilux-render`,
//! per corner of a leaf element), so that a walkthrough and a preview read
//! the same representation. Pure functions of directions and values: the
//! estimates themselves are the renderer's.

pub mod lobe;
pub mod sh;

/// Directions a fit is made from by default (the bake's
/// `glossy_directions`, the preview's): a spherical Fibonacci set over
/// the hemisphere ([`sh::hemisphere_directions`]), about 15° apart.
pub const FIT_DIRECTIONS: usize = 96;
/// BSDF-sampled gather rays per fitted point by default, shared by all of
/// its directions.
pub const FIT_GATHER_SAMPLES: u32 = 16;
/// Light samples per fitted point by default, shared likewise.
pub const FIT_LIGHT_SAMPLES: u32 = 8;
