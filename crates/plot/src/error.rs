//! Why charts could not be drawn.

use std::path::PathBuf;

use whirlmap_results::read::{LoadError, ReadError};

use crate::render::RenderError;

/// Why charts could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// Missing or bad input (no `points.jsonl`, an unreadable or malformed file), in the
    /// words of the results layer.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The charts directory could not be created.
    #[error("cannot create {}: {cause}", path.display())]
    Write {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// A chart could not be drawn or saved.
    #[error(transparent)]
    Render(#[from] RenderError),
}

impl ChartError {
    /// Whether this is a failure to write output (as opposed to missing or bad input).
    pub fn is_output(&self) -> bool {
        matches!(self, ChartError::Write { .. } | ChartError::Render(_))
    }
}

impl From<ReadError> for ChartError {
    fn from(e: ReadError) -> Self {
        LoadError::from(e).into()
    }
}
