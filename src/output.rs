//! Printing that never panics: every line the tool prints goes through `outln!` (standard
//! output) or `errln!` (standard error).
//!
//! `println!` panics when standard output is gone: `whirlmap sweep ... | head -1` closes the
//! pipe after one line, and the panic would end the sweep before its charts are drawn, with
//! exit code 101. Here a closed pipe (`BrokenPipe`) silences standard output for the rest of
//! the run and the work goes on; the exit code is the work's. Any other failure to write
//! standard output (a full disk behind `> file`) is kept and turned into exit code 4 by
//! [`finish`], since then the printed output, for `drop --json` the result itself, was lost.
//! Standard error is best effort: when it cannot be written there is nowhere to say so.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// Set once standard output has failed: nothing more is written to it.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);
/// The first failure to write standard output other than a closed pipe.
static STDOUT_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// Writes to standard output, unless it has failed before; see the module docs.
pub fn write_stdout(args: std::fmt::Arguments) {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    let result = out.write_fmt(args).and_then(|_| out.flush());
    if let Err(e) = result {
        STDOUT_GONE.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            let mut first = STDOUT_ERROR.lock().unwrap_or_else(|p| p.into_inner());
            first.get_or_insert_with(|| e.to_string());
        }
    }
}

/// Writes to standard error, ignoring failures.
pub fn write_stderr(args: std::fmt::Arguments) {
    let _ = std::io::stderr().lock().write_fmt(args);
}

/// The exit code after the work ended with `code`: 4 when the work succeeded (0 or 1) but
/// standard output could not be written for another reason than a closed pipe (said on
/// standard error), else `code`.
pub fn finish(code: u8) -> u8 {
    let failed = STDOUT_ERROR
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .clone();
    match failed {
        Some(e) if code <= 1 => {
            write_stderr(format_args!("error: cannot write standard output: {e}\n"));
            4
        }
        _ => code,
    }
}

/// `println!` that never panics (see [`write_stdout`]).
macro_rules! outln {
    () => {
        $crate::output::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` that never panics (see [`write_stderr`]).
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::output::write_stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}
