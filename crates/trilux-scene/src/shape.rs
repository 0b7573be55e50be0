//! `<shape>` elements → [`Shape`], and the surface area of a shape.
//!
//! Object-space conventions are Mitsuba 3's (see [`ShapeKind`]). A sphere's
//! `center`/`radius` and a cylinder's `p0`/`p1`/`radius` are kept in object
//! space and combined with `to_world` by the geometry layer, as Mitsuba
//! combines them (`to_world · translate(center) · scale(radius)`).
//!
//! Refused, each at the place that causes it: a singular `to_world` (a zero
//! scale), zero radius or length, a sphere scaled non-uniformly, a cylinder
//! whose cross-section is not a circle after `to_world` (Mitsuba only warns;
//! the exact analytic intersection needs a circle), a zero total area of an
//! analytic shape, and a missing or malformed mesh file. A mesh file (OBJ,
//! PLY, serialized) is only named here (`MeshRequest`); it is read once the
//! whole scene file is checked (`crate::meshes`), where its zero-area
//! triangles, or the whole mesh if they all are, are left out with a
//! warning as Mitsuba loads them and never hits them.

use std::path::Path;

use glam::{DMat3, DMat4, DVec3};
use trilux_geometry::limits::{MAX_COORDINATE, within};
use trilux_geometry::{Shape, ShapeKind, coordinate_system};

use crate::error::{Result, SceneError, SourceLocation};
use crate::props::Props;
use crate::transform::linear_part;

/// Surface area of a shape in world space (one side).
///
/// Exact for every kind: parallelograms for rectangles and cube faces, an
/// ellipse for a disk under any affine map, 4πr² for a uniformly scaled
/// sphere, 2πrh for a cylinder whose cross-section stays circular, and the
/// sum of the transformed triangles for a mesh. Never panics; a shape the
/// loader would refuse may give 0 or a non-finite value.
pub fn surface_area(shape: &Shape) -> f64 {
    let l = linear_part(&shape.world_from_object);
    let (x, y, z) = (l.x_axis, l.y_axis, l.z_axis);
    match &shape.kind {
        ShapeKind::Rectangle => 4.0 * x.cross(y).length(),
        ShapeKind::Cube => 8.0 * (y.cross(z).length() + x.cross(z).length() + x.cross(y).length()),
        ShapeKind::Disk => std::f64::consts::PI * x.cross(y).length(),
        ShapeKind::Sphere { radius, .. } => {
            let s = x.length() * radius;
            4.0 * std::f64::consts::PI * s * s
        }
        ShapeKind::Cylinder { p0, p1, radius } => {
            let (s, _, _) = cylinder_frame(*p0, *p1);
            2.0 * std::f64::consts::PI * (l * s).length() * radius * (l * (*p1 - *p0)).length()
        }
        ShapeKind::Mesh(mesh) => mesh
            .triangles
            .iter()
            .map(|t| {
                // A triangle naming a vertex that does not exist has no area
                // (the loader never makes one; the geometry layer refuses it).
                let p = |i: u32| mesh.positions.get(i as usize).map(|&p| l * p);
                match (p(t[0]), p(t[1]), p(t[2])) {
                    (Some(a), Some(b), Some(c)) => 0.5 * (b - a).cross(c - a).length(),
                    _ => 0.0,
                }
            })
            .sum(),
    }
}

/// Mitsuba's cylinder frame: (s, t, n) with n along p1 − p0 (zero vectors
/// when p0 = p1).
fn cylinder_frame(p0: DVec3, p1: DVec3) -> (DVec3, DVec3, DVec3) {
    let d = p1 - p0;
    if d.length_squared() == 0.0 {
        return (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    }
    let n = d.normalize();
    let (s, t) = coordinate_system(n);
    (s, t, n)
}

/// True when `a` and `b` have the same length and are orthogonal (relative
/// tolerance 1e-6, far below anything a scene author means).
fn same_length_orthogonal(a: DVec3, b: DVec3) -> bool {
    let (la, lb) = (a.length(), b.length());
    (la - lb).abs() <= 1e-6 * la.max(lb) && a.dot(b).abs() <= 1e-6 * la * lb
}

/// The mesh file formats a `<shape>` can name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum MeshFormat {
    /// Wavefront OBJ (`crate::obj`).
    Obj,
    /// Stanford PLY (`crate::ply`).
    Ply,
    /// Mesh `shape_index` of a Mitsuba serialized file
    /// (`crate::serialized`).
    Serialized {
        /// Which mesh of the file.
        shape_index: u32,
    },
}

impl MeshFormat {
    /// Reads `path` in this format; the error is one line naming the file.
    pub fn load(
        self,
        path: &std::path::Path,
        face_normals: bool,
        flip_tex_coords: bool,
    ) -> std::result::Result<trilux_geometry::TriangleMesh, String> {
        match self {
            MeshFormat::Obj => {
                crate::obj::load_obj(path, face_normals, flip_tex_coords).map_err(|e| e.to_string())
            }
            MeshFormat::Ply => {
                crate::ply::load_ply(path, face_normals, flip_tex_coords).map_err(|e| e.to_string())
            }
            MeshFormat::Serialized { shape_index } => {
                crate::serialized::load_serialized(path, shape_index, face_normals)
                    .map_err(|e| e.to_string())
            }
        }
    }

    /// The shape element that names a file of this format.
    pub fn element(self) -> &'static str {
        match self {
            MeshFormat::Obj => "<shape type=\"obj\">",
            MeshFormat::Ply => "<shape type=\"ply\">",
            MeshFormat::Serialized { .. } => "<shape type=\"serialized\">",
        }
    }

    /// Mitsuba's default `flip_tex_coords`: OBJ's v runs up, PLY's is
    /// taken as written.
    pub(crate) fn flips_by_default(self) -> bool {
        self == MeshFormat::Obj
    }
}

/// A mesh file a `<shape type="obj">` or `<shape type="ply">` names, to be
/// read after the whole scene file is checked.
#[derive(Clone, Debug)]
pub(crate) struct MeshRequest {
    /// The file's format.
    pub format: MeshFormat,
    /// The file (relative names resolved against the scene's folder).
    pub path: std::path::PathBuf,
    /// `face_normals` of the shape.
    pub face_normals: bool,
    /// `flip_tex_coords` of the shape (its format's default otherwise).
    pub flip_tex_coords: bool,
    /// Where the file name is written.
    pub filename: SourceLocation,
    /// Where the `<shape>` is written.
    pub shape: SourceLocation,
}

/// Builds the shape of a `<shape>` element. `props` are its parameters;
/// `folder` is the scene file's folder (OBJ file names are relative to it).
/// An OBJ shape comes with an empty mesh and the request to read it.
pub(crate) fn build_shape(
    props: &Props<'_>,
    folder: &Path,
) -> Result<(Shape, Option<MeshRequest>)> {
    let e = props.owner();
    let to_world = props
        .transform("to_world")?
        .map(|t| t.matrix)
        .unwrap_or_default();
    let flip_normals = props.boolean("flip_normals")?.unwrap_or(false);
    // How often Mitsuba's differentiable renderers sample the silhouette:
    // not the light.
    props.float("silhouette_sampling_weight")?;
    let l = check_to_world(props, &to_world)?;
    let mut request = None;
    let plugin = e.plugin_type()?;
    let kind = match plugin {
        // Mitsuba's rectangle and cube are meshes with a normal per face
        // already: `face_normals` changes nothing.
        "rectangle" | "cube" => {
            props.boolean("face_normals")?;
            match plugin {
                "rectangle" => ShapeKind::Rectangle,
                _ => ShapeKind::Cube,
            }
        }
        "disk" => ShapeKind::Disk,
        "sphere" => sphere(props, &l)?,
        "cylinder" => cylinder(props, &l)?,
        "obj" | "ply" | "serialized" => {
            let (kind, mesh) = mesh(props, plugin, folder)?;
            request = Some(mesh);
            kind
        }
        other => {
            return Err(SceneError::at(
                &e.required("type")?.loc,
                format!(
                    "unknown shape plugin \"{other}\" (supported: rectangle, cube, disk, sphere, cylinder, obj, ply, serialized)"
                ),
            ));
        }
    };
    let shape = Shape {
        kind,
        world_from_object: to_world,
        flip_normals,
    };
    if request.is_none() {
        check_area(&shape, &e.loc, &e.describe())?;
    }
    Ok((shape, request))
}

/// Refuses a `to_world` beyond the coordinate limits or singular; returns
/// its linear part.
fn check_to_world(props: &Props<'_>, to_world: &DMat4) -> Result<DMat3> {
    let l: DMat3 = linear_part(to_world);
    let largest = to_world
        .to_cols_array()
        .into_iter()
        .map(f64::abs)
        .fold(0.0, f64::max);
    if !within(largest) {
        return Err(SceneError::at(
            &props.loc("to_world"),
            format!(
                "to_world scales or moves by {largest:e}, beyond the coordinate limit ±{MAX_COORDINATE:e} (docs/limits.md)"
            ),
        ));
    }
    let scale = l.x_axis.length() * l.y_axis.length() * l.z_axis.length();
    if l.determinant().abs() <= 1e-12 * scale {
        return Err(SceneError::at(
            &props.loc("to_world"),
            "to_world is singular (a zero scale?): the shape would have no area or no normal",
        ));
    }
    Ok(l)
}

/// The float parameter `name` (else `default`), which must be positive.
fn positive(props: &Props<'_>, name: &str, default: f64) -> Result<f64> {
    let v = props.float(name)?.unwrap_or(default);
    if v <= 0.0 {
        return Err(SceneError::at(
            &props.loc(name),
            format!("{name} must be positive, found {v}"),
        ));
    }
    Ok(v)
}

/// A `sphere`: its centre and radius; `l` (its `to_world`'s linear part)
/// must scale uniformly, or it would be an ellipsoid.
fn sphere(props: &Props<'_>, l: &DMat3) -> Result<ShapeKind> {
    let center = props.vec3("center")?.unwrap_or(DVec3::ZERO);
    let radius = positive(props, "radius", 1.0)?;
    if !(same_length_orthogonal(l.x_axis, l.y_axis)
        && same_length_orthogonal(l.y_axis, l.z_axis)
        && same_length_orthogonal(l.x_axis, l.z_axis))
    {
        return Err(SceneError::at(
            &props.loc("to_world"),
            "a sphere's to_world must scale uniformly (no non-uniform scale or shear)",
        ));
    }
    Ok(ShapeKind::Sphere { center, radius })
}

/// A `cylinder` from `p0` to `p1`; `l` must keep its cross-section a
/// circle perpendicular to its axis.
fn cylinder(props: &Props<'_>, l: &DMat3) -> Result<ShapeKind> {
    let p0 = props.vec3("p0")?.unwrap_or(DVec3::ZERO);
    let p1 = props.vec3("p1")?.unwrap_or(DVec3::Z);
    let radius = positive(props, "radius", 1.0)?;
    let (s, t, n) = cylinder_frame(p0, p1);
    if n == DVec3::ZERO {
        return Err(SceneError::at(
            &props.loc("p1"),
            "cylinder p0 and p1 are the same point (zero length)",
        ));
    }
    let (ws, wt, wn) = (*l * s, *l * t, *l * n);
    let tol = 1e-6 * ws.length() * wn.length();
    if !same_length_orthogonal(ws, wt) || ws.dot(wn).abs() > tol || wt.dot(wn).abs() > tol {
        return Err(SceneError::at(
            &props.loc("to_world"),
            "a cylinder's to_world must keep its cross-section circular and its axis perpendicular to it",
        ));
    }
    Ok(ShapeKind::Cylinder { p0, p1, radius })
}

/// An `obj`, `ply` or `serialized` shape: an empty mesh (with its `face_normals` choice)
/// and the request to read its file, relative to `folder`.
fn mesh(props: &Props<'_>, plugin: &str, folder: &Path) -> Result<(ShapeKind, MeshRequest)> {
    let e = props.owner();
    let name = props.string("filename")?.ok_or_else(|| {
        SceneError::at(
            &e.loc,
            format!("<shape type=\"{plugin}\"> needs <string name=\"filename\">"),
        )
    })?;
    let face_normals = props.boolean("face_normals")?.unwrap_or(false);
    let format = match plugin {
        "obj" => MeshFormat::Obj,
        "ply" => MeshFormat::Ply,
        _ => MeshFormat::Serialized {
            shape_index: shape_index(props)?,
        },
    };
    // Mitsuba's serialized plugin has no `flip_tex_coords`: it keeps them.
    let flip_tex_coords = match format {
        MeshFormat::Serialized { .. } => false,
        _ => props
            .boolean("flip_tex_coords")?
            .unwrap_or(format.flips_by_default()),
    };
    let request = MeshRequest {
        format,
        path: folder.join(&name),
        face_normals,
        flip_tex_coords,
        filename: props.loc("filename"),
        shape: e.loc.clone(),
    };
    let kind = ShapeKind::Mesh(trilux_geometry::TriangleMesh {
        face_normals,
        ..Default::default()
    });
    Ok((kind, request))
}

/// A serialized shape's `shape_index` (Mitsuba's default 0), which must
/// not be negative; whether the file holds that many meshes is checked
/// when it is read.
fn shape_index(props: &Props<'_>) -> Result<u32> {
    let index = props.integer("shape_index")?.unwrap_or(0);
    u32::try_from(index).map_err(|_| {
        SceneError::at(
            &props.loc("shape_index"),
            format!("shape_index must be a mesh index (0, 1, ...), found {index}"),
        )
    })
}

/// Refuses a shape of zero (or non-finite) area, at `loc`.
pub(crate) fn check_area(shape: &Shape, loc: &SourceLocation, describe: &str) -> Result<()> {
    let area = surface_area(shape);
    if !(area > 0.0 && area.is_finite()) {
        return Err(SceneError::at(loc, format!("{describe} has zero area")));
    }
    Ok(())
}
