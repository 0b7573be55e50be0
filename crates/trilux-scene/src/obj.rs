//! Wavefront OBJ meshes (`<shape type="obj">`), read with `tobj`.
//!
//! Polygons are triangulated as fans; vertices are shared when they share
//! position, texture and normal indices (as Mitsuba's own OBJ loader keys
//! them). Materials (`mtllib`) are ignored, as Mitsuba ignores them.
//!
//! Shading normals follow Mitsuba 3: the file's `vn` when it has them for
//! every vertex; otherwise, unless `face_normals` is set, smooth vertex
//! normals recomputed from the faces with angle weights (Thürmer & Wüthrich,
//! the weighting Mitsuba's `recompute_vertex_normals` uses). With
//! `face_normals` there are none.
//!
//! The file must be a regular file of at most [`MAX_OBJ_BYTES`]
//! (`/dev/zero` is an error, not an endless read); [`parse_obj`] reads the
//! same format from bytes already in memory.

use std::path::Path;

use crate::limits::MAX_OBJ_BYTES;

use glam::DVec3;
use trilux_geometry::TriangleMesh;

/// Why an OBJ file could not be read (the caller adds the scene location).
#[derive(Debug, thiserror::Error)]
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
    #[error("OBJ file {} has {triangles} triangles and {vertices} vertices; the limits are {} and {} (docs/limits.md)", path.display(), crate::limits::MAX_OBJ_TRIANGLES, crate::limits::MAX_OBJ_VERTICES)]
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

/// Reads an OBJ file into one triangle mesh (all its objects merged).
pub fn load_obj(path: &Path, face_normals: bool) -> Result<TriangleMesh, ObjError> {
    let bytes = trilux_files::read_limited(path, MAX_OBJ_BYTES).map_err(|source| ObjError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_obj(&bytes, path, face_normals)
}

/// [`load_obj`] on the bytes of an OBJ file; `path` names it in errors.
pub fn parse_obj(bytes: &[u8], path: &Path, face_normals: bool) -> Result<TriangleMesh, ObjError> {
    // Before tobj spends memory on them: every face line makes at least
    // one triangle, every vertex line one position.
    let (faces, positions) = count_lines(bytes);
    if faces > crate::limits::MAX_OBJ_TRIANGLES || positions > crate::limits::MAX_OBJ_VERTICES {
        return Err(ObjError::TooLarge {
            path: path.to_path_buf(),
            triangles: faces,
            vertices: positions,
        });
    }
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
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

    let triangles: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    let vertices: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    if triangles > crate::limits::MAX_OBJ_TRIANGLES || vertices > crate::limits::MAX_OBJ_VERTICES {
        return Err(ObjError::TooLarge {
            path: path.to_path_buf(),
            triangles,
            vertices,
        });
    }
    let mut mesh = TriangleMesh {
        face_normals,
        ..Default::default()
    };
    let mut normals = Vec::new();
    let mut all_have_normals = true;
    for model in &models {
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
        for t in m.indices.chunks_exact(3) {
            mesh.triangles.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if mesh.triangles.is_empty() {
        return Err(ObjError::Empty {
            path: path.to_path_buf(),
        });
    }
    if !mesh.positions.iter().all(|p| p.is_finite()) || !normals.iter().all(|n| n.is_finite()) {
        return Err(ObjError::NotFinite {
            path: path.to_path_buf(),
        });
    }
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

/// Angle-weighted smooth vertex normals (Mitsuba's `recompute_vertex_normals`).
/// A vertex that only touches degenerate triangles gets +z, never NaN.
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
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
