//! Joins the output folders of the shards of one sweep ([`crate::shard`]) into one result.
//!
//! The merge refuses, listing every problem it finds, when
//! - a folder is not a shard's output (no `shard.json`), or the shards come from different
//!   specs (spec hash), shard counts, model versions or builds (whirlmap version and commit:
//!   a different commit may change results even under the same model version, so shards of
//!   two builds are never joined), or from another model version than this binary's;
//! - a shard is still running (its folder is locked), or a file it hands over
//!   (`critical.json`, `orbits/`, `probability/`) is not the one its manifest lists;
//! - a grid point is missing (named with its index and inputs, grouped by the shard that owns
//!   it, which is named with its folder and whether it finished), present twice, or not in
//!   the spec's grid;
//! - a shard lacks its critical-speed searches or orbit panels.
//!
//! Otherwise it writes `points.jsonl` (the shards' lines, verbatim, in grid order),
//! `summary.csv`, `critical.json` and `orbits/` byte-identical to a single-machine run of the
//! same spec, a `manifest.json` of the same form (counts and classes identical; run times,
//! threads and build taken from the shards, plus `merged_from`), `timings.jsonl` (the
//! shards' wall times in grid order), and the charts (drawn by the function its caller hands
//! in: this crate draws nothing). The output folder is taken as a sweep
//! takes it ([`crate::folder`]): locked, and refused when it holds another run's files
//! unless `overwrite`.

use crate::extras::{orbit_panels, write_critical, CRITICAL_FILE, PROBABILITY_DIR};
use crate::folder::{self, Mode, RunFolder, RunIdentity};
use crate::shard::{read_shard_manifest, spec_hash, Shard, ShardManifest};
use crate::spec::SpecError;
use crate::sweep::{
    io_err, point_key, write_manifest, write_summary, RunMeta, RunRecord, SweepError, POINTS_FILE,
    SUMMARY_FILE, TIMINGS_FILE,
};
use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;
use whirlmap_core::MODEL_VERSION;
use whirlmap_results::critical::{read_critical, CriticalRow};
use whirlmap_results::files::{orbit_error_file, orbit_file, CHARTS_DIR, ORBITS_DIR};
use whirlmap_results::manifest::{ManifestView, MergedShard, TimingRow};
use whirlmap_results::point::PointLine;
use whirlmap_results::read::complete_len;

/// Missing points listed per shard in an error, at most.
const MAX_LISTED: usize = 20;

/// Why a merge did not produce a result.
#[derive(Debug, Error)]
pub enum MergeError {
    /// The shards do not make one complete result; every problem found, one per entry.
    #[error("merge refused:\n  - {}", .0.join("\n  - "))]
    Refused(Vec<String>),
    /// The spec stored in the shards is unusable.
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// An output could not be written.
    #[error(transparent)]
    Output(#[from] SweepError),
    /// The charts could not be drawn.
    #[error("charts: {0}")]
    Charts(#[from] ChartsFailed),
}

pub use crate::pipeline::ChartsFailed;

impl MergeError {
    /// The process exit code: 2 refused or bad input, 4 an output failed.
    pub fn exit_code(&self) -> u8 {
        match self {
            MergeError::Refused(_) | MergeError::Spec(_) => 2,
            MergeError::Output(e) => e.exit_code(),
            MergeError::Charts(e) if e.output => 4,
            MergeError::Charts(_) => 2,
        }
    }
}

/// What a merge wrote.
#[derive(Debug, Clone)]
pub struct MergeOutcome {
    /// The sweep's name.
    pub name: String,
    /// The number of shards.
    pub shards: usize,
    /// Grid points.
    pub points: usize,
    /// Points recorded ok.
    pub ok: usize,
    /// Points recorded failed.
    pub failed: usize,
    /// Class name -> count over the ok points.
    pub classes: BTreeMap<String, usize>,
    /// Chart files drawn.
    pub charts: Vec<PathBuf>,
    /// What could not be checked (shards written by an older whirlmap, a build without a
    /// known commit), to be said loudly.
    pub warnings: Vec<String>,
}

/// One shard folder as read.
struct ShardDir {
    dir: PathBuf,
    m: ShardManifest,
    /// The shard's `manifest.json` (written when its grid points finished), if readable.
    finished: Option<ManifestView>,
}

impl ShardDir {
    fn shard(&self) -> Shard {
        Shard {
            index: self.m.shard,
            count: self.m.shards,
        }
    }
    fn name(&self) -> String {
        let done = if self.m.complete {
            ""
        } else {
            ", did not finish"
        };
        format!(
            "shard {} ({}{done})",
            self.shard().label(),
            self.dir.display()
        )
    }
}

fn point_text(spec: &crate::spec::SweepSpec, index: usize) -> String {
    let inputs = spec
        .inputs_at(index)
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ");
    format!("#{index} ({inputs})")
}

fn read_shards(dirs: &[PathBuf]) -> Result<Vec<ShardDir>, MergeError> {
    if dirs.is_empty() {
        return Err(MergeError::Refused(vec!["no shard folders given".into()]));
    }
    let mut shards = Vec::new();
    let mut problems = Vec::new();
    for dir in dirs {
        if let Some(who) = folder::running_writer(dir) {
            problems.push(format!(
                "{} is still being written ({who}): merge once that shard has finished",
                dir.display()
            ));
            continue;
        }
        match read_shard_manifest(dir) {
            Ok(m) => {
                let finished = folder::read_manifest(dir).ok().flatten();
                shards.push(ShardDir {
                    dir: dir.clone(),
                    m,
                    finished,
                })
            }
            Err(e) => problems.push(e),
        }
    }
    if !problems.is_empty() {
        return Err(MergeError::Refused(problems));
    }
    // Same spec, shard count and model version everywhere, and this binary's model version.
    let first = &shards[0];
    for s in &shards {
        if s.m.spec_hash != spec_hash(&s.m.spec) {
            problems.push(format!(
                "{}: the spec hash {} does not match its spec (edited by hand, or written by \
                 another whirlmap version)",
                s.dir.display(),
                s.m.spec_hash
            ));
        }
        if s.m.spec_hash != first.m.spec_hash {
            problems.push(format!(
                "the shards come from different specs: {} has spec {} (\"{}\"), {} has spec {} \
                 (\"{}\")",
                first.dir.display(),
                first.m.spec_hash,
                first.m.spec.name,
                s.dir.display(),
                s.m.spec_hash,
                s.m.spec.name
            ));
        }
        if s.m.model_version != first.m.model_version {
            problems.push(format!(
                "the shards come from different model versions: {} has model version {}, {} \
                 has {}",
                first.dir.display(),
                first.m.model_version,
                s.dir.display(),
                s.m.model_version
            ));
        } else if s.m.model_version != MODEL_VERSION {
            problems.push(format!(
                "{} was run with model version {}, this whirlmap has model version \
                 {MODEL_VERSION}: rerun the shard or merge with the same whirlmap",
                s.dir.display(),
                s.m.model_version
            ));
        }
        if (&s.m.whirlmap_version, &s.m.git_commit)
            != (&first.m.whirlmap_version, &first.m.git_commit)
        {
            problems.push(format!(
                "the shards come from different builds: {} was run by whirlmap {}, {} by \
                 whirlmap {} (rerun the shards with one build)",
                first.dir.display(),
                crate::build_info::describe(&first.m.whirlmap_version, &first.m.git_commit),
                s.dir.display(),
                crate::build_info::describe(&s.m.whirlmap_version, &s.m.git_commit)
            ));
        }
        if s.m.shards != first.m.shards {
            problems.push(format!(
                "the shards come from different partitions: {} is shard {}, {} is shard {}",
                first.dir.display(),
                first.shard().label(),
                s.dir.display(),
                s.shard().label()
            ));
        }
    }
    if !problems.is_empty() {
        problems.dedup();
        return Err(MergeError::Refused(problems));
    }
    Ok(shards)
}

/// Merges the shard folders `dirs` into `out_dir` (see the module docs). When the spec lists
/// charts, `draw_charts` draws them from the merged folder (the records written, the folder
/// still locked, before the manifest is completed) and returns the files it wrote, which the
/// manifest then lists. `out_dir` must not be one of the shard folders.
pub fn merge(
    dirs: &[PathBuf],
    out_dir: &Path,
    overwrite: bool,
    draw_charts: crate::pipeline::DrawCharts,
) -> Result<MergeOutcome, MergeError> {
    let shards = read_shards(dirs)?;
    let spec = shards[0].m.spec.clone();
    let count = shards[0].m.shards;
    let grid = spec.grid()?;
    let n_points = grid.len();
    let keys: Vec<String> = (0..n_points)
        .map(|i| grid.point(i).map(|p| point_key(&p.scene, spec.duration_s)))
        .collect::<Result<_, _>>()?;
    let by_key: HashMap<&str, usize> = keys
        .iter()
        .enumerate()
        .map(|(i, k)| (k.as_str(), i))
        .collect();
    let mut problems = Vec::new();

    // Which folders claim each shard.
    let mut claims: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (d, s) in shards.iter().enumerate() {
        claims.entry(s.m.shard).or_default().push(d);
    }
    for (i, ds) in &claims {
        if ds.len() > 1 {
            let names: Vec<String> = ds
                .iter()
                .map(|d| shards[*d].dir.display().to_string())
                .collect();
            problems.push(format!(
                "shard {i}/{count} given twice: {}",
                names.join(", ")
            ));
        }
    }

    // Every record line, by grid index.
    let mut lines: Vec<Vec<(usize, String)>> = vec![Vec::new(); n_points];
    for (d, s) in shards.iter().enumerate() {
        let path = s.dir.join(POINTS_FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => {
                problems.push(format!("{}: {e}", path.display()));
                continue;
            }
        };
        // A torn last line (no newline) is a record the shard did not finish writing.
        let complete = complete_len(text.as_bytes());
        for (n, line) in text[..complete].lines().enumerate() {
            let key = serde_json::from_str::<PointLine>(line)
                .ok()
                .and_then(|p| p.key);
            match key.as_deref().and_then(|k| by_key.get(k)) {
                Some(&i) => lines[i].push((d, line.to_string())),
                None => problems.push(format!(
                    "{} line {}: not a record of a grid point of spec \"{}\" ({})",
                    path.display(),
                    n + 1,
                    spec.name,
                    key.map_or("no key".to_string(), |k| format!("key {k}"))
                )),
            }
        }
    }
    for (index, found) in lines.iter().enumerate() {
        if found.len() > 1 {
            let wher: Vec<String> = found
                .iter()
                .map(|(d, _)| shards[*d].dir.display().to_string())
                .collect();
            problems.push(format!(
                "point {} is present {} times: in {}",
                point_text(&spec, index),
                found.len(),
                wher.join(", ")
            ));
        }
    }
    // Missing points, grouped by their owner.
    let mut missing: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (index, found) in lines.iter().enumerate() {
        if found.is_empty() {
            missing
                .entry(Shard::owner_of(index, count))
                .or_default()
                .push(index);
        }
    }
    for (owner, ps) in &missing {
        let owned = (0..n_points)
            .filter(|i| Shard::owner_of(*i, count) == *owner)
            .count();
        let who = match claims.get(owner) {
            Some(ds) => shards[ds[0]].name(),
            None => format!("shard {owner}/{count} (no folder given)"),
        };
        let mut list: Vec<String> = ps
            .iter()
            .take(MAX_LISTED)
            .map(|i| point_text(&spec, *i))
            .collect();
        if ps.len() > MAX_LISTED {
            list.push(format!("and {} more", ps.len() - MAX_LISTED));
        }
        problems.push(format!(
            "{who} lacks {} of its {owned} points: {}",
            ps.len(),
            list.join(", ")
        ));
    }
    // A shard whose points all arrived but that did not finish (its extras may be missing).
    for s in &shards {
        if !s.m.complete && !missing.contains_key(&s.m.shard) {
            problems.push(format!("{}: rerun it with --resume", s.name()));
        }
    }

    // Critical searches: row `k` of a shard's critical.json is its k-th owned position.
    let mut critical_rows: Vec<Option<CriticalRow>> = Vec::new();
    if let Some(c) = &spec.critical {
        let c_mu = c.mus();
        critical_rows = vec![None; c_mu.len()];
        for s in &shards {
            let path = s.dir.join(CRITICAL_FILE);
            let rows: Option<Vec<CriticalRow>> = read_critical(&s.dir).ok().flatten();
            let Some(rows) = rows.filter(|r| r.len() == s.m.critical_mu.len()) else {
                if !s.m.critical_mu.is_empty() {
                    let mus: Vec<String> =
                        s.m.critical_mu
                            .iter()
                            .map(|j| c_mu[*j].to_string())
                            .collect();
                    problems.push(format!(
                        "{} lacks its critical-speed searches (mu = {}): {} is missing or \
                         incomplete",
                        s.name(),
                        mus.join(", "),
                        path.display()
                    ));
                }
                continue;
            };
            for (j, row) in s.m.critical_mu.iter().zip(rows) {
                if Some(row.mu) != c_mu.get(*j).copied() {
                    problems.push(format!(
                        "{}: row for mu = {} expected, found {}",
                        path.display(),
                        c_mu[*j],
                        row.mu
                    ));
                }
                critical_rows[*j] = Some(row);
            }
        }
    }

    // Orbit panels: `orbits/NN_speed_mu.json` (or `.error.txt` for a failed drop).
    let mut orbit_files: Vec<PathBuf> = Vec::new();
    let panels = orbit_panels(&spec);
    // The extras of shards without a folder.
    for owner in (0..count).filter(|o| !claims.contains_key(o)) {
        let who = format!("shard {owner}/{count} (no folder given)");
        if let Some(c) = &spec.critical {
            let c_mu = c.mus();
            let mus: Vec<String> = (0..c_mu.len())
                .filter(|j| Shard::owner_of(*j, count) == owner)
                .map(|j| c_mu[j].to_string())
                .collect();
            if !mus.is_empty() {
                problems.push(format!(
                    "{who} lacks its critical-speed searches (mu = {})",
                    mus.join(", ")
                ));
            }
        }
        if let Some((_, mus)) = &panels {
            let own: Vec<String> = (0..mus.len())
                .filter(|i| Shard::owner_of(*i, count) == owner)
                .map(|i| format!("{i} (mu = {})", mus[i]))
                .collect();
            if !own.is_empty() {
                problems.push(format!("{who} lacks orbit panels {}", own.join(", ")));
            }
        }
    }
    if let Some((speed, mus)) = panels {
        for s in &shards {
            for &i in &s.m.orbit_panels {
                let Some(mu) = mus.get(i) else { continue };
                let stem = format!("{i:02}_{speed:.0}rpm_mu{mu:.3}");
                let found = [orbit_file(&stem), orbit_error_file(&stem)]
                    .iter()
                    .map(|name| s.dir.join(ORBITS_DIR).join(name))
                    .find(|p| p.is_file());
                match found {
                    Some(p) => orbit_files.push(p),
                    None => problems.push(format!(
                        "{} lacks orbit panel {i} (mu = {mu}): no orbits/{stem}.json",
                        s.name()
                    )),
                }
            }
        }
    }

    // The probability ensemble: one job, run by shard 0 into its `probability/`.
    let mut probability_files: Vec<PathBuf> = Vec::new();
    if spec.probability.is_some() {
        match shards.iter().find(|s| s.m.shard == 0) {
            Some(s) => {
                let dir = s.dir.join(PROBABILITY_DIR);
                let contours = dir.join(crate::ensemble::CONTOURS_FILE);
                if contours.is_file() {
                    if let Ok(entries) = std::fs::read_dir(&dir) {
                        // The ensemble's own files: a user's beside them is neither
                        // checked nor copied.
                        let mut files: Vec<PathBuf> = entries
                            .flatten()
                            .filter(|e| {
                                let name = e.file_name().to_string_lossy().into_owned();
                                folder::is_whirlmaps(&format!("{PROBABILITY_DIR}/{name}"))
                            })
                            .map(|e| e.path())
                            .filter(|p| p.is_file())
                            .collect();
                        files.sort();
                        probability_files = files;
                    }
                } else {
                    problems.push(format!(
                        "{} lacks the probability ensemble: no {}",
                        s.name(),
                        contours.display()
                    ));
                }
            }
            None => problems.push(format!(
                "shard 0/{count} (no folder given) lacks the probability ensemble"
            )),
        }
    }

    // The output folder must not be an input.
    let out_canon = std::fs::canonicalize(out_dir).ok();
    for s in &shards {
        if out_canon.is_some() && std::fs::canonicalize(&s.dir).ok() == out_canon {
            problems.push(format!(
                "the output folder {} is one of the shard folders: choose another --out",
                out_dir.display()
            ));
        }
    }
    // Each file handed over must be the one its shard's manifest lists.
    let mut warnings = Vec::new();
    // (A shard that did not finish is refused above already.)
    for (d, s) in shards.iter().enumerate().filter(|(_, s)| s.m.complete) {
        let mut inputs: Vec<String> = Vec::new();
        if spec.critical.is_some() && !s.m.critical_mu.is_empty() {
            inputs.push(CRITICAL_FILE.to_string());
        }
        let prefix = s.dir.clone();
        for f in orbit_files
            .iter()
            .chain(probability_files.iter())
            .filter(|f| f.starts_with(&prefix))
        {
            if let Ok(rel) = f.strip_prefix(&prefix) {
                inputs.push(
                    rel.components()
                        .map(|c| c.as_os_str().to_string_lossy())
                        .collect::<Vec<_>>()
                        .join("/"),
                );
            }
        }
        inputs.push(POINTS_FILE.to_string());
        inputs.retain(|f| shards[d].dir.join(f).is_file());
        match folder::check_inputs(&s.dir, &inputs) {
            Ok(c) => warnings.extend(
                c.warnings
                    .into_iter()
                    .filter(|w| !w.contains("did not finish")),
            ),
            Err(p) => problems.extend(p),
        }
    }
    if shards[0].m.git_commit == "unknown" {
        warnings.push(format!(
            "the shards' build has no known commit (whirlmap {}): that they come from one \
             build cannot be checked beyond the version",
            shards[0].m.whirlmap_version
        ));
    }
    if !problems.is_empty() {
        return Err(MergeError::Refused(problems));
    }
    if (
        &shards[0].m.whirlmap_version,
        shards[0].m.git_commit.as_str(),
    ) != (
        &crate::build_info::VERSION.to_string(),
        crate::build_info::GIT_COMMIT,
    ) {
        warnings.push(format!(
            "the shards were run by whirlmap {}, this merge is {}: the records are the \
             shards', the summary and charts this build's",
            crate::build_info::describe(&shards[0].m.whirlmap_version, &shards[0].m.git_commit),
            crate::build_info::DESCRIPTION
        ));
    }

    // Write: the output folder is taken as a sweep takes it.
    let hash = spec_hash(&spec);
    let id = RunIdentity {
        spec: &spec,
        spec_hash: hash.clone(),
        shard: None,
    };
    let mode = if overwrite {
        Mode::Overwrite
    } else {
        Mode::Fresh
    };
    let (mut out, _) = RunFolder::prepare(out_dir, "merge", &id, mode)?;
    let mut record = RunRecord {
        spec: spec.clone(),
        spec_hash: hash,
        meta: merged_meta(&shards),
        counts: None,
        classes: None,
    };
    write_manifest(&out, &record, false)?;
    let chosen: Vec<&str> = lines.iter().map(|l| l[0].1.as_str()).collect();
    folder::write_atomic_with(&out_dir.join(POINTS_FILE), |w| {
        for l in &chosen {
            w.write_all(l.as_bytes())?;
            w.write_all(b"\n")?;
        }
        Ok(())
    })?;
    out.release_previous()?;
    write_timings(&shards, &out_dir.join(TIMINGS_FILE))?;
    if spec.critical.is_some() {
        let rows: Vec<CriticalRow> = critical_rows.into_iter().flatten().collect();
        write_critical(out_dir, &rows).map_err(|e| match e {
            crate::extras::ExtrasError::Io { path, source } => SweepError::Io { path, source },
        })?;
        out.record(CRITICAL_FILE)?;
        out.record(crate::extras::CRITICAL_CSV_FILE)?;
    }
    for (files, sub) in [
        (&orbit_files, ORBITS_DIR),
        (&probability_files, PROBABILITY_DIR),
    ] {
        if files.is_empty() {
            continue;
        }
        let dir = out_dir.join(sub);
        std::fs::create_dir_all(&dir).map_err(io_err(&dir))?;
        for src in files {
            let dst = dir.join(src.file_name().expect("merged files have names"));
            let bytes = std::fs::read(src).map_err(io_err(src))?;
            folder::write_atomic(&dst, &bytes)?;
        }
        out.record_tree(sub)?;
    }
    let (ok, failed, classes) = write_summary(&spec, out_dir, &mut (0..n_points))?;
    for f in [POINTS_FILE, TIMINGS_FILE, SUMMARY_FILE] {
        out.record(f)?;
    }
    if crate::sweep::write_bearing_report(&spec, out_dir)? {
        out.record(crate::sweep::BEARING_REPORT_FILE)?;
    }
    record.counts = Some(crate::sweep::Counts {
        points: n_points,
        ok,
        failed,
        skipped: record_skipped(&shards),
    });
    record.classes = Some(classes.clone());
    write_manifest(&out, &record, false)?;
    let charts = crate::pipeline::draw_charts(&spec, out_dir, draw_charts)?.unwrap_or_default();
    out.record_tree(CHARTS_DIR)?;
    record.meta.ended_unix_s = merged_end(&shards);
    write_manifest(&out, &record, true)?;
    Ok(MergeOutcome {
        name: spec.name.clone(),
        shards: count,
        points: n_points,
        ok,
        failed,
        classes,
        charts,
        warnings,
    })
}

/// The resumed points of the shards, summed.
fn record_skipped(shards: &[ShardDir]) -> usize {
    shards
        .iter()
        .filter_map(|s| s.finished.as_ref())
        .filter_map(|m| m.counts.as_ref().map(|c| c.skipped))
        .sum()
}

/// The latest end time of the shards.
fn merged_end(shards: &[ShardDir]) -> Option<f64> {
    shards
        .iter()
        .filter_map(|s| s.finished.as_ref())
        .filter_map(|m| m.ended_unix_s)
        .reduce(f64::max)
}

/// Run facts of the merged manifest: the earliest start of the shards, their threads summed,
/// their build (the same in every shard), and the shards.
fn merged_meta(shards: &[ShardDir]) -> RunMeta {
    let mut order: Vec<&ShardDir> = shards.iter().collect();
    order.sort_by_key(|s| s.m.shard);
    RunMeta {
        whirlmap_version: order[0].m.whirlmap_version.clone(),
        git_commit: order[0].m.git_commit.clone(),
        started_unix_s: shards
            .iter()
            .filter_map(|s| s.finished.as_ref()?.started_unix_s)
            .fold(f64::INFINITY, f64::min),
        ended_unix_s: None,
        threads: shards
            .iter()
            .filter_map(|s| s.finished.as_ref()?.threads)
            .sum::<u64>() as usize,
        shard: None,
        merged_from: Some(
            order
                .iter()
                .map(|s| MergedShard {
                    dir: s.dir.display().to_string(),
                    points: s.m.points.len(),
                    shard: s.m.shard,
                    shards: s.m.shards,
                    spec_hash: s.m.spec_hash.clone(),
                })
                .collect(),
        ),
    }
}

/// The shards' `timings.jsonl` lines, in grid order (wall times are not deterministic; this
/// file is for profiling only).
fn write_timings(shards: &[ShardDir], path: &Path) -> Result<(), SweepError> {
    let mut rows: Vec<(usize, String)> = Vec::new();
    for s in shards {
        let Ok(text) = std::fs::read_to_string(s.dir.join(TIMINGS_FILE)) else {
            continue;
        };
        for line in text.lines() {
            if let Ok(row) = serde_json::from_str::<TimingRow>(line) {
                rows.push((row.index, line.to_string()));
            }
        }
    }
    rows.sort_by_key(|r| r.0);
    let mut text = String::new();
    for (_, l) in rows {
        text.push_str(&l);
        text.push('\n');
    }
    folder::write_atomic(path, text.as_bytes())
}
