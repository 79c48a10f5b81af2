//! A results folder as a record: one writer at a time, every file listed in its manifest, and
//! readers that refuse what the run did not write.
//!
//! ## The lock
//! A run (sweep, shard, merge) and `render` hold an advisory lock ([`std::fs::File::try_lock`])
//! on [`LOCK_FILE`] in the folder for as long as they write it. A second writer is refused
//! (exit 2) with the holder's process id and command. The operating system drops the lock
//! when the process ends, however it ends, so a `kill -9` never leaves a stale lock. The lock
//! file stays in the folder (deleting it would let two processes lock two different files).
//!
//! ## What a run owns
//! Every name in [`OWNED`] is whirlmap's. A new run into a folder that holds any of them is
//! refused (exit 2) unless it is told `--resume` (the same spec and build: the records are
//! kept, and so are what the extras finished: `critical.json`, the critical search's logged
//! drops ([`crate::critical_log`]), the orbit files and the probability ensemble's members,
//! [`crate::extras::run_all_owned`]; every other derived
//! file is removed and made again) or `--overwrite` (the old files are
//! moved into [`PREVIOUS_DIR`] and deleted once the new run's first records are synced to
//! disk, so a rerun killed early loses nothing). Other files are left alone and never read,
//! in the owned subfolders too: `charts/` and `orbits/` are moved and removed file by file,
//! only whirlmap's ([`is_whirlmaps`]).
//!
//! ## The manifest's file list
//! `manifest.json` is written when a run starts (`complete: false`) and rewritten after each
//! stage; it holds the spec, its hash ([`crate::shard::spec_hash`]), the build, and `files`:
//! every file the run wrote with its size and FNV-1a 64 hash. `complete` turns true when the
//! last stage is written. A reader ([`check_inputs`]) accepts a derived file (`critical.json`,
//! `orbits/`, `probability/`, `points.jsonl` of a finished run) only when the manifest lists
//! it with that size and hash: a file from an earlier spec, copied in or edited afterwards,
//! is refused, naming the file. In a run that did not finish, a file not yet listed is read
//! with a warning (the run started from a folder without another run's files). Folders
//! without a manifest, or with one from an earlier whirlmap that has no file list, are read
//! as before with a warning that they cannot be checked.

use crate::spec::SweepSpec;
use crate::sweep::{io_err, SweepError};
use serde::Deserialize;
use serde_json::Value;
use std::collections::BTreeMap;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use whirlmap_results::files::{
    ACCURACY_CSV_FILE, ACCURACY_REPORT_FILE, ADAPTIVE_CORNERS_FILE, ADAPTIVE_FILE,
    BEARING_REPORT_FILE, CELLS_CSV_FILE, CELLS_FILE, CHARTS_DIR, COMPARE_CLASSES_FILE,
    COMPARE_REPORT_FILE, CONTOURS_FILE, CRITICAL_CSV_FILE, CRITICAL_DROPS_FILE, CRITICAL_FILE,
    MANIFEST_FILE, MEMBERS_FILE, ORBITS_DIR, POINTS_FILE, PROBABILITY_DIR, SHARD_FILE, STUDY_FILE,
    SUMMARY_FILE, TIMINGS_FILE,
};
use whirlmap_results::manifest::{Manifest, ShardTag};

pub use whirlmap_results::files::{LOCK_FILE, PREVIOUS_DIR};

/// The names whirlmap writes into a results folder (files and folders): a sweep's, and those
/// of the other commands' folders (an ensemble's, an adaptive search's, a work-precision
/// study's), so that no command writes into another's folder unasked.
pub const OWNED: &[&str] = &[
    MEMBERS_FILE,
    CELLS_FILE,
    CELLS_CSV_FILE,
    CONTOURS_FILE,
    ADAPTIVE_FILE,
    ADAPTIVE_CORNERS_FILE,
    ACCURACY_CSV_FILE,
    ACCURACY_REPORT_FILE,
    STUDY_FILE,
    "work_precision.png",
    "work_precision.svg",
    "work_precision_wall.png",
    "work_precision_wall.svg",
    POINTS_FILE,
    TIMINGS_FILE,
    SUMMARY_FILE,
    BEARING_REPORT_FILE,
    MANIFEST_FILE,
    CRITICAL_FILE,
    CRITICAL_CSV_FILE,
    CRITICAL_DROPS_FILE,
    ORBITS_DIR,
    CHARTS_DIR,
    PROBABILITY_DIR,
    SHARD_FILE,
    COMPARE_REPORT_FILE,
    COMPARE_CLASSES_FILE,
    PREVIOUS_DIR,
];

/// The derived names a `--resume` removes before it makes them again.
const DERIVED: &[&str] = &[
    SUMMARY_FILE,
    BEARING_REPORT_FILE,
    CRITICAL_CSV_FILE,
    CHARTS_DIR,
    COMPARE_REPORT_FILE,
    COMPARE_CLASSES_FILE,
];

/// Whether an I/O error is a failure of the storage (disk full, quota, an I/O error: exit 4)
/// rather than a bad output path (a file in the way, no permission, a read-only file
/// system: exit 2).
pub fn is_storage_error(e: &std::io::Error) -> bool {
    use std::io::ErrorKind as K;
    !matches!(
        e.kind(),
        K::NotFound
            | K::PermissionDenied
            | K::AlreadyExists
            | K::NotADirectory
            | K::IsADirectory
            | K::ReadOnlyFilesystem
            | K::InvalidFilename
            | K::InvalidInput
    )
}

/// An advisory lock on a results folder, held until dropped (or the process ends).
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
}

impl FolderLock {
    /// Takes the lock of `dir` (which must exist) for `what` (the command, for the message a
    /// second writer gets). Refused (exit 2) when another process holds it.
    pub fn acquire(dir: &Path, what: &str) -> Result<Self, SweepError> {
        let path = dir.join(LOCK_FILE);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|source| output_error(dir, source))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                return Err(SweepError::Refused(busy_message(dir, &holder)));
            }
            Err(TryLockError::Error(e)) => return Err(output_error(dir, e)),
        }
        // Who holds it, for the message another writer gets (best effort: on a full disk
        // even these few bytes may not fit, and the lock holds without them).
        let _ = file.set_len(0);
        let _ = write!(file, "pid {}: whirlmap {what}", std::process::id());
        let _ = file.flush();
        Ok(Self { _file: file })
    }
}

fn busy_message(dir: &Path, holder: &str) -> String {
    let who = holder.trim();
    format!(
        "{} is in use by another whirlmap ({}): one run writes a results folder at a time; \
         wait for it to finish, or choose another --out",
        dir.display(),
        if who.is_empty() {
            "a running process"
        } else {
            who
        }
    )
}

/// `Some(holder)` when another process holds the lock of `dir` (a run is writing it).
pub fn running_writer(dir: &Path) -> Option<String> {
    let mut file = File::open(dir.join(LOCK_FILE)).ok()?;
    match file.try_lock_shared() {
        Ok(()) => None,
        Err(TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = file.read_to_string(&mut holder);
            Some(if holder.trim().is_empty() {
                "a running process".to_string()
            } else {
                holder.trim().to_string()
            })
        }
        Err(TryLockError::Error(_)) => None,
    }
}

/// The error for an output folder that cannot be created or written: bad input (exit 2) for
/// a bad path, an I/O error (exit 4) when the storage failed.
pub fn output_error(dir: &Path, source: std::io::Error) -> SweepError {
    // A file where the folder should be: said in words, not as "File exists (os error 17)".
    let in_the_way = source.kind() == std::io::ErrorKind::AlreadyExists;
    // A file where a parent folder should be: named, not "Not a directory (os error 20)".
    let file_above = dir
        .ancestors()
        .skip(1)
        .find(|a| !a.as_os_str().is_empty() && a.exists())
        .filter(|a| !a.is_dir());
    let source = if in_the_way && dir.exists() && !dir.is_dir() {
        std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "it is a file, not a folder (give --out a folder)",
        )
    } else if let Some(file) = file_above {
        std::io::Error::new(
            std::io::ErrorKind::NotADirectory,
            format!("{} is a file, not a folder", file.display()),
        )
    } else {
        source
    };
    if is_storage_error(&source) {
        SweepError::Io {
            path: dir.to_path_buf(),
            source,
        }
    } else {
        SweepError::Spec(crate::spec::SpecError::Output {
            path: dir.to_path_buf(),
            source,
        })
    }
}

pub use whirlmap_results::atomic::{sync_dir, TMP_SUFFIX};

/// [`whirlmap_results::write_atomic`] with the sweep's error: writes `bytes` to `path` all
/// or nothing.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), SweepError> {
    Ok(whirlmap_results::write_atomic(path, bytes)?)
}

/// [`whirlmap_results::write_atomic_with`] with the sweep's error: the content written by
/// `fill`, all or nothing.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<&File>) -> std::io::Result<()>,
) -> Result<(), SweepError> {
    Ok(whirlmap_results::write_atomic_with(path, fill)?)
}

/// Removes what a killed run may have left: temporary files of [`write_atomic`] and the
/// probe files of older versions, in `dir` and its owned subfolders.
fn remove_leftovers(dir: &Path) {
    let mut dirs = vec![dir.to_path_buf()];
    for sub in [ORBITS_DIR, CHARTS_DIR, PROBABILITY_DIR] {
        dirs.push(dir.join(sub));
    }
    for d in dirs {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.ends_with(TMP_SUFFIX) || name.starts_with(".whirlmap-probe-") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

pub use whirlmap_results::manifest::{read_manifest, FileEntry, ManifestView};

/// How a run treats a folder that already holds results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Refuse a folder that holds another run's files.
    Fresh,
    /// Continue the run recorded there (same spec, part and build), keeping its records.
    Resume,
    /// Move the files there aside and start anew.
    Overwrite,
}

/// A results folder being written by this process: the lock, the manifest's file list, and
/// the previous run's files while they are kept.
#[derive(Debug)]
pub struct RunFolder {
    dir: PathBuf,
    _lock: FolderLock,
    /// Relative path (`/`-separated) -> entry.
    pub(crate) files: BTreeMap<String, FileEntry>,
    /// The previous run's files (`--overwrite`), deleted once the first records are synced.
    previous: Option<PathBuf>,
}

/// What [`RunFolder::prepare`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Found {
    /// Nothing of whirlmap's.
    Empty,
    /// A run of the same spec, part and build, continued (`--resume`).
    Resumed,
    /// Another run's files, moved to [`PREVIOUS_DIR`] (`--overwrite`).
    MovedAside,
}

/// Who a run is, to compare with a folder's manifest on `--resume`.
#[derive(Debug, Clone, PartialEq)]
pub struct RunIdentity<'a> {
    /// The spec.
    pub spec: &'a SweepSpec,
    /// Its hash.
    pub spec_hash: String,
    /// The shard section of the manifest, `None` for a whole run.
    pub shard: Option<ShardTag>,
}

impl RunFolder {
    /// Creates `dir`, takes its lock (for `what`, the command), removes what a killed run left
    /// behind, and deals with files of an earlier run as `mode` says (see the module docs).
    /// Refusals are [`SweepError::Refused`] (exit 2) and say what to do.
    pub fn prepare(
        dir: &Path,
        what: &str,
        id: &RunIdentity,
        mode: Mode,
    ) -> Result<(Self, Found), SweepError> {
        std::fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
        let lock = FolderLock::acquire(dir, what)?;
        remove_leftovers(dir);
        let present: Vec<&str> = OWNED
            .iter()
            .copied()
            .filter(|n| dir.join(n).symlink_metadata().is_ok())
            .collect();
        let mut folder = Self {
            dir: dir.to_path_buf(),
            _lock: lock,
            files: BTreeMap::new(),
            previous: None,
        };
        if present.is_empty() {
            return Ok((folder, Found::Empty));
        }
        match mode {
            Mode::Fresh => Err(SweepError::Refused(format!(
                "{} holds the results of another run ({}; {}): a results folder is one run's \
                 record. Use {}--overwrite to replace it, or choose another --out",
                dir.display(),
                present.join(", "),
                describe_manifest(dir),
                // `merge` writes its folder whole: it has no --resume; and only a sweep's
                // folder (its records) holds a run a sweep can continue.
                if what == "merge" || !dir.join(POINTS_FILE).exists() {
                    ""
                } else {
                    "--resume to continue that run (the same spec), "
                }
            ))),
            Mode::Resume => {
                check_resumable(dir, id)?;
                take_owned(dir, DERIVED, None)?;
                if dir.join(PREVIOUS_DIR).exists() {
                    folder.previous = Some(dir.join(PREVIOUS_DIR));
                }
                Ok((folder, Found::Resumed))
            }
            Mode::Overwrite => {
                folder.move_aside(&present)?;
                Ok((folder, Found::MovedAside))
            }
        }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Moves the owned files in `present` into [`PREVIOUS_DIR`]. When an earlier overwrite
    /// was killed before its first records (the folder's own points hold no complete record),
    /// the files moved aside then are the ones worth keeping: they stay, and the current
    /// ones are removed; unless that move itself did not finish ([`keep_or_finish`]).
    fn move_aside(&mut self, present: &[&str]) -> Result<(), SweepError> {
        let prev = self.dir.join(PREVIOUS_DIR);
        let current_has_records = std::fs::read(self.dir.join(POINTS_FILE))
            .map(|b| b.contains(&b'\n'))
            .unwrap_or(false);
        let present: Vec<&str> = present
            .iter()
            .copied()
            .filter(|n| *n != PREVIOUS_DIR)
            .collect();
        if prev.exists() && !current_has_records {
            keep_or_finish(&self.dir, &present)?;
        } else {
            remove_path(&prev)?;
            std::fs::create_dir(&prev).map_err(io_err(&prev))?;
            take_owned(&self.dir, &present, Some(&prev))?;
            mark_moved(&prev)?;
        }
        sync_dir(&self.dir);
        self.previous = Some(prev);
        Ok(())
    }

    /// Deletes the previous run's files once the new run's first records are on disk.
    pub fn release_previous(&mut self) -> Result<(), SweepError> {
        if let Some(p) = self.previous.take() {
            remove_path(&p)?;
            sync_dir(&self.dir);
        }
        Ok(())
    }

    /// Lists the file `rel` (relative to the folder, `/`-separated) with its size and hash.
    pub fn record(&mut self, rel: &str) -> Result<(), SweepError> {
        let path = self.dir.join(rel);
        let entry = FileEntry::of(&path).map_err(io_err(&path))?;
        self.files.insert(rel.to_string(), entry);
        Ok(())
    }

    /// Lists every file under the subfolder `rel` (nothing if it does not exist).
    pub fn record_tree(&mut self, rel: &str) -> Result<(), SweepError> {
        self.files
            .retain(|k, _| !(k.starts_with(rel) && k[rel.len()..].starts_with('/')));
        let root = self.dir.join(rel);
        if !root.is_dir() {
            return Ok(());
        }
        let mut stack = vec![root];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).map_err(io_err(&d))? {
                let p = e.map_err(io_err(&d))?.path();
                if p.is_dir() {
                    stack.push(p);
                } else if let Ok(r) = p.strip_prefix(&self.dir) {
                    let r = r
                        .components()
                        .map(|c| c.as_os_str().to_string_lossy())
                        .collect::<Vec<_>>()
                        .join("/");
                    // A user's file in charts/ or orbits/ is not the run's.
                    if is_whirlmaps(&r) {
                        self.record(&r)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Lists a path the run wrote: a file or a whole subfolder (nothing for a subfolder that
    /// does not exist).
    pub fn record_path(&mut self, path: &Path) -> Result<(), SweepError> {
        let rel = path.strip_prefix(&self.dir).unwrap_or(path);
        let rel = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/");
        let full = self.dir.join(&rel);
        if full.is_dir() || !full.exists() {
            self.record_tree(&rel)
        } else {
            self.record(&rel)
        }
    }

    /// The file list, for the manifest.
    pub fn files(&self) -> &BTreeMap<String, FileEntry> {
        &self.files
    }
}

/// `--overwrite` for the commands that write their folder whole (`ensemble`, `adaptive`,
/// `accuracy`), with the folder's lock held: every name of [`OWNED`] in `dir` (a sweep's files,
/// another ensemble's, a study's) is moved into [`PREVIOUS_DIR`], so that what the command
/// writes is not mixed with another run's files, and nothing is lost if it is killed. When
/// [`PREVIOUS_DIR`] is there already, an earlier overwrite did not finish: what it moved aside
/// is kept, and the files of that unfinished run are removed (or, when that move itself
/// stopped part way, the move is finished). Returns the folder to remove
/// ([`release_previous`]) once the command's results are written; `None` when nothing of
/// whirlmap's was there.
pub fn move_owned_aside(dir: &Path) -> Result<Option<PathBuf>, SweepError> {
    let present: Vec<&str> = OWNED
        .iter()
        .copied()
        .filter(|n| *n != PREVIOUS_DIR && dir.join(n).symlink_metadata().is_ok())
        .collect();
    let prev = dir.join(PREVIOUS_DIR);
    if prev.symlink_metadata().is_ok() {
        keep_or_finish(dir, &present)?;
    } else if present.is_empty() {
        return Ok(None);
    } else {
        std::fs::create_dir(&prev).map_err(io_err(&prev))?;
        take_owned(dir, &present, Some(&prev))?;
        mark_moved(&prev)?;
    }
    sync_dir(dir);
    Ok(Some(prev))
}

/// The file in [`PREVIOUS_DIR`] that says the move into it finished.
const MOVED_MARK: &str = ".moved";

/// Marks `prev` as holding everything that was moved aside.
fn mark_moved(prev: &Path) -> Result<(), SweepError> {
    let mark = prev.join(MOVED_MARK);
    std::fs::write(&mark, b"").map_err(io_err(&mark))?;
    sync_dir(prev);
    Ok(())
}

/// With [`PREVIOUS_DIR`] there from an earlier `--overwrite`, and the folder's own files
/// (`present`) not worth keeping over it: when that overwrite's move finished (its mark is
/// there), the folder's files are a killed newer run's and are removed; when it did not (a
/// write error stopped it part way, or a build without the mark made it), they are the rest
/// of the older run: the move is finished, a file already in [`PREVIOUS_DIR`] kept over the
/// folder's own, so that nothing of the older run is lost.
fn keep_or_finish(dir: &Path, present: &[&str]) -> Result<(), SweepError> {
    let prev = dir.join(PREVIOUS_DIR);
    if prev.join(MOVED_MARK).exists() {
        take_owned(dir, present, None)
    } else {
        take_owned(dir, present, Some(&prev))?;
        mark_moved(&prev)
    }
}

/// Deletes what [`move_owned_aside`] moved aside, once the new results are written.
pub fn release_previous(prev: Option<PathBuf>) -> Result<(), SweepError> {
    if let Some(p) = prev {
        remove_path(&p)?;
        if let Some(dir) = p.parent() {
            sync_dir(dir);
        }
    }
    Ok(())
}

/// Whether the file at `rel` (`/`-separated, relative to a results folder) may be one
/// whirlmap writes: directly in `charts/` or `probability/charts/` only its charts
/// ([`whirlmap_results::files::is_chart_file`]), directly in `orbits/` only orbit and error
/// files, directly in `probability/` (an ensemble's folder) only the names of [`OWNED`];
/// nothing deeper in those folders; under `previous-run/`, and at the top level, any file
/// (the top-level names a run lists or moves are [`OWNED`]'s).
pub fn is_whirlmaps(rel: &str) -> bool {
    use whirlmap_results::files::{is_chart_file, is_orbit_file};
    let parts: Vec<&str> = rel.split('/').collect();
    match parts.as_slice() {
        [CHARTS_DIR, name] | [PROBABILITY_DIR, CHARTS_DIR, name] => is_chart_file(name),
        [ORBITS_DIR, name] => is_orbit_file(name),
        [PROBABILITY_DIR, PREVIOUS_DIR, ..] => true,
        [PROBABILITY_DIR, name] => OWNED.contains(name),
        [CHARTS_DIR | ORBITS_DIR | PROBABILITY_DIR, ..] => false,
        _ => true,
    }
}

/// Moves into `to` (or, with `None`, removes) the entries `names` of the folder `from` that
/// are whirlmap's, leaving a user's files in place: `charts/` and `orbits/` go file by file
/// ([`is_whirlmaps`]), `probability/` (an ensemble's folder) entry by entry, each of them
/// removed once empty; any other name goes whole. Absent names are skipped; an entry whose
/// name `to` already holds is removed, not moved over it.
fn take_owned(from: &Path, names: &[&str], to: Option<&Path>) -> Result<(), SweepError> {
    for name in names {
        let src = from.join(name);
        let Ok(meta) = src.symlink_metadata() else {
            continue;
        };
        let dest = to.map(|t| t.join(name));
        let by_entry = [CHARTS_DIR, ORBITS_DIR, PROBABILITY_DIR].contains(name);
        if !(meta.is_dir() && by_entry) {
            match &dest {
                // Finishing a move that stopped part way: what is there already was moved
                // first, and is kept.
                Some(d) if d.symlink_metadata().is_ok() => remove_path(&src)?,
                Some(d) => std::fs::rename(&src, d).map_err(io_err(&src))?,
                None => remove_path(&src)?,
            }
            continue;
        }
        if let Some(d) = &dest {
            std::fs::create_dir_all(d).map_err(io_err(d))?;
        }
        let entries: Vec<String> = std::fs::read_dir(&src)
            .map_err(io_err(&src))?
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        let inner: Vec<&str> = if *name == PROBABILITY_DIR {
            OWNED
                .iter()
                .copied()
                .filter(|n| entries.iter().any(|e| e == n))
                .collect()
        } else {
            entries
                .iter()
                .map(String::as_str)
                .filter(|n| src.join(n).is_file() && is_whirlmaps(&format!("{name}/{n}")))
                .collect()
        };
        take_owned(&src, &inner, dest.as_deref())?;
        // Gone when nothing else was in it; kept, with the user's files, otherwise.
        let _ = std::fs::remove_dir(&src);
    }
    Ok(())
}

/// Removes a file or a folder tree; absent is fine.
fn remove_path(p: &Path) -> Result<(), SweepError> {
    let r = match p.symlink_metadata() {
        Err(_) => return Ok(()),
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(p),
        Ok(_) => std::fs::remove_file(p),
    };
    r.map_err(io_err(p))
}

/// `spec "name" (hash H), finished` or what else the manifest says, for a message.
fn describe_manifest(dir: &Path) -> String {
    match read_manifest(dir) {
        Ok(Some(m)) => {
            let name = m.spec_name().unwrap_or("?");
            let hash = m.spec_hash.as_deref();
            let state = match m.complete {
                Some(true) => "finished",
                Some(false) => "did not finish",
                None => "written by an older whirlmap",
            };
            match hash {
                Some(h) => format!("spec \"{name}\", hash {h}, {state}"),
                None => format!("spec \"{name}\", {state}"),
            }
        }
        Ok(None) => "no manifest.json".to_string(),
        Err(e) => e,
    }
}

/// Refuses a `--resume` unless the folder's manifest records a run of the same spec, the same
/// part of it (whole or shard I/N) and the same build; the error says what differs.
fn check_resumable(dir: &Path, id: &RunIdentity) -> Result<(), SweepError> {
    let refuse = |why: String| {
        SweepError::Refused(format!(
            "cannot resume {}: {why}. Use --overwrite to replace it, or choose another --out",
            dir.display()
        ))
    };
    let m = match read_manifest(dir) {
        Ok(Some(m)) => m,
        Ok(None) => {
            return Err(refuse(
                "it has no manifest.json saying which spec its records belong to".into(),
            ))
        }
        Err(e) => return Err(refuse(format!("its manifest is unreadable ({e})"))),
    };
    if m.complete.is_none() {
        return Err(refuse(
            "it was written by an older whirlmap, whose manifest names neither its build nor \
             its files"
                .into(),
        ));
    }
    let old_shard = m.shard;
    if old_shard != id.shard {
        let part = |v: &Option<ShardTag>| match v {
            Some(s) => format!("shard {}/{}", s.index, s.count),
            None => "a whole sweep".to_string(),
        };
        return Err(refuse(format!(
            "it holds {} of spec {}, not {} of spec {}",
            part(&old_shard),
            m.spec_hash.as_deref().unwrap_or("?"),
            part(&id.shard),
            id.spec_hash
        )));
    }
    let old_hash = m.spec_hash.as_deref().unwrap_or("?");
    if old_hash != id.spec_hash {
        let diffs = match manifest_spec(dir) {
            Some(old) => spec_differences(&old, id.spec),
            None => value_differences(
                m.spec.as_ref().unwrap_or(&Value::Null),
                &serde_json::to_value(id.spec).expect("specs serialise"),
            ),
        };
        return Err(refuse(format!(
            "its records are of another spec (hash {old_hash}, this one {}): {}",
            id.spec_hash,
            if diffs.is_empty() {
                "the specs differ".to_string()
            } else {
                diffs.join("; ")
            }
        )));
    }
    if let Some(old) =
        crate::build_info::other_build(m.whirlmap_version.as_deref(), m.git_commit.as_deref())
    {
        return Err(refuse(format!(
            "it was started by whirlmap {old}, this is {}: records of two builds would be mixed \
             (resume it with that build)",
            crate::build_info::DESCRIPTION
        )));
    }
    let model = m.model_version;
    if model != Some(whirlmap_core::MODEL_VERSION as u64) {
        return Err(refuse(format!(
            "it was run with model version {}, this whirlmap has {}",
            model.map_or("?".to_string(), |v| v.to_string()),
            whirlmap_core::MODEL_VERSION
        )));
    }
    Ok(())
}

/// What differs between two specs as JSON, one entry per differing field path:
/// `duration_s: 1.0 -> 0.5`, `axes.mu: [0.1,0.2] -> [0.1]`, `critical: (none) -> {...}`.
/// Empty when they are equal. (JSON objects are compared by key, so the order of the axes is
/// compared by [`spec_differences`].)
pub fn value_differences(old: &Value, new: &Value) -> Vec<String> {
    let mut out = Vec::new();
    diff("", old, new, &mut out);
    out
}

/// What differs between two specs ([`value_differences`]), the order of the axes included
/// (`axes: order speed_rpm, mu -> mu, speed_rpm`: the grid's row-major order, so every
/// index, changes with it).
pub fn spec_differences(old: &SweepSpec, new: &SweepSpec) -> Vec<String> {
    let names = |s: &SweepSpec| s.axes.0.iter().map(|a| a.name.clone()).collect::<Vec<_>>();
    let (a, b) = (names(old), names(new));
    let mut out = Vec::new();
    let (mut sa, mut sb) = (a.clone(), b.clone());
    sa.sort();
    sb.sort();
    if sa == sb && a != b {
        out.push(format!("axes: order {} -> {}", a.join(", "), b.join(", ")));
    }
    out.extend(value_differences(
        &serde_json::to_value(old).expect("specs serialise"),
        &serde_json::to_value(new).expect("specs serialise"),
    ));
    out
}

/// The spec recorded in the folder's manifest, parsed from its text so the order of the axes
/// is kept; `None` when there is no manifest or its spec does not parse.
pub fn manifest_spec(dir: &Path) -> Option<SweepSpec> {
    #[derive(Deserialize)]
    struct OnlySpec {
        spec: SweepSpec,
    }
    let text = std::fs::read_to_string(dir.join(MANIFEST_FILE)).ok()?;
    serde_json::from_str::<OnlySpec>(&text).ok().map(|m| m.spec)
}

fn short(v: &Value) -> String {
    let mut s = v.to_string();
    if s.len() > 80 {
        let cut = (0..=77).rev().find(|i| s.is_char_boundary(*i)).unwrap_or(0);
        s.truncate(cut);
        s.push_str("...");
    }
    s
}

fn diff(path: &str, old: &Value, new: &Value, out: &mut Vec<String>) {
    if old == new {
        return;
    }
    let name = if path.is_empty() { "spec" } else { path };
    match (old, new) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, va) in a {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                match b.get(k) {
                    Some(vb) => diff(&p, va, vb, out),
                    None => out.push(format!("{p}: {} -> (none)", short(va))),
                }
            }
            for (k, vb) in b {
                if !a.contains_key(k) {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    out.push(format!("{p}: (none) -> {}", short(vb)));
                }
            }
        }
        _ => out.push(format!("{name}: {} -> {}", short(old), short(new))),
    }
}

/// What a reader learnt about a results folder ([`check_inputs`]).
#[derive(Debug, Clone, Default)]
pub struct Checked {
    /// Things to say loudly but not fatal: no manifest, an older manifest, a run that did
    /// not finish.
    pub warnings: Vec<String>,
    /// The manifest, when there is one.
    pub manifest: Option<ManifestView>,
    /// Whether the manifest has a file list (written by this version of whirlmap).
    pub listed: bool,
}

impl Checked {
    /// The spec recorded in the manifest, if any.
    pub fn spec(&self) -> Option<&Value> {
        self.manifest.as_ref().and_then(|m| m.spec.as_ref())
    }
    /// The spec hash recorded in the manifest, if any.
    pub fn spec_hash(&self) -> Option<&str> {
        self.manifest.as_ref().and_then(|m| m.spec_hash.as_deref())
    }
    /// Whether the manifest says the run finished (`None`: no manifest or an older one).
    pub fn complete(&self) -> Option<bool> {
        self.manifest.as_ref().and_then(|m| m.complete)
    }
}

/// The inputs a reader (render, compare, merge) takes from a results folder: each file that
/// exists among `points.jsonl`, `critical.json`, `orbits/*.json` and
/// `probability/contours.json`.
pub fn reader_inputs(dir: &Path) -> Vec<String> {
    let mut v = Vec::new();
    for f in [
        POINTS_FILE.to_string(),
        CRITICAL_FILE.to_string(),
        format!("{}/{}", PROBABILITY_DIR, CONTOURS_FILE),
    ] {
        if dir.join(&f).is_file() {
            v.push(f);
        }
    }
    if let Ok(entries) = std::fs::read_dir(dir.join(ORBITS_DIR)) {
        let mut orbits: Vec<String> = entries
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".json"))
            .map(|n| format!("orbits/{n}"))
            .collect();
        orbits.sort();
        v.extend(orbits);
    }
    v
}

/// Checks the files a reader is about to use (`inputs`, relative paths) against the folder's
/// manifest (see the module docs). `Err` lists every file that is not what the run recorded;
/// `Ok` carries warnings for folders that cannot be checked or did not finish.
pub fn check_inputs(dir: &Path, inputs: &[String]) -> Result<Checked, Vec<String>> {
    let manifest = read_manifest(dir).map_err(|e| vec![e])?;
    let mut checked = Checked {
        manifest,
        ..Default::default()
    };
    let Some(m) = checked.manifest.clone() else {
        checked.warnings.push(format!(
            "{} has no manifest.json: its files cannot be checked against the run that wrote \
             them",
            dir.display()
        ));
        return Ok(checked);
    };
    let Some(files) = &m.files else {
        checked.warnings.push(format!(
            "{} was written by an older whirlmap (its manifest has no file list): its files \
             cannot be checked against the run that wrote them",
            dir.display()
        ));
        return Ok(checked);
    };
    checked.listed = true;
    let complete = m.complete == Some(true);
    if !complete {
        checked.warnings.push(format!(
            "{} holds a run that did not finish (manifest.json: complete = false): its \
             results are partial",
            dir.display()
        ));
    }
    let name = m.spec_name().unwrap_or("?");
    let hash = m.spec_hash.as_deref().unwrap_or("?");
    let mut problems = Vec::new();
    for rel in inputs {
        let path = dir.join(rel);
        match files.get(rel) {
            Some(listed) => match FileEntry::of(&path) {
                Ok(actual) if &actual == listed => {}
                Ok(_) => problems.push(format!(
                    "{} is not the file the run of spec \"{name}\" (hash {hash}) wrote: \
                         its size or content changed afterwards",
                    path.display()
                )),
                Err(e) => problems.push(format!("{}: {e}", path.display())),
            },
            // The records of a run in progress or killed: not listed until the grid ends.
            None if !complete && (rel == POINTS_FILE || rel == TIMINGS_FILE) => {}
            // A run that did not finish lists a file only once its stage is done; the folder
            // held none of another run's files when it started.
            None if !complete => checked.warnings.push(format!(
                "{} is not listed by the run that did not finish: it cannot be checked",
                path.display()
            )),
            None => problems.push(format!(
                "{} was not written by the run recorded in {} (spec \"{name}\", hash {hash}): \
                 a stale file of an earlier run; remove it, or rerun the sweep with \
                 --overwrite",
                path.display(),
                dir.join(MANIFEST_FILE).display()
            )),
        }
    }
    if problems.is_empty() {
        Ok(checked)
    } else {
        Err(problems)
    }
}

/// Rewrites the manifest of `dir` with the subfolder `rel` listed anew (after `render`
/// redrew `charts/`); does nothing for a folder whose manifest has no file list.
pub fn relist_tree(dir: &Path, rel: &str) -> Result<(), SweepError> {
    // Read as written, so that everything but the list is written back unchanged; a manifest
    // this build cannot read as its own (an older whirlmap's) is left alone.
    let path = dir.join(MANIFEST_FILE);
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Ok(());
    };
    let Ok(mut m) = serde_json::from_str::<Manifest<SweepSpec>>(&text) else {
        return Ok(());
    };
    m.files
        .retain(|k, _| !(k.starts_with(rel) && k[rel.len()..].starts_with('/')));
    let root = dir.join(rel);
    let mut stack = vec![root];
    let mut found = Vec::new();
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                found.push(p);
            }
        }
    }
    for p in found {
        let r = p
            .strip_prefix(dir)
            .unwrap_or(&p)
            .components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/");
        if is_whirlmaps(&r) {
            let entry = FileEntry::of(&p).map_err(io_err(&p))?;
            m.files.insert(r, entry);
        }
    }
    let again = m.to_text();
    if again == text {
        return Ok(());
    }
    write_atomic(&path, again.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An overwrite whose move into previous-run/ stopped part way leaves the older run's
    /// other files in the folder: the next overwrite finishes the move instead of deleting
    /// them, and keeps what was moved first. Once a move has finished, the folder's files
    /// are a killed newer run's and go.
    #[test]
    fn a_move_aside_that_stopped_part_way_is_finished_not_lost() {
        let dir = std::env::temp_dir().join(format!("whirlmap-moved-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let prev = dir.join(PREVIOUS_DIR);
        std::fs::create_dir_all(prev.join(CHARTS_DIR)).unwrap();
        std::fs::create_dir_all(dir.join(CHARTS_DIR)).unwrap();
        // Moved before the stop: the old records and one chart.
        std::fs::write(prev.join(MEMBERS_FILE), "old members").unwrap();
        std::fs::write(prev.join("charts/classes.png"), "old").unwrap();
        // Left behind: the old contours and another chart; a same-named file is kept moved.
        std::fs::write(dir.join(CONTOURS_FILE), "old contours").unwrap();
        std::fs::write(dir.join("charts/fig4_probability.png"), "old").unwrap();
        std::fs::write(dir.join(MEMBERS_FILE), "newer").unwrap();
        let back = move_owned_aside(&dir).unwrap();
        assert_eq!(back.as_deref(), Some(prev.as_path()));
        let read = |p: &Path| std::fs::read_to_string(p).unwrap();
        assert_eq!(read(&prev.join(MEMBERS_FILE)), "old members");
        assert_eq!(read(&prev.join(CONTOURS_FILE)), "old contours");
        assert_eq!(read(&prev.join("charts/fig4_probability.png")), "old");
        assert_eq!(read(&prev.join("charts/classes.png")), "old");
        assert!(prev.join(MOVED_MARK).exists());
        assert!(!dir.join(MEMBERS_FILE).exists() && !dir.join(CHARTS_DIR).exists());
        // Killed again before writing anything worth keeping: now the folder's files go.
        std::fs::write(dir.join(MEMBERS_FILE), "newer still").unwrap();
        move_owned_aside(&dir).unwrap();
        assert!(!dir.join(MEMBERS_FILE).exists());
        assert_eq!(read(&prev.join(MEMBERS_FILE)), "old members");
        release_previous(back).unwrap();
        assert!(!prev.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn whirlmaps_files_are_told_from_a_users() {
        for rel in [
            "points.jsonl",
            "charts/classes.png",
            "charts/fig4_critical.svg",
            "orbits/00_8000rpm_mu0.100.json",
            "orbits/01_8000rpm_mu0.200.error.txt",
            "probability/members.jsonl",
            "probability/charts/fig4_probability.png",
        ] {
            assert!(is_whirlmaps(rel), "{rel}");
        }
        for rel in [
            "charts/my_plot.png",
            "charts/classes.pdf",
            "orbits/notes.txt",
            "probability/notes.md",
            "probability/charts/mine.svg",
            "charts/old/classes.png",
            "orbits/sub/00_8000rpm_mu0.100.json",
            "probability/x/members.jsonl",
        ] {
            assert!(!is_whirlmaps(rel), "{rel}");
        }
    }

    #[test]
    fn the_studies_charts_are_owned_names() {
        for stem in whirlmap_results::files::WORK_PRECISION_CHARTS {
            for ext in ["png", "svg"] {
                let name = format!("{stem}.{ext}");
                assert!(OWNED.contains(&name.as_str()), "{name}");
            }
        }
    }
    use serde_json::json;

    #[test]
    fn spec_differences_name_each_field_and_the_axis_order() {
        let a = crate::spec::parse(
            r#"{"name": "x", "duration_s": 1.0, "axes": {"speed_rpm": [1000, 2000], "mu": [0.1]}}"#,
        )
        .unwrap();
        let b = crate::spec::parse(
            r#"{"name": "x", "duration_s": 0.5, "axes": {"mu": [0.1], "speed_rpm": [1000]}}"#,
        )
        .unwrap();
        let d = spec_differences(&a, &b);
        assert!(d.contains(&"duration_s: 1.0 -> 0.5".to_string()), "{d:?}");
        assert!(
            d.contains(&"axes: order speed_rpm, mu -> mu, speed_rpm".to_string()),
            "{d:?}"
        );
        assert!(
            d.contains(&"axes.speed_rpm: [1000.0,2000.0] -> [1000.0]".to_string()),
            "{d:?}"
        );
        assert!(spec_differences(&a, &a).is_empty());
        let v = value_differences(
            &json!({"critical": null}),
            &json!({"critical": {"mu": [0.3]}}),
        );
        assert_eq!(v, ["critical: null -> {\"mu\":[0.3]}"]);
    }

    #[test]
    fn file_entries_hash_like_fnv1a64() {
        let dir = std::env::temp_dir().join(format!("whirlmap-folder-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("f");
        std::fs::write(&p, b"hello").unwrap();
        let e = FileEntry::of(&p).unwrap();
        assert_eq!(e.bytes, 5);
        assert_eq!(
            e.fnv1a64,
            format!("{:016x}", whirlmap_core::scene::fnv1a64(b"hello"))
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
