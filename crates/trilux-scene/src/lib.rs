//! # trilux-scene — the scene model and its file formats
//!
//! Layer: depends on `trilux-color`, `trilux-geometry` and `trilux-brdf`.
//! File formats live only here; the solver and the renderer never parse.
#![forbid(unsafe_code)]
