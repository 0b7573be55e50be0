//! Scenes with no finite solution, found before the solve.
//!
//! Light that is never absorbed and never leaves the scene grows without
//! bound: the series L = Le + ρF·Le + (ρF)²·Le + … only converges when
//! some of every bounce is lost. That happens exactly when, in some band,
//! every face the emitted light can reach reflects all of it (a Lambertian
//! albedo of 1 and no glossy part, whose microfacet models always lose a
//! little) and none of it escapes: a closed furnace of reflectance 1. The
//! shooting loop would then run to its shot cap and return a meaningless
//! solution.
//!
//! Only scenes with some face of albedo 1 are probed: from every face the
//! light reaches, [`PROBES`] cosine-distributed rays from stratified points
//! find the faces it reaches next; one ray that meets nothing proves the
//! scene open. A scene whose openings are too small for the probes to find
//! converges too slowly to be worth solving anyway; the solve's warning at
//! its shot cap covers what the probes let through.

use std::collections::HashSet;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use trilux_brdf::Bsdf;
use trilux_geometry::{ElementForest, FaceId, Ray, Side};

/// Probe rays from each face light reaches.
pub(crate) const PROBES: u32 = 1024;

/// Albedo this close to 1 counts as reflecting everything.
const FULL: f64 = 1.0 - 1e-9;

/// Light trapped forever: the shape whose emission is trapped, and the band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Trapped {
    /// Index of an emitting shape whose light is trapped.
    pub shape: usize,
    /// The band (0-based) in which nothing is absorbed.
    pub band: usize,
}

/// True when `face` of `bsdf` reflects all light of `band`.
fn conserves<const N: usize>(bsdf: &Bsdf<N>, side: Side, band: usize) -> bool {
    !bsdf.has_glossy(side) && bsdf.diffuse_albedo(side)[band] >= FULL
}

/// The scene's trapped light, if any (module docs). `emission` and
/// `materials` are per shape.
pub(crate) fn trapped_light<const N: usize>(
    forest: &ElementForest,
    materials: &[Bsdf<N>],
    emission: &[trilux_color::Spectrum<N>],
) -> Option<Trapped> {
    let geometry = forest.geometry();
    let shape_of = |f: FaceId| geometry.surface(f.surface()).shape as usize;
    let full = |f: FaceId, b: usize| conserves(&materials[shape_of(f)], f.side(), b);
    let emitting: Vec<FaceId> = (0..geometry.surfaces().len() as u32)
        .map(|s| FaceId::new(trilux_geometry::SurfaceId(s), Side::Front))
        .filter(|&f| !emission[shape_of(f)].is_black())
        .collect();
    // Bands in which light is emitted by a face that reflects it all.
    let mut possible: Vec<bool> = (0..N)
        .map(|b| {
            emitting
                .iter()
                .any(|&f| emission[shape_of(f)][b] > 0.0 && full(f, b))
        })
        .collect();
    if !possible.contains(&true) {
        return None;
    }
    let mut seen: HashSet<FaceId> = emitting.iter().copied().collect();
    let mut frontier = emitting.clone();
    while let Some(face) = frontier.pop() {
        for b in 0..N {
            possible[b] &= full(face, b);
        }
        if !possible.contains(&true) {
            return None;
        }
        let next = probe(forest, face)?;
        for f in next {
            if seen.insert(f) {
                frontier.push(f);
            }
        }
    }
    let band = possible.iter().position(|&p| p)?;
    let shape = emitting
        .iter()
        .find(|&&f| emission[shape_of(f)][band] > 0.0)
        .map(|&f| shape_of(f))?;
    Some(Trapped { shape, band })
}

/// The faces that [`PROBES`] rays leaving `face` meet; `None` as soon as
/// one meets nothing (the light escapes).
fn probe(forest: &ElementForest, face: FaceId) -> Option<Vec<FaceId>> {
    let geometry = forest.geometry();
    let hits: Vec<Option<FaceId>> = (0..PROBES)
        .into_par_iter()
        .map(|k| {
            let s = forest.sample_surface(face.surface(), r2(k, 0.5));
            let n = s.normal * face.side().sign();
            let ray = Ray {
                origin: s.point,
                dir: cosine_direction(n, r2(k, 0.25)),
            };
            geometry.intersect(&ray, f64::INFINITY).map(|hit| {
                let side = if hit.front_facing(&ray) {
                    Side::Front
                } else {
                    Side::Back
                };
                FaceId::new(hit.surface, side)
            })
        })
        .collect();
    hits.into_iter().collect()
}

/// Point `k` of the R2 low-discrepancy sequence (Roberts), shifted.
fn r2(k: u32, shift: f64) -> DVec2 {
    const G: f64 = 1.324_717_957_244_746;
    let k = f64::from(k) + 0.5;
    DVec2::new((shift + k / G).fract(), (shift + k / (G * G)).fract())
}

/// A cosine-distributed direction around the unit normal `n`.
fn cosine_direction(n: DVec3, u: DVec2) -> DVec3 {
    let r = u.x.sqrt();
    let phi = std::f64::consts::TAU * u.y;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u.x).max(0.0).sqrt()).normalize()
}
