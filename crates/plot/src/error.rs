//! Why charts could not be drawn.

use std::path::PathBuf;

use whirlmap_results::read::{LoadError, ReadError};

use crate::render::RenderError;

/// Why charts could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The results directory has no `points.jsonl`.
    #[error("no sweep results: {} does not exist", path.display())]
    NoPoints {
        /// The missing file.
        path: PathBuf,
    },
    /// An input file could not be read.
    #[error("cannot read {}: {cause}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// An input file is not what it should be (a torn last line of points.jsonl is not).
    #[error("{}: line {line}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (1 for whole-file JSON).
        line: usize,
        /// What is wrong.
        message: String,
    },
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

impl From<LoadError> for ChartError {
    fn from(e: LoadError) -> Self {
        match e {
            LoadError::NoPoints { path } => ChartError::NoPoints { path },
            LoadError::Read { path, cause } => ChartError::Read { path, cause },
            LoadError::Parse {
                path,
                line,
                message,
            } => ChartError::Parse {
                path,
                line,
                message,
            },
        }
    }
}

impl From<ReadError> for ChartError {
    fn from(e: ReadError) -> Self {
        LoadError::from(e).into()
    }
}
