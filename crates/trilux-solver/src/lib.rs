//! # trilux-solver — progressive hierarchical three-point transport
//!
//! Layer: depends on `trilux-color`, `trilux-geometry`, `trilux-brdf` and
//! `trilux-scene`. Implements Dumont, Bouatouch & Gosselin (1997).
#![forbid(unsafe_code)]
