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
    /// Also run the 60 s thermal coast-down of `scenes/coast-down.json` once (about 15 s).
    #[arg(long)]
    coast_down: bool,
}

/// The coast-down scene, embedded so the bench needs no files.
const COAST_DOWN_SCENE: &str = include_str!("../scenes/coast-down.json");

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
    let coast: Scene = serde_json::from_str(COAST_DOWN_SCENE)?;
    let cases = [
        ("pendulum 8000 r/min mu 0.1, 1 s", 8000.0, 0.1, false, 1.0),
        ("same, thermal model on", 8000.0, 0.1, true, 1.0),
        ("whirl 8000 r/min mu 0.4 (rule)", 8000.0, 0.4, false, 1.0),
        (
            "thermal coast-down (<= 60 s)",
            f64::NAN,
            f64::NAN,
            true,
            60.0,
        ),
    ];
    for (name, speed, mu, thermal, duration_s) in cases {
        let coast_down = speed.is_nan();
        if coast_down && !a.coast_down {
            continue;
        }
        let mut scene = if coast_down {
            coast.clone()
        } else {
            Scene::paper()
        };
        if !coast_down {
            scene.speed_rpm = speed;
            scene.mu_dynamic = mu;
            if thermal {
                scene.thermal = Some(whirlmap_core::ThermalParams::default());
            }
        }
        let opts = DropOptions {
            duration_s,
            ..Default::default()
        };
        let reps = if coast_down { 1 } else { reps };
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
        if let Some(th) = &r.thermal {
            println!(
                "    {:.3} s simulated: {:.0} dynamic RHS evaluations and {:.0} network steps per simulated second",
                r.end_time_s,
                r.stats.rhs_evals as f64 / r.end_time_s,
                th.network_steps as f64 / r.end_time_s
            );
        }
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
