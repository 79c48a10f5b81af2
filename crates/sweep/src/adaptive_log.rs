//! The adaptive search's evaluated corners, logged while it runs
//! ([`whirlmap_results::files::ADAPTIVE_CORNERS_FILE`]), so that a killed `whirlmap adaptive`
//! continued with `--resume` does not evaluate them again.
//!
//! The first line records the spec and the build; each further line is one corner, `i` and
//! `j` on the fine grid and its `p_whirl`, appended with one `write_all` per chunk of a batch
//! (a few corners per thread), so a kill loses at most the chunk in flight (and a torn last
//! line, which a resume cuts). A failed corner (`p_whirl` NaN) is not logged: it runs again.
//! The search is a function of its corners' values, so a resumed search writes the
//! `adaptive.json` an uninterrupted one writes. A resume refuses a log of another spec or build; the log is
//! removed once `adaptive.json` is written. It is appended and not synced: a power loss may
//! lose its last lines, and those corners run again.

use crate::ensemble::EnsembleSpec;
use crate::sweep::SweepError;
use serde::{Deserialize, Serialize};
use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use whirlmap_results::files::ADAPTIVE_CORNERS_FILE;

/// The log's first line: whose corners follow.
#[derive(Debug, Serialize, Deserialize)]
struct Header {
    spec: serde_json::Value,
    version: String,
    git_commit: String,
}

/// One evaluated corner.
#[derive(Debug, Serialize, Deserialize)]
struct Corner {
    i: usize,
    j: usize,
    p_whirl: f64,
}

/// The corner log of one adaptive search in a results folder: the corners an earlier, killed
/// run of the same spec and build evaluated, and the file this run appends to.
#[derive(Debug)]
pub struct CornerLog {
    path: PathBuf,
    file: File,
    /// (i, j) -> p_whirl, from the earlier run.
    known: HashMap<(usize, usize), f64>,
}

impl CornerLog {
    /// Opens the log in `out_dir` for `spec` on a fine grid of `shape` points. With `resume`,
    /// the corners an earlier run of the same spec and build logged are known (a log of another
    /// spec or build is refused, exit 2), and the file is rewritten with its header and the
    /// corner lines it keeps: whole lines that can be read, of a point on the grid, with a
    /// value in [0, 1], the first of a point (a torn last line, or anything else, is dropped,
    /// and that corner runs again); otherwise, or when there is no log, it starts with a new
    /// header.
    pub fn open(
        out_dir: &Path,
        spec: &EnsembleSpec,
        shape: (usize, usize),
        resume: bool,
    ) -> Result<Self, SweepError> {
        let path = out_dir.join(ADAPTIVE_CORNERS_FILE);
        let io = |e| crate::sweep::io_err(&path)(e);
        let spec_value = serde_json::to_value(spec).expect("specs serialise");
        let header = Header {
            spec: spec_value.clone(),
            version: crate::build_info::VERSION.to_string(),
            git_commit: crate::build_info::GIT_COMMIT.to_string(),
        };
        let mut text = serde_json::to_string(&header).expect("a header serialises");
        text.push('\n');
        let mut known = HashMap::new();
        let bytes = if resume {
            match std::fs::read(&path) {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
                Err(e) => return Err(io(e)),
            }
        } else {
            Vec::new()
        };
        // Only whole lines: a line without its newline was cut by the kill.
        let whole = &bytes[..whirlmap_results::read::complete_len(&bytes)];
        let mut lines = whole.split_inclusive(|b| *b == b'\n');
        if let Some(first) = lines.next() {
            let refuse = |why: String| {
                SweepError::Refused(format!(
                    "cannot resume the adaptive search in {}: {why}. Use --overwrite to replace \
                     it, or choose another --out",
                    out_dir.display()
                ))
            };
            let old: Header = serde_json::from_slice(first).map_err(|e| {
                refuse(format!(
                    "{} does not start with its header ({e})",
                    path.display()
                ))
            })?;
            if old.spec != spec_value {
                return Err(refuse("its corners were evaluated for another spec".into()));
            }
            if let Some(b) =
                crate::build_info::other_build(Some(&old.version), Some(&old.git_commit))
            {
                return Err(refuse(format!(
                    "its corners were evaluated by another build ({b}, this is {})",
                    crate::build_info::DESCRIPTION
                )));
            }
            for line in lines {
                let (Ok(c), Ok(line)) = (
                    serde_json::from_slice::<Corner>(line),
                    std::str::from_utf8(line),
                ) else {
                    continue;
                };
                let on_grid = c.i < shape.0 && c.j < shape.1 && (0.0..=1.0).contains(&c.p_whirl);
                if let (true, Entry::Vacant(v)) = (on_grid, known.entry((c.i, c.j))) {
                    v.insert(c.p_whirl);
                    text.push_str(line);
                }
            }
        }
        std::fs::create_dir_all(out_dir).map_err(|e| crate::folder::output_error(out_dir, e))?;
        crate::folder::write_atomic(&path, text.as_bytes())?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(io)?;
        Ok(Self { path, file, known })
    }

    /// The value an earlier run found at fine point `(i, j)`, if it logged one.
    pub fn known(&self, p: (usize, usize)) -> Option<f64> {
        self.known.get(&p).copied()
    }

    /// How many corners of the earlier run are kept.
    pub fn known_len(&self) -> usize {
        self.known.len()
    }

    /// Appends the evaluated corners with a finite value (a failed one runs again on resume).
    pub fn record(&mut self, corners: &[((usize, usize), f64)]) -> Result<(), SweepError> {
        let mut text = String::new();
        for &((i, j), p_whirl) in corners.iter().filter(|(_, p)| p.is_finite()) {
            text.push_str(&serde_json::to_string(&Corner { i, j, p_whirl }).expect("serialises"));
            text.push('\n');
        }
        self.file
            .write_all(text.as_bytes())
            .map_err(crate::sweep::io_err(&self.path))
    }

    /// Removes the log (once `adaptive.json` holds the search).
    pub fn remove(self) -> Result<(), SweepError> {
        drop(self.file);
        match std::fs::remove_file(&self.path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(crate::sweep::io_err(&self.path)(e))
            }
            _ => Ok(()),
        }
    }
}
