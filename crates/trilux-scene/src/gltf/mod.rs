//! glTF 2.0 scenes (`.gltf` with its buffers and images beside it, or one
//! `.glb`) into the same [`Scene`] as the Mitsuba XML subset, with the
//! `gltf` crate's JSON parsing and validation (indices in range, required
//! fields) and without its `import` feature: buffers and images are
//! resolved here, with bounded reads (`buffers`).
//!
//! Stages, as for XML:
//! 1. `open`: the file (bounded), its JSON validated, required extensions
//!    checked, the default scene's node hierarchy walked (`nodes`): every
//!    mesh primitive of every node becomes one shape (one input-surface
//!    chart set per primitive, as an OBJ), its material mapped
//!    (`material`), the camera chosen. Nothing large is read yet.
//! 2. `GltfMeshes::finish` (from [`crate::Pending::finish`]): the buffers
//!    are read, the accessors checked and read (`accessor`), each mesh
//!    put into world space (so a mirroring node keeps glTF's winding rule),
//!    and the textures requested.
//!
//! Errors name the file and the JSON path: `scene.gltf:/meshes/0/primitives/1/mode: ...`.

mod accessor;
mod buffers;
mod lights;
mod material;
mod nodes;

use std::path::Path;
use std::sync::Arc;

use crate::error::{Errors, Result, SceneError, SourceLocation};
use crate::limits::{MAX_GLB_BYTES, MAX_SCENE_BYTES};
use crate::scene::Scene;

pub(crate) use nodes::GltfMeshes;

/// Extensions a file may require (others in `extensionsRequired` are
/// refused; others only used are refused where they may change the light,
/// see [`IGNORED_EXTENSIONS`]).
pub(crate) const SUPPORTED_EXTENSIONS: [&str; 3] = [
    "KHR_materials_specular",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
];

/// True when `path` names a glTF file (`.gltf` or `.glb`, any case).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// Reads and checks a glTF file, all but its buffers and images (the
/// returned [`GltfMeshes`] read them); `camera` names the camera to use (a
/// camera's or its node's name), else the first one in the scene.
pub(crate) fn open(path: &Path, camera: Option<&str>) -> Result<(Scene, GltfMeshes)> {
    let file: Arc<Path> = Arc::from(path);
    let glb = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let limit = if glb { MAX_GLB_BYTES } else { MAX_SCENE_BYTES };
    let bytes = trilux_files::read_limited(path, limit).map_err(|source| SceneError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    open_bytes(&bytes, &file, camera)
}

/// [`open`] on the bytes of a glTF or GLB file; `file` names it in errors
/// and anchors relative URIs.
pub(crate) fn open_bytes(
    bytes: &[u8],
    file: &Arc<Path>,
    camera: Option<&str>,
) -> Result<(Scene, GltfMeshes)> {
    let gltf = parse(bytes, file)?;
    if let Some(ext) = gltf
        .document
        .extensions_required()
        .find(|e| !SUPPORTED_EXTENSIONS.contains(e))
    {
        return Err(SceneError::at(
            &SourceLocation::json(file, "/extensionsRequired"),
            format!(
                "the file requires extension {ext}, which trilux does not support (supported: {})",
                SUPPORTED_EXTENSIONS.join(", ")
            ),
        ));
    }
    let used: Vec<String> = gltf.document.extensions_used().map(String::from).collect();
    let mut errors = Errors::default();
    let built = match nodes::build(file, gltf, camera, &mut errors) {
        Ok(built) => built,
        Err(limit) => return Err(errors.stop(limit)),
    };
    // Only after a clean walk: an extension refused where it is used is
    // not reported a second time at its listing.
    if errors.is_empty() {
        errors.keep(refuse_used(file, &used));
    }
    errors.or(built)
}

/// Extensions ignored because they do not change the light: variants
/// (the default material is the one rendered), XMP metadata, quantized
/// attributes (the accessors trilux cannot read are refused there), and
/// alternative image formats (the texture's fallback `source` is read).
pub(crate) const IGNORED_EXTENSIONS: [&str; 5] = [
    "KHR_materials_variants",
    "KHR_xmp_json_ld",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "EXT_texture_webp",
];

/// Extensions checked where they occur (a punctual light on a node; an
/// index of refraction on a material, accepted at glTF's default 1.5).
const CHECKED_WHERE_USED: [&str; 2] = ["KHR_lights_punctual", "KHR_materials_ior"];

/// Refuses an extension listed in `extensionsUsed` that trilux neither
/// implements nor ignores: after the walk, so that one used on a material
/// or node of the scene is named there first.
fn refuse_used(file: &Arc<Path>, used: &[String]) -> Result<()> {
    let known = |e: &str| {
        SUPPORTED_EXTENSIONS.contains(&e)
            || IGNORED_EXTENSIONS.contains(&e)
            || CHECKED_WHERE_USED.contains(&e)
    };
    match used.iter().enumerate().find(|(_, e)| !known(e)) {
        Some((i, e)) => Err(SceneError::at(
            &SourceLocation::json(file, format!("/extensionsUsed/{i}")),
            refusal(e),
        )),
        None => Ok(()),
    }
}

/// Why an extension trilux does not implement is refused rather than
/// ignored: ignoring it would render something other than the file.
pub(crate) fn refusal(ext: &str) -> String {
    let why = match ext {
        "KHR_materials_transmission"
        | "KHR_materials_volume"
        | "KHR_materials_diffuse_transmission"
        | "KHR_materials_dispersion" => {
            "it lets light through the surface, and trilux's surfaces are opaque (ignored, glass would render as an opaque surface)"
        }
        "KHR_materials_ior" => {
            "an index of refraction other than glTF's default 1.5 changes the dielectric's reflectance, which trilux fixes at that default"
        }
        "KHR_materials_clearcoat"
        | "KHR_materials_sheen"
        | "KHR_materials_iridescence"
        | "KHR_materials_anisotropy"
        | "KHR_materials_pbrSpecularGlossiness"
        | "KHR_materials_unlit" => {
            "it changes how the surface reflects light, which trilux's materials do not model"
        }
        _ => "trilux does not implement it, and it may change the light",
    };
    format!("extension {ext} is refused rather than ignored: {why} (docs/gltf.md)")
}

/// A `gltf` crate error as one located line.
/// The document, validated by the `gltf` crate after the one check its
/// validation needs first: it indexes each primitive's POSITION accessor
/// before checking that the accessor exists (and panics where not).
fn parse(bytes: &[u8], file: &Arc<Path>) -> Result<gltf::Gltf> {
    let unchecked =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| parse_error(file, e))?;
    let json = unchecked.document.as_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (k, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= json.accessors.len() {
                    let name = match semantic {
                        gltf::json::validation::Checked::Valid(s) => s.to_string(),
                        gltf::json::validation::Checked::Invalid => "an attribute".into(),
                    };
                    return Err(SceneError::at(
                        &SourceLocation::json(
                            file,
                            format!("/meshes/{m}/primitives/{k}/attributes"),
                        ),
                        format!(
                            "{name} names accessor {}, which does not exist",
                            index.value()
                        ),
                    ));
                }
            }
        }
    }
    let blob = unchecked.blob;
    let document = gltf::Document::from_json(unchecked.document.into_json())
        .map_err(|e| parse_error(file, e))?;
    Ok(gltf::Gltf { document, blob })
}

fn parse_error(file: &Arc<Path>, e: gltf::Error) -> SceneError {
    match e {
        gltf::Error::Validation(problems) => {
            // Each problem is at its own JSON path: all are reported.
            let mut errors = Errors::default();
            for (p, e) in &problems {
                errors.push(SceneError::at(
                    &SourceLocation::json(file, pointer(&p.to_string())),
                    format!("invalid glTF: {e}"),
                ));
            }
            match errors.or(()) {
                Err(e) => e,
                Ok(()) => SceneError::at(&SourceLocation::json(file, "/"), "invalid glTF"),
            }
        }
        gltf::Error::Deserialize(e) => SceneError::at(
            &SourceLocation {
                file: Arc::clone(file),
                line: e.line() as u32,
                col: e.column() as u32,
                pointer: None,
            },
            format!("malformed glTF JSON: {e}"),
        ),
        gltf::Error::Binary(e) => SceneError::at(
            &SourceLocation::json(file, "/"),
            format!("malformed GLB file: {e:?}"),
        ),
        other => SceneError::at(&SourceLocation::json(file, "/"), other.to_string()),
    }
}

/// The `gltf` crate's path (`meshes[0].primitives[1].mode`) as a JSON
/// pointer (`/meshes/0/primitives/1/mode`).
fn pointer(path: &str) -> String {
    let mut out = String::from("/");
    for c in path.chars() {
        match c {
            '.' | '[' => out.push('/'),
            ']' | '"' => {}
            c => out.push(c),
        }
    }
    out.replace("//", "/")
}
