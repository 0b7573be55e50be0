//! # trilux-color — the lowest layer: light as spectra
//!
//! Layer: depends on nothing else in trilux. Everything above carries light
//! with the types defined here.
//!
//! Contents:
//! - [`param`]: colour values as a scene file states them ([`ColorParam`]),
//!   before they are turned into the spectra of one solve.
#![forbid(unsafe_code)]

pub mod param;

pub use param::ColorParam;
