//! The critical search's finished drops, logged while it runs
//! ([`whirlmap_results::files::CRITICAL_DROPS_FILE`]), so that a killed sweep continued with
//! `--resume` does not run them again.
//!
//! One line per classified drop: the friction coefficient, the speed, the hash of that
//! coefficient's scene and the class. Each line is one `write_all` of a whole line, so a kill
//! loses only the drops in flight (and a torn last line, which a resume cuts). A failed drop is
//! not logged: it runs again on resume, as a failed grid point does. The search is a function
//! of its drops' classes, so a resumed search gives the rows an uninterrupted one gives. The
//! log is removed once `critical.json` is written. A resume reuses a line only for the same
//! coefficient, speed and scene hash (the sweep's `--resume` has already checked the spec and
//! the build); lines it cannot read are dropped, and their drops run again.

use crate::extras::ExtrasError;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use whirlmap_core::OrbitClass;
use whirlmap_results::files::CRITICAL_DROPS_FILE;

/// One logged drop.
#[derive(Debug, Serialize, Deserialize)]
struct Line {
    mu: f64,
    speed_rpm: f64,
    scene_hash: String,
    class: OrbitClass,
}

/// The log of one critical search in a results folder: what an earlier, killed run of the same
/// spec finished, and the file this run appends to.
#[derive(Debug)]
pub struct DropLog {
    path: PathBuf,
    file: Mutex<File>,
    /// (mu bits, speed bits, scene hash) -> class, from the earlier run.
    known: HashMap<(u64, u64, String), OrbitClass>,
    /// Drops answered from `known`.
    reused: AtomicUsize,
    /// The first failed append: the search goes on, and [`DropLog::finish`] reports it.
    error: Mutex<Option<std::io::Error>>,
}

impl DropLog {
    /// Opens the log in `out_dir`. With `resume`, the lines an earlier run left are read, and
    /// the file is rewritten with only the lines that can be read (a torn last line, a line
    /// that is not a drop's, are dropped); otherwise it starts empty. A log that exists but
    /// cannot be read is an error (a missing one is an empty one).
    pub fn open(out_dir: &Path, resume: bool) -> Result<Self, ExtrasError> {
        let path = out_dir.join(CRITICAL_DROPS_FILE);
        let io = |source| ExtrasError::Io {
            path: path.clone(),
            source,
        };
        let mut known = HashMap::new();
        let mut kept = Vec::new();
        if resume {
            let bytes = match std::fs::read(&path) {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
                Err(e) => return Err(io(e)),
            };
            // Only whole lines: a line without its newline was cut by the kill.
            let whole = &bytes[..whirlmap_results::read::complete_len(&bytes)];
            for line in whole.split_inclusive(|b| *b == b'\n') {
                if let Ok(l) = serde_json::from_slice::<Line>(line) {
                    known.insert(
                        (l.mu.to_bits(), l.speed_rpm.to_bits(), l.scene_hash),
                        l.class,
                    );
                    kept.extend_from_slice(line);
                }
            }
        }
        std::fs::create_dir_all(out_dir).map_err(|source| ExtrasError::Io {
            path: out_dir.to_path_buf(),
            source,
        })?;
        whirlmap_results::write_atomic(&path, &kept).map_err(|e| ExtrasError::Io {
            path: e.path,
            source: e.source,
        })?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(io)?;
        Ok(Self {
            path,
            file: Mutex::new(file),
            known,
            reused: AtomicUsize::new(0),
            error: Mutex::new(None),
        })
    }

    /// The class an earlier run found for this coefficient, speed and scene, if it logged it.
    pub fn known(&self, mu: f64, speed_rpm: f64, scene_hash: &str) -> Option<OrbitClass> {
        let key = (mu.to_bits(), speed_rpm.to_bits(), scene_hash.to_string());
        let class = *self.known.get(&key)?;
        self.reused.fetch_add(1, Ordering::Relaxed);
        Some(class)
    }

    /// Appends one classified drop.
    pub fn record(&self, mu: f64, speed_rpm: f64, scene_hash: &str, class: OrbitClass) {
        let line = Line {
            mu,
            speed_rpm,
            scene_hash: scene_hash.to_string(),
            class,
        };
        let mut text = serde_json::to_string(&line).expect("a log line serialises");
        text.push('\n');
        let result = self
            .file
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .write_all(text.as_bytes());
        if let Err(e) = result {
            self.error
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .get_or_insert(e);
        }
    }

    /// How many drops were answered from the earlier run's lines.
    pub fn reused(&self) -> usize {
        self.reused.load(Ordering::Relaxed)
    }

    /// The first failed append, if any, as a message: the search itself is unaffected, only
    /// what a later resume could have reused is lost.
    pub fn finish(self) -> Option<String> {
        let error = self.error.into_inner().unwrap_or_else(|e| e.into_inner())?;
        Some(format!(
            "cannot append to {}: {error} (the search is complete; a resume would have run \
             those drops again)",
            self.path.display()
        ))
    }
}
