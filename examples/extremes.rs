//! The full stability matrix (docs/accuracy.md#stability-at-the-extremes):
//! `cargo run --release --example extremes [-- --json]`. Prints one line per point and exits
//! 1 if any point breaks the contract (a non-finite result, a failed energy audit, a panic, or
//! a valid scene rejected).

use whirlmap_sweep::extremes::{matrix, run_point};

fn main() {
    let json = std::env::args().any(|a| a == "--json");
    let mut bad = 0;
    let mut all = Vec::new();
    for p in matrix(true) {
        let o = run_point(&p);
        if json {
            all.push(o.clone());
        } else {
            println!(
                "| {} | {} | {} | {} | {} | {} | {:.0} | {} |",
                o.name,
                o.duration_s,
                o.status,
                o.end_time_s.map_or("-".into(), |t| format!("{t:.4}")),
                o.attempts.map_or("-".into(), |a| a.to_string()),
                o.residual_rel.map_or("-".into(), |r| format!("{r:.1e}")),
                o.wall_ms,
                if o.problems.is_empty() {
                    "pass".to_string()
                } else {
                    o.problems.join("; ")
                }
            );
        }
        if !o.problems.is_empty() {
            bad += 1;
        }
    }
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&all).expect("outcomes serialise")
        );
    }
    if bad > 0 {
        eprintln!("{bad} point(s) broke the contract");
        std::process::exit(1);
    }
}
