//! `whirlmap bench`: the performance figures the README reports, as counts and ratios.

use std::hint::black_box;
use std::time::Instant;
use whirlmap_core::model::{ix, DropSystem, Mode, Slip};
use whirlmap_core::ode::OdeSystem;
use whirlmap_core::{simulate, DropOptions, Scene, StopReason};

/// Options of `whirlmap bench`.
#[derive(clap::Args)]
pub struct BenchArgs {
    /// Repetitions per drop case (the median wall time is reported).
    #[arg(long, default_value_t = 5)]
    reps: usize,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Runs the benchmark cases and prints a table.
pub fn run(a: &BenchArgs) -> anyhow::Result<()> {
    let reps = a.reps.max(1);
    println!(
        "whirlmap bench (one thread, default tolerance rtol = {:e})",
        Scene::paper().solver.rtol
    );
    println!(
        "{:<34} {:>10} {:>11} {:>9} {:>8} {:>7} {:>12}",
        "case", "wall ms", "RHS evals", "steps", "rejected", "events", "ns/RHS eval"
    );
    for (name, speed, mu) in [
        ("pendulum 8000 r/min mu 0.1, 1 s", 8000.0, 0.1),
        ("whirl 8000 r/min mu 0.4 (rule)", 8000.0, 0.4),
    ] {
        let mut scene = Scene::paper();
        scene.speed_rpm = speed;
        scene.mu_dynamic = mu;
        let opts = DropOptions {
            duration_s: 1.0,
            ..Default::default()
        };
        let mut walls = Vec::new();
        let mut last = None;
        for _ in 0..reps {
            let t = Instant::now();
            let r = simulate(&scene, &opts)?;
            walls.push(t.elapsed().as_secs_f64() * 1e3);
            last = Some(r);
        }
        let r = last.expect("reps >= 1");
        let wall = median(walls);
        let note = if r.stop_reason == StopReason::WhirlTurnsReached {
            " (whirl decided)"
        } else {
            ""
        };
        println!(
            "{:<34} {:>10.2} {:>11} {:>9} {:>8} {:>7} {:>12.0}{note}",
            name,
            wall,
            r.stats.rhs_evals,
            r.stats.steps,
            r.stats.rejected,
            r.stats.events,
            wall * 1e6 / r.stats.rhs_evals as f64
        );
    }
    // One right-hand-side evaluation at a loaded, slipping contact (drag on).
    let scene = Scene::paper();
    let mut sys = DropSystem::new(&scene);
    let mut y = sys.initial_state(scene.spin_rad_s());
    y[ix::YR] = y[ix::YB] - scene.clearance_m - 2e-7;
    y[ix::VYR] = -0.01;
    y[ix::WB] = 300.0;
    sys.mode = Mode {
        contact: true,
        support: true,
        slip: Slip::Slipping(1.0),
    };
    let mut dy = [0.0; whirlmap_core::model::N];
    let n = 2_000_000;
    for (label, slip) in [
        ("slipping", Slip::Slipping(1.0)),
        ("sticking", Slip::Sticking),
    ] {
        sys.mode.slip = slip;
        let t = Instant::now();
        for i in 0..n {
            y[ix::TR] = i as f64 * 1e-9;
            sys.rhs(0.0, black_box(&y), &mut dy);
            black_box(&dy);
        }
        let ns = t.elapsed().as_secs_f64() * 1e9 / n as f64;
        println!("one RHS evaluation (contact, {label}, drag on): {ns:.1} ns");
    }
    Ok(())
}
