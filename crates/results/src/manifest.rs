//! The run's bookkeeping files: `manifest.json` (what ran, with which build, and every file
//! it wrote), `timings.jsonl` (one wall time per grid point) and an ensemble's
//! `manifest.json`.
//!
//! The writer's form, [`Manifest`], is generic over the spec (the sweep crate's `SweepSpec`),
//! which this crate does not know; fields are in the order they are written, so a manifest
//! read and written again gives the same bytes. [`ManifestView`] is the tolerant reading of
//! any `manifest.json` a results folder may hold (this whirlmap's, an older one's without a
//! file list, an ensemble's): every field optional, unknown fields ignored.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::Read;
use std::path::Path;

use crate::files::MANIFEST_FILE;

/// One file in a manifest's list: its size and FNV-1a 64 hash.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileEntry {
    /// Its size in bytes.
    pub bytes: u64,
    /// FNV-1a 64 of its bytes, 16 hex digits.
    pub fnv1a64: String,
}

impl FileEntry {
    /// Reads `path` in blocks and hashes it.
    pub fn of(path: &Path) -> std::io::Result<Self> {
        let mut f = File::open(path)?;
        let mut buf = vec![0u8; 1 << 16];
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut bytes = 0u64;
        loop {
            let n = f.read(&mut buf)?;
            if n == 0 {
                break;
            }
            bytes += n as u64;
            for b in &buf[..n] {
                h ^= *b as u64;
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
        debug_assert_eq!(whirlmap_core::scene::fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        Ok(Self {
            bytes,
            fnv1a64: format!("{h:016x}"),
        })
    }
}

/// A shard run's part of the grid, the manifest's `shard` section (keys in the order
/// whirlmap has always written them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardTag {
    /// The number of shards.
    pub count: usize,
    /// This shard, from 0.
    pub index: usize,
}

/// One shard a merged result was made from, an entry of the manifest's `merged_from`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct MergedShard {
    /// The shard's folder, as given to the merge.
    pub dir: String,
    /// The grid points it owned.
    pub points: usize,
    /// The shard, from 0.
    pub shard: usize,
    /// The number of shards.
    pub shards: usize,
    /// Its spec hash.
    pub spec_hash: String,
}

/// The counts of a finished grid.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Grid points.
    pub points: usize,
    /// Points recorded ok.
    pub ok: usize,
    /// Points recorded failed.
    pub failed: usize,
    /// Points kept from a resumed run.
    #[serde(default)]
    pub skipped: usize,
}

/// `manifest.json` of a sweep, a shard or a merge, as written; `S` is the spec.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest<S> {
    /// The spec, as parsed.
    pub spec: S,
    /// With a `fidelity` preset in the spec: the integrator settings every drop started from,
    /// the spec's `scene.solver` with the preset applied (an axis may still vary them; the
    /// preset also runs the full model, `quasi_static_race` off). The spec's own
    /// `scene.solver` is what the file gave, which the preset replaced. Absent without a
    /// preset.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset_solver: Option<whirlmap_core::SolverSettings>,
    /// The spec's hash.
    pub spec_hash: String,
    /// The whirlmap version of the binary that ran the drops.
    pub whirlmap_version: String,
    /// The model version of that binary.
    pub model_version: u32,
    /// The commit that binary was built from.
    pub git_commit: String,
    /// False while the run is going on (or after it was killed); true once every file is
    /// written.
    pub complete: bool,
    /// When the run started (Unix seconds).
    pub started_unix_s: f64,
    /// When it ended, once complete.
    pub ended_unix_s: Option<f64>,
    /// Worker threads.
    pub threads: usize,
    /// The grid's counts, once the grid is done.
    pub counts: Option<Counts>,
    /// Class name -> count over the ok points, once the grid is done.
    pub classes: Option<BTreeMap<String, usize>>,
    /// A shard run's part of the grid; absent for a whole run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardTag>,
    /// The shards a merged result was made from; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub merged_from: Option<Vec<MergedShard>>,
    /// Every file the run wrote (relative path -> size and hash).
    pub files: BTreeMap<String, FileEntry>,
}

impl<S: Serialize> Manifest<S> {
    /// The file's text: pretty JSON and a final newline.
    pub fn to_text(&self) -> String {
        let text = serde_json::to_string_pretty(self).expect("manifests serialise");
        format!("{text}\n")
    }
}

/// Any `manifest.json` of a results folder, read tolerantly: this whirlmap's, an older one's
/// (no build, no file list), an ensemble's (no hash, no file list). Every field is optional.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
pub struct ManifestView {
    /// The spec, as written (a sweep's or an ensemble's).
    #[serde(default)]
    pub spec: Option<serde_json::Value>,
    /// The spec's hash.
    #[serde(default)]
    pub spec_hash: Option<String>,
    /// The whirlmap version that wrote it.
    #[serde(default)]
    pub whirlmap_version: Option<String>,
    /// The model version.
    #[serde(default)]
    pub model_version: Option<u64>,
    /// The commit.
    #[serde(default)]
    pub git_commit: Option<String>,
    /// Whether the run finished; absent in manifests of older whirlmaps.
    #[serde(default)]
    pub complete: Option<bool>,
    /// When the run started.
    #[serde(default)]
    pub started_unix_s: Option<f64>,
    /// When it ended.
    #[serde(default)]
    pub ended_unix_s: Option<f64>,
    /// Worker threads.
    #[serde(default)]
    pub threads: Option<u64>,
    /// The grid's counts.
    #[serde(default)]
    pub counts: Option<Counts>,
    /// A shard run's part of the grid.
    #[serde(default)]
    pub shard: Option<ShardTag>,
    /// The file list; absent in manifests of older whirlmaps and of ensembles.
    #[serde(default)]
    pub files: Option<BTreeMap<String, FileEntry>>,
}

impl ManifestView {
    /// The spec's `name`, if the manifest has one.
    pub fn spec_name(&self) -> Option<&str> {
        self.spec.as_ref()?.get("name")?.as_str()
    }
}

/// The folder's `manifest.json`, read tolerantly; `None` when there is none. The error names
/// the file.
pub fn read_manifest(dir: &Path) -> Result<Option<ManifestView>, String> {
    let path = dir.join(MANIFEST_FILE);
    match std::fs::read_to_string(&path) {
        Ok(t) => serde_json::from_str(&t)
            .map(Some)
            .map_err(|e| format!("{}: {e}", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// One line of `timings.jsonl`: a grid point's wall time (keys in the order whirlmap has
/// always written them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimingRow {
    /// Grid index.
    pub index: usize,
    /// The record key.
    pub key: String,
    /// Wall time of the drop (seconds).
    pub wall_time_s: f64,
}

impl TimingRow {
    /// The line, without its newline.
    pub fn to_line(&self) -> String {
        serde_json::to_string(self).expect("timings serialise")
    }
}

/// A value written with the keys of every object in it sorted, as whirlmap has always
/// written the spec in an ensemble's manifest; read back as `T`.
#[derive(Debug, Clone, PartialEq)]
pub struct SortedKeys<T>(pub T);

impl<T: Serialize> Serialize for SortedKeys<T> {
    fn serialize<Ser: serde::Serializer>(&self, s: Ser) -> Result<Ser::Ok, Ser::Error> {
        // A JSON value keeps its object keys sorted.
        serde_json::to_value(&self.0)
            .map_err(serde::ser::Error::custom)?
            .serialize(s)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for SortedKeys<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        T::deserialize(d).map(SortedKeys)
    }
}

/// An ensemble's `manifest.json` (`whirlmap ensemble`, a sweep's `probability/`); `S` is the
/// ensemble spec. Keys in the order whirlmap has always written them (sorted).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnsembleManifest<S> {
    /// Cells of the grid.
    pub cells: usize,
    /// `false` while the ensemble runs (written before its first drop, so a `--resume` knows
    /// which spec the members already in `members.jsonl` belong to), `true` once every file
    /// is written. Manifests without the key were only ever written complete.
    #[serde(default = "complete_by_default")]
    pub complete: bool,
    /// Drops (cells x members; while running: the drops planned).
    pub drops: usize,
    /// Drops that failed (while running: 0).
    pub failed: usize,
    /// The commit the binary was built from (absent in an older whirlmap's manifest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_commit: Option<String>,
    /// The model version of the binary that ran them.
    pub model_version: u32,
    /// With a `fidelity` preset in the spec: the integrator settings every drop started
    /// from, as [`Manifest::preset_solver`]. Absent without a preset.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset_solver: Option<whirlmap_core::SolverSettings>,
    /// The ensemble spec.
    pub spec: SortedKeys<S>,
    /// Worker threads.
    pub threads: usize,
    /// Wall time of the whole ensemble (seconds).
    pub wall_time_s: f64,
    /// The whirlmap version of the binary.
    pub whirlmap_version: String,
}

/// An ensemble manifest without `complete` was written by an older whirlmap at the end.
fn complete_by_default() -> bool {
    true
}

impl<S: Serialize> EnsembleManifest<S> {
    /// The file's text: pretty JSON and a final newline.
    pub fn to_text(&self) -> String {
        let text = serde_json::to_string_pretty(self).expect("manifests serialise");
        format!("{text}\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_committed_manifest_reads_back_to_the_same_bytes() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../results/paper");
        let text = std::fs::read_to_string(dir.join(MANIFEST_FILE)).unwrap();
        let m: Manifest<serde_json::Value> = serde_json::from_str(&text).unwrap();
        // The spec as a `Value` has its keys sorted; everything around it keeps its order.
        let again = m.to_text();
        let keys = |t: &str| {
            t.lines()
                .filter(|l| l.starts_with("  \""))
                .map(|l| l.split('"').nth(1).unwrap().to_string())
                .collect::<Vec<_>>()
        };
        assert_eq!(keys(&text), keys(&again));
        let files = |t: &str| t[t.find("\"files\"").unwrap()..].to_string();
        assert_eq!(files(&text), files(&again));
        let view = read_manifest(&dir).unwrap().unwrap();
        assert_eq!(view.spec_name(), Some("paper"));
        assert_eq!(view.files.map(|f| f.len()), Some(m.files.len()));
    }

    #[test]
    fn timing_rows_and_ensemble_manifests_keep_their_key_order() {
        let row = TimingRow {
            index: 3,
            key: "ab".into(),
            wall_time_s: 0.25,
        };
        assert_eq!(
            row.to_line(),
            r#"{"index":3,"key":"ab","wall_time_s":0.25}"#
        );
        let back: TimingRow = serde_json::from_str(&row.to_line()).unwrap();
        assert_eq!(back, row);
        let m = EnsembleManifest {
            cells: 1,
            complete: true,
            drops: 2,
            failed: 0,
            git_commit: Some("abc".into()),
            model_version: 5,
            preset_solver: None,
            spec: SortedKeys(serde_json::json!({"name": "e", "axes": {}})),
            threads: 2,
            wall_time_s: 0.5,
            whirlmap_version: "0.1.0".into(),
        };
        let text = m.to_text();
        assert!(text.contains("\"spec\": {\n    \"axes\": {},\n    \"name\": \"e\"\n  }"));
        assert!(text.starts_with("{\n  \"cells\": 1,\n  \"complete\": true,\n  \"drops\""));
        assert!(text.contains("\"failed\": 0,\n  \"git_commit\": \"abc\",\n  \"model_version\""));
        let view: ManifestView = serde_json::from_str(&text).unwrap();
        assert_eq!(view.files, None);
        assert_eq!(view.complete, Some(true));
        // A manifest from before the key was only ever written complete.
        let old = text
            .replace("  \"complete\": true,\n", "")
            .replace("  \"git_commit\": \"abc\",\n", "");
        let back: EnsembleManifest<serde_json::Value> = serde_json::from_str(&old).unwrap();
        assert!(back.complete);
        assert_eq!(back.git_commit, None);
    }
}
