//! The prepared scene: geometry, materials and emitters built once for a
//! band count, and shared (behind an `Arc`) by the solver, its solution
//! and the renderer.
//!
//! The solver never parses: it takes a [`SceneDescription`], the plain data
//! of a scene (shapes, BSDF parameters, emitted radiance, one of each per
//! shape), which the scene layer hands over. Errors name the shape by its
//! index, so that the caller can point at its place in the file.

use std::io::Write;
use std::sync::Arc;

use thiserror::Error;
use trilux_brdf::{BrdfError, Bsdf, BsdfParams, Shading, TextureSlot, TexturedBsdf};
use trilux_color::{ColorError, ColorParam, Spectrum};
use trilux_geometry::{
    Bounds, Geometry, GeometryError, Punctual, Shape, SurfaceCoord, SurfaceId, Transmittance,
};

use crate::lights::{LightError, PreparedLight};
use crate::sky::PreparedSky;

/// What light transport needs of a scene, as plain data: per shape its
/// geometry, its material and its area emitter's radiance (if any).
#[derive(Clone, Copy, Debug)]
pub struct SceneDescription<'a> {
    /// The shapes, in scene order.
    pub shapes: &'a [Shape],
    /// One material per shape.
    pub bsdfs: &'a [BsdfParams],
    /// One optional area-emitter radiance per shape.
    pub emission: &'a [Option<ColorParam>],
}

/// What is wrong with a scene description.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PrepareError {
    /// A shape's geometry could not be built.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// A material could not be built for this band count.
    #[error("shape {shape}: {source}")]
    Material {
        /// Index of the shape.
        shape: usize,
        /// What is wrong.
        #[source]
        source: BrdfError,
    },
    /// An emitter's radiance could not be converted to this band count.
    #[error("shape {shape}: emitted radiance: {source}")]
    Emission {
        /// Index of the shape.
        shape: usize,
        /// What is wrong.
        #[source]
        source: ColorError,
    },
    /// An emitter's radiance is negative or not finite after conversion.
    #[error("shape {shape}: emitted radiance must be finite and non-negative")]
    BadEmission {
        /// Index of the shape.
        shape: usize,
    },
    /// An emitter's radiance is beyond `MAX_BAND_RADIANCE` in these
    /// bands, or its flux π·A·Le overflows.
    #[error(
        "shape {shape}: emitted radiance beyond 1e30 in some band, or a flux that overflows (docs/limits.md)"
    )]
    FluxOverflow {
        /// Index of the shape.
        shape: usize,
    },
    /// A shape's textures need texture coordinates it does not have.
    #[error("shape {shape}: its material has textures but the shape has no texture coordinates")]
    NoTexcoords {
        /// Index of the shape.
        shape: usize,
    },
    /// The three per-shape lists differ in length.
    #[error("{shapes} shapes but {bsdfs} materials and {emission} emitter entries")]
    Lengths {
        /// Number of shapes.
        shapes: usize,
        /// Number of materials.
        bsdfs: usize,
        /// Number of emitter entries.
        emission: usize,
    },
    /// The description could not be serialised for its hash.
    #[error("cannot hash the scene description: {0}")]
    Hash(#[source] serde_json::Error),
}

impl PrepareError {
    /// What is wrong, without naming the shape (for a caller that names
    /// its place in a file instead).
    pub fn problem(&self) -> String {
        match self {
            PrepareError::Geometry(e) => e.problem.to_string(),
            PrepareError::Material { source, .. } => source.to_string(),
            PrepareError::Emission { source, .. } => format!("emitted radiance: {source}"),
            PrepareError::BadEmission { .. } => {
                "emitted radiance must be finite and non-negative".into()
            }
            PrepareError::FluxOverflow { .. } => {
                "emitted radiance beyond 1e30 in some band, or a flux that overflows (docs/limits.md)"
                    .into()
            }
            PrepareError::NoTexcoords { .. } => {
                "its material has textures but the shape has no texture coordinates".into()
            }
            PrepareError::Lengths { .. } | PrepareError::Hash(_) => self.to_string(),
        }
    }

    /// True when the problem is the shape's emitter rather than the shape.
    pub fn is_emitter(&self) -> bool {
        matches!(
            self,
            PrepareError::Emission { .. }
                | PrepareError::BadEmission { .. }
                | PrepareError::FluxOverflow { .. }
        )
    }

    /// The index of the shape at fault, when one is.
    pub fn shape(&self) -> Option<usize> {
        match self {
            PrepareError::Geometry(e) => Some(e.shape),
            PrepareError::Material { shape, .. }
            | PrepareError::Emission { shape, .. }
            | PrepareError::BadEmission { shape }
            | PrepareError::FluxOverflow { shape }
            | PrepareError::NoTexcoords { shape } => Some(*shape),
            PrepareError::Lengths { .. } | PrepareError::Hash(_) => None,
        }
    }
}

/// A scene prepared for light transport with `N` bands.
#[derive(Debug)]
pub struct PreparedScene<const N: usize> {
    geometry: Arc<Geometry>,
    materials: Vec<Bsdf<N>>,
    /// The textured materials, by shape (`None` for uniform ones).
    textured: Vec<Option<TexturedBsdf<N>>>,
    emission: Vec<Spectrum<N>>,
    /// The lights without area (`lights`).
    lights: Vec<PreparedLight<N>>,
    /// The box standing for a `constant` sky, if any (`with_enclosure`).
    enclosure: Option<Bounds>,
    /// The environment map, if any (`with_sky`).
    sky: Option<PreparedSky<N>>,
    hash: u64,
}

impl<const N: usize> PreparedScene<N> {
    /// Builds the geometry, every material and every emitter.
    pub fn new(desc: &SceneDescription<'_>) -> Result<Self, PrepareError> {
        Self::new_textured(desc, &[])
    }

    /// [`PreparedScene::new`] with the textures of each shape's material
    /// (`textures` is empty, or holds one list per shape; an empty list
    /// means no textures). A textured material replaces the shape's
    /// material by its nominal one (`trilux_brdf::textured`).
    pub fn new_textured(
        desc: &SceneDescription<'_>,
        textures: &[Vec<TextureSlot>],
    ) -> Result<Self, PrepareError> {
        let n = desc.shapes.len();
        if desc.bsdfs.len() != n || desc.emission.len() != n {
            return Err(PrepareError::Lengths {
                shapes: n,
                bsdfs: desc.bsdfs.len(),
                emission: desc.emission.len(),
            });
        }
        if !textures.is_empty() && textures.len() != n {
            return Err(PrepareError::Lengths {
                shapes: n,
                bsdfs: textures.len(),
                emission: desc.emission.len(),
            });
        }
        let geometry = Geometry::build_shared(desc.shapes)?;
        let mut materials: Vec<Bsdf<N>> = desc
            .bsdfs
            .iter()
            .enumerate()
            .map(|(shape, p)| {
                Bsdf::new(p).map_err(|source| PrepareError::Material { shape, source })
            })
            .collect::<Result<_, _>>()?;
        let emission: Vec<Spectrum<N>> = desc
            .emission
            .iter()
            .enumerate()
            .map(|(shape, e)| emitted(shape, e.as_ref()))
            .collect::<Result<_, _>>()?;
        check_flux(&geometry, &emission)?;
        let textured = textured_materials(desc, textures, &geometry)?;
        for (m, t) in materials.iter_mut().zip(&textured) {
            if let Some(t) = t {
                *m = t.bsdf().clone();
            }
        }
        Ok(PreparedScene {
            geometry,
            materials,
            textured,
            emission,
            lights: Vec::new(),
            enclosure: None,
            sky: None,
            hash: content_hash(desc, textures, N)?,
        })
    }

    /// The textured material of a shape (`None` when it is uniform).
    pub fn textured(&self, shape: usize) -> Option<&TexturedBsdf<N>> {
        self.textured.get(shape).and_then(Option::as_ref)
    }

    /// True when some material has textures.
    pub(crate) fn has_textures(&self) -> bool {
        self.textured.iter().any(Option::is_some)
    }

    /// The material of `shape` at `coord` of its input surface `surface`:
    /// a textured material evaluated at the point's texture coordinates.
    pub fn shading(&self, shape: usize, surface: SurfaceId, coord: SurfaceCoord) -> Shading<'_, N> {
        match (self.textured(shape), self.geometry.texcoord(surface, coord)) {
            (Some(t), Some(uv)) => t.at(uv),
            _ => Shading::uniform(&self.materials[shape]),
        }
    }

    /// The geometry, shared.
    pub fn geometry(&self) -> &Arc<Geometry> {
        &self.geometry
    }

    /// The material of every shape.
    pub fn materials(&self) -> &[Bsdf<N>] {
        &self.materials
    }

    /// The material of one shape.
    pub fn material(&self, shape: usize) -> &Bsdf<N> {
        &self.materials[shape]
    }

    /// The scene with lights without area (`lights`: each with its
    /// intensity as written); they enter the content hash.
    pub fn with_lights(mut self, lights: &[(Punctual, ColorParam)]) -> Result<Self, LightError> {
        self.lights = lights
            .iter()
            .enumerate()
            .map(|(k, (p, c))| PreparedLight::new(k, *p, c))
            .collect::<Result<_, _>>()?;
        if !lights.is_empty() {
            let mut h = Fnv1a(self.hash);
            serde_json::to_writer(&mut h, lights).map_err(|e| LightError {
                index: 0,
                problem: e.to_string(),
            })?;
            self.hash = h.0;
        }
        Ok(self)
    }

    /// The lights without area.
    pub fn lights(&self) -> &[PreparedLight<N>] {
        &self.lights
    }

    /// The scene whose shapes include `enclosure`, the box standing for a
    /// `constant` sky (trilux-scene's `Scene::enclosure`): shadow rays
    /// towards directional lights end inside it.
    pub fn with_enclosure(mut self, enclosure: Option<Bounds>) -> Self {
        self.enclosure = enclosure;
        self
    }

    /// The scene with some shapes letting a fraction of the light through
    /// (`by_shape[i]` for shape `i`: trilux-geometry's `transmission`),
    /// which every visibility of the solve and the render multiplies; they
    /// enter the content hash.
    pub fn with_transmission(mut self, by_shape: &[Option<Transmittance>]) -> Self {
        if by_shape.iter().any(Option::is_some) {
            Arc::make_mut(&mut self.geometry).set_transmission(by_shape);
            let mut h = Fnv1a(self.hash);
            if serde_json::to_writer(&mut h, by_shape).is_ok() {
                self.hash = h.0;
            }
        }
        self
    }

    /// The scene lit by an environment map (`crate::sky`); its texels and
    /// orientation enter the content hash.
    pub fn with_sky(mut self, sky: Option<PreparedSky<N>>) -> Self {
        if let Some(s) = &sky {
            let mut h = Fnv1a(self.hash);
            s.hash_into(&mut h);
            self.hash = h.0;
        }
        self.sky = sky;
        self
    }

    /// The environment map, if any.
    pub fn sky(&self) -> Option<&PreparedSky<N>> {
        self.sky.as_ref()
    }

    /// Where a shadow ray from `x` towards the sky in direction `wi` ends:
    /// beyond everything in the scene.
    pub fn sky_end(&self, x: glam::DVec3, wi: glam::DVec3) -> glam::DVec3 {
        let b = self.geometry.bounds();
        let reach = (b.max - b.min).length() + (x - 0.5 * (b.max + b.min)).length() + 1.0;
        x + wi * reach
    }

    /// Where a shadow ray from `x` towards the light of `a` ends, `None`
    /// where no light arrives ([`crate::lights::shadow_end`]).
    pub fn shadow_end(&self, x: glam::DVec3, a: &trilux_geometry::Arrival) -> Option<glam::DVec3> {
        crate::lights::shadow_end(&self.geometry, self.enclosure.as_ref(), x, a)
    }

    /// The emitted radiance of every shape (zero where it does not emit).
    pub fn emission(&self) -> &[Spectrum<N>] {
        &self.emission
    }

    /// A hash of everything the description holds and of `N`: the same
    /// scene file gives the same hash on any machine.
    pub fn content_hash(&self) -> u64 {
        self.hash
    }
}

/// The textured material of every shape that has textures; a shape with
/// textures must have texture coordinates.
fn textured_materials<const N: usize>(
    desc: &SceneDescription<'_>,
    textures: &[Vec<TextureSlot>],
    geometry: &Geometry,
) -> Result<Vec<Option<TexturedBsdf<N>>>, PrepareError> {
    let mut out = Vec::with_capacity(desc.shapes.len());
    for shape in 0..desc.shapes.len() {
        let slots = textures.get(shape).filter(|s| !s.is_empty());
        let Some(slots) = slots else {
            out.push(None);
            continue;
        };
        let has_uv = match &desc.shapes[shape].kind {
            trilux_geometry::ShapeKind::Mesh(m) => m.texcoords.is_some(),
            trilux_geometry::ShapeKind::Rectangle => true,
            _ => false,
        };
        if !has_uv || geometry.surfaces_of_shape(shape as u32).is_empty() {
            return Err(PrepareError::NoTexcoords { shape });
        }
        let t = TexturedBsdf::new(&desc.bsdfs[shape], slots.clone())
            .map_err(|source| PrepareError::Material { shape, source })?;
        out.push(Some(t));
    }
    Ok(out)
}

/// One shape's emitted radiance as `N` bands (zero without an emitter).
fn emitted<const N: usize>(
    shape: usize,
    radiance: Option<&ColorParam>,
) -> Result<Spectrum<N>, PrepareError> {
    let Some(c) = radiance else {
        return Ok(Spectrum::zero());
    };
    let le = c
        .emission::<N>()
        .map_err(|source| PrepareError::Emission { shape, source })?;
    if le.is_finite() && le.is_non_negative() {
        Ok(le)
    } else {
        Err(PrepareError::BadEmission { shape })
    }
}

/// The largest radiance of any band of an emitter (1e30): the scene file
/// may state at most [`trilux_color::MAX_RADIANCE`] (1e20), which
/// conversion to bands can scale a few times; this is the solver's own
/// guard, far enough below the 32-bit floats of the solution file (3.4e38)
/// for the sums of many reflections.
pub(crate) const MAX_BAND_RADIANCE: f64 = 1e30;

/// Refuses an emitter whose flux π·A·Le overflows in some band (it would
/// make an infinite solution, which no renderer can use), and one whose
/// radiance is beyond `MAX_BAND_RADIANCE`.
fn check_flux<const N: usize>(
    geometry: &Geometry,
    emission: &[Spectrum<N>],
) -> Result<(), PrepareError> {
    let mut area = vec![0.0; emission.len()];
    for surface in geometry.surfaces() {
        if let Some(a) = area.get_mut(surface.shape as usize) {
            *a += surface.area();
        }
    }
    for (shape, le) in emission.iter().enumerate() {
        let flux = std::f64::consts::PI * area[shape] * le.max_value();
        if !flux.is_finite() || le.max_value() > MAX_BAND_RADIANCE {
            return Err(PrepareError::FluxOverflow { shape });
        }
    }
    Ok(())
}

/// FNV-1a (64 bits) as an `io::Write`: stable across platforms and Rust
/// versions, fed by the serialiser without an intermediate string.
pub(crate) struct Fnv1a(pub u64);

impl Fnv1a {
    pub(crate) fn new() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Write for Fnv1a {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn content_hash(
    desc: &SceneDescription<'_>,
    textures: &[Vec<TextureSlot>],
    bands: usize,
) -> Result<u64, PrepareError> {
    let mut h = Fnv1a::new();
    serde_json::to_writer(&mut h, &(desc.shapes, desc.bsdfs, desc.emission, bands))
        .map_err(PrepareError::Hash)?;
    // Scenes without textures keep the hash they always had.
    if textures.iter().any(|t| !t.is_empty()) {
        serde_json::to_writer(&mut h, textures).map_err(PrepareError::Hash)?;
    }
    Ok(h.0)
}
