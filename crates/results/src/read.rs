//! Reading the files of a results folder: JSON Lines that tolerate a torn last line, and
//! whole-file JSON.
//!
//! ## Torn last lines
//! Records are appended line by line and a run can be killed in the middle of a write, so
//! the bytes after the last newline may be a torn record. [`parse_jsonl`] ignores such a
//! final line when it does not parse, and reports it ([`Jsonl::torn`]); a final line that
//! lacks only its newline but parses is kept. Blank lines are skipped. Any other line that
//! does not parse is an error naming the file and the line.

use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

/// Why a file of a results folder could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file does not exist.
    #[error("{} does not exist", path.display())]
    NotFound {
        /// The missing file.
        path: PathBuf,
    },
    /// The file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A line (or the whole file) is not what it should be.
    #[error("{}: line {line}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// Why a reader of a results folder (the charts, a comparison) could not take its inputs, in
/// the words those readers print: a missing `points.jsonl` means "no sweep results".
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
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
}

impl From<ReadError> for LoadError {
    fn from(e: ReadError) -> Self {
        match e {
            ReadError::NotFound { path } => LoadError::NoPoints { path },
            ReadError::Io { path, source } => LoadError::Read {
                path,
                cause: source,
            },
            ReadError::Parse {
                path,
                line,
                message,
            } => LoadError::Parse {
                path,
                line,
                message,
            },
        }
    }
}

/// A final line without its newline that did not parse: a write torn by a crash.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TornLine {
    /// 1-based line number.
    pub line: usize,
    /// Its length in bytes.
    pub bytes: usize,
}

/// The rows of a JSON Lines file.
#[derive(Debug, Clone, PartialEq)]
pub struct Jsonl<T> {
    /// Every row, with its 1-based line number, in file order.
    pub rows: Vec<(usize, T)>,
    /// The torn last line that was ignored, if any.
    pub torn: Option<TornLine>,
}

impl<T> Jsonl<T> {
    /// The rows without their line numbers.
    pub fn into_rows(self) -> Vec<T> {
        self.rows.into_iter().map(|(_, r)| r).collect()
    }
}

/// The length of `bytes` up to and including the last newline: the complete lines (what is
/// after it was not finished).
pub fn complete_len(bytes: &[u8]) -> usize {
    bytes.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1)
}

/// Reads the file `path` whole.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, ReadError> {
    std::fs::read(path).map_err(|source| {
        if source.kind() == std::io::ErrorKind::NotFound {
            ReadError::NotFound {
                path: path.to_path_buf(),
            }
        } else {
            ReadError::Io {
                path: path.to_path_buf(),
                source,
            }
        }
    })
}

/// Parses `bytes`, the text of the JSON Lines file `path`, into rows (see the module docs
/// for what is tolerated). Invalid UTF-8 is replaced, as a parse of it would fail anyway.
pub fn parse_jsonl<T: DeserializeOwned>(path: &Path, bytes: &[u8]) -> Result<Jsonl<T>, ReadError> {
    let complete = complete_len(bytes);
    let mut rows = Vec::new();
    let mut torn = None;
    let mut line_no = 0;
    let mut start = 0;
    while start < bytes.len() {
        let end = if start < complete {
            start + bytes[start..].iter().position(|b| *b == b'\n').unwrap_or(0)
        } else {
            bytes.len()
        };
        let last = end == bytes.len() && start >= complete;
        line_no += 1;
        let text = String::from_utf8_lossy(&bytes[start..end]);
        start = end + 1;
        if text.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<T>(&text) {
            Ok(row) => rows.push((line_no, row)),
            Err(_) if last => {
                torn = Some(TornLine {
                    line: line_no,
                    bytes: text.len(),
                })
            }
            Err(e) => {
                return Err(ReadError::Parse {
                    path: path.to_path_buf(),
                    line: line_no,
                    message: e.to_string(),
                })
            }
        }
    }
    Ok(Jsonl { rows, torn })
}

/// Reads the JSON Lines file `path` ([`parse_jsonl`]).
pub fn read_jsonl<T: DeserializeOwned>(path: &Path) -> Result<Jsonl<T>, ReadError> {
    parse_jsonl(path, &read_bytes(path)?)
}

/// Reads and parses the JSON file `path`, or `None` if it does not exist.
pub fn read_json_optional<T: DeserializeOwned>(path: &Path) -> Result<Option<T>, ReadError> {
    let bytes = match read_bytes(path) {
        Ok(b) => b,
        Err(ReadError::NotFound { .. }) => return Ok(None),
        Err(e) => return Err(e),
    };
    serde_json::from_slice(&bytes)
        .map(Some)
        .map_err(|e| ReadError::Parse {
            path: path.to_path_buf(),
            line: e.line(),
            message: e.to_string(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::Value;

    fn parse(text: &str) -> Result<Jsonl<Value>, ReadError> {
        parse_jsonl(Path::new("f.jsonl"), text.as_bytes())
    }

    #[test]
    fn a_torn_last_line_is_ignored_and_reported() {
        let j = parse("{\"a\":1}\n\n{\"a\":2}\n{\"a\":").unwrap();
        assert_eq!(j.rows.len(), 2);
        assert_eq!(j.rows[1].0, 3);
        assert_eq!(j.torn, Some(TornLine { line: 4, bytes: 5 }));
        // A last line lacking only its newline is a row.
        let j = parse("{\"a\":1}\n{\"a\":2}").unwrap();
        assert_eq!(j.rows.len(), 2);
        assert_eq!(j.torn, None);
        assert_eq!(parse("").unwrap().rows.len(), 0);
    }

    #[test]
    fn other_bad_lines_name_file_and_line() {
        let e = parse("{\"a\":1}\n{\"a\":\n{\"a\":2}\n").unwrap_err();
        assert!(matches!(e, ReadError::Parse { line: 2, .. }), "{e}");
        assert!(e.to_string().starts_with("f.jsonl: line 2: "), "{e}");
        // A bad last line with its newline was written whole: an error.
        let e = parse("{\"a\":1}\n{\"a\":\n").unwrap_err();
        assert!(matches!(e, ReadError::Parse { line: 2, .. }), "{e}");
    }
}
