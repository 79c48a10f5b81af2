//! All-or-nothing writes: a file is written beside its target, synced and renamed over it.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The suffix of a file being written ([`write_atomic`]); one left behind by a killed run is
/// removed by the next run that takes the folder's lock.
pub const TMP_SUFFIX: &str = ".whirlmap-tmp";

/// A file that could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// The I/O error.
    pub source: std::io::Error,
}

/// Writes `bytes` to `path` all or nothing: into a temporary file beside it, synced, renamed
/// over `path`, and the folder synced. On any failure the temporary file is removed, so a
/// full disk leaves neither a partial file nor the old one damaged.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// [`write_atomic`] with the content written by `fill` (for files written line by line).
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<&File>) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}{TMP_SUFFIX}"));
    let result = (|| {
        let file = File::create(&tmp)?;
        let mut w = std::io::BufWriter::new(&file);
        fill(&mut w)?;
        w.flush()?;
        drop(w);
        file.sync_all()?;
        Ok(())
    })();
    if let Err(source) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(WriteError {
            path: path.to_path_buf(),
            source,
        });
    }
    if let Err(source) = std::fs::rename(&tmp, path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(WriteError {
            path: path.to_path_buf(),
            source,
        });
    }
    sync_dir(path.parent().unwrap_or(Path::new(".")));
    Ok(())
}

/// Syncs a folder so a rename in it survives a power loss (best effort: not every file
/// system can sync a folder).
pub fn sync_dir(dir: &Path) {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}
