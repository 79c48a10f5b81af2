//! Every sweep, ensemble, adaptive, accuracy-case and scene file the repository ships passes
//! the checks a run makes before its first drop, so a check made stricter cannot refuse a
//! committed file unseen.

use std::path::{Path, PathBuf};
use whirlmap_core::Scene;
use whirlmap_sweep::{accuracy::AccuracySpec, ensemble, spec};

/// The `.json` files of `dir`, sorted.
fn json_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_committed_input_file_passes_the_checks_of_its_command() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut checked = 0;
    for p in json_files(&root.join("sweeps")) {
        let text = std::fs::read_to_string(&p).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        // The file's kind by its keys, as its command reads it.
        let result = if v.get("cases").is_some() {
            AccuracySpec::load(&p).map(drop).map_err(|e| e.to_string())
        } else if v.get("ensemble").is_some() || v.get("adaptive").is_some() {
            ensemble::load(&p).map(drop).map_err(|e| e.to_string())
        } else {
            spec::load(&p).map(drop).map_err(|e| e.to_string())
        };
        assert!(result.is_ok(), "{}: {}", p.display(), result.unwrap_err());
        checked += 1;
    }
    for p in json_files(&root.join("scenes")) {
        let text = std::fs::read_to_string(&p).unwrap();
        let scene: Scene =
            whirlmap_core::json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        if let Err(e) = scene.validate() {
            panic!("{}: {e}", p.display());
        }
        checked += 1;
    }
    // Not vacuous: the folders hold the files this was written against (20 and 2).
    assert!(checked >= 22, "{checked} files");
}
