//! # whirlmap-results: the files of a results folder
//!
//! One typed layer between the model ([`whirlmap_core`]) and everything that writes or reads
//! a results folder (sweeps, merges, charts, comparisons):
//!
//! - [`files`]: the name of every file and folder of a results folder, in one place.
//! - [`record`], [`point`]: the record of one drop and the lines of `points.jsonl`, written
//!   and read back through the same types, byte for byte.
//! - [`summary`]: the rows of `summary.csv`, made from the lines of `points.jsonl`.
//! - [`bearing_report`]: `bearing.md`, the touchdown-bearing survival report, made from the
//!   lines of `points.jsonl`.
//! - [`critical`]: the rows of `critical.json` and `critical.csv`.
//! - [`orbit`]: the recorded orbits of `orbits/`.
//! - [`contours`]: an ensemble's `contours.json`.
//! - [`ensemble`]: an ensemble's `members.jsonl` and `cells.jsonl`.
//! - [`adaptive`]: `adaptive.json`, an adaptive refinement of the class map.
//! - [`manifest`]: `manifest.json` (a run's, tolerantly any folder's, an ensemble's) and
//!   `timings.jsonl`.
//! - [`grid`]: the points arranged over release speed and friction (the grid charts, a
//!   comparison's changed cells).
//! - [`read`]: JSON Lines that tolerate a torn last line, whole-file JSON, typed errors that
//!   name the file and line.
//! - [`atomic`]: all-or-nothing writes.
//!
//! No threads, no charts: this crate only knows the files.
#![warn(missing_docs)]

pub mod adaptive;
pub mod atomic;
pub mod bearing_report;
pub mod contours;
pub mod critical;
pub mod ensemble;
pub mod files;
pub mod grid;
pub mod manifest;
mod nan;
pub mod orbit;
pub mod point;
pub mod read;
pub mod record;
pub mod summary;

pub use atomic::{write_atomic, write_atomic_with, WriteError};
pub use read::{LoadError, ReadError};
