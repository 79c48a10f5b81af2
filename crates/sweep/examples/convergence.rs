//! Evidence of convergence: the main job's results at the `standard` fidelity against the same
//! job at `reference` (DOPRI5 at rtol 1e-9).
//!
//! ```text
//! whirlmap sweep sweeps/paper.json                 # results/paper (standard)
//! whirlmap sweep sweeps/paper-reference.json       # results/paper-reference
//! cargo run --release -p whirlmap-sweep --example convergence [-- STANDARD REFERENCE OUT]
//! ```
//!
//! writes `OUT/convergence.md` (default `results/convergence`) with three checks, each with
//! its numbers and PASS or FAIL:
//!
//! 1. every grid cell farther than one lattice step (`resolution_rpm` of the critical search)
//!    from a whirl boundary of its friction coefficient has the same class;
//! 2. the maximum contact force of every cell that is not whirl in either run agrees within
//!    0.1 % (whirl cells are stopped by the whirl rule, so their maximum is a stopping-rule
//!    quantity, reported but not checked);
//! 3. every onset agrees within two lattice steps.
//!
//! The exit code is 1 when a check fails.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use whirlmap_results::critical::read_critical;
use whirlmap_results::point::{load_points, PointRow, PointStatus};
use whirlmap_sweep::critical::CriticalRow;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| PathBuf::from(args.get(i).map_or(d, |s| s.as_str()));
    let (std_dir, ref_dir, out) = (
        arg(0, "results/paper"),
        arg(1, "results/paper-reference"),
        arg(2, "results/convergence"),
    );
    let (a, b) = (
        load_points(&std_dir).expect("standard points"),
        load_points(&ref_dir).expect("reference points"),
    );
    let (ca, cb) = (
        read_critical(&std_dir)
            .expect("standard critical.json")
            .expect("a critical search"),
        read_critical(&ref_dir)
            .expect("reference critical.json")
            .expect("a critical search"),
    );
    let md = report(&a, &b, &ca, &cb, &std_dir, &ref_dir);
    let pass = !md.contains("**FAIL**");
    std::fs::create_dir_all(&out).expect("the output folder can be made");
    std::fs::write(out.join("convergence.md"), &md).expect("convergence.md is written");
    print!("{md}");
    if !pass {
        std::process::exit(1);
    }
}

fn key(r: &PointRow) -> Option<(u64, u64)> {
    Some((r.speed_rpm()?.to_bits(), r.mu()?.to_bits()))
}

/// The whirl boundaries (r/min) of the row for `mu`: every interval end inside the range.
fn boundaries(rows: &[CriticalRow], mu: f64) -> Option<(Vec<f64>, f64)> {
    let r = rows.iter().find(|r| (r.mu - mu).abs() < 1e-9)?;
    let mut b = Vec::new();
    for (k, [lo, hi]) in r.whirl_intervals_rpm.iter().enumerate() {
        if r.bracket_rpm.is_some() || k > 0 {
            b.push(*lo);
        }
        let last = k + 1 == r.whirl_intervals_rpm.len();
        if !(last && r.whirl_at_range_top) {
            b.push(*hi);
        }
    }
    Some((b, r.resolution_rpm))
}

fn report(
    a: &[PointRow],
    b: &[PointRow],
    ca: &[CriticalRow],
    cb: &[CriticalRow],
    std_dir: &std::path::Path,
    ref_dir: &std::path::Path,
) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Convergence of the main job: standard against reference\n\n`{}` (standard) against `{}` (reference: DOPRI5 at rtol 1e-9).\n",
        std_dir.display(),
        ref_dir.display()
    );
    let by_key: BTreeMap<(u64, u64), &PointRow> =
        b.iter().filter_map(|r| Some((key(r)?, r))).collect();

    // 1. Classes away from the boundaries.
    let (mut compared, mut near, mut differ) = (0, 0, Vec::new());
    let mut near_differ = Vec::new();
    for r in a {
        let (Some(k), Some(v), Some(mu)) = (key(r), r.speed_rpm(), r.mu()) else {
            continue;
        };
        let Some(q) = by_key.get(&k) else { continue };
        let is_near = [ca, cb].iter().any(|rows| {
            boundaries(rows, mu).is_some_and(|(bs, res)| bs.iter().any(|x| (v - x).abs() <= res))
        });
        if is_near {
            near += 1;
            if r.class != q.class {
                near_differ.push(format!("{v:.0} r/min, mu {mu}"));
            }
            continue;
        }
        compared += 1;
        if r.class != q.class || r.status != q.status {
            differ.push(format!(
                "{v:.0} r/min, mu {mu}: {:?} / {:?}",
                r.class, q.class
            ));
        }
    }
    let _ = writeln!(
        md,
        "## 1. Classes away from a whirl boundary: {}\n\n{compared} cells compared, {} differ; {near} cells lie within one lattice step of a boundary (not compared; {} of them differ{}).\n{}",
        if differ.is_empty() { "PASS" } else { "**FAIL**" },
        differ.len(),
        near_differ.len(),
        if near_differ.is_empty() {
            String::new()
        } else {
            format!(": {}", near_differ.join("; "))
        },
        differ
            .iter()
            .map(|d| format!("- {d}\n"))
            .collect::<String>()
    );

    // 2. Maximum contact force.
    let (mut worst, mut worst_at, mut n, mut worst_whirl) = (0.0_f64, String::new(), 0, 0.0_f64);
    for r in a {
        let (Some(k), Some(fa)) = (key(r), r.max_contact_force_n) else {
            continue;
        };
        let Some(q) = by_key.get(&k) else { continue };
        let Some(fb) = q.max_contact_force_n else {
            continue;
        };
        if r.status != PointStatus::Ok || q.status != PointStatus::Ok {
            continue;
        }
        let rel = (fa - fb).abs() / fb.abs().max(1e-12);
        let whirl = r.class.is_some_and(|c| c.is_whirl()) || q.class.is_some_and(|c| c.is_whirl());
        if whirl {
            worst_whirl = worst_whirl.max(rel);
            continue;
        }
        n += 1;
        if rel > worst {
            worst = rel;
            worst_at = format!(
                "{:.0} r/min, mu {}",
                r.speed_rpm().unwrap_or(f64::NAN),
                r.mu().unwrap_or(f64::NAN)
            );
        }
    }
    let _ = writeln!(
        md,
        "## 2. Maximum contact force within 0.1 %: {}\n\nWorst relative difference over {n} cells that are not whirl in either run: {:.2e} (at {worst_at}). Whirl cells (stopped by the whirl rule; not checked): worst {:.2e}.\n",
        if worst <= 1e-3 { "PASS" } else { "**FAIL**" },
        worst,
        worst_whirl
    );

    // 3. Onsets.
    let _ = writeln!(md, "## 3. Onsets within two lattice steps\n\n| mu | standard (r/min) | reference (r/min) | difference (lattice steps) | check |\n|---|---|---|---|---|");
    for r in ca {
        let q = cb.iter().find(|q| (q.mu - r.mu).abs() < 1e-9);
        let (oa, ob) = (r.onset_rpm, q.and_then(|q| q.onset_rpm));
        let (diff, ok) = match (oa, ob) {
            (Some(x), Some(y)) => {
                let d = (x - y).abs() / r.resolution_rpm;
                (format!("{d:.2}"), d <= 2.0)
            }
            (None, None) => ("-".to_string(), true),
            _ => ("one run only".to_string(), false),
        };
        let f = |o: Option<f64>| o.map_or("none".to_string(), |x| format!("{x:.1}"));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {diff} | {} |",
            r.mu,
            f(oa),
            f(ob),
            if ok { "PASS" } else { "**FAIL**" }
        );
    }
    md
}
