//! Wavefront OBJ meshes (`<shape type="obj">`), read with `tobj`.
//!
//! Texture coordinates (`vt`) are kept when every vertex has them, with v
//! flipped as Mitsuba's loader flips it. Polygons of up to `FAN_MAX` vertices are
//! triangulated as fans from their first vertex (as Mitsuba's and tobj's
//! loaders do), larger ones by halving ([`triangulate`]); vertices are shared when they share
//! position, texture and normal indices (as Mitsuba's own OBJ loader keys
//! them). Materials (`mtllib`) are ignored, as Mitsuba ignores them.
//!
//! Shading normals follow Mitsuba 3: the file's `vn` when it has them for
//! every vertex; otherwise, unless `face_normals` is set, smooth vertex
//! normals recomputed from the faces with angle weights (Thürmer & Wüthrich,
//! the weighting Mitsuba's `recompute_vertex_normals` uses). With
//! `face_normals` there are none.
//!
//! The file must be a regular file of at most [`MAX_MESH_BYTES`]
//! (`/dev/zero` is an error, not an endless read); [`parse_obj`] reads the
//! same format from bytes already in memory.

use std::path::Path;

use crate::limits::MAX_MESH_BYTES;

use glam::{DVec2, DVec3};
use trilux_geometry::TriangleMesh;

/// Why an OBJ file could not be read (the caller adds the scene location).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ObjError {
    /// The file could not be read (missing, not a regular file, too
    /// large).
    #[error("cannot read OBJ file {}: {source}", path.display())]
    Io {
        /// The OBJ file.
        path: std::path::PathBuf,
        /// Why.
        #[source]
        source: trilux_files::ReadError,
    },
    /// tobj refused the contents.
    #[error("malformed OBJ file {}: {reason}", path.display())]
    Parse {
        /// The OBJ file.
        path: std::path::PathBuf,
        /// tobj's reason.
        reason: String,
    },
    /// The file holds no triangles.
    #[error("OBJ file {} has no faces", path.display())]
    Empty {
        /// The OBJ file.
        path: std::path::PathBuf,
    },
    /// The mesh has more triangles or vertices than the loader takes.
    #[error("OBJ file {} has {triangles} triangles and {vertices} vertices; the limits are {} and {} (docs/limits.md)", path.display(), crate::limits::MAX_MESH_TRIANGLES, crate::limits::MAX_MESH_VERTICES)]
    TooLarge {
        /// The OBJ file.
        path: std::path::PathBuf,
        /// Its triangles.
        triangles: usize,
        /// Its vertices (after splitting by position, texture and normal).
        vertices: usize,
    },
    /// A coordinate is not finite.
    #[error("OBJ file {} has a coordinate that is not a finite number", path.display())]
    NotFinite {
        /// The OBJ file.
        path: std::path::PathBuf,
    },
}

/// Reads an OBJ file into one triangle mesh (all its objects merged);
/// `flip_tex_coords` is Mitsuba's parameter (true by default: v ↦ 1 − v).
pub(crate) fn load_obj(
    path: &Path,
    face_normals: bool,
    flip_tex_coords: bool,
) -> Result<TriangleMesh, ObjError> {
    let bytes =
        trilux_files::read_limited(path, MAX_MESH_BYTES).map_err(|source| ObjError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    parse_obj(&bytes, path, face_normals, flip_tex_coords)
}

/// `load_obj` on the bytes of an OBJ file; `path` names it in errors.
pub fn parse_obj(
    bytes: &[u8],
    path: &Path,
    face_normals: bool,
    flip_tex_coords: bool,
) -> Result<TriangleMesh, ObjError> {
    // Before tobj spends memory on them: every face line makes at least
    // one triangle, every vertex line one position.
    let (faces, positions) = count_lines(bytes);
    if faces > crate::limits::MAX_MESH_TRIANGLES || positions > crate::limits::MAX_MESH_VERTICES {
        return Err(ObjError::TooLarge {
            path: path.to_path_buf(),
            triangles: faces,
            vertices: positions,
        });
    }
    if let Some(index) = bad_face_index(bytes) {
        return Err(ObjError::Parse {
            path: path.to_path_buf(),
            reason: format!("a face refers to vertex index {index}, which no vertex line has"),
        });
    }
    let models = load_models(bytes, path)?;
    merge_models(&models, path, face_normals, flip_tex_coords)
}

/// Polygons of up to this many vertices are triangulated as fans from
/// their first vertex; larger ones by halving ([`triangulate`]).
pub(crate) const FAN_MAX: usize = 64;

/// The triangles of faces of `arities` vertices each (all triangles when
/// `arities` is empty, as tobj gives them), each face's indices in turn in
/// `indices`. A face of up to `FAN_MAX` vertices is a fan from its first
/// vertex. A larger one is cut by the chord from its first vertex to its
/// middle one, and each part again (a triangle of the first, middle and
/// last vertex of every arc): a fan of a polygon of a million vertices is
/// a million slivers whose boxes all reach the first vertex, so every ray
/// near it tests most of them, while the halves' triangles shrink with
/// their depth (log₂ n levels). Both keep the polygon's winding and cover
/// the same area when it is convex.
pub fn triangulate(indices: &[u32], arities: &[u32], mut push: impl FnMut([u32; 3])) {
    if arities.is_empty() {
        for t in indices.chunks_exact(3) {
            push([t[0], t[1], t[2]]);
        }
        return;
    }
    let mut start = 0;
    for &k in arities {
        let k = k as usize;
        let Some(face) = indices.get(start..start + k) else {
            return;
        };
        start += k;
        if k < 3 {
            continue;
        }
        if k <= FAN_MAX {
            for i in 1..k - 1 {
                push([face[0], face[i], face[i + 1]]);
            }
            continue;
        }
        let mut arcs = vec![(0, k - 1)];
        while let Some((a, b)) = arcs.pop() {
            if b - a >= 2 {
                let m = (a + b) / 2;
                push([face[a], face[m], face[b]]);
                arcs.push((m, b));
                arcs.push((a, m));
            }
        }
    }
}

/// Triangles the faces make ([`triangulate`]).
fn triangle_count(m: &tobj::Mesh) -> usize {
    if m.face_arities.is_empty() {
        m.indices.len() / 3
    } else {
        m.face_arities
            .iter()
            .map(|&k| (k as usize).saturating_sub(2))
            .sum()
    }
}

/// The OBJ's models as tobj reads them (faces with their arities, one
/// index per vertex), refused beyond the mesh limits.
fn load_models(bytes: &[u8], path: &Path) -> Result<Vec<tobj::Model>, ObjError> {
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj_buf(&mut &bytes[..], &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| ObjError::Parse {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;

    let triangles: usize = models.iter().map(|m| triangle_count(&m.mesh)).sum();
    let vertices: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    if triangles > crate::limits::MAX_MESH_TRIANGLES || vertices > crate::limits::MAX_MESH_VERTICES
    {
        return Err(ObjError::TooLarge {
            path: path.to_path_buf(),
            triangles,
            vertices,
        });
    }
    Ok(models)
}

/// One [`TriangleMesh`] from all the models: positions, normals (kept
/// only if every model has them, else computed per vertex) and texture
/// coordinates (kept only if every model has them, `v` flipped if asked).
fn merge_models(
    models: &[tobj::Model],
    path: &Path,
    face_normals: bool,
    flip_tex_coords: bool,
) -> Result<TriangleMesh, ObjError> {
    let mut mesh = TriangleMesh {
        face_normals,
        ..Default::default()
    };
    let mut normals = Vec::new();
    let mut all_have_normals = true;
    let mut texcoords = Vec::new();
    let mut all_have_texcoords = true;
    for model in models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let count = m.positions.len() / 3;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
        );
        if m.normals.len() == m.positions.len() {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64)),
            );
        } else {
            all_have_normals = false;
            normals.extend(std::iter::repeat_n(DVec3::ZERO, count));
        }
        // Mitsuba's OBJ loader flips v by default (v = 0 is an image's
        // bottom row in OBJ, its top row in trilux and Mitsuba).
        if m.texcoords.len() / 2 == count {
            let v = |t: f32| match flip_tex_coords {
                true => 1.0 - f64::from(t),
                false => f64::from(t),
            };
            texcoords.extend(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| DVec2::new(f64::from(t[0]), v(t[1]))),
            );
        } else {
            all_have_texcoords = false;
        }
        triangulate(&m.indices, &m.face_arities, |t| {
            mesh.triangles.push(t.map(|i| base + i));
        });
    }
    if mesh.triangles.is_empty() {
        return Err(ObjError::Empty {
            path: path.to_path_buf(),
        });
    }
    if !mesh.positions.iter().all(|p| p.is_finite())
        || !normals.iter().all(|n| n.is_finite())
        || !texcoords.iter().all(|t| t.is_finite())
    {
        return Err(ObjError::NotFinite {
            path: path.to_path_buf(),
        });
    }
    mesh.texcoords = (all_have_texcoords && !texcoords.is_empty()).then_some(texcoords);
    mesh.normals = if face_normals {
        None
    } else if all_have_normals {
        Some(normals)
    } else {
        Some(vertex_normals(&mesh.positions, &mesh.triangles))
    };
    Ok(mesh)
}

/// Lines that start (after blanks) with `f` and with `v` then a blank.
fn count_lines(bytes: &[u8]) -> (usize, usize) {
    let (mut faces, mut positions) = (0, 0);
    for line in bytes.split(|&b| b == b'\n') {
        let start = line.iter().position(|b| !b.is_ascii_whitespace());
        let rest = start.map_or(&[][..], |i| &line[i..]);
        match rest {
            [b'f', b' ' | b'\t', ..] => faces += 1,
            [b'v', b' ' | b'\t', ..] => positions += 1,
            _ => {}
        }
    }
    (faces, positions)
}

/// The first face index that refers to no vertex line (`v`, `vt` or `vn`):
/// a positive index above the file's count of its kind, or a negative
/// (relative) one reaching before the first line of its kind so far.
/// tobj computes such indices with unchecked arithmetic (a relative index
/// before the start wraps around, and an index past 2^62 overflows when
/// doubled), so they are refused before it sees them. Lines continued
/// with a trailing backslash are joined, as tobj joins them.
fn bad_face_index(bytes: &[u8]) -> Option<i64> {
    let mut logical: Vec<Vec<u8>> = Vec::new();
    let mut joining = false;
    for line in bytes.split(|&b| b == b'\n') {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let (body, continued) = match line.strip_suffix(b"\\") {
            Some(body) => (body, true),
            None => (line, false),
        };
        match logical.last_mut() {
            Some(last) if joining => last.extend_from_slice(body),
            _ => logical.push(body.to_vec()),
        }
        joining = continued;
    }
    let kind = |line: &[u8]| -> Option<usize> {
        let text = std::str::from_utf8(line).ok()?;
        match text.split_ascii_whitespace().next()? {
            "v" => Some(0),
            "vt" => Some(1),
            "vn" => Some(2),
            "f" => Some(3),
            _ => None,
        }
    };
    let mut total = [0i64; 3];
    for line in &logical {
        if let Some(k @ 0..=2) = kind(line) {
            total[k] += 1;
        }
    }
    let mut so_far = [0i64; 3];
    for line in &logical {
        match kind(line) {
            Some(k @ 0..=2) => so_far[k] += 1,
            Some(_) => {
                let Ok(text) = std::str::from_utf8(line) else {
                    continue;
                };
                for vertex in text.split_ascii_whitespace().skip(1) {
                    for (k, part) in vertex.split('/').take(3).enumerate() {
                        let Ok(n) = part.parse::<i64>() else { continue };
                        if n == 0
                            || n > total[k]
                            || (n < 0 && n.unsigned_abs() > so_far[k].unsigned_abs())
                        {
                            return Some(n);
                        }
                    }
                }
            }
            None => {}
        }
    }
    None
}

/// Angle-weighted smooth vertex normals (Mitsuba's `recompute_vertex_normals`).
/// A vertex that only touches degenerate triangles gets +z, never NaN.
pub(crate) fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut acc = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let v = t.map(|i| positions[i as usize]);
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        if n.length_squared() == 0.0 {
            continue;
        }
        let n = n.normalize();
        for i in 0..3 {
            let d0 = (v[(i + 1) % 3] - v[i]).normalize_or_zero();
            let d1 = (v[(i + 2) % 3] - v[i]).normalize_or_zero();
            let angle = d0.dot(d1).clamp(-1.0, 1.0).acos();
            acc[t[i] as usize] += n * angle;
        }
    }
    acc.into_iter()
        .map(|n| {
            let n = n.normalize_or_zero();
            if n == DVec3::ZERO { DVec3::Z } else { n }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n";

    #[test]
    fn face_indices_that_name_no_vertex_are_refused_before_tobj() {
        let cases = [
            // A relative texture index reaching before the first `vt`
            // (tobj wraps it around and then overflows doubling it), even
            // though more `vt` lines follow.
            (format!("{QUAD}f 1/-4 2/-2 3/-1\nvt 0 1\n"), Some(-4)),
            (
                format!("{QUAD}f 1/4611686018427387904 2/2 3/3\n"),
                Some(4_611_686_018_427_387_904),
            ),
            (format!("{QUAD}f 0 2 3\n"), Some(0)),
            (format!("{QUAD}f 1 2 \\\n 4\n"), Some(4)),
            (format!("{QUAD}f -3/-3 -2/-2 -1/-1\n"), None),
            (format!("{QUAD}f 1/1 2/2 3/3\n"), None),
        ];
        for (text, bad) in &cases {
            assert_eq!(bad_face_index(text.as_bytes()), *bad, "{text:?}");
            let parsed = parse_obj(text.as_bytes(), Path::new("t.obj"), false, true);
            assert_eq!(parsed.is_err(), bad.is_some(), "{text:?}: {parsed:?}");
        }
    }

    /// A polygon of `n` vertices on the unit circle, counter-clockwise.
    fn circle(n: usize) -> String {
        let mut t = String::new();
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            t += &format!("v {} {} 0\nvt {} {}\n", a.cos(), a.sin(), a.cos(), a.sin());
        }
        t
    }

    /// Faces up to `FAN_MAX` vertices give tobj's own fans, vertex for
    /// vertex (triangles, quads, a pentagon, a 64-gon, with and without
    /// texture indices).
    #[test]
    fn small_polygons_are_tobj_fans() {
        let mut text = circle(FAN_MAX);
        text += "f 1 2 3\nf 1/1 2/2 3/3 4/4\nf 5 6 7 8 9\nf 10 11 12 13\nf";
        for i in 1..=FAN_MAX {
            text += &format!(" {i}");
        }
        text += "\n";
        let ours = parse_obj(text.as_bytes(), Path::new("t.obj"), true, true)
            .unwrap_or_else(|e| panic!("{e}"));
        let options = tobj::LoadOptions {
            single_index: true,
            triangulate: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| {
            Ok((Vec::new(), Default::default()))
        })
        .unwrap_or_else(|e| panic!("{e}"));
        let theirs: Vec<[u32; 3]> = models[0]
            .mesh
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        assert_eq!(ours.triangles.len(), 1 + 2 + 3 + 2 + (FAN_MAX - 2));
        assert_eq!(ours.triangles, theirs);
        assert_eq!(ours.positions.len() * 3, models[0].mesh.positions.len());
    }

    /// A polygon of n > `FAN_MAX` vertices makes n − 2 triangles of its
    /// winding covering its area, each corner of each triangle used, and
    /// the triangles' boxes shrink by halves: their summed extents are
    /// O(log n) times the polygon's, where a fan's are O(n) times.
    #[test]
    fn large_polygons_are_halved() {
        for n in [FAN_MAX + 1, 1000, 4096] {
            let mut text = circle(n);
            text += "f";
            for i in 1..=n {
                text += &format!(" {i}");
            }
            text += "\n";
            let mesh = parse_obj(text.as_bytes(), Path::new("t.obj"), true, true)
                .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(mesh.triangles.len(), n - 2);
            let p = &mesh.positions;
            let mut area = 0.0;
            let mut extents = 0.0;
            let mut used = vec![false; n];
            for t in &mesh.triangles {
                let [a, b, c] = t.map(|i| p[i as usize]);
                let z = (b - a).cross(c - a).z;
                assert!(z > 0.0, "counter-clockwise, as the polygon");
                area += 0.5 * z;
                extents += (a.max(b).max(c) - a.min(b).min(c)).length();
                t.iter().for_each(|&i| used[i as usize] = true);
            }
            // The shoelace area of the polygon as read (tobj keeps f32).
            let exact: f64 = (0..n)
                .map(|i| 0.5 * p[i].truncate().perp_dot(p[(i + 1) % n].truncate()))
                .sum();
            assert!(
                (area - exact).abs() < 1e-9 * exact,
                "{area} against {exact}"
            );
            assert!(used.iter().all(|&u| u));
            let levels = (n as f64).log2().ceil();
            assert!(extents <= 8.0 * levels, "{n}: summed extents {extents}");
        }
    }
}
