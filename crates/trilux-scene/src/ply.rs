//! Stanford PLY meshes (`<shape type="ply">`), as Mitsuba 3 reads them.
//!
//! The three encodings (`ascii`, `binary_little_endian`,
//! `binary_big_endian`, version 1.0) and every scalar type (`char`/`int8`
//! … `double`/`float64`). The `vertex` element gives positions (`x y z`,
//! required), shading normals (`nx ny nz`) and texture coordinates (`u v`,
//! `s t`, `texture_u texture_v` or `texture_s texture_t`, kept as written:
//! Mitsuba flips OBJ's `vt` but not PLY's); the `face` element's
//! `vertex_indices` (or `vertex_index`) list gives polygons, triangulated as
//! fans (Mitsuba 3.9 reads triangles only; a fan is what a polygon means),
//! those of more than 64 vertices by halving as OBJ polygons are
//! (`crate::obj::triangulate`).
//! Other properties (colours) and other elements are read past. Normals
//! follow the OBJ rules: the file's when it has them, otherwise smooth ones
//! recomputed, none with `face_normals`.
//!
//! Memory is bounded before it is spent: the file is at most
//! [`MAX_MESH_BYTES`] and the counts the header declares must fit in the
//! file and within the mesh limits.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use trilux_geometry::TriangleMesh;

use crate::limits::{MAX_MESH_BYTES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES};
use crate::obj::{triangulate, vertex_normals};

/// Why a PLY file could not be read (the caller adds the scene location).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlyError {
    /// The file could not be read (missing, not a regular file, too
    /// large).
    #[error("cannot read PLY file {}: {source}", path.display())]
    Io {
        /// The PLY file.
        path: PathBuf,
        /// Why.
        #[source]
        source: trilux_files::ReadError,
    },
    /// The header or the data is malformed; `place` is a header or data
    /// line (ASCII) or a byte offset (binary).
    #[error("malformed PLY file {}: {place}: {reason}", path.display())]
    Parse {
        /// The PLY file.
        path: PathBuf,
        /// Where in the file.
        place: String,
        /// What is wrong.
        reason: String,
    },
    /// The file holds no faces.
    #[error("PLY file {} has no faces", path.display())]
    Empty {
        /// The PLY file.
        path: PathBuf,
    },
    /// The header declares more than the loader takes.
    #[error("PLY file {} declares {faces} faces and {vertices} vertices; the limits are {MAX_MESH_TRIANGLES} triangles and {MAX_MESH_VERTICES} vertices (docs/limits.md)", path.display())]
    TooLarge {
        /// The PLY file.
        path: PathBuf,
        /// Faces declared.
        faces: usize,
        /// Vertices declared.
        vertices: usize,
    },
    /// A coordinate is not finite.
    #[error("PLY file {} has a coordinate that is not a finite number", path.display())]
    NotFinite {
        /// The PLY file.
        path: PathBuf,
    },
}

/// Reads a PLY file into one triangle mesh; `flip_tex_coords` (false by
/// default in Mitsuba for PLY) maps v ↦ 1 − v.
pub(crate) fn load_ply(
    path: &Path,
    face_normals: bool,
    flip_tex_coords: bool,
) -> Result<TriangleMesh, PlyError> {
    let bytes =
        trilux_files::read_limited(path, MAX_MESH_BYTES).map_err(|source| PlyError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    parse_ply(&bytes, path, face_normals, flip_tex_coords)
}

/// `load_ply` on the bytes of a PLY file; `path` names it in errors.
pub fn parse_ply(
    bytes: &[u8],
    path: &Path,
    face_normals: bool,
    flip_tex_coords: bool,
) -> Result<TriangleMesh, PlyError> {
    let fail = |place: String, reason: String| PlyError::Parse {
        path: path.to_path_buf(),
        place,
        reason,
    };
    let header =
        Header::parse(bytes).map_err(|(line, reason)| fail(format!("line {line}"), reason))?;
    header.check_size(bytes.len(), path)?;
    let mut data = Data::new(&bytes[header.data_start..], header.format, header.lines);
    let raw = read_elements(&header, &mut data).map_err(|reason| fail(data.place(), reason))?;
    let mut mesh = raw.into_mesh(path, face_normals)?;
    if flip_tex_coords && let Some(t) = &mut mesh.texcoords {
        t.iter_mut().for_each(|uv| uv.y = 1.0 - uv.y);
    }
    Ok(mesh)
}

/// A scalar type of the format.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn bytes(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// A property: one scalar, or a list (its length's type, its items' type).
#[derive(Clone, Debug)]
enum Property {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct ElementDef {
    name: String,
    count: usize,
    properties: Vec<(String, Property)>,
}

impl ElementDef {
    fn find(&self, name: &str) -> Option<usize> {
        self.properties.iter().position(|(n, _)| n == name)
    }

    /// The fewest bytes one element takes (binary: exact for scalars, a
    /// list at least its length; ASCII: one character and a separator per
    /// value).
    fn min_bytes(&self, format: Format) -> usize {
        self.properties
            .iter()
            .map(|(_, p)| match (format, p) {
                (Format::Ascii, _) => 2,
                (_, Property::Scalar(s)) => s.bytes(),
                (_, Property::List { count, .. }) => count.bytes(),
            })
            .sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

/// The header: the encoding, the elements in file order, where data starts.
#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<ElementDef>,
    data_start: usize,
    /// Lines in the header (ASCII data lines are counted on from here).
    lines: usize,
}

impl Header {
    /// Parses the header; an error is (line, reason).
    fn parse(bytes: &[u8]) -> Result<Header, (usize, String)> {
        let mut format = None;
        let mut elements: Vec<ElementDef> = Vec::new();
        let mut pos = 0;
        let mut line_no = 0;
        loop {
            line_no += 1;
            let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
                return Err((line_no, "the header has no end_header line".into()));
            };
            let raw = &bytes[pos..pos + len];
            pos += len + 1;
            let line = std::str::from_utf8(raw)
                .map_err(|_| (line_no, "the header is not ASCII text".to_string()))?
                .trim_end_matches('\r');
            let words: Vec<&str> = line.split_ascii_whitespace().collect();
            if line_no == 1 {
                if words != ["ply"] {
                    return Err((1, "the file does not start with the line \"ply\"".into()));
                }
                continue;
            }
            match words.as_slice() {
                ["format", f, "1.0"] => {
                    format = Some(match *f {
                        "ascii" => Format::Ascii,
                        "binary_little_endian" => Format::BinaryLe,
                        "binary_big_endian" => Format::BinaryBe,
                        other => return Err((line_no, format!("unknown format \"{other}\""))),
                    })
                }
                ["format", ..] => {
                    return Err((
                        line_no,
                        format!("unsupported format line \"{line}\" (version 1.0 only)"),
                    ));
                }
                ["comment", ..] | ["obj_info", ..] | [] => {}
                ["element", name, count] => {
                    let count = count.parse().map_err(|_| {
                        (line_no, format!("element count \"{count}\" is not a count"))
                    })?;
                    elements.push(ElementDef {
                        name: (*name).to_string(),
                        count,
                        properties: Vec::new(),
                    });
                }
                ["property", rest @ ..] => {
                    let Some(element) = elements.last_mut() else {
                        return Err((line_no, "a property before any element".into()));
                    };
                    element
                        .properties
                        .push(Self::property(rest).map_err(|r| (line_no, r))?);
                }
                ["end_header"] => break,
                _ => return Err((line_no, format!("unexpected header line \"{line}\""))),
            }
        }
        let format = format.ok_or((line_no, "the header has no format line".to_string()))?;
        Ok(Header {
            format,
            elements,
            data_start: pos,
            lines: line_no,
        })
    }

    fn property(words: &[&str]) -> Result<(String, Property), String> {
        let scalar =
            |w: &str| Scalar::parse(w).ok_or_else(|| format!("unknown property type \"{w}\""));
        match words {
            ["list", count, item, name] => {
                let count = scalar(count)?;
                if !count.is_integer() {
                    return Err(format!(
                        "list length type \"{}\" is not an integer type",
                        words[1]
                    ));
                }
                Ok((
                    (*name).to_string(),
                    Property::List {
                        count,
                        item: scalar(item)?,
                    },
                ))
            }
            [kind, name] => Ok(((*name).to_string(), Property::Scalar(scalar(kind)?))),
            _ => Err(format!(
                "malformed property line \"property {}\"",
                words.join(" ")
            )),
        }
    }

    fn count(&self, name: &str) -> usize {
        self.elements
            .iter()
            .filter(|e| e.name == name)
            .map(|e| e.count)
            .sum()
    }

    /// Refuses counts beyond the mesh limits, or that the file cannot hold.
    fn check_size(&self, file_bytes: usize, path: &Path) -> Result<(), PlyError> {
        let (faces, vertices) = (self.count("face"), self.count("vertex"));
        let needed = self.elements.iter().try_fold(0usize, |sum, e| {
            sum.checked_add(e.count.checked_mul(e.min_bytes(self.format).max(1))?)
        });
        if faces > MAX_MESH_TRIANGLES || vertices > MAX_MESH_VERTICES {
            return Err(PlyError::TooLarge {
                path: path.to_path_buf(),
                faces,
                vertices,
            });
        }
        let data = file_bytes - self.data_start;
        if needed.is_none_or(|n| n > data) {
            return Err(PlyError::Parse {
                path: path.to_path_buf(),
                place: format!("line {}", self.lines),
                reason: format!(
                    "the header declares {vertices} vertices and {faces} faces, more than the file's {data} bytes of data can hold"
                ),
            });
        }
        Ok(())
    }
}

/// The data after the header, read value by value.
struct Data<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
    /// The current line (ASCII).
    line: usize,
}

impl<'a> Data<'a> {
    fn new(bytes: &'a [u8], format: Format, header_lines: usize) -> Self {
        Data {
            bytes,
            pos: 0,
            format,
            line: header_lines + 1,
        }
    }

    /// Where the reader is, for errors.
    fn place(&self) -> String {
        match self.format {
            Format::Ascii => format!("line {}", self.line),
            _ => format!("data byte {}", self.pos),
        }
    }

    /// The next value of type `s`.
    fn value(&mut self, s: Scalar) -> Result<f64, String> {
        let v = match self.format {
            Format::Ascii => self.token(s)?,
            Format::BinaryLe | Format::BinaryBe => self.binary(s)?,
        };
        if s.is_integer() && v.fract() != 0.0 {
            return Err(format!("{v} is not an integer"));
        }
        Ok(v)
    }

    fn token(&mut self, s: Scalar) -> Result<f64, String> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if start == self.pos {
            return Err("the data ends before every element the header declares".into());
        }
        let text = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("?");
        let parsed = match s.is_integer() {
            true => text.parse::<i64>().ok().map(|i| i as f64),
            false => text.parse::<f64>().ok(),
        };
        parsed.ok_or_else(|| format!("\"{text}\" is not a number of type {s:?}"))
    }

    fn binary(&mut self, s: Scalar) -> Result<f64, String> {
        let n = s.bytes();
        let Some(raw) = self.bytes.get(self.pos..self.pos + n) else {
            return Err("the data ends before every element the header declares".into());
        };
        self.pos += n;
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(raw);
        if self.format == Format::BinaryBe {
            b[..n].reverse();
        }
        Ok(match s {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }
}

/// What the elements hold, before it becomes a mesh.
#[derive(Default)]
struct RawMesh {
    positions: Vec<DVec3>,
    normals: Option<Vec<DVec3>>,
    texcoords: Option<Vec<DVec2>>,
    triangles: Vec<[u32; 3]>,
    /// The largest vertex index a face names (checked once every vertex
    /// is read, since elements may come in any order; meaningful once a
    /// face is read).
    max_index: u32,
}

/// Where the vertex element keeps what the mesh needs.
struct VertexLayout {
    position: [usize; 3],
    normal: Option<[usize; 3]>,
    texcoord: Option<[usize; 2]>,
}

impl VertexLayout {
    fn of(e: &ElementDef) -> Result<VertexLayout, String> {
        let find3 = |names: [&str; 3]| -> Option<[usize; 3]> {
            Some([e.find(names[0])?, e.find(names[1])?, e.find(names[2])?])
        };
        let position =
            find3(["x", "y", "z"]).ok_or("the vertex element has no x, y and z properties")?;
        let texcoord = [
            ("u", "v"),
            ("s", "t"),
            ("texture_u", "texture_v"),
            ("texture_s", "texture_t"),
        ]
        .iter()
        .find_map(|(u, v)| Some([e.find(u)?, e.find(v)?]));
        Ok(VertexLayout {
            position,
            normal: find3(["nx", "ny", "nz"]),
            texcoord,
        })
    }
}

/// Reads every element in file order.
fn read_elements(header: &Header, data: &mut Data<'_>) -> Result<RawMesh, String> {
    let mut raw = RawMesh::default();
    let mut values = Vec::new();
    let mut list = Vec::new();
    for element in &header.elements {
        let vertex = match element.name.as_str() {
            "vertex" => Some(VertexLayout::of(element)?),
            _ => None,
        };
        let face_list = (element.name == "face")
            .then(|| {
                element
                    .find("vertex_indices")
                    .or_else(|| element.find("vertex_index"))
            })
            .map(|i| i.ok_or("the face element has no vertex_indices list"))
            .transpose()?;
        if let Some(v) = &vertex {
            raw.positions.reserve(element.count);
            raw.normals = v.normal.map(|_| Vec::with_capacity(element.count));
            raw.texcoords = v.texcoord.map(|_| Vec::with_capacity(element.count));
        }
        for _ in 0..element.count {
            values.clear();
            for (index, (_, property)) in element.properties.iter().enumerate() {
                match property {
                    Property::Scalar(s) => values.push(data.value(*s)?),
                    Property::List { count, item } => {
                        let n = data.value(*count)?;
                        if n < 0.0 {
                            return Err(format!("a list of length {n}"));
                        }
                        let keep = face_list == Some(index);
                        if keep {
                            list.clear();
                        }
                        for _ in 0..n as usize {
                            let x = data.value(*item)?;
                            if keep {
                                list.push(x);
                            }
                        }
                        values.push(f64::NAN);
                    }
                }
            }
            if let Some(v) = &vertex {
                raw.add_vertex(v, &values);
            }
            if face_list.is_some() {
                raw.add_face(&list)?;
            }
        }
    }
    Ok(raw)
}

impl RawMesh {
    fn add_vertex(&mut self, v: &VertexLayout, values: &[f64]) {
        let [x, y, z] = v.position.map(|i| values[i]);
        self.positions.push(DVec3::new(x, y, z));
        if let (Some(n), Some(normals)) = (v.normal, &mut self.normals) {
            let [x, y, z] = n.map(|i| values[i]);
            normals.push(DVec3::new(x, y, z));
        }
        if let (Some(t), Some(texcoords)) = (v.texcoord, &mut self.texcoords) {
            texcoords.push(DVec2::new(values[t[0]], values[t[1]]));
        }
    }

    /// A polygon as triangles: a fan up to 64 vertices, halves beyond
    /// ([`triangulate`]).
    fn add_face(&mut self, list: &[f64]) -> Result<(), String> {
        if list.len() < 3 {
            return Err(format!("a face with {} vertices (at least 3)", list.len()));
        }
        for &i in list {
            if !(0.0..=f64::from(u32::MAX - 1)).contains(&i) {
                return Err(format!("vertex index {i} is out of range"));
            }
            self.max_index = self.max_index.max(i as u32);
        }
        if self.triangles.len() + list.len() - 2 > MAX_MESH_TRIANGLES {
            return Err(format!(
                "the faces make more than {MAX_MESH_TRIANGLES} triangles (docs/limits.md)"
            ));
        }
        // Integers within u32 (checked above): `as` is exact.
        let ids: Vec<u32> = list.iter().map(|&i| i as u32).collect();
        let triangles = &mut self.triangles;
        triangulate(&ids, &[ids.len() as u32], |t| triangles.push(t));
        Ok(())
    }

    fn into_mesh(self, path: &Path, face_normals: bool) -> Result<TriangleMesh, PlyError> {
        if self.triangles.is_empty() {
            return Err(PlyError::Empty {
                path: path.to_path_buf(),
            });
        }
        // Checked after the empty case: with a face there is a max_index.
        let max = self.max_index;
        if max as usize >= self.positions.len() {
            return Err(PlyError::Parse {
                path: path.to_path_buf(),
                place: "faces".into(),
                reason: format!(
                    "a face refers to vertex {max}, but the file has {} vertices",
                    self.positions.len()
                ),
            });
        }
        let finite = self.positions.iter().all(|p| p.is_finite())
            && self.normals.iter().flatten().all(|n| n.is_finite())
            && self.texcoords.iter().flatten().all(|t| t.is_finite());
        if !finite {
            return Err(PlyError::NotFinite {
                path: path.to_path_buf(),
            });
        }
        let normals = match (face_normals, self.normals) {
            (true, _) => None,
            (false, Some(n)) => Some(n),
            (false, None) => Some(vertex_normals(&self.positions, &self.triangles)),
        };
        Ok(TriangleMesh {
            positions: self.positions,
            normals,
            triangles: self.triangles,
            face_normals,
            texcoords: self.texcoords,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad and a triangle above it: x y z, nx ny nz, u v per vertex.
    const VERTICES: [[f64; 8]; 5] = [
        [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0],
        [1.0, 1.0, 0.0, 0.0, 0.6, 0.8, 1.0, 1.0],
        [0.0, 1.0, 0.0, 0.0, 0.6, 0.8, 0.0, 1.0],
        [0.5, 2.0, 0.25, 0.0, 0.0, 1.0, 0.5, 2.0],
    ];
    const FACES: [&[u32]; 2] = [&[0, 1, 2, 3], &[3, 2, 4]];

    /// Writes the mesh in `format` (an independent writer: the PLY
    /// specification's layout), with a colour property between the
    /// coordinates and an `edge` element the reader must read past.
    fn write(format: &str, uv: (&str, &str)) -> Vec<u8> {
        let mut out = format!(
            "ply\nformat {format} 1.0\ncomment written by the test\n\
             element vertex 5\nproperty float x\nproperty float y\nproperty double z\n\
             property uchar red\nproperty float nx\nproperty float ny\nproperty float nz\n\
             property float {}\nproperty float {}\n\
             element face 2\nproperty list uchar int vertex_indices\nproperty short flags\n\
             element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n",
            uv.0, uv.1
        )
        .into_bytes();
        let big = format == "binary_big_endian";
        let put = |out: &mut Vec<u8>, bytes: &mut [u8]| {
            if big {
                bytes.reverse();
            }
            out.extend_from_slice(bytes);
        };
        for v in VERTICES {
            if format == "ascii" {
                out.extend(
                    format!(
                        "{} {} {} 200 {} {} {} {} {}\n",
                        v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]
                    )
                    .bytes(),
                );
                continue;
            }
            put(&mut out, &mut (v[0] as f32).to_le_bytes());
            put(&mut out, &mut (v[1] as f32).to_le_bytes());
            put(&mut out, &mut v[2].to_le_bytes());
            out.push(200);
            for x in &v[3..] {
                put(&mut out, &mut (*x as f32).to_le_bytes());
            }
        }
        for f in FACES {
            if format == "ascii" {
                let ids: Vec<String> = f.iter().map(u32::to_string).collect();
                out.extend(format!("{} {} -3\n", f.len(), ids.join(" ")).bytes());
                continue;
            }
            out.push(f.len() as u8);
            for i in f {
                put(&mut out, &mut (*i as i32).to_le_bytes());
            }
            put(&mut out, &mut (-3i16).to_le_bytes());
        }
        if format == "ascii" {
            out.extend(b"0 4\n");
        } else {
            put(&mut out, &mut 0i32.to_le_bytes());
            put(&mut out, &mut 4i32.to_le_bytes());
        }
        out
    }

    fn parse(bytes: &[u8], face_normals: bool) -> Result<TriangleMesh, PlyError> {
        parse_ply(bytes, Path::new("t.ply"), face_normals, false)
    }

    #[test]
    fn the_three_encodings_read_the_same_mesh() {
        for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
            let mesh = parse(&write(format, ("u", "v")), false).expect(format);
            let positions: Vec<DVec3> = VERTICES
                .iter()
                .map(|v| DVec3::new(v[0], v[1], v[2]))
                .collect();
            let normals: Vec<DVec3> = VERTICES
                .iter()
                .map(|v| DVec3::new(v[3], v[4], v[5]))
                .collect();
            let uv: Vec<DVec2> = VERTICES.iter().map(|v| DVec2::new(v[6], v[7])).collect();
            // f32 in the binary files: the values above are exact in f32
            // except 0.6 and 0.8, within 3e-8.
            let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-7;
            assert!(
                mesh.positions
                    .iter()
                    .zip(&positions)
                    .all(|(a, b)| close(*a, *b)),
                "{format}"
            );
            let n = mesh.normals.as_ref().expect("the file's normals");
            assert!(
                n.iter().zip(&normals).all(|(a, b)| close(*a, *b)),
                "{format}"
            );
            assert_eq!(
                mesh.texcoords.as_deref(),
                Some(&uv[..]),
                "{format}: kept as written"
            );
            // The quad as a fan from its first vertex, then the triangle.
            assert_eq!(
                mesh.triangles,
                vec![[0, 1, 2], [0, 2, 3], [3, 2, 4]],
                "{format}"
            );
        }
    }

    #[test]
    fn every_texture_coordinate_naming_is_read() {
        for names in [
            ("s", "t"),
            ("texture_u", "texture_v"),
            ("texture_s", "texture_t"),
        ] {
            let mesh = parse(&write("ascii", names), false).expect("parses");
            assert_eq!(
                mesh.texcoords.map(|t| t[4]),
                Some(DVec2::new(0.5, 2.0)),
                "{names:?}"
            );
        }
        let mesh = parse(&write("ascii", ("q", "r")), false).expect("parses");
        assert!(
            mesh.texcoords.is_none(),
            "other names are not texture coordinates"
        );
    }

    #[test]
    fn without_normals_they_are_recomputed_and_face_normals_drops_them() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n\
                    0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let mesh = parse(text.as_bytes(), false).expect("parses");
        // A counter-clockwise triangle in z = 0 faces +z.
        assert_eq!(mesh.normals, Some(vec![DVec3::Z; 3]));
        let flat = parse(text.as_bytes(), true).expect("parses");
        assert!(flat.normals.is_none() && flat.face_normals);
    }

    /// Each malformed file gives its error, naming where it is.
    #[test]
    fn malformed_files_are_refused_with_the_place() {
        let good = String::from_utf8(write("ascii", ("u", "v"))).expect("ascii");
        let binary = write("binary_little_endian", ("u", "v"));
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"plx\n".to_vec(), "line 1: the file does not start"),
            (
                good.as_bytes()[..good.find("end_header").expect("a header")].to_vec(),
                "no end_header line",
            ),
            (
                good.replace("ascii 1.0", "ascii 2.0").into_bytes(),
                "line 2: unsupported format line",
            ),
            (
                good.replace("format ascii", "format utf8").into_bytes(),
                "unknown format \"utf8\"",
            ),
            (
                good.replace("property float y", "property quad y")
                    .into_bytes(),
                "line 6: unknown property type \"quad\"",
            ),
            (
                good.replace("property float x\n", "").into_bytes(),
                "no x, y and z properties",
            ),
            (
                good.replace("3 3 2 4 -3", "3 3 2 5 -3").into_bytes(),
                "refers to vertex 5, but the file has 5 vertices",
            ),
            (
                good.replace("3 3 2 4 -3", "3 3 2.5 4 -3").into_bytes(),
                "line 27: \"2.5\" is not a number of type I32",
            ),
            (
                good.replace("3 3 2 4 -3", "2 3 2 -3").into_bytes(),
                "a face with 2 vertices",
            ),
            (
                good.replace("0.5 2 0.25", "0.5 nan 0.25").into_bytes(),
                "not a finite number",
            ),
            (
                good.replace("element edge 1", "element edge 1000")
                    .into_bytes(),
                "more than the file's",
            ),
            (
                binary[..binary.len() - 3].to_vec(),
                "data byte 223: the data ends",
            ),
            (
                good.replace("element face 2", "element face 5000000")
                    .into_bytes(),
                "declares 5000000 faces",
            ),
        ];
        for (bytes, what) in cases {
            let e = parse(&bytes, false).expect_err(what).to_string();
            assert!(e.contains(what), "{e:?} should say {what:?}");
            assert!(
                e.starts_with("malformed PLY file t.ply: ") || e.starts_with("PLY file t.ply "),
                "{e}"
            );
        }
    }
}
