//! # whirlmap-sweep: classification, records and charts on top of whirlmap-core
//!
//! - [`classify`]: the orbit class as a pure function of a drop's streamed features.
//! - [`record`]: the JSON record of one drop (the output contract).
//! - [`overrides`]: scene parameters set by name (`--set key=value`, sweep axes).
//! - [`render`] and [`fonts`]: charts with an embedded font (no system fonts needed).
#![warn(missing_docs)]

pub mod classify;
pub mod fonts;
pub mod overrides;
pub mod record;
pub mod render;
