//! Adaptive refinement of the whirl boundary over (speed, mu): instead of every point of a
//! fine grid, a coarse seed grid whose cells are split where the boundary runs.
//!
//! ## Algorithm ([`refine`], generic over the evaluation)
//! The fine grid (the `speed_rpm` and `mu` axes of the file) fixes the smallest cell. Seed
//! points are spread evenly over its indices. Each evaluated point's value (P(whirl), or 0/1
//! for single drops) falls in a bin, "safe" (<= the lower bound), "whirl" (>= the upper
//! bound) or "uncertain" (between). A cell is split unless every evaluated point in it
//! (closed: its corners, and points on its edges or inside that finer neighbouring cells
//! have evaluated) shares the safe or the whirl bin. Splitting is at the integer midpoints
//! of its index ranges (only along ranges wider than one fine step), so every corner is a
//! fine-grid point. Every cell is checked again each round, so a feature narrower than a
//! cell (a tongue of non-whirl between whirl regions), once a neighbour's refinement has
//! found a point of it on the cell's edge, splits the cell and is followed along. Rounds
//! continue until no cell splits; a 1 x 1 cell that disagrees is a boundary cell. Every
//! round's new corners are evaluated as one batch in index order and cached, so no corner
//! is evaluated twice and the order (and the result) is deterministic. Failed evaluations
//! (NaN) count as uncertain.
//!
//! Every fine point not evaluated lies in a leaf whose known points agree, and takes its
//! corners' value ([`Refinement::inferred`]). The remaining blind spot: a feature that
//! touches no refined cell (an island inside a seed cell whose corners agree, or a tongue
//! that enters and leaves such a cell through one edge) is not seen. The seed grid must be
//! fine enough for those.
//!
//! ## Use
//! `whirlmap adaptive FILE [--compare-full] [--resume]`: the file is an ensemble file
//! ([`crate::ensemble`]) with exactly the axes `speed_rpm` and `mu` and an `adaptive`
//! section ([`AdaptiveParams`]); with an `ensemble` section each corner is an ensemble and
//! its value P(whirl), else one drop (whirl 1, else 0). `--compare-full` also evaluates
//! every fine point (reusing the corners already run: same inputs, same result) and reports
//! how far the boundaries lie apart. `--resume` continues a search killed in its folder,
//! reusing the corners it logged ([`crate::adaptive_log`]).

use crate::ensemble::{self, first_crossing, Cell, EnsembleSpec};
use crate::spec::{check_output_dir, SpecError};
use crate::sweep::{run_case, SweepError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;
pub use whirlmap_results::adaptive::{
    AdaptiveReport, Agreement, BoundaryPoint, Comparison, Corner,
};

pub use whirlmap_results::files::ADAPTIVE_FILE;

fn default_bounds() -> [f64; 2] {
    [0.1, 0.9]
}

/// The `adaptive` section of an ensemble file.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveParams {
    /// Seed grid points along the speed axis, [2, points of the axis].
    pub seed_speed_points: usize,
    /// Seed grid points along the mu axis, [2, points of the axis].
    pub seed_mu_points: usize,
    /// P(whirl) at or below the first is safe, at or above the second whirl; between is
    /// uncertain (always refined). Default [0.1, 0.9]; 0 < lower <= upper < 1. Single drops
    /// give 0 or 1, so then only disagreeing corners refine.
    #[serde(default = "default_bounds")]
    pub p_bounds: [f64; 2],
}

impl AdaptiveParams {
    /// Checks the section against the file's axes (exactly `speed_rpm` and `mu`).
    pub fn validate(&self, spec: &EnsembleSpec) -> Result<(), SpecError> {
        let bad = |field: &str, value: String, allowed: String| {
            Err(SpecError::Invalid {
                field: field.into(),
                value,
                allowed,
            })
        };
        let names: Vec<&str> = spec.axes.0.iter().map(|a| a.name.as_str()).collect();
        if names.len() != 2 || !names.contains(&"speed_rpm") || !names.contains(&"mu") {
            return bad(
                "axes",
                names.join(", "),
                "exactly speed_rpm and mu for an adaptive search".into(),
            );
        }
        let (speeds, mus) = fine_axes(spec);
        for (field, axis, n, len) in [
            (
                "adaptive.seed_speed_points",
                "axes.speed_rpm",
                self.seed_speed_points,
                speeds.len(),
            ),
            (
                "adaptive.seed_mu_points",
                "axes.mu",
                self.seed_mu_points,
                mus.len(),
            ),
        ] {
            if len < 2 {
                return bad(
                    axis,
                    format!("{len} point{}", if len == 1 { "" } else { "s" }),
                    "at least 2 points for an adaptive search (its seed grid has 2 or more)".into(),
                );
            }
            // Cells are between neighbouring values: the values must be in order.
            let values = if axis == "axes.speed_rpm" {
                &speeds
            } else {
                &mus
            };
            if values.windows(2).any(|w| !(w[0] < w[1])) {
                return bad(
                    axis,
                    format!("{values:?}"),
                    "values in ascending order for an adaptive search (a cell lies between \
                     neighbouring values)"
                        .into(),
                );
            }
            if n < 2 || n > len {
                return bad(
                    field,
                    n.to_string(),
                    format!("[2, {len}] (the axis's points)"),
                );
            }
        }
        let [lo, hi] = self.p_bounds;
        if !(lo > 0.0 && lo <= hi && hi < 1.0) {
            return bad(
                "adaptive.p_bounds",
                format!("[{lo}, {hi}]"),
                "0 < lower <= upper < 1".into(),
            );
        }
        Ok(())
    }
}

/// The fine speed and mu values of an adaptive file (axis values in file order).
fn fine_axes(spec: &EnsembleSpec) -> (Vec<f64>, Vec<f64>) {
    let get = |n: &str| {
        spec.axes
            .0
            .iter()
            .find(|a| a.name == n)
            .map(|a| a.values.values())
            .unwrap_or_default()
    };
    (get("speed_rpm"), get("mu"))
}

/// A final cell of the refinement: fine-grid index ranges (inclusive) along speed (`i`) and
/// mu (`j`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Leaf {
    /// First speed index.
    pub i0: usize,
    /// Last speed index.
    pub i1: usize,
    /// First mu index.
    pub j0: usize,
    /// Last mu index.
    pub j1: usize,
    /// Its corners disagree (a refined cell of the smallest size).
    pub boundary: bool,
}

impl Leaf {
    fn corners(&self) -> [(usize, usize); 4] {
        [
            (self.i0, self.j0),
            (self.i1, self.j0),
            (self.i0, self.j1),
            (self.i1, self.j1),
        ]
    }
    fn contains(&self, i: usize, j: usize) -> bool {
        (self.i0..=self.i1).contains(&i) && (self.j0..=self.j1).contains(&j)
    }
}

/// The result of [`refine`].
#[derive(Debug, Clone, PartialEq)]
pub struct Refinement {
    /// Fine grid points along speed and mu.
    pub shape: (usize, usize),
    /// Every evaluated point: (speed index, mu index) -> value.
    pub values: BTreeMap<(usize, usize), f64>,
    /// The final cells.
    pub leaves: Vec<Leaf>,
    /// Refinement rounds after the seed grid.
    pub rounds: usize,
}

/// `n` indices spread evenly over `0..len` (both ends included), without repeats.
fn spread(len: usize, n: usize) -> Vec<usize> {
    let n = n.clamp(2, len.max(2));
    let mut v: Vec<usize> = (0..n)
        .map(|k| ((k * (len - 1)) as f64 / (n - 1) as f64).round() as usize)
        .collect();
    v.dedup();
    v
}

/// 0 safe, 1 uncertain (or failed), 2 whirl.
fn bin(v: f64, [lo, hi]: [f64; 2]) -> u8 {
    if v <= lo {
        0
    } else if v >= hi {
        2
    } else {
        1 // also NaN
    }
}

/// A cell disagrees unless every evaluated point in it (corners, and any point on its edges
/// or inside that a neighbouring, finer cell has evaluated) is safe, or every one is whirl.
/// The points beyond the corners let a feature narrower than the cell (a tongue of the
/// other class) be followed from where a neighbour's refinement has found it.
fn disagrees(c: &Leaf, values: &BTreeMap<(usize, usize), f64>, bounds: [f64; 2]) -> bool {
    let first = bin(values[&(c.i0, c.j0)], bounds);
    if first == 1 {
        return true;
    }
    (c.i0..=c.i1).any(|i| {
        values
            .range((i, c.j0)..=(i, c.j1))
            .any(|(_, v)| bin(*v, bounds) != first)
    })
}

/// The halves (or quarters) of a cell, split at the integer midpoints of the index ranges
/// wider than one fine step.
fn split(c: &Leaf) -> Vec<Leaf> {
    let halves = |a: usize, b: usize| {
        if b - a > 1 {
            vec![(a, (a + b) / 2), ((a + b) / 2, b)]
        } else {
            vec![(a, b)]
        }
    };
    let mut out = Vec::with_capacity(4);
    for (i0, i1) in halves(c.i0, c.i1) {
        for (j0, j1) in halves(c.j0, c.j1) {
            out.push(Leaf {
                i0,
                i1,
                j0,
                j1,
                boundary: false,
            });
        }
    }
    out
}

/// Evaluates a batch of fine points (speed index, mu index), in index order, to one value
/// each in the same order.
pub type BatchEval<'a> = dyn FnMut(&[(usize, usize)]) -> Vec<f64> + 'a;

/// Refines the fine grid of `shape` (points along speed, mu; each >= 2) from a seed grid of
/// `seed` points, evaluating corners with `eval` (a batch of (i, j) in index order -> one
/// value each, in the same order). See the module doc.
pub fn refine(
    shape: (usize, usize),
    seed: (usize, usize),
    bounds: [f64; 2],
    eval: &mut BatchEval<'_>,
) -> Refinement {
    let (nx, ny) = shape;
    let mut values: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    let mut evaluate = |cells: &[Leaf], values: &mut BTreeMap<(usize, usize), f64>| {
        let mut todo: Vec<(usize, usize)> = cells
            .iter()
            .flat_map(|c| c.corners())
            .filter(|p| !values.contains_key(p))
            .collect();
        todo.sort_unstable();
        todo.dedup();
        if !todo.is_empty() {
            let got = eval(&todo);
            for (p, v) in todo.into_iter().zip(got) {
                values.insert(p, v);
            }
        }
    };
    let xs = spread(nx, seed.0);
    let ys = spread(ny, seed.1);
    let mut cells: Vec<Leaf> = xs
        .windows(2)
        .flat_map(|x| {
            ys.windows(2).map(move |y| Leaf {
                i0: x[0],
                i1: x[1],
                j0: y[0],
                j1: y[1],
                boundary: false,
            })
        })
        .collect();
    evaluate(&cells, &mut values);
    // `cells` is the current partition. Each round splits every cell that disagrees (see
    // `disagrees`), in place; cells kept in one round are checked again in the next, as
    // points evaluated around them may now lie on their edges.
    let mut rounds = 0;
    loop {
        let mut next = Vec::with_capacity(cells.len());
        let mut split_any = false;
        for c in &cells {
            let splittable = c.i1 - c.i0 > 1 || c.j1 - c.j0 > 1;
            if !splittable || !disagrees(c, &values, bounds) {
                next.push(*c);
                continue;
            }
            split_any = true;
            next.extend(split(c));
        }
        if !split_any {
            break;
        }
        rounds += 1;
        evaluate(&next, &mut values);
        cells = next;
    }
    let mut leaves: Vec<Leaf> = cells
        .into_iter()
        .map(|c| Leaf {
            boundary: c.i1 - c.i0 <= 1 && c.j1 - c.j0 <= 1 && disagrees(&c, &values, bounds),
            ..c
        })
        .collect();
    leaves.sort_by_key(|l| (l.i0, l.j0, l.i1, l.j1));
    Refinement {
        shape,
        values,
        leaves,
        rounds,
    }
}

impl Refinement {
    /// The value at every fine point, row-major `[i * ny + j]`: evaluated, or the mean of the
    /// corners of the first leaf (in index order) that holds it.
    pub fn inferred(&self) -> Vec<f64> {
        let (nx, ny) = self.shape;
        let mut out = vec![f64::NAN; nx * ny];
        for i in 0..nx {
            for j in 0..ny {
                out[i * ny + j] = match self.values.get(&(i, j)) {
                    Some(v) => *v,
                    None => self
                        .leaves
                        .iter()
                        .find(|l| l.contains(i, j))
                        .map(|l| l.corners().iter().map(|p| self.values[p]).sum::<f64>() / 4.0)
                        .unwrap_or(f64::NAN),
                };
            }
        }
        out
    }
}

/// The boundary of a row-major map `[i * ny + j]` at `level`: for each mu index `j`, the
/// first speed (as a fractional speed index) where the value reaches `level`, linear between
/// points; `None` if it never does or already does at index 0.
pub fn boundary(map: &[f64], shape: (usize, usize), level: f64) -> Vec<Option<f64>> {
    let (nx, ny) = shape;
    let idx: Vec<f64> = (0..nx).map(|i| i as f64).collect();
    (0..ny)
        .map(|j| {
            let col: Vec<f64> = (0..nx).map(|i| map[i * ny + j]).collect();
            first_crossing(&idx, &col, level).ok()
        })
        .collect()
}

/// Compares an inferred map with the full one at `level` (and `bounds` for the bins).
pub fn agreement(
    inferred: &[f64],
    full: &[f64],
    shape: (usize, usize),
    level: f64,
    bounds: [f64; 2],
) -> Agreement {
    let a = boundary(inferred, shape, level);
    let b = boundary(full, shape, level);
    let mut max_shift: f64 = 0.0;
    let mut columns_differing = 0;
    for (x, y) in a.iter().zip(&b) {
        match (x, y) {
            (Some(x), Some(y)) => max_shift = max_shift.max((x - y).abs()),
            (None, None) => {}
            _ => columns_differing += 1,
        }
    }
    let points_differing = inferred
        .iter()
        .zip(full)
        .filter(|(x, y)| bin(**x, bounds) != bin(**y, bounds))
        .count();
    Agreement {
        max_shift_cells: max_shift,
        columns_differing,
        points_differing,
    }
}

/// Evaluates fine points: one drop each (whirl 1, not 0, failed NaN), or an ensemble each
/// (P(whirl)); parallel, results in input order.
fn evaluate_points(spec: &EnsembleSpec, cells: &[&Cell]) -> Vec<f64> {
    match &spec.ensemble {
        None => cells
            .par_iter()
            .map(|c| {
                let point = crate::spec::Point {
                    index: c.index,
                    inputs: c.inputs.0.clone(),
                    scene: c.scene.clone(),
                };
                match run_case(&point, spec.duration_s).record {
                    Some(r) if r.class.is_whirl() => 1.0,
                    Some(_) => 0.0,
                    None => f64::NAN,
                }
            })
            .collect(),
        Some(params) => {
            let owned: Vec<Cell> = cells.iter().map(|c| (*c).clone()).collect();
            let members = ensemble::run_members(params, &owned, spec.duration_s, &|_, _| {});
            members
                .chunks(params.members)
                .zip(&owned)
                .map(|(ms, c)| ensemble::cell_stats(c.index, &c.inputs, ms, 1.96).p_whirl)
                .collect()
        }
    }
}

/// Runs the adaptive search of `spec` (and, with `compare_full`, the full grid) and writes
/// `adaptive.json` to `out_dir`. Every evaluated corner is logged while the search runs
/// ([`crate::adaptive_log`]); with `resume`, the corners a killed run of the same spec and
/// build logged there are not evaluated again. The log is removed once `adaptive.json` is
/// written.
pub fn run_adaptive(
    spec: &EnsembleSpec,
    out_dir: &Path,
    threads: Option<usize>,
    compare_full: bool,
    show_progress: bool,
    resume: bool,
) -> Result<(AdaptiveReport, PathBuf), SweepError> {
    let cells = spec.cells()?;
    let params = spec.adaptive.clone().ok_or_else(|| SpecError::Invalid {
        field: "adaptive".into(),
        value: "(missing)".into(),
        allowed: "an adaptive section".into(),
    })?;
    check_output_dir(out_dir)?;
    let pool = crate::pool::pool(threads).map_err(|e| SweepError::ThreadPool(e.to_string()))?;
    let (speeds, mus) = fine_axes(spec);
    let shape = (speeds.len(), mus.len());
    let speed_first = spec.axes.0[0].name == "speed_rpm";
    let cell_at = |(i, j): (usize, usize)| {
        let k = if speed_first {
            i * shape.1 + j
        } else {
            j * shape.0 + i
        };
        &cells[k]
    };
    let mut log = crate::adaptive_log::CornerLog::open(out_dir, spec, shape, resume)?;
    if log.known_len() > 0 {
        crate::sweep::progress_line(&format!(
            "adaptive {}: {} corners kept from the killed run's {}",
            spec.name,
            log.known_len(),
            whirlmap_results::files::ADAPTIVE_CORNERS_FILE
        ));
    }
    // The first failed append: the search goes on, and the run reports it at the end.
    let mut log_error = None;
    let start = Instant::now();
    let mut done = 0usize;
    let mut eval = |pts: &[(usize, usize)]| {
        // The corners the log knows keep their values; the others are evaluated and logged.
        let mut values: Vec<Option<f64>> = pts.iter().map(|p| log.known(*p)).collect();
        let todo: Vec<usize> = (0..pts.len()).filter(|&k| values[k].is_none()).collect();
        // In chunks of a few corners per thread, each logged as it is done, so a kill loses
        // one chunk rather than a whole round (or the whole comparison with the full grid).
        // Each corner's value is its own: the chunking changes no value.
        let chunk = 4 * pool.current_num_threads();
        for part in todo.chunks(chunk) {
            let batch: Vec<&Cell> = part.iter().map(|&k| cell_at(pts[k])).collect();
            let fresh = pool.install(|| evaluate_points(spec, &batch));
            let done: Vec<((usize, usize), f64)> = part
                .iter()
                .map(|&k| pts[k])
                .zip(fresh.iter().copied())
                .collect();
            if let Err(e) = log.record(&done) {
                log_error.get_or_insert(e);
            }
            for (&k, p) in part.iter().zip(fresh) {
                values[k] = Some(p);
            }
        }
        let v: Vec<f64> = values
            .into_iter()
            .map(|p| p.expect("every corner known or evaluated"))
            .collect();
        done += pts.len();
        if show_progress {
            crate::sweep::progress_line(&format!(
                "adaptive {}: {done} corners evaluated, {:.0} s",
                spec.name,
                start.elapsed().as_secs_f64()
            ));
        }
        v
    };
    let r = refine(
        shape,
        (params.seed_speed_points, params.seed_mu_points),
        params.p_bounds,
        &mut eval,
    );
    let per_corner = spec.ensemble.as_ref().map_or(1, |e| e.members);
    let inferred = r.inferred();
    let adaptive_b = boundary(&inferred, shape, 0.5);
    let at_speed = |x: Option<f64>| {
        x.map(|f| {
            let i = (f.floor() as usize).min(shape.0 - 2);
            speeds[i] + (f - i as f64) * (speeds[i + 1] - speeds[i])
        })
    };
    let mut full_b = None;
    let comparison = if compare_full {
        let mut all = r.values.clone();
        let missing: Vec<(usize, usize)> = (0..shape.0)
            .flat_map(|i| (0..shape.1).map(move |j| (i, j)))
            .filter(|p| !all.contains_key(p))
            .collect();
        for (p, v) in missing.iter().zip(eval(&missing)) {
            all.insert(*p, v);
        }
        let full: Vec<f64> = all.values().copied().collect(); // BTreeMap: (i, j) order
        full_b = Some(boundary(&full, shape, 0.5));
        Some(Comparison {
            full_grid_drops: shape.0 * shape.1 * per_corner,
            agreement: agreement(&inferred, &full, shape, 0.5, params.p_bounds),
        })
    } else {
        None
    };
    let full_grid_drops = shape.0 * shape.1 * per_corner;
    let drops_used = r.values.len() * per_corner;
    let report = AdaptiveReport {
        name: spec.name.clone(),
        fine_points: shape,
        seed_points: (params.seed_speed_points, params.seed_mu_points),
        p_bounds: params.p_bounds,
        drops_per_corner: per_corner,
        rounds: r.rounds,
        corners: r.values.len(),
        drops_used,
        full_grid_drops,
        drops_ratio: drops_used as f64 / full_grid_drops as f64,
        boundary_cells: r.leaves.iter().filter(|l| l.boundary).count(),
        boundary: mus
            .iter()
            .enumerate()
            .map(|(j, &mu)| BoundaryPoint {
                mu,
                speed_rpm: at_speed(adaptive_b[j]),
                full_speed_rpm: full_b.as_ref().map(|b: &Vec<Option<f64>>| at_speed(b[j])),
            })
            .collect(),
        comparison,
        evaluated: r
            .values
            .iter()
            .map(|(&(i, j), &p)| Corner {
                speed_rpm: speeds[i],
                mu: mus[j],
                p_whirl: p,
            })
            .collect(),
    };
    let path = out_dir.join(ADAPTIVE_FILE);
    crate::folder::write_atomic(&path, report.to_text().as_bytes())?;
    // A failed append or removal loses only what a resume could have kept: the search is
    // complete and written.
    if let Some(e) = log_error {
        crate::sweep::progress_line(&format!("warning: the corner log: {e}"));
    }
    if let Err(e) = log.remove() {
        crate::sweep::progress_line(&format!("warning: the corner log: {e}"));
    }
    Ok((report, path))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evaluates a synthetic map and counts the evaluations (each point at most once).
    fn run(
        shape: (usize, usize),
        seed: (usize, usize),
        f: &dyn Fn(usize, usize) -> f64,
    ) -> (Refinement, Vec<f64>, usize) {
        let mut seen = std::collections::BTreeSet::new();
        let mut count = 0;
        let r = refine(shape, seed, [0.1, 0.9], &mut |pts| {
            count += pts.len();
            for p in pts {
                assert!(seen.insert(*p), "{p:?} evaluated twice");
            }
            pts.iter().map(|&(i, j)| f(i, j)).collect()
        });
        let full: Vec<f64> = (0..shape.0)
            .flat_map(|i| (0..shape.1).map(move |j| (i, j)))
            .map(|(i, j)| f(i, j))
            .collect();
        assert_eq!(count, r.values.len());
        (r, full, count)
    }

    #[test]
    fn seed_points_spread_over_the_axis() {
        assert_eq!(spread(64, 9), vec![0, 8, 16, 24, 32, 39, 47, 55, 63]);
        assert_eq!(spread(5, 5), vec![0, 1, 2, 3, 4]);
        assert_eq!(spread(3, 2), vec![0, 2]);
    }

    #[test]
    fn uniform_maps_stop_at_the_seed_grid() {
        let (r, _, n) = run((64, 64), (9, 9), &|_, _| 0.0);
        assert_eq!(n, 81);
        assert_eq!(r.rounds, 0);
        assert!(r.inferred().iter().all(|v| *v == 0.0));
    }

    /// The synthetic benchmark: on a 64 x 64 map with a known boundary, the adaptive search
    /// must find the full grid's boundary to within one fine cell in every column, with at
    /// most 25 % of the full grid's 4096 evaluations (the target). The counts are
    /// printed (`cargo test -p whirlmap-sweep adaptive -- --nocapture`).
    fn check_against_full(name: &str, f: &dyn Fn(usize, usize) -> f64) -> usize {
        let shape = (64, 64);
        let (r, full, count) = run(shape, (9, 9), f);
        let a = agreement(&r.inferred(), &full, shape, 0.5, [0.1, 0.9]);
        println!(
            "{name}: {count} of 4096 evaluations ({:.1} %), {} rounds, {a:?}",
            100.0 * count as f64 / 4096.0,
            r.rounds
        );
        assert!(
            boundary(&full, shape, 0.5).iter().all(Option::is_some),
            "{name}: a boundary in every column"
        );
        assert!(a.max_shift_cells <= 1.0, "{name}: {a:?}");
        assert_eq!(a.columns_differing, 0, "{name}: {a:?}");
        assert!(count * 4 <= 4096, "{name}: {count} evaluations");
        count
    }

    #[test]
    fn finds_a_straight_boundary_with_a_quarter_of_the_drops() {
        // Critical speed index falling linearly with mu, as Fig. 4's trend.
        let n = check_against_full("line", &|i, j| {
            f64::from(u8::from(i as f64 >= 50.0 - 0.5 * j as f64))
        });
        assert!(n > 81, "the boundary was refined");
    }

    #[test]
    fn finds_a_curved_boundary_with_a_quarter_of_the_drops() {
        // A hyperbola-like critical speed, steep at low mu and flat at high mu.
        check_against_full("curve", &|i, j| {
            f64::from(u8::from(i as f64 >= 4.0 + 1700.0 / (j as f64 + 30.0)))
        });
    }

    #[test]
    fn follows_a_tongue_narrower_than_a_seed_cell() {
        // The paper scene's feature: a strip of non-whirl four columns wide (j 33-36, inside
        // the seed cell j 32-39) across every speed, between whirl regions. Its corners
        // alone never see it above the boundary; the points found on its edge where the
        // boundary crosses it do, and the strip is followed to the top speed.
        let f = |i: usize, j: usize| {
            let strip = (33..=36).contains(&j);
            f64::from(u8::from(!strip && i as f64 >= 50.0 - 0.5 * j as f64))
        };
        let shape = (64, 64);
        let (r, full, count) = run(shape, (9, 9), &f);
        let a = agreement(&r.inferred(), &full, shape, 0.5, [0.1, 0.9]);
        println!("tongue: {count} of 4096 evaluations, {a:?}");
        assert_eq!(a.columns_differing, 0, "{a:?}");
        assert_eq!(a.points_differing, 0, "{a:?}");
        assert!(count * 4 <= 4096, "{count} evaluations");
    }

    #[test]
    fn probability_maps_refine_the_uncertain_band_too() {
        // A logistic P(whirl) with a band about 8 cells wide between 10 % and 90 %: its
        // 50 % line is found to within a cell. The band is evaluated point by point, so the
        // count is larger than for a sharp boundary; it is printed, not bounded here.
        let shape = (64, 64);
        let p = |i: usize, j: usize| {
            let c = 45.0 - 0.3 * j as f64;
            1.0 / (1.0 + (-(i as f64 - c) / 2.0).exp())
        };
        let (r, full, count) = run(shape, (9, 9), &p);
        let a = agreement(&r.inferred(), &full, shape, 0.5, [0.1, 0.9]);
        println!("logistic: {count} of 4096 evaluations, {a:?}");
        assert!(
            a.max_shift_cells <= 1.0 && a.columns_differing == 0,
            "{a:?}"
        );
        // Every uncertain point of the full map was evaluated.
        for (k, v) in full.iter().enumerate() {
            if bin(*v, [0.1, 0.9]) == 1 {
                assert!(
                    r.values.contains_key(&(k / 64, k % 64)),
                    "uncertain point {k} skipped"
                );
            }
        }
    }
}
