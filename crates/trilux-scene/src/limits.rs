//! What a scene file may ask of memory and time (docs/limits.md gives the
//! reasons). Each limit is far above any scene trilux can solve in
//! reasonable time, and low enough that a hostile file is refused, with
//! its location, before it costs more than a few hundred megabytes.

/// Largest scene file (64 MiB): scenes hold no inline geometry, so real
/// ones are kilobytes; the parsed tree takes several times the text.
pub const MAX_SCENE_BYTES: u64 = 64 << 20;

/// Largest mesh file, OBJ or PLY (256 MiB, about 4 million triangles of
/// OBJ text): the mesh in memory takes several times the text, and the
/// solver's charts and elements more again.
pub const MAX_MESH_BYTES: u64 = 256 << 20;

/// Most triangles of one mesh, from any file format (4 million): an OBJ
/// file of short lines (`f 1 2 3`) holds 30 million in [`MAX_MESH_BYTES`],
/// and every triangle costs a few hundred bytes once built into charts,
/// elements and the BVH.
pub const MAX_MESH_TRIANGLES: usize = 4_000_000;

/// Most vertices of one mesh, from any file format (12 million: three
/// per triangle, what splitting an OBJ by position, texture and normal
/// index can make).
pub const MAX_MESH_VERTICES: usize = 12_000_000;

/// Most files a scene may `<include>` (all levels together).
pub const MAX_INCLUDES: usize = 64;

/// Most bytes of all the files a scene includes together (64 MiB, as one
/// scene file).
pub const MAX_INCLUDED_BYTES: u64 = 64 << 20;

/// Most XML nodes in a scene file (elements, text and comments).
pub const MAX_XML_NODES: u32 = 2_000_000;

/// Deepest nesting of elements, `<scene>` counting as 1, also after
/// `<ref>`s are replaced by what they name. Mitsuba scenes nest about 6
/// deep (scene, shape, bsdf, bsdf, spectrum); the loader's stages recurse
/// once per level.
pub const MAX_DEPTH: usize = 64;

/// Most elements once every `<ref>` is replaced by a copy of what it names
/// (a chain of BSDFs each referencing the previous one twice doubles at
/// every step). About 400 MB of expanded tree at the limit.
pub const MAX_ELEMENTS: usize = 1_000_000;

/// Longest attribute value after its `$name`s are substituted (1 MiB: a
/// spectrum of ten thousand samples is 150 KB).
pub const MAX_VALUE_BYTES: usize = 1 << 20;

/// Most bytes that `$name` substitution may produce over the whole file
/// (16 MiB): `<default>`s that expand into one another grow exponentially.
pub const MAX_EXPANDED_BYTES: usize = 16 << 20;

/// The film's limits, shared with the renderer (which checks a film given
/// on the command line against them too).
pub use trilux_files::film::{
    FILM_BYTES_PER_PIXEL, MAX_FILM_EDGE, MAX_FILM_PIXELS, MAX_SAMPLES_PER_PIXEL, check_film,
};

/// Largest emitted radiance (1e20 in any band).
pub use trilux_color::MAX_RADIANCE;

/// Largest image file a texture reads (256 MiB).
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;

/// Most texels of one texture (2^25 = 33.5 M, e.g. 8192 × 4096): trilux
/// keeps 12 bytes a texel (linear RGB, 32-bit floats), 400 MB at the limit.
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 25;

/// Most texels of all the textures of one scene (2^26, 800 MB).
pub const MAX_SCENE_TEXELS: u64 = 1 << 26;

/// Largest `.glb` file, and largest buffer file a `.gltf` names (1 GiB).
pub const MAX_GLB_BYTES: u64 = 1 << 30;

/// Most bytes of all the buffers of one glTF file (2 GiB).
pub const MAX_GLTF_BUFFER_BYTES: u64 = 2 << 30;

/// Most triangles of all the mesh instances of one glTF scene (8 million:
/// a mesh placed by many nodes counts once for each).
pub const MAX_GLTF_TRIANGLES: usize = 8_000_000;

/// Deepest glTF node hierarchy (the loader recurses once a level).
pub const MAX_NODE_DEPTH: usize = 64;

/// Most shapes of one scene: XML `<shape>`s, or mesh primitives placed by
/// glTF nodes (a mesh placed by many nodes counts once for each). Every
/// shape is at least one input surface, and loading takes about 2 KB a
/// shape before its triangles (200 MB at the limit); the solver's setup
/// costs more per input surface, and near pairs of them grow as their
/// square. The largest scene solved in docs/results.md has 1 543.
pub const MAX_SHAPES: usize = 100_000;

/// Most node instances a glTF scene places (a node reached twice is
/// refused: glTF's node graph is a set of disjoint trees).
pub const MAX_GLTF_NODES: usize = 1_000_000;

/// Most errors reported at once (20, then a count of the rest): as a
/// compiler's, enough to repair a file in few runs, few enough to read.
pub const MAX_REPORTED_ERRORS: usize = 20;
