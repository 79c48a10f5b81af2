//! A full disk: a sweep or a resume that cannot write exits 4 (an output could not be
//! written, not bad input), leaves no probe or temporary file behind to keep the disk full,
//! never damages the records already written, and resumes once there is space again.
//!
//! Needs root, to mount a small tmpfs; without it (or where mounting is not allowed) the test
//! says so on stderr and passes without running.

mod common;
use common::*;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A 200 kB tmpfs, unmounted when dropped.
struct SmallDisk(PathBuf);

impl SmallDisk {
    fn mount(dir: &Path) -> Result<SmallDisk, String> {
        let uid = Command::new("id")
            .arg("-u")
            .output()
            .map_err(|e| e.to_string())?;
        if uid.stdout != b"0\n" {
            return Err("not root".into());
        }
        let o = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=200k", "tmpfs"])
            .arg(dir)
            .output()
            .map_err(|e| e.to_string())?;
        if !o.status.success() {
            return Err(String::from_utf8_lossy(&o.stderr).trim().to_string());
        }
        Ok(SmallDisk(dir.to_path_buf()))
    }

    /// Writes `filler` until the disk is full, down to the last byte it takes.
    fn fill(&self) -> PathBuf {
        let path = self.0.join("filler");
        let mut f = std::fs::File::create(&path).unwrap();
        for size in [65536, 4096, 512, 1] {
            let block = vec![7u8; size];
            while f.write_all(&block).is_ok() {}
        }
        path
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Files whirlmap must not leave behind: probes and temporary files, anywhere under `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if p.is_dir() {
                stack.push(p);
            } else if name.contains("probe") || name.contains("tmp") {
                found.push(p.display().to_string());
            }
        }
    }
    found
}

#[test]
fn a_full_disk_exits_4_and_leaves_nothing_behind() {
    let dir = temp_dir("disk-full");
    let mnt = dir.join("mnt");
    std::fs::create_dir_all(&mnt).unwrap();
    let disk = match SmallDisk::mount(&mnt) {
        Ok(d) => d,
        Err(why) => {
            eprintln!("disk-full test SKIPPED: cannot mount a small tmpfs ({why}); run as root");
            let _ = std::fs::remove_dir_all(&dir);
            return;
        }
    };
    let spec = dir.join("tiny.json");
    std::fs::write(
        &spec,
        r#"{"name": "tiny", "scene": {"classification": {"max_extension_s": 0}},
            "duration_s": 0.05, "axes": {"speed_rpm": [4000, 8000], "mu": [0.1, 0.3]}}"#,
    )
    .unwrap();
    let out = mnt.join("out");
    let sweep = |out: &Path, extra: &[&str]| {
        let mut args = vec!["sweep", s(&spec), "--out", s(out), "--no-progress"];
        args.extend_from_slice(extra);
        whirlmap(&args)
    };
    let o = sweep(&out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let records = std::fs::read(out.join("points.jsonl")).unwrap();

    let filler = disk.fill();
    // A resume on the full disk: exit 4, the records intact, nothing left behind.
    let o = sweep(&out, &["--resume"]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("No space left on device"),
        "{}",
        stderr(&o)
    );
    assert!(std::fs::read(out.join("points.jsonl")).unwrap() == records);
    assert_eq!(leftovers(&mnt), Vec::<String>::new());
    // A new sweep on the full disk: exit 4 too.
    let o = sweep(&mnt.join("out2"), &[]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert_eq!(leftovers(&mnt), Vec::<String>::new());

    // Space again: the resume finishes, and the records are those of the first run.
    std::fs::remove_file(&filler).unwrap();
    let o = sweep(&out, &["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::read(out.join("points.jsonl")).unwrap() == records);
    let m = read_json(&out.join("manifest.json"));
    assert_eq!(m["complete"], true);
    assert_eq!(leftovers(&mnt), Vec::<String>::new());
    drop(disk);
    std::fs::remove_dir_all(&dir).unwrap();
}
