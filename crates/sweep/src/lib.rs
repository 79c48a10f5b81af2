//! # whirlmap-sweep: classification, sweeps, searches and ensembles on top of whirlmap-core
//!
//! - [`classify`]: the orbit class as a pure function of a drop's streamed features.
//! - [`record`]: the JSON record of one drop (the output contract), re-exported from
//!   [`results`] (`whirlmap-results`: the files of a results folder, their names and typed
//!   rows, JSONL reading, atomic writes).
//! - [`overrides`]: scene parameters set by name (`--set key=value`, sweep axes).
//! - [`spec`] and [`sweep`]: sweep specs (JSON grids over scene parameters) and the
//!   parallel, crash-safe, resumable sweep engine (`points.jsonl`, `summary.csv`, manifest).
//! - [`folder`]: a results folder's lock, its manifest's file list and the checks of a
//!   reader; [`build_info`]: the build (version and commit) every manifest records.
//! - [`ordered`]: work stealing over numbered jobs with an ordered, bounded writer (how a
//!   sweep's grid runs).
//! - [`shard`] and [`merge`]: a sweep split over machines and joined again.
//! - [`compare`]: what changed between two results (nightly jobs).
//! - [`cancel`]: a stop request for a running search or grid (the Python package's Ctrl-C).
//! - [`accuracy`]: the work-precision study (`whirlmap accuracy`).
//! - [`ensemble`]: whirl probability per cell (seeded ensembles of drops), probability
//!   contours; [`adaptive`]: adaptive refinement of the whirl boundary;
//!   [`adaptive_log`] and [`critical_log`]: what a killed search finished, for `--resume`.
//!
//! No charts: drawing is `whirlmap-plot`'s, which reads what this crate writes. A merge
//! and a comparison take the drawing as a function from their caller.
#![warn(missing_docs)]
// `!(x <= bound)` on purpose: a NaN fails the check instead of passing it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub use whirlmap_results as results;

pub mod accuracy;
pub mod adaptive;
pub mod adaptive_log;
pub mod build_info;
pub mod cancel;
pub mod classify;
pub mod compare;
pub mod critical;
pub mod critical_log;
pub mod ensemble;
pub mod extras;
pub mod extremes;
pub mod folder;
pub mod merge;
pub mod ordered;
pub mod overrides;
pub mod pipeline;
pub mod pool;
pub mod progress;
pub mod recheck;
pub mod record;
pub mod run;
#[cfg(feature = "schema")]
pub mod schema;
pub mod shard;
pub mod spec;
pub mod sweep;
