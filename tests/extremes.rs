//! Stability at the extremes, reduced matrix: every point finishes with finite results and a
//! passing energy audit, or fails with a typed solver error within its step budget.
//! The full matrix: `cargo run --release --example extremes`.

use whirlmap_sweep::extremes::{matrix, run_point};

#[test]
fn every_extreme_point_finishes_finite_and_audited_or_fails_typed() {
    let mut problems = Vec::new();
    for p in matrix(false) {
        let o = run_point(&p);
        eprintln!(
            "{:<45} {:<20} t_end {:?} attempts {:?} residual {:?} ({:.0} ms)",
            o.name, o.status, o.end_time_s, o.attempts, o.residual_rel, o.wall_ms
        );
        problems.extend(o.problems.iter().map(|q| format!("{}: {q}", o.name)));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
