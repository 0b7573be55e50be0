//! What can go wrong in a bake.

use thiserror::Error;

/// A bake that cannot be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BakeError {
    /// The scene's light has no finite value somewhere.
    #[error("shape {shape}: its baked radiance is not finite")]
    NotFinite {
        /// The shape's index in the scene.
        shape: u32,
    },
    /// The file would pass glTF's 32-bit length fields.
    #[error("the baked file would hold {bytes} bytes, more than glTF's 4 GiB limit")]
    TooLarge {
        /// The size it would have.
        bytes: u64,
    },
    /// An albedo map could not be encoded.
    #[error("an albedo map could not be encoded as PNG: {0}")]
    Image(String),
    /// The JSON part could not be written.
    #[error("the glTF JSON could not be written: {0}")]
    Json(#[from] serde_json::Error),
}
