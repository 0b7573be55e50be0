//! Textures a scene asks for, read last: each request names its image (a
//! file, or bytes of a glTF buffer), how it is looked up, and the material
//! parameter it stands for (a [`TextureSlot`]). [`Pending::finish`]
//! reads and decodes them ([`crate::image`]), each image once however many
//! materials use it, within [`MAX_SCENE_TEXELS`] for the whole scene.
//!
//! [`Pending::finish`]: crate::Pending::finish

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use trilux_brdf::{
    Branch, NormalMap, NormalPerturbation, SlotFactor, SlotKind, Texture, TextureSlot, UvTransform,
};

use crate::error::{Result, SceneError, SourceLocation};
use crate::image::{MAX_IMAGE_BYTES, Sampling, decode_counted};
use crate::limits::MAX_SCENE_TEXELS;

/// Where an image's bytes are.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum ImageSource {
    /// A file (relative names already joined to the scene's folder).
    File(PathBuf),
    /// Bytes already in memory (a glTF `data:` URI or buffer view).
    Bytes(Arc<[u8]>),
    /// Mitsuba's `checkerboard`: 1 on the diagonal of 2 × 2 texels, 0 off
    /// it (its colours are the request's offset and scale).
    Checkerboard,
}

/// A texture of one material parameter, not read yet.
#[derive(Clone, Debug)]
pub(crate) struct TextureRequest {
    /// The BSDF that has the parameter, from the top of the material.
    pub path: Vec<Branch>,
    /// The parameter.
    pub kind: SlotKind,
    /// The image.
    pub source: ImageSource,
    /// Its lookups.
    pub sampling: Sampling,
    /// value = offset + scale ⊙ texture.
    pub scale: [f64; 3],
    /// See `scale`.
    pub offset: [f64; 3],
    /// The map from the shape's texture coordinates to the image's
    /// (Mitsuba's `to_uv`, glTF's `KHR_texture_transform`).
    pub to_uv: UvTransform,
    /// Where the texture is named, for errors.
    pub location: SourceLocation,
    /// Set for a normal or bump map: how it turns the shading normal
    /// (`path` and `kind` then mean nothing).
    pub normal: Option<NormalPerturbation>,
    /// A second texture multiplying part of the value
    /// (`trilux_brdf::SlotFactor`; its `path`, `kind`, `factor` and `max`
    /// mean nothing).
    pub factor: Option<Box<TextureRequest>>,
    /// The largest value at a point (`trilux_brdf::TextureSlot::max`).
    pub max: f64,
}

/// Decoded images, by source and lookup, with their channel counts, and
/// the texels they hold.
#[derive(Default)]
pub(crate) struct TextureCache {
    images: HashMap<(ImageSource, Sampling), (Arc<Texture>, usize)>,
    texels: u64,
}

impl TextureCache {
    /// The image of a request and its channel count, read and decoded once.
    fn image(&mut self, request: &TextureRequest) -> Result<(Arc<Texture>, usize)> {
        let key = (request.source.clone(), request.sampling);
        if let Some((t, c)) = self.images.get(&key) {
            return Ok((Arc::clone(t), *c));
        }
        let (t, channels) = read(request)?;
        let t = Arc::new(t);
        self.texels += u64::from(t.width()) * u64::from(t.height());
        if self.texels > MAX_SCENE_TEXELS {
            return Err(SceneError::at(
                &request.location,
                format!(
                    "the scene's textures hold more than {MAX_SCENE_TEXELS} texels in all (docs/limits.md)"
                ),
            ));
        }
        self.images.insert(key, (Arc::clone(&t), channels));
        Ok((t, channels))
    }

    /// The slot a request stands for, its image read and decoded once.
    pub fn slot(&mut self, request: &TextureRequest) -> Result<TextureSlot> {
        let (texture, _) = self.image(request)?;
        let factor = match &request.factor {
            Some(f) => Some(SlotFactor {
                texture: self.image(f)?.0,
                to_uv: f.to_uv,
                scale: f.scale,
                offset: f.offset,
            }),
            None => None,
        };
        Ok(TextureSlot {
            path: request.path.clone(),
            kind: request.kind,
            texture,
            scale: request.scale,
            offset: request.offset,
            to_uv: request.to_uv,
            factor,
            max: request.max,
        })
    }

    /// The normal or bump map of a request whose `normal` is set; a normal
    /// map's image must be RGB (Mitsuba's `eval_3` refuses a grey one).
    pub fn normal_map(
        &mut self,
        request: &TextureRequest,
        perturbation: NormalPerturbation,
    ) -> Result<NormalMap> {
        let (texture, channels) = self.image(request)?;
        if matches!(perturbation, NormalPerturbation::Normal { .. }) && channels < 3 {
            return Err(SceneError::at(
                &request.location,
                format!(
                    "a normal map needs an RGB image, found {channels} channel{}",
                    if channels == 1 { "" } else { "s" }
                ),
            ));
        }
        Ok(NormalMap {
            perturbation,
            texture,
            to_uv: request.to_uv,
        })
    }
}

fn read(request: &TextureRequest) -> Result<(Texture, usize)> {
    let at = |m: String| SceneError::at(&request.location, m);
    match &request.source {
        ImageSource::File(path) => {
            let bytes = trilux_files::read_limited(path, MAX_IMAGE_BYTES)
                .map_err(|e| at(format!("cannot read image {}: {e}", path.display())))?;
            decode_counted(&bytes, request.sampling)
                .map_err(|e| at(format!("{}: {e}", path.display())))
        }
        ImageSource::Checkerboard => Texture::new(
            2,
            2,
            vec![[1.0; 3], [0.0; 3], [0.0; 3], [1.0; 3]],
            request.sampling.wrap,
            request.sampling.filter,
        )
        .map(|t| (t, 3))
        .map_err(|e| at(e.to_string())),
        ImageSource::Bytes(bytes) => {
            if bytes.len() as u64 > MAX_IMAGE_BYTES {
                return Err(at(format!(
                    "image of {} bytes is beyond the limit of {MAX_IMAGE_BYTES} bytes (docs/limits.md)",
                    bytes.len()
                )));
            }
            decode_counted(bytes, request.sampling).map_err(|e| at(e.to_string()))
        }
    }
}
