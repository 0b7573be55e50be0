//! The glossy (view-dependent) light of a bake: per vertex of a glossy
//! side, the outgoing glossy radiance L_g(x, ω_o) in world coordinates,
//! by default as order-2 real spherical harmonics plus one spherical
//! Gaussian lobe ([`GlossyForm::Lobe`], module `lobe`), or as the
//! harmonics alone ([`GlossyForm::Sh2`]).
//!
//! The bake asks a [`GlossyLight`] (the renderer's own estimate of the
//! glossy part, supplied by the `trilux` crate) for L_g at every vertex
//! towards [`BakeOptions::glossy_directions`](crate::BakeOptions)
//! directions spread uniformly in solid angle over the side's hemisphere
//! (a spherical Fibonacci set), all estimated from one set of incident
//! samples per vertex ([`GlossySamples`]), and fits the form by least
//! squares over them. The constant Y₀₀ is in the basis, so the residuals
//! sum to zero: the fit's mean over the sample directions is the
//! estimate's mean. The harmonics alone spread a narrow highlight (GGX
//! α ≲ 0.2) over the hemisphere, brightening the directions a camera
//! mostly sees; the lobe keeps it (docs/bake.md measures both by
//! roughness).
//!
//! A viewer evaluates the form for ω_o from the point to the eye, clamped
//! at zero, and adds it to the diffuse vertex colour.

use glam::DVec3;
use rayon::prelude::*;
use trilux_geometry::{Side, SurfaceCoord, SurfaceId};

use trilux_geometry::glossy_fit::sh::sh_part;
pub use trilux_geometry::glossy_fit::sh::{
    GlossyRecord, SH_COEFFICIENTS, SLOTS, fit_sh, hemisphere_directions, sh_basis, sh_eval,
};

/// Where the bake asks for glossy light: a vertex of a glossy side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossyPoint {
    /// The scene shape.
    pub shape: u32,
    /// The input surface the vertex belongs to.
    pub surface: SurfaceId,
    /// Its coordinates on that surface.
    pub coord: SurfaceCoord,
    /// The side whose light is asked for.
    pub side: Side,
    /// World-space position.
    pub point: DVec3,
    /// Unit normal of the front side.
    pub normal: DVec3,
    /// A number no other point of the bake has (seeds its samples).
    pub key: u64,
}

/// Incident samples a [`GlossyLight`] draws per point, shared by all of
/// the point's directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlossySamples {
    /// BSDF-sampled gather rays.
    pub gather: u32,
    /// Light samples.
    pub light: u32,
    /// Gather hits read through their links, as the full render reads
    /// them; without, the solution's radiance there (much cheaper).
    pub links: bool,
}

/// The glossy part of the radiance leaving surface points.
pub trait GlossyLight: Sync {
    /// The glossy radiance, linear Rec. 709, leaving each of `points`
    /// towards each of its directions, estimated from `samples` incident
    /// samples per point: `directions` holds `directions.len() /
    /// points.len()` unit vectors per point, point after point, and the
    /// answer is laid out the same way.
    fn outgoing(
        &self,
        points: &[GlossyPoint],
        directions: &[DVec3],
        samples: GlossySamples,
    ) -> Vec<[f64; 3]>;
}

/// How a vertex's glossy light is written ([`SLOTS`] RGB slots).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GlossyForm {
    /// Order-2 real spherical harmonics alone, slots 0..9 (`_TRILUX_SH0..8`).
    Sh2,
    /// Order-2 harmonics plus one spherical Gaussian (module `lobe`):
    /// slots 0..9 (`_TRILUX_SH0..8`), the lobe's axis × sharpness
    /// (`_TRILUX_LOBE`) and its RGB amplitude (`_TRILUX_LOBE_RGB`).
    #[default]
    Lobe,
}

impl GlossyForm {
    /// The form's value towards unit `d`, per channel.
    pub fn eval(self, c: &GlossyRecord, d: DVec3) -> [f64; 3] {
        match self {
            GlossyForm::Sh2 => sh_eval(&sh_part(c), d),
            GlossyForm::Lobe => trilux_geometry::glossy_fit::lobe::lobe_eval(c, d),
        }
    }

    /// The least-squares fit to `values` towards `directions`.
    pub fn fit(self, directions: &[DVec3], values: &[[f64; 3]]) -> Option<GlossyRecord> {
        match self {
            GlossyForm::Sh2 => fit_sh(directions, values).map(|c| {
                let mut r = [[0.0; 3]; SLOTS];
                r[..SH_COEFFICIENTS].copy_from_slice(&c);
                r
            }),
            GlossyForm::Lobe => trilux_geometry::glossy_fit::lobe::fit_lobe(directions, values),
        }
    }

    /// The glTF attribute of each slot used (the harmonics first, so that
    /// `Sh2` uses the first nine).
    pub fn attributes(self) -> &'static [&'static str] {
        const ALL: [&str; SLOTS] = [
            "_TRILUX_SH0",
            "_TRILUX_SH1",
            "_TRILUX_SH2",
            "_TRILUX_SH3",
            "_TRILUX_SH4",
            "_TRILUX_SH5",
            "_TRILUX_SH6",
            "_TRILUX_SH7",
            "_TRILUX_SH8",
            "_TRILUX_LOBE",
            "_TRILUX_LOBE_RGB",
        ];
        match self {
            GlossyForm::Sh2 => &ALL[..SH_COEFFICIENTS],
            GlossyForm::Lobe => &ALL,
        }
    }

    /// The name the materials' `extras.trilux.glossy` gives it.
    pub fn name(self) -> &'static str {
        match self {
            GlossyForm::Sh2 => "sh2",
            GlossyForm::Lobe => "sh2+lobe",
        }
    }
}

/// The fitted `form` of every vertex of `points`' side (zero for
/// vertices not in `points`): asks `light` in
/// batches of [`BATCH_POINTS`] points, `n_dir` directions each.
pub(crate) fn fit_vertices(
    light: &dyn GlossyLight,
    points: &[(usize, GlossyPoint)],
    vertices: usize,
    (form, n_dir, samples): (GlossyForm, usize, GlossySamples),
) -> Vec<GlossyRecord> {
    let mut out = vec![[[0.0; 3]; SLOTS]; vertices];
    for batch in points.chunks(BATCH_POINTS) {
        let dirs: Vec<Vec<DVec3>> = batch
            .iter()
            .map(|(_, p)| hemisphere_directions(p.normal * p.side.sign(), n_dir))
            .collect();
        let flat: Vec<DVec3> = dirs.iter().flatten().copied().collect();
        let only: Vec<GlossyPoint> = batch.iter().map(|(_, p)| *p).collect();
        let values = light.outgoing(&only, &flat, samples);
        let fits: Vec<Option<GlossyRecord>> = (0..batch.len())
            .into_par_iter()
            .map(|k| {
                let measured = values.get(k * n_dir..(k + 1) * n_dir).unwrap_or(&[]);
                form.fit(&dirs[k], measured)
            })
            .collect();
        for ((v, _), fit) in batch.iter().zip(fits) {
            if let Some(c) = fit {
                out[*v] = c;
            }
        }
    }
    out
}

/// Points per request to a [`GlossyLight`] (bounds the directions held).
const BATCH_POINTS: usize = 2048;
