//! Mitsuba's own compressed meshes (`<shape type="serialized">`), as
//! Mitsuba 3 reads them (`src/shapes/serialized.cpp`, versions 3 and 4).
//!
//! A file is a sequence of meshes. Each starts with the little-endian
//! `u16` 0x041C and the `u16` version (3 or 4), then one zlib stream
//! holding: a `u32` of flags (0x0001 vertex normals, 0x0002 texture
//! coordinates, 0x0008 vertex colours, 0x2000 double precision, else
//! single), the mesh name (version 4: UTF-8, NUL-terminated), the `u64`
//! vertex and triangle counts, positions, normals, texture coordinates,
//! colours (each an array over the vertices, in that order) and the `u32`
//! triangle indices. The file ends with the offset of every mesh (`u64`,
//! version 3: `u32`) and the `u32` number of meshes; `shape_index` 0 is
//! read from the start, as Mitsuba reads it, the others through these
//! offsets. Colours are read past, as Mitsuba 3 reads them past, and so is
//! the face-normals flag (0x0010): the shape's `face_normals` decides.
//! Texture coordinates are kept as written (Mitsuba 3 does not flip them).
//!
//! Bounded like the other readers: the file is at most [`MAX_MESH_BYTES`],
//! the declared counts within the mesh limits, and memory grows only as
//! decompressed data arrives (a file declaring millions of vertices but
//! holding few is refused once its data ends, having allocated for what
//! it held). Decompression stops at the bytes the counts need, so a zlib
//! stream that would expand without end costs nothing beyond them.

use std::io::Read;
use std::path::{Path, PathBuf};

use flate2::read::ZlibDecoder;
use glam::{DVec2, DVec3};
use trilux_geometry::TriangleMesh;

use crate::limits::{MAX_MESH_BYTES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES};
use crate::obj::vertex_normals;

/// The first `u16` of every mesh of a serialized file.
const MAGIC: u16 = 0x041C;

/// Longest mesh name read (a name without its NUL would otherwise be read
/// for as long as the stream expands).
const MAX_NAME_BYTES: usize = 1 << 16;

/// Why a serialized file could not be read (the caller adds the scene
/// location).
#[derive(Debug, thiserror::Error)]
pub enum SerializedError {
    /// The file could not be read (missing, not a regular file, too
    /// large).
    #[error("cannot read serialized file {}: {source}", path.display())]
    Io {
        /// The serialized file.
        path: PathBuf,
        /// Why.
        #[source]
        source: trilux_files::ReadError,
    },
    /// The file is not a serialized mesh, or its data is malformed.
    #[error("malformed serialized file {}: {place}: {reason}", path.display())]
    Malformed {
        /// The serialized file.
        path: PathBuf,
        /// Where: a byte offset of the file, or a mesh and part of it.
        place: String,
        /// What is wrong.
        reason: String,
    },
}

/// Reads mesh `shape_index` of a serialized file.
pub fn load_serialized(
    path: &Path,
    shape_index: u32,
    face_normals: bool,
) -> Result<TriangleMesh, SerializedError> {
    let bytes =
        trilux_files::read_limited(path, MAX_MESH_BYTES).map_err(|source| SerializedError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    parse_serialized(&bytes, path, shape_index, face_normals)
}

/// [`load_serialized`] on the bytes of a file; `path` names it in errors.
pub fn parse_serialized(
    bytes: &[u8],
    path: &Path,
    shape_index: u32,
    face_normals: bool,
) -> Result<TriangleMesh, SerializedError> {
    let fail = |place: String, reason: String| SerializedError::Malformed {
        path: path.to_path_buf(),
        place,
        reason,
    };
    let version = header(bytes, 0).map_err(|r| fail("byte 0".into(), r))?;
    let start = if shape_index == 0 {
        0
    } else {
        mesh_offset(bytes, version, shape_index).map_err(|r| fail("end of file".into(), r))?
    };
    let here = format!("mesh {shape_index} (at byte {start})");
    let v = header(bytes, start).map_err(|r| fail(here.clone(), r))?;
    if v != version {
        return Err(fail(
            here,
            format!("version {v}, but the file's first mesh is version {version}"),
        ));
    }
    let mut stream = Inflate::new(&bytes[start + 4..]);
    read_mesh(&mut stream, version, face_normals).map_err(|(part, reason)| {
        fail(
            format!("{here}, {part} (decompressed byte {})", stream.read),
            reason,
        )
    })
}

/// The version of the mesh header at `at`, checked.
fn header(bytes: &[u8], at: usize) -> Result<u16, String> {
    let word = |i: usize| {
        bytes
            .get(at + i..at + i + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    let (Some(magic), Some(version)) = (word(0), word(2)) else {
        return Err("the file ends inside the mesh header (4 bytes)".into());
    };
    if magic != MAGIC {
        return Err(format!(
            "starts with 0x{magic:04X}, not 0x{MAGIC:04X}: not a serialized mesh"
        ));
    }
    if version != 3 && version != 4 {
        return Err(format!(
            "version {version}; Mitsuba 3 reads versions 3 and 4"
        ));
    }
    Ok(version)
}

/// Where mesh `index` (> 0) starts, from the dictionary at the end of the
/// file (module docs).
fn mesh_offset(bytes: &[u8], version: u16, index: u32) -> Result<usize, String> {
    let len = bytes.len();
    let tail = |from: usize, n: usize| bytes.get(len.checked_sub(from)?..len - from + n);
    let count = tail(4, 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .ok_or("the file is too short for its dictionary of meshes")?;
    if index >= count {
        return Err(format!(
            "shape_index {index} is out of range: the file holds {count} meshes (0 to {})",
            count.saturating_sub(1)
        ));
    }
    let left = (count - index) as usize;
    let offset = if version == 4 {
        tail(4 + 8 * left, 8).map(|b| {
            let mut a = [0; 8];
            a.copy_from_slice(b);
            u64::from_le_bytes(a)
        })
    } else {
        tail(4 * (left + 1), 4).map(|b| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])))
    }
    .ok_or_else(|| format!("the file is too short for a dictionary of {count} meshes"))?;
    usize::try_from(offset)
        .ok()
        .filter(|&o| o < len)
        .ok_or_else(|| {
            format!("mesh {index} starts at byte {offset}, beyond the file's {len} bytes")
        })
}

/// The decompressed stream of one mesh, counting the bytes read.
struct Inflate<'a> {
    inner: std::io::BufReader<ZlibDecoder<&'a [u8]>>,
    read: u64,
}

/// A failure inside a mesh's stream: which part, and what is wrong.
type Failure = (&'static str, String);

impl<'a> Inflate<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Inflate {
            inner: std::io::BufReader::with_capacity(1 << 16, ZlibDecoder::new(bytes)),
            read: 0,
        }
    }

    fn bytes<const N: usize>(&mut self, part: &'static str) -> Result<[u8; N], Failure> {
        let mut b = [0; N];
        self.inner.read_exact(&mut b).map_err(|e| {
            let reason = if e.kind() == std::io::ErrorKind::UnexpectedEof {
                "the data ends early (a truncated file, or counts larger than the data)".into()
            } else {
                format!("the compressed data is corrupt ({e})")
            };
            (part, reason)
        })?;
        self.read += N as u64;
        Ok(b)
    }

    fn u32(&mut self, part: &'static str) -> Result<u32, Failure> {
        self.bytes::<4>(part).map(u32::from_le_bytes)
    }

    fn u64(&mut self, part: &'static str) -> Result<u64, Failure> {
        self.bytes::<8>(part).map(u64::from_le_bytes)
    }

    /// One float of the file's precision.
    fn float(&mut self, double: bool, part: &'static str) -> Result<f64, Failure> {
        if double {
            self.bytes::<8>(part).map(f64::from_le_bytes)
        } else {
            self.bytes::<4>(part)
                .map(|b| f64::from(f32::from_le_bytes(b)))
        }
    }

    /// `count` vectors of `N` finite floats.
    fn vectors<const N: usize>(
        &mut self,
        count: usize,
        double: bool,
        part: &'static str,
    ) -> Result<Vec<[f64; N]>, Failure> {
        // Grows with the data, not with the declared count (module docs).
        let mut out = Vec::with_capacity(count.min(1 << 10));
        for _ in 0..count {
            let mut v = [0.0; N];
            for x in &mut v {
                *x = self.float(double, part)?;
                if !x.is_finite() {
                    return Err((part, format!("a value is not a finite number ({x})")));
                }
            }
            out.push(v);
        }
        Ok(out)
    }
}

/// The mesh in `s` (its stream after the header).
fn read_mesh(
    s: &mut Inflate<'_>,
    version: u16,
    face_normals: bool,
) -> Result<TriangleMesh, Failure> {
    let flags = s.u32("flags")?;
    if version == 4 {
        let mut name = 0;
        while s.bytes::<1>("name")?[0] != 0 {
            name += 1;
            if name > MAX_NAME_BYTES {
                return Err(("name", format!("longer than {MAX_NAME_BYTES} bytes")));
            }
        }
    }
    let vertices = s.u64("counts")?;
    let triangles = s.u64("counts")?;
    if vertices > MAX_MESH_VERTICES as u64 || triangles > MAX_MESH_TRIANGLES as u64 {
        return Err((
            "counts",
            format!(
                "{triangles} triangles and {vertices} vertices; the limits are {MAX_MESH_TRIANGLES} triangles and {MAX_MESH_VERTICES} vertices (docs/limits.md)"
            ),
        ));
    }
    if triangles == 0 {
        return Err(("counts", "the mesh has no triangles".into()));
    }
    // Within the limits (checked above): the counts fit a usize.
    let (nv, nt) = (vertices as usize, triangles as usize);
    let double = flags & 0x2000 != 0;
    let positions: Vec<DVec3> = s
        .vectors::<3>(nv, double, "positions")?
        .into_iter()
        .map(DVec3::from_array)
        .collect();
    let normals = if flags & 0x0001 != 0 {
        let n = s.vectors::<3>(nv, double, "normals")?;
        Some(n.into_iter().map(DVec3::from_array).collect::<Vec<_>>())
    } else {
        None
    };
    let texcoords = if flags & 0x0002 != 0 {
        let t = s.vectors::<2>(nv, double, "texture coordinates")?;
        Some(t.into_iter().map(DVec2::from_array).collect::<Vec<_>>())
    } else {
        None
    };
    if flags & 0x0008 != 0 {
        s.vectors::<3>(nv, double, "colours")?;
    }
    let mut tris = Vec::with_capacity(nt.min(1 << 10));
    for _ in 0..nt {
        let t = [
            s.u32("triangles")?,
            s.u32("triangles")?,
            s.u32("triangles")?,
        ];
        if let Some(&i) = t.iter().find(|&&i| i as usize >= nv) {
            return Err((
                "triangles",
                format!(
                    "triangle {} refers to vertex {i}, but the mesh has {nv} vertices",
                    tris.len()
                ),
            ));
        }
        tris.push(t);
    }
    let normals = match (face_normals, normals) {
        (true, _) => None,
        (false, Some(n)) => Some(n),
        (false, None) => Some(vertex_normals(&positions, &tris)),
    };
    Ok(TriangleMesh {
        positions,
        normals,
        triangles: tris,
        face_normals,
        texcoords,
    })
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;

    /// A mesh's stream as Mitsuba 0.6 writes it: `flags`, the name
    /// (version 4), the counts, then `arrays` of floats and the indices.
    fn stream(version: u16, flags: u32, nv: u64, arrays: &[&[f64]], tris: &[u32]) -> Vec<u8> {
        let mut d = flags.to_le_bytes().to_vec();
        if version == 4 {
            d.extend(b"a mesh\0");
        }
        d.extend(nv.to_le_bytes());
        d.extend((tris.len() as u64 / 3).to_le_bytes());
        for &x in arrays.iter().copied().flatten() {
            if flags & 0x2000 != 0 {
                d.extend(x.to_le_bytes());
            } else {
                d.extend((x as f32).to_le_bytes());
            }
        }
        tris.iter().for_each(|i| d.extend(i.to_le_bytes()));
        d
    }

    fn compress(data: &[u8]) -> Vec<u8> {
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(data).unwrap();
        z.finish().unwrap()
    }

    /// The meshes' streams, each behind its header, and the dictionary
    /// (offsets `u64` in version 4, `u32` in version 3).
    fn file(version: u16, streams: &[Vec<u8>]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut offsets = Vec::new();
        for s in streams {
            offsets.push(out.len() as u64);
            out.extend(MAGIC.to_le_bytes());
            out.extend(version.to_le_bytes());
            out.extend(compress(s));
        }
        for o in offsets {
            if version == 4 {
                out.extend(o.to_le_bytes());
            } else {
                out.extend((o as u32).to_le_bytes());
            }
        }
        out.extend((streams.len() as u32).to_le_bytes());
        out
    }

    fn parse(bytes: &[u8], index: u32, face_normals: bool) -> Result<TriangleMesh, String> {
        parse_serialized(bytes, Path::new("m.serialized"), index, face_normals)
            .map_err(|e| e.to_string())
    }

    const P: [f64; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

    /// Every part of both versions, in single and double precision, is
    /// where the layout puts it: normals and texture coordinates as
    /// written, colours read past (the indices after them still right),
    /// each mesh of a file reached through the dictionary.
    #[test]
    fn both_versions_read_every_part_of_every_mesh() {
        let n = [0.0, 0.0, 1.0, 0.0, 0.5, 0.75, 0.0, 0.0, 1.0];
        let uv = [0.0, 0.0, 0.25, 0.0, 0.0, 0.75];
        let colours = [9.0; 9];
        for version in [3, 4] {
            for precision in [0x1000, 0x2000] {
                let first = stream(
                    version,
                    precision | 0x0B,
                    3,
                    &[&P, &n, &uv, &colours],
                    &[0, 1, 2],
                );
                let second = stream(
                    version,
                    precision,
                    4,
                    &[&P, &[5.0, 5.0, 5.0]],
                    &[2, 1, 0, 3, 1, 2],
                );
                let bytes = file(version, &[first, second]);
                let m = parse(&bytes, 0, false).unwrap();
                assert_eq!(m.positions[1], DVec3::X);
                assert_eq!(m.normals.as_ref().unwrap()[1], DVec3::new(0.0, 0.5, 0.75));
                assert_eq!(m.texcoords.as_ref().unwrap()[2], DVec2::new(0.0, 0.75));
                assert_eq!(m.triangles, [[0, 1, 2]]);
                assert!(parse(&bytes, 0, true).unwrap().normals.is_none());
                let m = parse(&bytes, 1, false).unwrap();
                assert_eq!(m.positions[3], DVec3::splat(5.0));
                assert_eq!(m.triangles, [[2, 1, 0], [3, 1, 2]]);
                assert!(m.texcoords.is_none());
                // Without normals in the file: recomputed smooth ones
                // (the first triangle faces −z).
                assert_eq!(m.normals.unwrap()[0], -DVec3::Z);
            }
        }
    }

    /// A name that never ends is refused after [`MAX_NAME_BYTES`], however
    /// far its stream would expand; a value that is not finite is refused.
    #[test]
    fn endless_names_and_non_finite_values_are_refused() {
        let mut name = 0x1000u32.to_le_bytes().to_vec();
        name.extend(vec![b'a'; 8 << 20]);
        let e = parse(&file(4, &[name]), 0, false).unwrap_err();
        assert!(
            e.contains("name") && e.contains("longer than 65536 bytes"),
            "{e}"
        );
        let mut p = P;
        p[4] = f64::NAN;
        let e = parse(
            &file(4, &[stream(4, 0x2000, 3, &[&p], &[0, 1, 2])]),
            0,
            false,
        )
        .unwrap_err();
        assert!(
            e.contains("positions") && e.contains("not a finite number"),
            "{e}"
        );
        let e = parse(&file(4, &[stream(4, 0x1000, 3, &[&P], &[])]), 0, false).unwrap_err();
        assert!(e.contains("no triangles"), "{e}");
    }

    /// The dictionary is checked: a count beyond it, an offset beyond the
    /// file, a mesh of another version there.
    #[test]
    fn a_bad_dictionary_is_refused() {
        let one = file(4, &[stream(4, 0x1000, 3, &[&P], &[0, 1, 2])]);
        let e = parse(&one, 1, false).unwrap_err();
        assert!(
            e.contains("shape_index 1 is out of range: the file holds 1 meshes"),
            "{e}"
        );
        let mut far = one.clone();
        let n = far.len();
        far[n - 12..n - 4].copy_from_slice(&u64::MAX.to_le_bytes());
        far[n - 4..].copy_from_slice(&2u32.to_le_bytes());
        let e = parse(&far, 1, false).unwrap_err();
        assert!(e.contains("beyond the file"), "{e}");
        let e = parse(&[0x1C, 0x04, 4, 0, 2, 0, 0, 0], 1, false).unwrap_err();
        assert!(e.contains("too short"), "{e}");
        let mut mixed = file(4, &[stream(4, 0x1000, 3, &[&P], &[0, 1, 2])]);
        let at = mixed.len() - 12;
        mixed.truncate(at);
        let second = mixed.len() as u64;
        mixed.extend(MAGIC.to_le_bytes());
        mixed.extend(3u16.to_le_bytes());
        mixed.extend(compress(&stream(3, 0x1000, 3, &[&P], &[0, 1, 2])));
        mixed.extend(0u64.to_le_bytes());
        mixed.extend(second.to_le_bytes());
        mixed.extend(2u32.to_le_bytes());
        assert!(parse(&mixed, 0, false).is_ok());
        let e = parse(&mixed, 1, false).unwrap_err();
        assert!(
            e.contains("version 3, but the file's first mesh is version 4"),
            "{e}"
        );
    }
}
