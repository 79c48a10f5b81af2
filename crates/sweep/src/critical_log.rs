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
//!
//! `whirlmap critical --log FILE` keeps such a log of its own across runs
//! ([`DropLog::open_kept`]): its lines also carry the drop length and the build, and a line
//! answers a drop only for the same coefficient, speed, scene, length and build. A killed
//! search run again resumes, and a rerun with a narrower tolerance or a wider range reuses
//! the drops the two share.

use crate::extras::ExtrasError;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use thiserror::Error;
use whirlmap_core::OrbitClass;
use whirlmap_results::files::CRITICAL_DROPS_FILE;

/// One logged drop.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Line {
    mu: f64,
    speed_rpm: f64,
    scene_hash: String,
    class: OrbitClass,
    /// The drop length (s): in a kept log only (a sweep's spec fixes it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    duration_s: Option<f64>,
    /// The build, `version (commit c)`: in a kept log only (a sweep's resume checks it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    build: Option<String>,
}

/// What a drop is looked up by: the coefficient's and the speed's bits, the scene hash, and
/// in a kept log the drop length's bits and the build.
type Key = (u64, u64, String, Option<u64>, Option<String>);

/// Why a kept log ([`DropLog::open_kept`]) cannot be used.
#[derive(Debug, Error)]
pub enum KeptLogError {
    /// The file exists but holds something else: it is left as it is.
    #[error(
        "{path} is not a critical-search drop log (line {line}: {reason}); it is left as it \
         is: name another --log file"
    )]
    NotALog {
        /// The file.
        path: PathBuf,
        /// The first line that is not a logged drop (1-based).
        line: usize,
        /// Why it is not.
        reason: String,
    },
    /// Another process holds the file's lock.
    #[error(
        "{path} is in use by another whirlmap critical; wait for it, or name another --log file"
    )]
    Busy {
        /// The file.
        path: PathBuf,
    },
    /// The file cannot be opened, read, locked or trimmed.
    #[error("cannot use {path} as the drop log")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

impl KeptLogError {
    /// Whether the storage failed (exit 4: disk full, an I/O error) rather than the file
    /// named being unusable (exit 2: another kind of file, a directory, no permission, in
    /// use), as [`crate::folder::is_storage_error`] tells them apart.
    pub fn is_storage_error(&self) -> bool {
        match self {
            KeptLogError::Io { source, .. } => crate::folder::is_storage_error(source),
            _ => false,
        }
    }
}

impl Line {
    fn key(self) -> Key {
        (
            self.mu.to_bits(),
            self.speed_rpm.to_bits(),
            self.scene_hash,
            self.duration_s.map(f64::to_bits),
            self.build,
        )
    }
}

/// The log of one critical search in a results folder: what an earlier, killed run of the same
/// spec finished, and the file this run appends to.
#[derive(Debug)]
pub struct DropLog {
    path: PathBuf,
    file: Mutex<File>,
    /// The lines' keys -> class, from the earlier runs.
    known: HashMap<Key, OrbitClass>,
    /// What this run's lines carry beside the drop: `(duration_s, build)` in a kept log.
    context: Option<(f64, String)>,
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
                    let class = l.class;
                    known.insert(l.key(), class);
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
            context: None,
            reused: AtomicUsize::new(0),
            error: Mutex::new(None),
        })
    }

    /// Opens (or creates) the log a user names, kept across runs: every line it holds is
    /// read, and those of drops `duration_s` long made by this build answer their drops. The
    /// file is locked while the search runs (a second search on it is refused). A torn last
    /// line, which a kill leaves, is cut; the file is otherwise never rewritten, and a file
    /// with any other whole line that is not a logged drop is refused and left as it is.
    pub fn open_kept(path: &Path, duration_s: f64) -> Result<Self, KeptLogError> {
        let io = |source| KeptLogError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(KeptLogError::Busy {
                    path: path.to_path_buf(),
                })
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
        }
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut file, &mut bytes).map_err(io)?;
        let whole = whirlmap_results::read::complete_len(&bytes);
        let mut known = HashMap::new();
        for (i, line) in bytes[..whole].split(|b| *b == b'\n').enumerate() {
            if line.is_empty() {
                continue;
            }
            let l = serde_json::from_slice::<Line>(line).map_err(|e| KeptLogError::NotALog {
                path: path.to_path_buf(),
                line: i + 1,
                reason: e.to_string(),
            })?;
            let class = l.class;
            known.insert(l.key(), class);
        }
        if whole < bytes.len() {
            // A kill tears a line of this log, which starts as every line does; anything
            // else without its newline is another file's (a one-line JSON file), left as it
            // is.
            let tail = &bytes[whole..];
            let start = br#"{"mu":"#;
            if !(tail.starts_with(start) || start.starts_with(tail)) {
                return Err(KeptLogError::NotALog {
                    path: path.to_path_buf(),
                    line: bytes[..whole].iter().filter(|b| **b == b'\n').count() + 1,
                    reason: "it does not end with a newline, and is not a torn line of this log"
                        .into(),
                });
            }
            file.set_len(whole as u64).map_err(io)?;
        }
        Ok(Self {
            path: path.to_path_buf(),
            file: Mutex::new(file),
            known,
            context: Some((duration_s, crate::build_info::DESCRIPTION.to_string())),
            reused: AtomicUsize::new(0),
            error: Mutex::new(None),
        })
    }

    /// How many drops the log holds that this run can use (read when it was opened).
    pub fn usable(&self) -> usize {
        let (d, b) = self.context_key();
        self.known
            .keys()
            .filter(|k| k.3 == d && k.4.as_deref() == b)
            .count()
    }

    fn context_key(&self) -> (Option<u64>, Option<&str>) {
        match &self.context {
            Some((d, b)) => (Some(d.to_bits()), Some(b.as_str())),
            None => (None, None),
        }
    }

    /// The class an earlier run found for this coefficient, speed and scene, if it logged it.
    pub fn known(&self, mu: f64, speed_rpm: f64, scene_hash: &str) -> Option<OrbitClass> {
        let (d, b) = self.context_key();
        let key = (
            mu.to_bits(),
            speed_rpm.to_bits(),
            scene_hash.to_string(),
            d,
            b.map(str::to_string),
        );
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
            duration_s: self.context.as_ref().map(|c| c.0),
            build: self.context.as_ref().map(|c| c.1.clone()),
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
