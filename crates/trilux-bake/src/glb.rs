//! The glTF 2.0 binary container (glTF 2.0 specification, §4.4 "GLB File
//! Format"): a 12-byte header, a JSON chunk padded with spaces and a BIN
//! chunk padded with zeros, each to 4 bytes. One buffer holds every
//! accessor's data and every image; each has its own buffer view (tightly
//! packed, 4-byte aligned).

use serde_json::{Value, json};

use crate::error::BakeError;

/// `ARRAY_BUFFER`, the target of vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// `ELEMENT_ARRAY_BUFFER`, the target of indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// `FLOAT`.
const FLOAT: u32 = 5126;
/// `UNSIGNED_INT`.
const UNSIGNED_INT: u32 = 5125;

/// The parts of a glTF document being written.
#[derive(Debug, Default)]
pub struct Document {
    /// The BIN chunk's contents.
    pub bin: Vec<u8>,
    /// `bufferViews`.
    pub views: Vec<Value>,
    /// `accessors`.
    pub accessors: Vec<Value>,
    /// `meshes`.
    pub meshes: Vec<Value>,
    /// `materials`.
    pub materials: Vec<Value>,
    /// `nodes`.
    pub nodes: Vec<Value>,
    /// `cameras`.
    pub cameras: Vec<Value>,
    /// `images`.
    pub images: Vec<Value>,
    /// `textures`.
    pub textures: Vec<Value>,
    /// `samplers`.
    pub samplers: Vec<Value>,
}

impl Document {
    /// A buffer view of `bytes` (4-byte aligned) for `target`, if any.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.views.push(view);
        self.views.len() - 1
    }

    /// An accessor over 4-byte little-endian `components`, `width` per
    /// element (`type_`: "SCALAR", "VEC2", "VEC3"), of `component_type`,
    /// in a view for `target`. Returns the accessor's index.
    fn accessor(
        &mut self,
        components: impl Iterator<Item = [u8; 4]>,
        (type_, width): (&str, usize),
        component_type: u32,
        target: u32,
    ) -> usize {
        let bytes: Vec<u8> = components.flatten().collect();
        let view = self.view(&bytes, Some(target));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": component_type,
            "count": bytes.len() / (4 * width),
            "type": type_,
        }));
        self.accessors.len() - 1
    }

    /// A `VEC2` float vertex attribute (texture coordinates). Returns the
    /// accessor's index.
    pub fn vec2(&mut self, data: &[[f32; 2]]) -> usize {
        let c = data.iter().flatten().map(|x| x.to_le_bytes());
        self.accessor(c, ("VEC2", 2), FLOAT, ARRAY_BUFFER)
    }

    /// A `VEC3` float vertex attribute; with `bounds`, its `min` and `max`
    /// (required for `POSITION`). Returns the accessor's index.
    pub fn vec3(&mut self, data: &[[f32; 3]], bounds: bool) -> usize {
        let c = data.iter().flatten().map(|x| x.to_le_bytes());
        let index = self.accessor(c, ("VEC3", 3), FLOAT, ARRAY_BUFFER);
        if bounds {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in data {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            self.accessors[index]["min"] = json!(lo);
            self.accessors[index]["max"] = json!(hi);
        }
        index
    }

    /// Triangle indices. Returns the accessor's index.
    pub fn indices(&mut self, data: &[[u32; 3]]) -> usize {
        let c = data.iter().flatten().map(|x| x.to_le_bytes());
        self.accessor(c, ("SCALAR", 1), UNSIGNED_INT, ELEMENT_ARRAY_BUFFER)
    }

    /// A PNG image in the buffer with its sampler, as a texture. Returns
    /// the texture's index.
    pub(crate) fn png_texture(&mut self, png: &[u8], sampler: Value) -> usize {
        let view = self.view(png, None);
        self.images
            .push(json!({ "bufferView": view, "mimeType": "image/png" }));
        self.samplers.push(sampler);
        self.textures.push(json!({
            "source": self.images.len() - 1,
            "sampler": self.samplers.len() - 1,
        }));
        self.textures.len() - 1
    }

    /// The whole file: `asset` and `extensionsUsed` as given, one scene of
    /// every node.
    pub(crate) fn into_glb(self, asset: Value, extensions: &[&str]) -> Result<Vec<u8>, BakeError> {
        let nodes: Vec<usize> = (0..self.nodes.len()).collect();
        let mut root = json!({
            "asset": asset,
            "extensionsUsed": extensions,
            "scene": 0,
            "scenes": [{ "nodes": nodes }],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{ "byteLength": self.bin.len() }],
        });
        for (key, list) in [
            ("cameras", self.cameras),
            ("images", self.images),
            ("textures", self.textures),
            ("samplers", self.samplers),
        ] {
            if !list.is_empty() {
                root[key] = json!(list);
            }
        }
        let mut text = serde_json::to_vec(&root)?;
        text.resize(text.len().next_multiple_of(4), b' ');
        let mut bin = self.bin;
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + text.len() as u64 + 8 + bin.len() as u64;
        let length = u32::try_from(total).map_err(|_| BakeError::TooLarge { bytes: total })?;
        let mut out = Vec::with_capacity(total as usize);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&length.to_le_bytes());
        for (kind, chunk) in [(b"JSON", &text), (b"BIN\0", &bin)] {
            out.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
            out.extend_from_slice(kind);
            out.extend_from_slice(chunk);
        }
        Ok(out)
    }
}
