//! Shards: a deterministic partition of a sweep so that several machines (a Slurm job array,
//! a Kubernetes Indexed Job, GNU parallel) each run a part and [`crate::merge`] joins them.
//!
//! Shard `I` of `N` owns
//! - the grid points whose index `k` has `k mod N = I`,
//! - the critical-speed searches whose position `j` in `critical.mu` has `j mod N = I`,
//! - the Fig. 3 orbit panels whose position `i` has `i mod N = I`.
//!
//! Round-robin over the grid spreads cheap and expensive regions (low and high friction, low
//! and high speed) over all shards, and depends on nothing but the spec, so any machine
//! computes the same partition. A shard writes into its own folder the usual
//! `points.jsonl` (its points only, in grid order), `timings.jsonl`, `summary.csv`,
//! `manifest.json` (with a `shard` section), `critical.json` (its friction values only) and
//! `orbits/`, and, BEFORE it runs anything, [`SHARD_FILE`]: the spec, its hash, the model
//! version, `I/N` and the indices and keys it owns, so a merge can name what a shard that
//! died lacks; `complete` in it turns true when everything is written. Charts are drawn by the merge, not by shards. A shard runs through
//! [`crate::pipeline::run`], as a whole sweep does.

use crate::spec::SweepSpec;
use crate::sweep::{point_key, SweepError};
use serde::{Deserialize, Serialize};
use std::path::Path;
use whirlmap_core::scene::fnv1a64;
use whirlmap_core::MODEL_VERSION;
use whirlmap_results::manifest::ShardTag;

/// The file a shard writes before it runs: [`ShardManifest`].
pub use whirlmap_results::files::SHARD_FILE;

/// Largest shard count accepted (a sanity bound for user input).
pub const MAX_SHARDS: usize = 100_000;

/// Shard `index` of `count`, `index < count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, from 0.
    pub index: usize,
    /// The number of shards, >= 1.
    pub count: usize,
}

impl Shard {
    /// Checks `index < count` and `1 <= count <= MAX_SHARDS`; the error names the option,
    /// the value and the allowed range.
    pub fn new(index: usize, count: usize) -> Result<Self, String> {
        if !(1..=MAX_SHARDS).contains(&count) {
            return Err(format!(
                "--shards = {count} is out of range: allowed [1, {MAX_SHARDS}]"
            ));
        }
        if index >= count {
            return Err(format!(
                "--shard = {index} is out of range for --shards {count}: allowed [0, {}]",
                count - 1
            ));
        }
        Ok(Self { index, count })
    }

    /// Whether this shard owns item `k` of a list (a grid index, a position in
    /// `critical.mu` or among the orbit panels).
    pub fn owns(&self, k: usize) -> bool {
        k % self.count == self.index
    }

    /// The shard that owns item `k` among `count` shards.
    pub fn owner_of(k: usize, count: usize) -> usize {
        k % count
    }

    /// `shard-I-of-N`: the default folder name of a shard's output.
    pub fn dir_name(&self) -> String {
        format!("shard-{}-of-{}", self.index, self.count)
    }

    /// `I/N` for messages.
    pub fn label(&self) -> String {
        format!("{}/{}", self.index, self.count)
    }

    /// The `shard` section of the shard's `manifest.json`.
    pub fn manifest_tag(&self) -> ShardTag {
        ShardTag {
            count: self.count,
            index: self.index,
        }
    }
}

/// A grid point a shard owns.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct OwnedPoint {
    /// Grid index.
    pub index: usize,
    /// The record key ([`point_key`]).
    pub key: String,
}

/// `shard.json`: what a shard is and owns, written before it runs anything.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardManifest {
    /// This shard, from 0.
    pub shard: usize,
    /// The number of shards.
    pub shards: usize,
    /// [`spec_hash`] of `spec`.
    pub spec_hash: String,
    /// `whirlmap_core::MODEL_VERSION` of the binary that ran the shard.
    pub model_version: u32,
    /// The whirlmap package version of that binary.
    pub whirlmap_version: String,
    /// The commit that binary was built from ([`crate::build_info::GIT_COMMIT`]); `unknown`
    /// for a shard written by an older whirlmap.
    #[serde(default = "unknown")]
    pub git_commit: String,
    /// The grid points owned, in grid order.
    pub points: Vec<OwnedPoint>,
    /// Positions in `critical.mu` owned, increasing.
    pub critical_mu: Vec<usize>,
    /// Positions among the orbit panels owned, increasing.
    pub orbit_panels: Vec<usize>,
    /// False while the shard runs; true once its points, critical searches and orbits are
    /// all written.
    #[serde(default)]
    pub complete: bool,
    /// The spec, as parsed.
    pub spec: SweepSpec,
}

fn unknown() -> String {
    "unknown".to_string()
}

/// Stable FNV-1a 64 hash of the spec's canonical JSON (16 hex digits): shards of the same
/// sweep have the same hash.
pub fn spec_hash(spec: &SweepSpec) -> String {
    let text = serde_json::to_string(spec).expect("specs serialise");
    format!("{:016x}", fnv1a64(text.as_bytes()))
}

/// The [`ShardManifest`] of `shard` for `spec` (validates the spec).
pub fn shard_manifest(spec: &SweepSpec, shard: Shard) -> Result<ShardManifest, SweepError> {
    let grid = spec.grid()?;
    let points = (shard.index..grid.len())
        .step_by(shard.count)
        .map(|index| {
            let p = grid.point(index)?;
            Ok(OwnedPoint {
                index,
                key: point_key(&p.scene, spec.duration_s),
            })
        })
        .collect::<Result<Vec<_>, SweepError>>()?;
    let owned = |n: usize| (0..n).filter(|k| shard.owns(*k)).collect::<Vec<_>>();
    let n_orbits = crate::extras::orbit_panels(spec).map_or(0, |(_, mus)| mus.len());
    Ok(ShardManifest {
        shard: shard.index,
        shards: shard.count,
        spec_hash: spec_hash(spec),
        model_version: MODEL_VERSION,
        whirlmap_version: crate::build_info::VERSION.to_string(),
        git_commit: crate::build_info::GIT_COMMIT.to_string(),
        points,
        critical_mu: owned(spec.critical.as_ref().map_or(0, |c| c.mus().len())),
        orbit_panels: owned(n_orbits),
        complete: false,
        spec: spec.clone(),
    })
}

/// Reads a shard folder's [`SHARD_FILE`].
pub fn read_shard_manifest(dir: &Path) -> Result<ShardManifest, String> {
    let path = dir.join(SHARD_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "{}: {e} (not a shard's output folder, or the shard never started)",
            path.display()
        )
    })?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_every_index_exactly_once() {
        for count in 1..=7 {
            for k in 0..50 {
                let owners: Vec<usize> = (0..count)
                    .filter(|&i| Shard::new(i, count).unwrap().owns(k))
                    .collect();
                assert_eq!(owners, vec![Shard::owner_of(k, count)], "k {k} of {count}");
            }
        }
    }

    #[test]
    fn bad_shard_numbers_name_the_option_and_range() {
        let e = Shard::new(4, 4).unwrap_err();
        assert!(e.contains("--shard = 4") && e.contains("[0, 3]"), "{e}");
        let e = Shard::new(0, 0).unwrap_err();
        assert!(e.contains("--shards = 0") && e.contains("[1, "), "{e}");
    }

    #[test]
    fn spec_hash_changes_with_the_spec() {
        let a =
            crate::spec::parse(r#"{"name": "t", "duration_s": 0.05, "axes": {"mu": [0.1, 0.2]}}"#)
                .unwrap();
        let mut b = a.clone();
        b.duration_s = 0.06;
        assert_eq!(spec_hash(&a), spec_hash(&a.clone()));
        assert_ne!(spec_hash(&a), spec_hash(&b));
        let m = shard_manifest(&a, Shard::new(1, 2).unwrap()).unwrap();
        assert_eq!(m.points.len(), 1);
        assert_eq!(m.points[0].index, 1);
    }
}
