//! A stop request for a running search or grid, from a caller that cannot kill the process
//! (the Python package, whose user presses Ctrl-C in a notebook).
//!
//! The engine never stops a drop half-way: a drop that has started runs to its end, and every
//! drop not yet started is skipped once [`Cancel::request`] has been called. The caller then
//! discards the unfinished result; [`Cancel::drops_run`] says how far it got.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// A shared stop flag and a count of the drops that ran to their end.
#[derive(Debug, Default)]
pub struct Cancel {
    requested: AtomicBool,
    drops_run: AtomicUsize,
}

impl Cancel {
    /// A flag not yet raised, no drop counted.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks every drop not yet started to be skipped.
    pub fn request(&self) {
        self.requested.store(true, Ordering::SeqCst);
    }

    /// Whether a stop has been asked for.
    pub fn requested(&self) -> bool {
        self.requested.load(Ordering::SeqCst)
    }

    /// Counts one drop that ran to its end.
    pub fn count_drop(&self) {
        self.drops_run.fetch_add(1, Ordering::Relaxed);
    }

    /// The drops counted so far.
    pub fn drops_run(&self) -> usize {
        self.drops_run.load(Ordering::Relaxed)
    }
}
