//! A whole bake: tessellate, reconstruct both sides of every shape, write
//! the file.
//!
//! The file holds one node and mesh per scene shape (world-space
//! positions, identity transform) with one primitive per input surface and
//! side (`extras.trilux.surface`, `side`): all share the shape's positions,
//! the back's triangles are wound the other way and its normals flipped,
//! and each side has its own colours (a side the material does not reflect
//! on is black, as in the renderer).
//!
//! Colours are linear Rec. 709 (sRGB primaries) radiance in the scene's
//! units. glTF requires `COLOR_0` to lie in [0, 1] (the Khronos validator
//! refuses anything above), so `COLOR_0` holds radiance × 2^exposure
//! clamped to [0, 1], and the application attribute `_RADIANCE` the
//! radiance itself; `asset.extras.trilux.exposure` says the exposure.
//! Materials are `KHR_materials_unlit` with a white base colour, so any
//! viewer shows `COLOR_0`; trilux's viewer (docs/viewer) shows `_RADIANCE`
//! × 2^exposure. The scene's camera, when it has one, is the file's first
//! camera.

use std::collections::BTreeMap;
use std::time::Instant;

use glam::DVec3;
use serde_json::{Value, json};
use trilux_brdf::BsdfParams;
use trilux_geometry::glossy_fit::{FIT_DIRECTIONS, FIT_GATHER_SAMPLES, FIT_LIGHT_SAMPLES};
use trilux_geometry::{ElementForest, ElementId, FaceId, Side, SurfaceId};
use trilux_solver::{ElementTextures, Solution};

use crate::albedo::{AlbedoMap, albedo_map};
use crate::camera::BakeCamera;
use crate::directional::{
    GlossyForm, GlossyLight, GlossyPoint, GlossyRecord, GlossySamples, fit_vertices,
};
use crate::error::BakeError;
use crate::gathered::{DiffuseLight, GatheredLight};
use crate::glb::Document;
use crate::reconstruct::{baked_flux, vertex_values};
use crate::tessellate::{ShapeMesh, tessellate};

/// What a bake reads.
#[derive(Clone, Copy)]
pub struct BakeInput<'a, const N: usize> {
    /// The solved scene.
    pub solution: &'a Solution<N>,
    /// Every shape's material as the scene gives it (kept in the
    /// materials' `extras`).
    pub materials: &'a [BsdfParams],
    /// Every shape's name (its `id`), if any.
    pub names: &'a [Option<String>],
    /// The scene's camera.
    pub camera: Option<BakeCamera>,
    /// The glossy light of glossy sides (module `directional`); without,
    /// it is left out as before.
    pub glossy: Option<&'a dyn GlossyLight>,
    /// The diffuse light as the renderer reads it at points (module
    /// `gathered`); without, every leaf shows its constant.
    pub gathered: Option<&'a dyn GatheredLight>,
}

/// How to bake.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct BakeOptions {
    /// `COLOR_0` is radiance × 2^exposure, clamped to [0, 1] (for viewers
    /// that show vertex colours as display values).
    pub exposure: f64,
    /// Textured sides as an albedo map times the light (module `albedo`);
    /// without, their radiance goes into the vertex colours like any other
    /// (smaller files, texture detail finer than the leaves lost).
    pub albedo_maps: bool,
    /// Fit the glossy light of glossy sides per vertex (module
    /// `directional`; on by default: without, the glossy light is left out
    /// and its materials marked).
    pub glossy: bool,
    /// The glossy light's form (order-2 harmonics and a lobe, or order-2
    /// harmonics).
    pub glossy_form: GlossyForm,
    /// Directions per vertex over which the glossy light is fitted
    /// (module `directional`; at least [`MIN_GLOSSY_DIRECTIONS`]). Cheap:
    /// every direction reuses the vertex's incident samples.
    pub glossy_directions: u32,
    /// BSDF-sampled gather rays per vertex, shared by its directions (0:
    /// leave glossy light out).
    pub glossy_samples: u32,
    /// Light samples per vertex, shared by its directions.
    pub glossy_light_samples: u32,
    /// Gather hits read through their links, as the full render does
    /// (slower); without, the solution's radiance there.
    pub glossy_links: bool,
    /// Most incident samples of glossy light in one bake (vertices ×
    /// (gather rays + light samples)): a larger bake takes fewer per
    /// vertex, down to a quarter of each (at least one).
    pub glossy_budget: u64,
    /// How the diffuse light is read at the vertices (module `gathered`).
    pub diffuse: DiffuseLight,
}

/// Fewest directions a vertex's glossy light is fitted over.
pub const MIN_GLOSSY_DIRECTIONS: u32 = 16;

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            exposure: 0.0,
            albedo_maps: true,
            glossy: true,
            glossy_form: GlossyForm::Lobe,
            // The preview's counts too (`trilux_geometry::glossy_fit`).
            glossy_directions: FIT_DIRECTIONS as u32,
            glossy_samples: FIT_GATHER_SAMPLES,
            glossy_light_samples: FIT_LIGHT_SAMPLES,
            glossy_links: false,
            glossy_budget: 8_000_000,
            diffuse: DiffuseLight::default(),
        }
    }
}

/// What a bake made.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct BakeStats {
    /// Vertex positions written (each shared by both sides).
    pub vertices: usize,
    /// Triangles written, both sides.
    pub triangles: usize,
    /// Size of the file.
    pub bytes: usize,
    /// Wall-clock seconds of the bake.
    pub seconds: f64,
    /// Largest relative gap, over input surfaces and sides carrying more
    /// than 10⁻⁶ of the scene's largest flux, between the flux the file
    /// shows and the solution's (module `reconstruct`).
    pub max_flux_error: f64,
    /// Vertices (counted once per side) given directional glossy light.
    pub glossy_vertices: usize,
    /// Of `seconds`, those spent estimating and fitting glossy light.
    pub glossy_seconds: f64,
}

/// A baked file and its statistics.
#[derive(Clone, Debug)]
pub struct Baked {
    /// The `.glb` file's bytes.
    pub glb: Vec<u8>,
    /// What it holds.
    pub stats: BakeStats,
}

/// Bakes `input`'s solution (module docs).
pub fn bake<const N: usize>(
    input: &BakeInput<'_, N>,
    options: &BakeOptions,
) -> Result<Baked, BakeError> {
    let start = Instant::now();
    let scene = input.solution.scene();
    let meshes = tessellate(input.solution.forest(), |shape| {
        options.albedo_maps && scene.textured(shape as usize).is_some()
    });
    let textures = input
        .solution
        .element_textures()
        .filter(|_| options.albedo_maps);
    let mut doc = Document::default();
    let mut flux = FluxCheck::default();
    let (mut vertices, mut triangles) = (0, 0);
    let mut glossy = GlossyCount::new(input, options, &meshes);
    for mesh in meshes.iter().filter(|m| !m.triangles.is_empty()) {
        let sides = Side::BOTH.map(|side| {
            let mut light = SideLight::new(input.solution, textures.as_ref(), mesh, side);
            if let Some(gathered) = input
                .gathered
                .filter(|_| options.diffuse == DiffuseLight::Gathered)
            {
                light.gather(input.solution, gathered, mesh, vertices);
            }
            flux.add(input.solution, mesh, side, &light);
            light.sh = glossy.fit(input, options, mesh, side, vertices);
            light
        });
        write_shape(
            &mut doc,
            input,
            mesh,
            &sides,
            (options.exposure.exp2(), options.glossy_form),
        )?;
        vertices += mesh.positions.len();
        triangles += 2 * mesh.triangles.len();
    }
    if let Some(camera) = input.camera {
        write_camera(&mut doc, input.solution, &camera);
    }
    let glb = doc.into_glb(asset(options), &["KHR_materials_unlit"])?;
    let stats = BakeStats {
        vertices,
        triangles,
        bytes: glb.len(),
        seconds: start.elapsed().as_secs_f64(),
        max_flux_error: flux.max_error(),
        glossy_vertices: glossy.vertices,
        glossy_seconds: glossy.seconds,
    };
    Ok(Baked { glb, stats })
}

/// A leaf's exitant radiance (reflected and emitted) on `side`, averaged
/// over its area with buried parts black, in linear sRGB.
pub(crate) fn leaf_value<const N: usize>(
    solution: &Solution<N>,
    side: Side,
    leaf: ElementId,
) -> [f64; 3] {
    let element = solution.forest().element(leaf);
    let face = FaceId::new(element.surface, side);
    let exposed = if element.area > 0.0 {
        (solution.exposed_area(face, leaf) / element.area).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let rgb = solution.face_radiance(face, leaf).to_linear_srgb();
    rgb.map(|x| (x * exposed).max(0.0))
}

/// What one side of a shape shows: its vertex values and, for a textured
/// side, its albedo map and every leaf's mean albedo (module `albedo`).
struct SideLight<'t, const N: usize> {
    side: Side,
    values: Vec<[f64; 3]>,
    map: Option<AlbedoMap>,
    textures: Option<&'t ElementTextures<N>>,
    /// The glossy light's SH coefficients per vertex (module
    /// `directional`), on a glossy side when the bake has them.
    sh: Option<Vec<GlossyRecord>>,
}

impl<'t, const N: usize> SideLight<'t, N> {
    fn new(
        solution: &Solution<N>,
        textures: Option<&'t ElementTextures<N>>,
        mesh: &ShapeMesh,
        side: Side,
    ) -> Self {
        let map = solution
            .scene()
            .textured(mesh.shape as usize)
            .filter(|_| textures.is_some())
            .and_then(|t| albedo_map(t, side));
        let textured = map.is_some();
        let mut light = SideLight {
            side,
            values: Vec::new(),
            map,
            textures: textures.filter(|_| textured),
            sh: None,
        };
        let values = vertex_values(
            mesh,
            |leaf| light.value(solution, leaf),
            |leaf| light.weight(solution, leaf),
        );
        light.values = values;
        light
    }

    /// The light as the renderer reads it at each vertex (module
    /// `gathered`); `first` numbers the mesh's vertices in the bake. A
    /// side that reflects nothing, an emitting textured side, and a
    /// solution without links keep the leaves' values.
    fn gather(
        &mut self,
        solution: &Solution<N>,
        gathered: &dyn GatheredLight,
        mesh: &ShapeMesh,
        first: usize,
    ) {
        let scene = solution.scene();
        let le = match self.side {
            Side::Front => scene.emission()[mesh.shape as usize].to_linear_srgb(),
            Side::Back => [0.0; 3],
        };
        // E/π times what the side shows it with: its albedo, or 1 on a
        // textured side (whose values are the light).
        let scale = match self.map {
            Some(_) if le != [0.0; 3] => return,
            Some(_) => [1.0; 3],
            None => {
                let rho = scene
                    .material(mesh.shape as usize)
                    .diffuse_albedo(self.side);
                rho.to_linear_srgb().map(|x| x.max(0.0))
            }
        };
        if scale == [0.0; 3] {
            return;
        }
        let points = mesh_points(mesh, self.side, first);
        let only: Vec<GlossyPoint> = points.iter().map(|(_, p)| *p).collect();
        let Some(light) = gathered.irradiance(&only) else {
            return;
        };
        for ((v, _), e) in points.iter().zip(light) {
            self.values[*v] = std::array::from_fn(|c| (le[c] + scale[c] * e[c]).max(0.0));
        }
    }

    /// The leaf's mean albedo on a textured side.
    fn albedo(&self, solution: &Solution<N>, leaf: ElementId) -> Option<[f64; 3]> {
        let face = FaceId::new(solution.forest().element(leaf).surface, self.side);
        let rho = self.textures?.rho(face, leaf)?;
        Some(rho.to_linear_srgb().map(|x| x.max(0.0)))
    }

    /// The leaf's value: its radiance, or on a textured side the light
    /// E/π (radiance over mean albedo).
    fn value(&self, solution: &Solution<N>, leaf: ElementId) -> [f64; 3] {
        let l = leaf_value(solution, self.side, leaf);
        match self.albedo(solution, leaf) {
            Some(rho) => std::array::from_fn(|c| if rho[c] > 0.0 { l[c] / rho[c] } else { 0.0 }),
            None => l,
        }
    }

    /// The leaf's weight in the reconstruction (`reconstruct`).
    fn weight(&self, solution: &Solution<N>, leaf: ElementId) -> [f64; 3] {
        self.albedo(solution, leaf).unwrap_or([1.0; 3])
    }
}

/// The glossy light's fits: directions and samples per vertex, counted.
struct GlossyCount {
    form: GlossyForm,
    directions: usize,
    samples: GlossySamples,
    vertices: usize,
    seconds: f64,
}

impl GlossyCount {
    /// Directions and incident samples within `options.glossy_budget` for every
    /// used vertex of every glossy side of `meshes`.
    fn new<const N: usize>(
        input: &BakeInput<'_, N>,
        options: &BakeOptions,
        meshes: &[ShapeMesh],
    ) -> Self {
        let scene = input.solution.scene();
        let mut total = 0u64;
        for mesh in meshes {
            let material = scene.material(mesh.shape as usize);
            let sides = Side::BOTH
                .iter()
                .filter(|&&s| material.has_glossy(s))
                .count();
            if sides > 0 {
                let mut used = vec![false; mesh.positions.len()];
                for &v in mesh.triangles.iter().flatten() {
                    used[v as usize] = true;
                }
                total += (sides * used.iter().filter(|&&u| u).count()) as u64;
            }
        }
        let (gather, light) = within_budget(
            options.glossy_budget,
            total,
            options.glossy_samples,
            options.glossy_light_samples,
        );
        GlossyCount {
            form: options.glossy_form,
            directions: options.glossy_directions.max(MIN_GLOSSY_DIRECTIONS) as usize,
            samples: GlossySamples {
                gather,
                light,
                links: options.glossy_links,
            },
            vertices: 0,
            seconds: 0.0,
        }
    }

    /// The SH coefficients of `mesh`'s vertices on `side` (module
    /// `directional`), when the bake has glossy light and the side's
    /// material a glossy part; `first` numbers the mesh's vertices in the
    /// bake.
    fn fit<const N: usize>(
        &mut self,
        input: &BakeInput<'_, N>,
        options: &BakeOptions,
        mesh: &ShapeMesh,
        side: Side,
        first: usize,
    ) -> Option<Vec<GlossyRecord>> {
        let light = input.glossy.filter(|_| options.glossy)?;
        let scene = input.solution.scene();
        if !scene.material(mesh.shape as usize).has_glossy(side) {
            return None;
        }
        let start = Instant::now();
        let points = mesh_points(mesh, side, first);
        if options.glossy_samples == 0 {
            return None;
        }
        let sizes = (self.form, self.directions, self.samples);
        let sh = fit_vertices(light, &points, mesh.positions.len(), sizes);
        self.vertices += points.len();
        self.seconds += start.elapsed().as_secs_f64();
        Some(sh)
    }
}

/// Every vertex a triangle of `mesh` uses, as a point of `side`, with
/// its index; `first` numbers the mesh's vertices in the bake (the
/// points' keys).
fn mesh_points(mesh: &ShapeMesh, side: Side, first: usize) -> Vec<(usize, GlossyPoint)> {
    let mut used = vec![false; mesh.positions.len()];
    for &v in mesh.triangles.iter().flatten() {
        used[v as usize] = true;
    }
    (0..mesh.positions.len())
        .filter(|&v| used[v])
        .map(|v| {
            let (surface, coord) = mesh.sites[v];
            let key = 2 * (first + v) as u64 + u64::from(side == Side::Back);
            let point = GlossyPoint {
                shape: mesh.shape,
                surface,
                coord,
                side,
                point: mesh.positions[v],
                normal: mesh.normals[v],
                key,
            };
            (v, point)
        })
        .collect()
}

/// One shape's node, mesh, materials and accessors.
fn write_shape<const N: usize>(
    doc: &mut Document,
    input: &BakeInput<'_, N>,
    mesh: &ShapeMesh,
    sides: &[SideLight<'_, N>; 2],
    scale: (f64, GlossyForm),
) -> Result<(), BakeError> {
    for light in sides {
        let sh = light.sh.iter().flatten().flatten().flatten();
        if light
            .values
            .iter()
            .flatten()
            .chain(sh)
            .any(|x| !x.is_finite())
        {
            return Err(BakeError::NotFinite { shape: mesh.shape });
        }
    }
    let shared = SharedAttributes::write(doc, mesh, sides.iter().any(|l| l.map.is_some()));
    let surfaces = by_surface(input.solution.forest(), mesh);
    let mut primitives = Vec::new();
    for light in sides {
        primitives.extend(side_primitives(
            doc,
            input,
            mesh.shape,
            light,
            (&shared, &surfaces),
            scale,
        )?);
    }
    let name = shape_name(input.names, mesh.shape);
    doc.nodes
        .push(json!({ "name": name, "mesh": doc.meshes.len() }));
    doc.meshes.push(json!({
        "name": name,
        "primitives": primitives,
        "extras": { "trilux": { "shape": mesh.shape } },
    }));
    Ok(())
}

/// The accessors both sides of a shape share: positions, the normals of
/// each side, texture coordinates when a side has an albedo map.
struct SharedAttributes {
    position: usize,
    normals: [usize; 2],
    texcoord: Option<usize>,
}

impl SharedAttributes {
    fn write(doc: &mut Document, mesh: &ShapeMesh, texcoords: bool) -> Self {
        let f32s =
            |v: &[DVec3]| -> Vec<[f32; 3]> { v.iter().map(|p| p.as_vec3().to_array()).collect() };
        let flipped: Vec<DVec3> = mesh.normals.iter().map(|n| -*n).collect();
        let position = doc.vec3(&f32s(&mesh.positions), true);
        let normals = [
            doc.vec3(&f32s(&mesh.normals), false),
            doc.vec3(&f32s(&flipped), false),
        ];
        let texcoord = texcoords.then(|| {
            let uv: Vec<[f32; 2]> = mesh
                .texcoords
                .iter()
                .map(|t| t.unwrap_or_default().as_vec2().to_array())
                .collect();
            doc.vec2(&uv)
        });
        SharedAttributes {
            position,
            normals,
            texcoord,
        }
    }
}

/// One side's colours, material and a primitive per input surface.
fn side_primitives<const N: usize>(
    doc: &mut Document,
    input: &BakeInput<'_, N>,
    shape: u32,
    light: &SideLight<'_, N>,
    (shared, surfaces): (&SharedAttributes, &[SurfaceTriangles]),
    (scale, form): (f64, GlossyForm),
) -> Result<Vec<Value>, BakeError> {
    let side = light.side;
    let radiance: Vec<[f32; 3]> = light.values.iter().map(|c| c.map(|x| x as f32)).collect();
    let display: Vec<[f32; 3]> = light
        .values
        .iter()
        .map(|c| c.map(|x| (x * scale).clamp(0.0, 1.0) as f32))
        .collect();
    let (radiance, display) = (doc.vec3(&radiance, false), doc.vec3(&display, false));
    let material = doc.materials.len();
    let mut m = material_of(input, shape, side);
    m["extras"]["trilux"]["glossy_left_out"] =
        json!(light.sh.is_none() && glossy_side(input, shape, side));
    if light.sh.is_some() {
        m["extras"]["trilux"]["glossy"] = json!(form.name());
    }
    if let Some(map) = &light.map {
        let png = map.png().map_err(|e| BakeError::Image(e.to_string()))?;
        let texture = doc.png_texture(&png, map.sampler());
        m["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": texture, "texCoord": 0 });
        m["extras"]["trilux"]["albedo_map"] = json!(true);
    }
    doc.materials.push(m);
    let mut attributes = json!({
        "POSITION": shared.position,
        "NORMAL": shared.normals[usize::from(side == Side::Back)],
        "COLOR_0": display,
        "_RADIANCE": radiance,
    });
    if let (Some(uv), Some(_)) = (shared.texcoord, &light.map) {
        attributes["TEXCOORD_0"] = json!(uv);
    }
    if let Some(sh) = &light.sh {
        for (j, name) in form.attributes().iter().enumerate() {
            let c: Vec<[f32; 3]> = sh.iter().map(|v| v[j].map(|x| x as f32)).collect();
            attributes[*name] = json!(doc.vec3(&c, false));
        }
    }
    let mut primitives = Vec::new();
    for (surface, triangles) in surfaces {
        let triangles: Vec<[u32; 3]> = match side {
            Side::Front => triangles.clone(),
            Side::Back => triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        };
        primitives.push(json!({
            "attributes": attributes,
            "indices": doc.indices(&triangles),
            "material": material,
            "mode": 4,
            "extras": { "trilux": { "surface": surface.0, "side": side_name(side) } },
        }));
    }
    Ok(primitives)
}

/// An input surface and its triangles in a shape's mesh.
type SurfaceTriangles = (SurfaceId, Vec<[u32; 3]>);

/// The mesh's triangles by input surface, in surface order (one pass).
fn by_surface(forest: &ElementForest, mesh: &ShapeMesh) -> Vec<SurfaceTriangles> {
    let mut groups: BTreeMap<u32, Vec<[u32; 3]>> = BTreeMap::new();
    for (tri, &owner) in mesh.triangles.iter().zip(&mesh.owners) {
        groups
            .entry(forest.element(owner).surface.0)
            .or_default()
            .push(*tri);
    }
    groups.into_iter().map(|(s, t)| (SurfaceId(s), t)).collect()
}

fn shape_name(names: &[Option<String>], shape: u32) -> String {
    match names.get(shape as usize) {
        Some(Some(id)) => id.clone(),
        _ => format!("shape {shape}"),
    }
}

fn side_name(side: Side) -> &'static str {
    match side {
        Side::Front => "front",
        Side::Back => "back",
    }
}

/// An unlit material showing `COLOR_0`, the scene's own in `extras`.
fn material_of<const N: usize>(input: &BakeInput<'_, N>, shape: u32, side: Side) -> Value {
    let bsdf = input
        .materials
        .get(shape as usize)
        .and_then(|b| serde_json::to_value(b).ok())
        .unwrap_or(Value::Null);
    let glossy = glossy_side(input, shape, side);
    json!({
        "name": format!("{} ({})", shape_name(input.names, shape), side_name(side)),
        "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "extensions": { "KHR_materials_unlit": {} },
        "extras": { "trilux": {
            "shape": shape,
            "side": side_name(side),
            "bsdf": bsdf,
            "glossy_left_out": glossy,
        } },
    })
}

/// The side's material has a glossy part.
fn glossy_side<const N: usize>(input: &BakeInput<'_, N>, shape: u32, side: Side) -> bool {
    input
        .solution
        .scene()
        .material(shape as usize)
        .has_glossy(side)
}

/// The scene camera's node and camera.
fn write_camera<const N: usize>(doc: &mut Document, solution: &Solution<N>, camera: &BakeCamera) {
    let Some((origin, rotation)) = camera.pose() else {
        return;
    };
    let bounds = solution.forest().geometry().bounds();
    let extent = (bounds.max - bounds.min).length();
    let distance = (0.5 * (bounds.min + bounds.max) - origin).length();
    doc.cameras.push(camera.gltf_camera(extent, distance));
    doc.nodes.push(json!({
        "name": "camera",
        "camera": 0,
        "translation": origin.to_array(),
        "rotation": rotation.to_array(),
    }));
}

fn asset(options: &BakeOptions) -> Value {
    json!({
        "version": "2.0",
        "generator": concat!("trilux ", env!("CARGO_PKG_VERSION")),
        "extras": { "trilux": {
            "exposure": options.exposure,
            "colour": "_RADIANCE is linear Rec. 709 radiance (W sr^-1 m^-2 per channel); COLOR_0 is it times 2^exposure, clamped to [0, 1]",
            "baked": "the view-independent (Lambertian) light of the solution, emission included",
            "left_out": "the glossy (view-dependent) reflection of materials marked glossy_left_out",
            "glossy": "on materials marked glossy, the glossy outgoing radiance towards a world direction w (unit, from the point to the eye), added to _RADIANCE: \"sh2+lobe\": max(0, sum_{j<9} _TRILUX_SHj * Y_j(w) + _TRILUX_LOBE_RGB * exp(dot(v, w) - |v|)), v = _TRILUX_LOBE; \"sh2\": max(0, sum_{j<9} _TRILUX_SHj * Y_j(w)); Y the real spherical harmonics Y_0 = 0.282095, Y_1..3 = 0.488603 (y, z, x), Y_4 = 1.092548 xy, Y_5 = 1.092548 yz, Y_6 = 0.315392 (3z^2 - 1), Y_7 = 1.092548 xz, Y_8 = 0.546274 (x^2 - y^2)",
        } },
    })
}

/// The baked flux of every input surface and side against the solution's.
#[derive(Default)]
struct FluxCheck {
    /// (baked, solution) flux sums over bands, without the factor π.
    pairs: Vec<(f64, f64)>,
}

impl FluxCheck {
    fn add<const N: usize>(
        &mut self,
        solution: &Solution<N>,
        mesh: &ShapeMesh,
        side: Side,
        light: &SideLight<'_, N>,
    ) {
        let forest = solution.forest();
        let baked = baked_flux(
            mesh,
            &light.values,
            |leaf| light.weight(solution, leaf),
            |leaf| forest.element(leaf).surface.0,
        );
        for surface in forest.geometry().surfaces_of_shape(mesh.shape) {
            let exact: f64 = forest
                .leaves(forest.root(surface))
                .into_iter()
                .map(|leaf| {
                    leaf_value(solution, side, leaf).iter().sum::<f64>() * forest.element(leaf).area
                })
                .sum();
            let baked = baked.get(&surface.0).map_or(0.0, |f| f.iter().sum());
            self.pairs.push((baked, exact));
        }
    }

    fn max_error(&self) -> f64 {
        let largest = self.pairs.iter().map(|p| p.1).fold(0.0, f64::max);
        self.pairs
            .iter()
            .filter(|(_, exact)| *exact > 1e-6 * largest)
            .map(|(baked, exact)| (baked - exact).abs() / exact)
            .fold(0.0, f64::max)
    }
}

/// The gather and light samples per glossy vertex (`gather`, `light`
/// asked) that keep `vertices` within `budget` estimates, both scaled
/// alike and to a quarter at least; as asked when there is no glossy
/// vertex.
fn within_budget(budget: u64, vertices: u64, gather: u32, light: u32) -> (u32, u32) {
    let per_vertex = budget.checked_div(vertices).unwrap_or(u64::MAX);
    let (g, l) = (u64::from(gather), u64::from(light));
    let scale = |n: u64| {
        // Saturating: with no glossy vertex per_vertex is u64::MAX.
        let fit = n.saturating_mul(per_vertex).checked_div(g + l).unwrap_or(n);
        fit.clamp(n.div_ceil(4).max(1), n.max(1)) as u32
    };
    (scale(g), scale(l))
}

#[cfg(test)]
mod tests {
    use super::within_budget;

    #[test]
    fn sample_counts_stay_within_the_budget_and_are_asked_without_glossy_vertices() {
        // No glossy vertex (a diffuse scene baked with glossy light on):
        // the counts asked, no overflow.
        assert_eq!(within_budget(8_000_000, 0, 16, 8), (16, 8));
        // Room for all: as asked.
        assert_eq!(within_budget(8_000_000, 1_000, 16, 8), (16, 8));
        // 24 estimates a vertex asked, 12 allowed: both halved.
        assert_eq!(within_budget(12_000, 1_000, 16, 8), (8, 4));
        // Far over: a quarter at least.
        assert_eq!(within_budget(1, 1_000_000, 16, 8), (4, 2));
    }
}
