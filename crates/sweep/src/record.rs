//! The JSON record of one drop, re-exported from [`whirlmap_results::record`] (the results
//! layer owns every row of a results folder); this module keeps the sweep crate's paths.

pub use whirlmap_results::record::DropRecord;
