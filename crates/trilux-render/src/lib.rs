//! # trilux-render — final gathering from a solution
//!
//! Layer: depends on every library crate below it; nothing depends on it
//! but the `trilux` command.
#![forbid(unsafe_code)]
