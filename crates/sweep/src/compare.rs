//! Compares two sweep results (a baseline and a new run, e.g. last night's and tonight's):
//! what a nightly job reports.
//!
//! - Per grid point (matched by its inputs, so a new model version whose keys differ is still
//!   compared point by point): a class change, an ok/failed change, or a relative change of
//!   the maximum contact force or the peak heat power beyond its threshold
//!   (`|new - base| / |base|`). A point in only one of the two is a change too.
//! - Per friction coefficient of `critical.json`: a shift of the critical speed larger than
//!   the two brackets allow, i.e. the brackets do not overlap; a transition found in one run
//!   and not in the other is a change as well. Overlapping brackets are "the same": the search
//!   cannot tell the speeds apart.
//!
//! - Only like with like: a point is comparable when both runs have it (the same inputs) with
//!   the same simulated duration; the specs' differences (from the manifests: `duration_s`,
//!   the scene, the axes, ...) are always stated, and when no point is comparable the
//!   comparison is refused rather than reported as the same. Each folder is checked first
//!   ([`crate::folder::check_inputs`]): a file its run did not write is refused, a folder
//!   being written is refused, a run that did not finish is said loudly.
//!
//! [`compare`] returns the findings; [`write_report`] writes them as Markdown with a class map
//! of the new run whose changed cells are outlined (drawn by the function its caller hands
//! in: this crate draws nothing).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use whirlmap_results::critical::{read_critical, CriticalRow};
use whirlmap_results::grid::{assemble_grid, Grid};
use whirlmap_results::point::{load_points, PointRow, PointStatus};
use whirlmap_results::read::LoadError;

/// Relative changes above which a point counts as changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds {
    /// Maximum contact force, relative (0.05 = 5 %).
    pub force_rel: f64,
    /// Peak heat power, relative.
    pub power_rel: f64,
}

impl Default for Thresholds {
    /// 5 % for both: far above the solver's own scatter (forces agree to 0.001 % between
    /// rtol 1e-5 and 1e-9, docs/clusters.md#compare), well below a design-relevant change.
    /// A choice, not a measured optimum.
    fn default() -> Self {
        Self {
            force_rel: 0.05,
            power_rel: 0.05,
        }
    }
}

impl Thresholds {
    /// Checks that both are finite and >= 0; the error names the option.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("--force-rel", self.force_rel),
            ("--power-rel", self.power_rel),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} = {v} is out of range: allowed [0, inf)"));
            }
        }
        Ok(())
    }
}

/// One point that changed.
#[derive(Debug, Clone, PartialEq)]
pub struct PointChange {
    /// `name=value, ...` of the point.
    pub inputs: String,
    /// What changed, one entry per quantity (`class pendulum -> backward_whirl`, ...).
    pub what: Vec<String>,
    /// The point in the new run (`None` if it is only in the baseline).
    pub new_row: Option<PointRow>,
    /// The point is in one run only (not one of the points compared).
    pub in_one_run: bool,
}

/// One friction coefficient whose critical speed moved.
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalChange {
    /// Friction coefficient.
    pub mu: f64,
    /// Baseline bracket (r/min), `None` if no transition or not searched.
    pub baseline: Option<[f64; 2]>,
    /// New bracket.
    pub new: Option<[f64; 2]>,
    /// In words.
    pub what: String,
    /// Searched in one run only (not one of the searches compared).
    pub in_one_run: bool,
}

/// The findings of a comparison.
#[derive(Debug, Clone)]
pub struct Comparison {
    /// The baseline folder.
    pub baseline: PathBuf,
    /// The new folder.
    pub new: PathBuf,
    /// The thresholds used.
    pub thresholds: Thresholds,
    /// Points compared (present in both).
    pub points_compared: usize,
    /// Points that changed beyond the thresholds, in the new run's order.
    pub points: Vec<PointChange>,
    /// Critical searches compared (present in both).
    pub critical_compared: usize,
    /// Critical speeds that moved beyond the brackets.
    pub critical: Vec<CriticalChange>,
    /// Both runs' manifests' `spec.name`, `model_version` (for the report header).
    pub runs: [RunInfo; 2],
    /// What differs between the two specs (`duration_s: 1.0 -> 0.5`, ...), the name and the
    /// chart list aside; empty when they are the same or a manifest is missing.
    pub spec_differences: Vec<String>,
    /// Points in both runs that cannot be compared (a different duration), with why.
    pub not_comparable: Vec<String>,
    /// How many of [`Comparison::not_comparable`] are grid points (the rest are critical
    /// searches).
    pub points_not_comparable: usize,
    /// What could not be checked or is partial (a folder without a manifest, a run that did
    /// not finish), to be said loudly.
    pub warnings: Vec<String>,
    /// The new run's rows (for the class map).
    new_rows: Vec<PointRow>,
}

impl Comparison {
    /// Whether anything changed beyond the thresholds.
    pub fn changed(&self) -> bool {
        !self.points.is_empty() || !self.critical.is_empty()
    }

    /// The counts in words: `3 of 64 points and 0 of 5 critical speeds changed`, then, when
    /// some are in one run only, `; in one run only: 2 points, 1 critical speed`, and when
    /// points in both could not be compared, `; not comparable: 1 point`. A point or search
    /// in one run only counts as a change, but not among those compared.
    pub fn counts(&self) -> String {
        let one = |n: usize, what: &str| match n {
            1 => format!("1 {what}"),
            n => format!("{n} {what}s"),
        };
        let pts_one = self.points.iter().filter(|p| p.in_one_run).count();
        let crit_one = self.critical.iter().filter(|c| c.in_one_run).count();
        let mut s = format!(
            "{} of {} points and {} of {} critical speeds changed",
            self.points.len() - pts_one,
            self.points_compared,
            self.critical.len() - crit_one,
            self.critical_compared
        );
        if pts_one + crit_one > 0 {
            s.push_str(&format!(
                "; in one run only: {}, {}",
                one(pts_one, "point"),
                one(crit_one, "critical speed")
            ));
        }
        if self.points_not_comparable > 0 {
            s.push_str(&format!(
                "; not comparable: {}",
                one(self.points_not_comparable, "point")
            ));
        }
        s
    }
}

/// What a run's manifest says about it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunInfo {
    /// The spec's name.
    pub name: String,
    /// The model version.
    pub model_version: String,
    /// The git commit, if recorded.
    pub git_commit: String,
    /// The spec hash, if recorded.
    pub spec_hash: String,
}

/// Why two results cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A folder's points or critical speeds could not be read.
    #[error(transparent)]
    Read(#[from] LoadError),
    /// The folders cannot be compared: nothing comparable, a folder being written, a file
    /// its run did not write. Every reason, one per entry.
    #[error("compare refused:\n  - {}", .0.join("\n  - "))]
    Refused(Vec<String>),
}

fn run_info(dir: &Path) -> RunInfo {
    let m = crate::folder::read_manifest(dir)
        .ok()
        .flatten()
        .unwrap_or_default();
    let text = |v: Option<&str>| v.unwrap_or("?").to_string();
    RunInfo {
        name: text(m.spec_name()),
        model_version: m.model_version.map_or("?".to_string(), |v| v.to_string()),
        git_commit: text(m.git_commit.as_deref()),
        spec_hash: text(m.spec_hash.as_deref()),
    }
}

/// Canonical text of a point's inputs (sorted names, JSON numbers): the matching key.
fn inputs_key(r: &PointRow) -> String {
    serde_json::to_string(&r.inputs).expect("inputs serialise")
}

fn inputs_text(r: &PointRow) -> String {
    r.inputs
        .iter()
        .map(|(k, v)| match v.as_f64() {
            Some(x) => format!("{k}={x}"),
            None => format!("{k}={v}"),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn class_name(r: &PointRow) -> String {
    match (r.status, r.class) {
        (PointStatus::Failed, _) => "failed".to_string(),
        (_, Some(c)) => serde_json::to_value(c)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_else(|| format!("{c:?}")),
        (_, None) => "none".to_string(),
    }
}

/// `Some(description)` when `new` differs from `base` by more than `rel` relatively.
fn rel_change(
    name: &str,
    unit: &str,
    base: Option<f64>,
    new: Option<f64>,
    rel: f64,
) -> Option<String> {
    match (base, new) {
        (Some(b), Some(n)) => {
            let change = if b == 0.0 {
                if n == 0.0 {
                    0.0
                } else {
                    f64::INFINITY
                }
            } else {
                (n - b) / b.abs()
            };
            (change.abs() > rel)
                .then(|| format!("{name} {b:.1} -> {n:.1} {unit} ({:+.1} %)", 100.0 * change))
        }
        (None, None) => None,
        (b, n) => Some(format!(
            "{name} {} -> {}",
            b.map_or("none".to_string(), |v| format!("{v:.1} {unit}")),
            n.map_or("none".to_string(), |v| format!("{v:.1} {unit}"))
        )),
    }
}

fn fmt_bracket(b: Option<[f64; 2]>) -> String {
    b.map_or("no transition".to_string(), |[lo, hi]| {
        format!("{lo:.0}-{hi:.0} r/min")
    })
}

fn compare_critical(base: &[CriticalRow], new: &[CriticalRow]) -> (usize, Vec<CriticalChange>) {
    let mut changes = Vec::new();
    let mut compared = 0;
    let find = |list: &[CriticalRow], mu: f64| {
        list.iter()
            .find(|e| (e.mu - mu).abs() <= 1e-12 * mu.abs().max(1.0))
            .cloned()
    };
    for n in new {
        let Some(b) = find(base, n.mu) else {
            changes.push(CriticalChange {
                mu: n.mu,
                baseline: None,
                new: n.bracket_rpm,
                what: "searched in the new run only".into(),
                in_one_run: true,
            });
            continue;
        };
        compared += 1;
        let (bb, nb) = (b.bracket_rpm, n.bracket_rpm);
        let mut what = match (bb, nb) {
            (Some([blo, bhi]), Some([nlo, nhi])) if nhi < blo || nlo > bhi => Some(format!(
                "onset moved {} (brackets do not overlap)",
                if nlo > bhi { "up" } else { "down" }
            )),
            _ => None,
        };
        if what.is_none() && b.onset_rpm.is_some() != n.onset_rpm.is_some() {
            what = Some(if n.onset_rpm.is_some() {
                "whirl found, none before".into()
            } else {
                "whirl no longer found".into()
            });
        }
        if what.is_none() && b.whirl_intervals_rpm.len() != n.whirl_intervals_rpm.len() {
            what = Some(format!(
                "whirl intervals {} -> {}",
                b.whirl_intervals_rpm.len(),
                n.whirl_intervals_rpm.len()
            ));
        }
        if let Some(what) = what {
            changes.push(CriticalChange {
                mu: n.mu,
                baseline: bb,
                new: nb,
                what,
                in_one_run: false,
            });
        }
    }
    for b in base {
        if find(new, b.mu).is_none() {
            changes.push(CriticalChange {
                mu: b.mu,
                baseline: b.bracket_rpm,
                new: None,
                what: "searched in the baseline only".into(),
                in_one_run: true,
            });
        }
    }
    (compared, changes)
}

/// Checks a folder before it is compared: not being written, and every file it holds is its
/// run's ([`crate::folder::check_inputs`]). Returns its warnings.
fn check_folder(dir: &Path) -> Result<Vec<String>, Vec<String>> {
    if let Some(who) = crate::folder::running_writer(dir) {
        return Err(vec![format!(
            "{} is being written by a running whirlmap ({who}): compare it when that run has \
             finished",
            dir.display()
        )]);
    }
    crate::folder::check_inputs(dir, &crate::folder::reader_inputs(dir)).map(|c| c.warnings)
}

/// The differences between the specs of two folders' manifests, the name and the charts
/// aside (they change no record).
fn specs_differ(baseline: &Path, new: &Path) -> Vec<String> {
    let (Some(a), Some(b)) = (
        crate::folder::manifest_spec(baseline),
        crate::folder::manifest_spec(new),
    ) else {
        return Vec::new();
    };
    crate::folder::spec_differences(&a, &b)
        .into_iter()
        .filter(|d| !d.starts_with("name:") && !d.starts_with("charts"))
        .collect()
}

/// Compares the result folders `baseline` and `new` (each with `points.jsonl`, optionally
/// `critical.json` and `manifest.json`).
pub fn compare(baseline: &Path, new: &Path, t: Thresholds) -> Result<Comparison, CompareError> {
    let mut warnings = Vec::new();
    let mut refused = Vec::new();
    for dir in [baseline, new] {
        match check_folder(dir) {
            Ok(w) => warnings.extend(w),
            Err(p) => refused.extend(p),
        }
    }
    if !refused.is_empty() {
        return Err(CompareError::Refused(refused));
    }
    let spec_differences = specs_differ(baseline, new);
    let base_rows = load_points(baseline).map_err(LoadError::from)?;
    let new_rows = load_points(new).map_err(LoadError::from)?;
    let mut base_by: BTreeMap<String, &PointRow> = BTreeMap::new();
    for r in &base_rows {
        base_by.insert(inputs_key(r), r); // a rerun line replaces an earlier one
    }
    let mut new_by: BTreeMap<String, &PointRow> = BTreeMap::new();
    for r in &new_rows {
        new_by.insert(inputs_key(r), r);
    }
    let mut points = Vec::new();
    let mut compared = 0;
    let mut not_comparable = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for r in &new_rows {
        let key = inputs_key(r);
        if !seen.insert(key.clone()) {
            continue;
        }
        let n = new_by[&key];
        let mut what = Vec::new();
        match base_by.get(&key) {
            None => what.push("not in the baseline".to_string()),
            Some(b) if b.duration_s != n.duration_s => {
                let d = |v: Option<f64>| v.map_or("?".to_string(), |x| format!("{x} s"));
                not_comparable.push(format!(
                    "{}: simulated for {} in the baseline, {} in the new run",
                    inputs_text(n),
                    d(b.duration_s),
                    d(n.duration_s)
                ));
                continue;
            }
            Some(b) => {
                compared += 1;
                let (bc, nc) = (class_name(b), class_name(n));
                if bc != nc {
                    what.push(format!("class {bc} -> {nc}"));
                }
                what.extend(rel_change(
                    "max force",
                    "N",
                    b.max_contact_force_n,
                    n.max_contact_force_n,
                    t.force_rel,
                ));
                what.extend(rel_change(
                    "peak heat power",
                    "W",
                    b.peak_heat_power_w,
                    n.peak_heat_power_w,
                    t.power_rel,
                ));
            }
        }
        if !what.is_empty() {
            points.push(PointChange {
                inputs: inputs_text(n),
                what,
                new_row: Some(n.clone()),
                in_one_run: !base_by.contains_key(&key),
            });
        }
    }
    for (key, b) in &base_by {
        if !new_by.contains_key(key) {
            points.push(PointChange {
                inputs: inputs_text(b),
                what: vec!["not in the new run".to_string()],
                new_row: None,
                in_one_run: true,
            });
        }
    }
    if compared == 0 {
        let mut why = vec![format!(
            "nothing to compare: no grid point of {} is in {} with the same inputs and \
             duration ({} and {} points read)",
            new.display(),
            baseline.display(),
            new_rows.len(),
            base_rows.len()
        )];
        if !spec_differences.is_empty() {
            why.push(format!("the specs differ: {}", spec_differences.join("; ")));
        }
        why.extend(not_comparable.iter().take(3).cloned());
        return Err(CompareError::Refused(why));
    }
    let points_not_comparable = not_comparable.len();
    let (critical_compared, critical) = match (
        read_critical(baseline).map_err(LoadError::from)?,
        read_critical(new).map_err(LoadError::from)?,
    ) {
        (None, None) => (0, Vec::new()),
        (b, n) => {
            // Searches with other drop durations are other experiments.
            let (b, n) = (b.unwrap_or_default(), n.unwrap_or_default());
            let same = |r: &CriticalRow, other: &[CriticalRow]| {
                other
                    .iter()
                    .all(|o| (o.mu - r.mu).abs() > 1e-12 || o.duration_s == r.duration_s)
            };
            let b2: Vec<CriticalRow> = b.iter().filter(|r| same(r, &n)).cloned().collect();
            let n2: Vec<CriticalRow> = n.iter().filter(|r| same(r, &b)).cloned().collect();
            for r in n.iter().filter(|r| !same(r, &b)) {
                not_comparable.push(format!(
                    "critical speed at mu = {}: searched with drops of another duration",
                    r.mu
                ));
            }
            compare_critical(&b2, &n2)
        }
    };
    Ok(Comparison {
        baseline: baseline.to_path_buf(),
        new: new.to_path_buf(),
        thresholds: t,
        points_compared: compared,
        points,
        critical_compared,
        critical,
        runs: [run_info(baseline), run_info(new)],
        spec_differences,
        not_comparable,
        points_not_comparable,
        warnings,
        new_rows,
    })
}

/// The class map beside a report: the new run's grid with the changed cells marked, for the
/// caller of [`write_report`] to draw.
#[derive(Debug, Clone, Copy)]
pub struct ClassMap<'a> {
    /// The image to write (`<stem>-classes.png` beside the report).
    pub path: &'a Path,
    /// The new run's points over speed and friction.
    pub grid: &'a Grid,
    /// The chart's title.
    pub title: &'a str,
    /// The changed cells, as (speed index, friction index) into the grid's axes.
    pub marked: &'a [(usize, usize)],
}

/// Why a report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The report's folder or the report could not be written.
    #[error("cannot create {}: {cause}", path.display())]
    Write {
        /// The folder or file.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// The class map could not be drawn, in the drawing's words.
    #[error("{0}")]
    Draw(String),
    /// The report or its class map would replace a folder or another run's file.
    #[error("{0}")]
    Refused(String),
}

/// The class map's path beside the report at `path`: `<stem>-classes.png`.
fn class_map_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or("compare".into(), |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}-classes.png"))
}

/// Refuses a report path (checked before anything is compared or written) whose report or
/// class map would be a folder, or would replace a file a whirlmap run wrote in a results
/// folder (`--out RUN/points.jsonl`): only the comparison's own two names may be replaced
/// there.
pub fn check_report_path(path: &Path) -> Result<(), ReportError> {
    let own = [
        whirlmap_results::files::COMPARE_REPORT_FILE,
        whirlmap_results::files::COMPARE_CLASSES_FILE,
    ];
    for p in [path.to_path_buf(), class_map_path(path)] {
        if p.is_dir() {
            return Err(ReportError::Refused(format!(
                "the report would replace the folder {}: give --out a file name (e.g. {})",
                p.display(),
                p.join(own[0]).display()
            )));
        }
        let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty());
        if let (Some(name), Some(dir)) = (name, dir) {
            let theirs =
                crate::folder::OWNED.contains(&name.as_str()) && !own.contains(&name.as_str());
            let results = [
                whirlmap_results::files::MANIFEST_FILE,
                whirlmap_results::files::POINTS_FILE,
            ]
            .iter()
            .any(|f| dir.join(f).exists());
            if theirs && results {
                return Err(ReportError::Refused(format!(
                    "the report would replace {}, a file of the results folder {}: name another \
                     report (e.g. {})",
                    p.display(),
                    dir.display(),
                    dir.join(own[0]).display()
                )));
            }
        }
    }
    Ok(())
}

/// Writes the Markdown report to `path` and, with `draw_class_map`, the class map of the new
/// run with the changed cells outlined beside it (`<stem>-classes.png`), before the report.
/// Returns the image's path.
pub fn write_report(
    c: &Comparison,
    path: &Path,
    draw_class_map: &dyn Fn(&ClassMap) -> Result<(), String>,
) -> Result<PathBuf, ReportError> {
    let write_err = |path: &Path| {
        let path = path.to_path_buf();
        move |cause| ReportError::Write { path, cause }
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(write_err(dir))?;
    }
    check_report_path(path)?;
    let png = class_map_path(path);
    let grid = assemble_grid(&c.new_rows);
    let mut marked = Vec::new();
    for (j, _) in grid.mus.iter().enumerate() {
        for (i, _) in grid.speeds_rpm.iter().enumerate() {
            if let Some(cell) = grid.cell(i, j) {
                let key = inputs_key(cell);
                if c.points
                    .iter()
                    .any(|p| p.new_row.as_ref().is_some_and(|r| inputs_key(r) == key))
                {
                    marked.push((i, j));
                }
            }
        }
    }
    draw_class_map(&ClassMap {
        path: &png,
        grid: &grid,
        title: "Orbit class of the new run; changed cells outlined",
        marked: &marked,
    })
    .map_err(ReportError::Draw)?;

    let t = &c.thresholds;
    let mut md = String::new();
    let _ = writeln!(md, "# whirlmap compare\n");
    let _ = writeln!(
        md,
        "**{}**: {}{}.\n",
        if c.changed() { "CHANGED" } else { "SAME" },
        c.counts()
            .replacen(" changed", " changed beyond the thresholds", 1),
        if c.spec_differences.is_empty() {
            ""
        } else {
            " (the specs differ: see below)"
        }
    );
    for w in &c.warnings {
        let _ = writeln!(md, "**Warning**: {w}\n");
    }
    if !c.spec_differences.is_empty() {
        let _ = writeln!(md, "## The specs differ\n");
        for d in &c.spec_differences {
            let _ = writeln!(md, "- `{d}`");
        }
        let _ = writeln!(md);
    }
    if !c.not_comparable.is_empty() {
        let _ = writeln!(md, "## Not comparable\n");
        for d in &c.not_comparable {
            let _ = writeln!(md, "- {d}");
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "| | baseline | new |\n|---|---|---|");
    let _ = writeln!(
        md,
        "| folder | `{}` | `{}` |",
        c.baseline.display(),
        c.new.display()
    );
    let [b, n] = &c.runs;
    let _ = writeln!(md, "| sweep | {} | {} |", b.name, n.name);
    let _ = writeln!(
        md,
        "| model version | {} | {} |",
        b.model_version, n.model_version
    );
    let _ = writeln!(md, "| spec hash | {} | {} |", b.spec_hash, n.spec_hash);
    let _ = writeln!(md, "| git commit | {} | {} |\n", b.git_commit, n.git_commit);
    let _ = writeln!(
        md,
        "Thresholds: maximum contact force {} %, peak heat power {} % (relative to the \
         baseline); a critical speed has moved when the two brackets do not overlap.\n",
        100.0 * t.force_rel,
        100.0 * t.power_rel
    );
    let _ = writeln!(md, "## Points\n");
    if c.points.is_empty() {
        let _ = writeln!(md, "No point changed.\n");
    } else {
        let _ = writeln!(md, "| point | change |\n|---|---|");
        for p in &c.points {
            let _ = writeln!(md, "| {} | {} |", p.inputs, p.what.join("; "));
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "## Critical speeds\n");
    if c.critical.is_empty() {
        let _ = writeln!(
            md,
            "{}\n",
            if c.critical_compared == 0 {
                "No critical-speed search to compare."
            } else {
                "No critical speed moved beyond its brackets, and every friction coefficient has as many whirl intervals as before."
            }
        );
    } else {
        let _ = writeln!(md, "| mu | baseline | new | change |\n|---|---|---|---|");
        for k in &c.critical {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} |",
                k.mu,
                fmt_bracket(k.baseline),
                fmt_bracket(k.new),
                k.what
            );
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(
        md,
        "## Class map\n\n![class map, changed cells outlined]({})",
        png.file_name().unwrap_or_default().to_string_lossy()
    );
    std::fs::write(path, md).map_err(write_err(path))?;
    Ok(png)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_changes_respect_the_threshold() {
        assert_eq!(rel_change("f", "N", Some(100.0), Some(104.9), 0.05), None);
        assert!(rel_change("f", "N", Some(100.0), Some(105.1), 0.05)
            .unwrap()
            .contains("+5.1 %"));
        assert!(rel_change("f", "N", Some(100.0), Some(94.0), 0.05).is_some());
        assert!(rel_change("f", "N", Some(0.0), Some(1.0), 0.05).is_some());
        assert_eq!(rel_change("f", "N", Some(0.0), Some(0.0), 0.0), None);
        assert!(rel_change("f", "N", Some(1.0), None, 0.05).is_some());
    }

    fn entry(mu: f64, bracket: Option<[f64; 2]>) -> CriticalRow {
        crate::critical::SearchResult {
            onset_rpm: bracket.map(|b| b[1]),
            bracket_rpm: bracket,
            class_below: None,
            class_above: None,
            whirl_intervals_rpm: bracket.map(|b| vec![[b[1], 30000.0]]).unwrap_or_default(),
            whirl_at_range_top: bracket.is_some(),
            converged: true,
            undecided: false,
            scan: Vec::new(),
            bisections: Vec::new(),
            note: String::new(),
        }
        .into_row(mu, &Default::default(), String::new())
    }

    #[test]
    fn critical_speeds_move_only_when_brackets_are_disjoint() {
        let base = [entry(0.3, Some([4000.0, 4500.0])), entry(0.4, None)];
        // Overlapping: the same.
        let (n, ch) = compare_critical(
            &base,
            &[entry(0.3, Some([4400.0, 4900.0])), entry(0.4, None)],
        );
        assert_eq!((n, ch.len()), (2, 0));
        // Touching ends overlap too.
        let (_, ch) = compare_critical(
            &base,
            &[entry(0.3, Some([4500.0, 4900.0])), entry(0.4, None)],
        );
        assert!(ch.is_empty());
        // Disjoint: moved up; a new transition: changed.
        let (_, ch) = compare_critical(
            &base,
            &[
                entry(0.3, Some([4600.0, 5000.0])),
                entry(0.4, Some([3000.0, 3500.0])),
            ],
        );
        assert_eq!(ch.len(), 2);
        assert!(ch[0].what.contains("moved up"), "{:?}", ch[0]);
        assert!(ch[1].what.contains("whirl found"), "{:?}", ch[1]);
        assert!(ch[1].what.contains("found"), "{:?}", ch[1]);
        // A mu searched only in one run.
        let (n, ch) = compare_critical(&base, &[entry(0.3, Some([4000.0, 4500.0]))]);
        assert_eq!((n, ch.len()), (1, 1));
        assert!(ch[0].what.contains("baseline only"));
    }
}
