//! Orbit classification, re-exported from the core
//! ([`whirlmap_core::classify`](mod@whirlmap_core::classify)): the drop
//! itself needs the classifier to know when its class has settled (and to extend a run that
//! has not), so the classifier lives beside the model; this module keeps the sweep crate's
//! paths.

pub use whirlmap_core::classify::{classify, ClassifyParams, OrbitClass, Reason, Verdict};
