//! The diffuse light as the renderer reads it at each vertex
//! ([`DiffuseLight::Gathered`], `trilux bake --gathered-light`), instead
//! of the leaves' constants ([`DiffuseLight::Leaves`], the default;
//! module `reconstruct`).
//!
//! A leaf's radiance is constant, and two things keep it from what the
//! full render shows. Where the solve linked a sender to an element above
//! the leaves (its flux below the refinement threshold), every leaf under
//! it holds the same value: a wall lit from one side is flat where the
//! render shows the light falling off across it. And light that reaches
//! a Lambertian surface by a glossy reflection is carried by the solve's
//! three-point links at their own levels, where the render gathers it at
//! the point: paper-scene2's back wall, lit mostly by the floor and by
//! the glossy cylinder, has leaves about 20 % darker than the render
//! reads it (docs/results.md, "Directional bake"). At every vertex the
//! bake therefore takes what the renderer's preview takes at a diffuse
//! hit ([`GatheredLight`]): the link sum of the vertex's leaf (every link
//! into the leaf and its ancestors, the sender's radiance times the
//! vertex's form factor to it, with the visibility the solve measured:
//! no rays), the lights without area, and E_g, the light glossy senders
//! reflect onto it (cosine rays, in scenes with glossy surfaces). The
//! vertex shows
//!
//!   v = L_e + ρ · E/π   (a textured side: E/π, the albedo map times it),
//!
//! so the viewer and `trilux render --preview` read the same light. The
//! file's flux is then the gathered light's, not the leaves'; the gap is
//! `BakeStats::max_flux_error`, and it counts buried parts, which the
//! leaves show black and a vertex reads as lit. Not yet the default: it
//! costs several times the bake (link sums and 64 rays a vertex; 3.2 s
//! on paper-scene3 against 0.4 s), it gives up the leaves' exact flux
//! (a closed issue's gate for the default bake), and the link sum is not
//! the exact direct light at a point: far from a sender, some vertices
//! read it as an element's average.

use crate::directional::GlossyPoint;

/// How a bake reads the diffuse light at its vertices (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DiffuseLight {
    /// The leaves' constants, averaged at the vertices with each
    /// surface's flux kept (module `reconstruct`).
    #[default]
    Leaves,
    /// The light as the renderer reads it at each vertex, from a
    /// [`GatheredLight`] (the leaves' constants where the bake has none).
    Gathered,
}

/// The solution's Lambertian light at points, as the renderer reads it.
pub trait GatheredLight: Sync {
    /// E/π at each of `points` on its side (irradiance over π, linear
    /// Rec. 709): the link sum of the point's leaf, the lights without
    /// area and the light glossy senders reflect onto it; `None` when the
    /// solution has no links to read (the bake keeps the leaves').
    fn irradiance(&self, points: &[GlossyPoint]) -> Option<Vec<[f64; 3]>>;
}
