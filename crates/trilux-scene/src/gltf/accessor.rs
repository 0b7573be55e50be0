//! glTF accessors read with every bound checked: the element type and
//! component type the attribute needs, the view and stride inside the
//! buffer, and every value finite (an index within the vertex count).
//! Sparse accessors and accessors without a buffer view are refused.

use std::sync::Arc;

use gltf::accessor::{DataType, Dimensions};
use std::path::Path;

use super::buffers::Buffers;
use crate::error::{Result, SceneError, SourceLocation};

/// What an attribute may be made of.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Kind {
    /// VEC3 of FLOAT (positions, normals).
    Vec3,
    /// VEC2 of FLOAT, or of normalized UNSIGNED_BYTE / UNSIGNED_SHORT.
    Vec2,
    /// SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT (indices).
    Index,
}

impl Kind {
    fn accepts(self, d: Dimensions, t: DataType, normalized: bool) -> bool {
        match self {
            Kind::Vec3 => d == Dimensions::Vec3 && t == DataType::F32,
            Kind::Vec2 => {
                d == Dimensions::Vec2
                    && (t == DataType::F32
                        || (normalized && matches!(t, DataType::U8 | DataType::U16)))
            }
            Kind::Index => {
                d == Dimensions::Scalar
                    && !normalized
                    && matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
            }
        }
    }

    fn name(self) -> &'static str {
        match self {
            Kind::Vec3 => "VEC3 of FLOAT",
            Kind::Vec2 => "VEC2 of FLOAT or normalized UNSIGNED_BYTE/UNSIGNED_SHORT",
            Kind::Index => "SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
        }
    }
}

/// Reads accessor `a` as `kind`: `count` elements of `width` f64 each,
/// flattened.
pub(crate) fn read(
    file: &Arc<Path>,
    buffers: &mut Buffers,
    a: &gltf::Accessor<'_>,
    kind: Kind,
    what: &str,
) -> Result<Vec<f64>> {
    let at = |m: String| {
        SceneError::at(
            &SourceLocation::json(file, format!("/accessors/{}", a.index())),
            format!("{what}: {m}"),
        )
    };
    let (d, t) = (a.dimensions(), a.data_type());
    if !kind.accepts(d, t, a.normalized()) {
        return Err(at(format!(
            "the accessor is {d:?} of {t:?}{}; it must be {}",
            if a.normalized() { " (normalized)" } else { "" },
            kind.name()
        )));
    }
    if a.sparse().is_some() {
        return Err(at("sparse accessors are not supported".into()));
    }
    let view = a
        .view()
        .ok_or_else(|| at("accessors without a bufferView (all zeros) are not supported".into()))?;
    let bytes = buffers.view(&view)?;
    let width = d.multiplicity();
    let size = t.size();
    let element = width * size;
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(at(format!(
            "byteStride {stride} is smaller than an element ({element} bytes)"
        )));
    }
    let count = a.count();
    let end = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(a.offset()))
            .and_then(|x| x.checked_add(element)),
    };
    if end.is_none_or(|e| e > bytes.len()) {
        return Err(at(format!(
            "{count} elements from byte {} with stride {stride} do not fit in the {} bytes of bufferView {}",
            a.offset(),
            bytes.len(),
            view.index()
        )));
    }
    let mut out = Vec::with_capacity(count * width);
    for i in 0..count {
        let base = a.offset() + i * stride;
        for c in 0..width {
            let p = base + c * size;
            let b = &bytes[p..p + size];
            let v = match t {
                DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                DataType::U8 if a.normalized() => f64::from(b[0]) / 255.0,
                DataType::U16 if a.normalized() => {
                    f64::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0
                }
                DataType::U8 => f64::from(b[0]),
                DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                DataType::I8 | DataType::I16 => return Err(at("signed components".into())),
            };
            if !v.is_finite() {
                return Err(at(format!("element {i} is not a finite number")));
            }
            out.push(v);
        }
    }
    Ok(out)
}
