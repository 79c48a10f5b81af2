//! Helpers shared by the CLI integration tests: run the `whirlmap` binary, make a fresh
//! scratch folder, read an output. Each test file uses a subset, hence the `dead_code` allow.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `whirlmap` binary Cargo built for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_whirlmap");

/// Runs `whirlmap` with `args` and waits for it.
pub fn whirlmap<S: AsRef<OsStr>>(args: &[S]) -> Output {
    Command::new(BIN)
        .args(args)
        .output()
        .expect("runs the binary")
}

/// A fresh, empty scratch folder unique to this test process and `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("whirlmap-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path named `name` in a scratch folder shared by this test process (not emptied, so
/// tests running in parallel threads keep each other's files).
pub fn temp_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("whirlmap-test-{}-files", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A path as `&str`, for argument lists.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The standard error of a finished run, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Standard output followed by standard error, as text.
pub fn out(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Runs `whirlmap` with `args`, killing it after `limit` (a hang or a runaway allocation
/// fails the test instead of stalling it). `None` when it had to be killed.
pub fn whirlmap_within<S: AsRef<OsStr>>(args: &[S], limit: std::time::Duration) -> Option<Output> {
    use std::process::Stdio;
    let mut child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs the binary");
    let start = std::time::Instant::now();
    loop {
        if child.try_wait().expect("waits").is_some() {
            return Some(child.wait_with_output().expect("collects the output"));
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// Runs `whirlmap` with `args` and kills it (SIGKILL) as soon as `file` holds `lines` complete
/// lines; returns how many it held then. Fails the test if the command ends first or writes
/// nothing for two minutes.
pub fn kill_after_lines<S: AsRef<OsStr>>(args: &[S], file: &Path, lines: usize) -> usize {
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let mut child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("runs the binary");
    let start = Instant::now();
    loop {
        let n = std::fs::read_to_string(file)
            .map(|t| t.matches('\n').count())
            .unwrap_or(0);
        if n >= lines {
            child.kill().expect("kills the run");
            child.wait().expect("waits");
            return n;
        }
        assert!(
            child.try_wait().expect("waits").is_none(),
            "the run ended before writing {lines} lines to {}",
            file.display()
        );
        assert!(start.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Runs shard `i` of `n` of the sweep `spec` into `out`, without progress output.
pub fn sweep_shard(spec: &Path, out: &Path, i: usize, n: usize) -> Output {
    sweep_shard_with(spec, out, i, n, &[])
}

/// [`sweep_shard`] with `extra` arguments after the others.
pub fn sweep_shard_with(spec: &Path, out: &Path, i: usize, n: usize, extra: &[&str]) -> Output {
    let (i, n) = (i.to_string(), n.to_string());
    let mut args = vec![
        "sweep",
        s(spec),
        "--shard",
        &i,
        "--shards",
        &n,
        "--out",
        s(out),
        "--no-progress",
    ];
    args.extend_from_slice(extra);
    whirlmap(&args)
}

/// Writes a sweep spec `text` to `dir/<name>.json` and returns its path.
pub fn spec_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(format!("{name}.json"));
    std::fs::write(&p, text).unwrap();
    p
}

/// A file's JSON.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}
