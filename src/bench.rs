//! `whirlmap bench`: the performance figures the README reports, as counts and ratios.

use std::hint::black_box;
use std::ops::ControlFlow;
use std::time::Instant;
use whirlmap_core::model::{ix, DropSystem, Mode, ModelEvals, Slip, N};
use whirlmap_core::ode::{Observer, OdeSystem, StepView};
use whirlmap_core::{simulate_observed, DropOptions, DropReport, Fidelity, Scene, StopReason};

/// Reads the force model's evaluation counters after every step (the last read is the drop's).
#[derive(Default)]
struct EvalCount(ModelEvals);
impl Observer<DropSystem, N> for EvalCount {
    fn on_step(&mut self, sys: &DropSystem, _s: &StepView<'_, N>) -> ControlFlow<()> {
        self.0 = sys.model_evals();
        ControlFlow::Continue(())
    }
}

/// Options of `whirlmap bench`.
#[derive(clap::Args)]
pub struct BenchArgs {
    /// Repetitions per drop case (the median wall time is reported).
    #[arg(long, default_value_t = 5)]
    reps: usize,
    /// Also run the long thermal scenes (`scenes/coast-down.json` to its stop speed and for
    /// 60 s, `scenes/runaway.json` for 60 s), each with the full model and with the `draft`
    /// fidelity (quasi-static race), and compare them (about 30 s of CPU in all).
    #[arg(long)]
    coast_down: bool,
}

/// The long thermal scenes, embedded so the bench needs no files.
const COAST_DOWN_SCENE: &str = include_str!("../scenes/coast-down.json");
const RUNAWAY_SCENE: &str = include_str!("../scenes/runaway.json");

/// How a bench row departs from the default scene.
#[derive(Clone, Copy)]
enum Numerics {
    /// The scene's defaults (DOPRI5, rtol 1e-5, isotropic support damper).
    Default,
    /// The paper's radial-only support damper, default numerics.
    Radial,
    /// ROS34PW2 with the gap bound at `rtol`; with `race`, also that factor on the race's
    /// absolute tolerances.
    Ros { rtol: f64, race: Option<f64> },
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Runs the benchmark cases and prints a table.
pub fn run(a: &BenchArgs) -> anyhow::Result<()> {
    let reps = a.reps.max(1);
    outln!(
        "whirlmap bench (one thread, default tolerance rtol = {:e})",
        Scene::paper().solver.rtol
    );
    outln!(
        "{:<36} {:>10} {:>11} {:>9} {:>8} {:>7} {:>12} {:>16}",
        "case",
        "wall ms",
        "RHS evals",
        "steps",
        "rejected",
        "events",
        "ns/RHS eval",
        "model evals/step"
    );
    // Then the linearly implicit ROS34PW2 with the free-flight gap bound (README, "Speed
    // against accuracy") at two tolerances, the paper's radial-only support damper
    // (`support_damper = radial_only`) with DOPRI5, and ROS34PW2 with the gap bound and the
    // race's absolute tolerances x1000 (`solver.race_atol_scale`).
    let plain = Numerics::Default;
    let ros = |rtol| Numerics::Ros { rtol, race: None };
    let iso_ros = |rtol| Numerics::Ros {
        rtol,
        race: Some(1000.0),
    };
    let cases = [
        ("pendulum 8000 r/min mu 0.1, 1 s", 8000.0, 0.1, false, plain),
        ("same, thermal model on", 8000.0, 0.1, true, plain),
        ("whirl 8000 r/min mu 0.4 (rule)", 8000.0, 0.4, false, plain),
        (
            "pendulum, ros34pw2+gap rtol 1e-4",
            8000.0,
            0.1,
            false,
            ros(1e-4),
        ),
        (
            "whirl, ros34pw2+gap rtol 1e-4",
            8000.0,
            0.4,
            false,
            ros(1e-4),
        ),
        (
            "pendulum, ros34pw2+gap rtol 1e-5",
            8000.0,
            0.1,
            false,
            ros(1e-5),
        ),
        (
            "whirl, ros34pw2+gap rtol 1e-5",
            8000.0,
            0.4,
            false,
            ros(1e-5),
        ),
        (
            "radial: pendulum, dopri5 rtol 1e-5",
            8000.0,
            0.1,
            false,
            Numerics::Radial,
        ),
        (
            "radial: whirl, dopri5 rtol 1e-5",
            8000.0,
            0.4,
            false,
            Numerics::Radial,
        ),
        (
            "pendulum, ros+race x1000 1e-4",
            8000.0,
            0.1,
            false,
            iso_ros(1e-4),
        ),
        (
            "whirl, ros+race x1000 1e-4",
            8000.0,
            0.4,
            false,
            iso_ros(1e-4),
        ),
        (
            "pendulum, ros+race x1000 1e-5",
            8000.0,
            0.1,
            false,
            iso_ros(1e-5),
        ),
        (
            "whirl, ros+race x1000 1e-5",
            8000.0,
            0.4,
            false,
            iso_ros(1e-5),
        ),
    ];
    for (name, speed, mu, thermal, numerics) in cases {
        let mut scene = Scene::paper();
        scene.speed_rpm = speed;
        scene.mu_dynamic = mu;
        match numerics {
            Numerics::Default => {}
            Numerics::Radial => scene.support_damper = whirlmap_core::SupportDamper::RadialOnly,
            Numerics::Ros { rtol, race } => {
                scene.solver.method = whirlmap_core::Method::Ros34pw2;
                scene.solver.free_flight_gap_bound = true;
                scene.solver.rtol = rtol;
                if let Some(f) = race {
                    scene.solver.race_atol_scale = f;
                }
            }
        }
        if thermal {
            scene.thermal = Some(whirlmap_core::ThermalParams::default());
        }
        let opts = DropOptions {
            duration_s: 1.0,
            ..Default::default()
        };
        let mut walls = Vec::new();
        let mut last = None;
        for _ in 0..reps {
            let mut count = EvalCount::default();
            let t = Instant::now();
            let r = simulate_observed(&scene, &opts, &mut count)?;
            walls.push(t.elapsed().as_secs_f64() * 1e3);
            last = Some((r, count.0));
        }
        let (r, evals) = last.expect("reps >= 1");
        print_row(name, median(walls), &r, evals);
        if let Some(th) = &r.thermal {
            outln!(
                "    {} network steps for {:.3} s simulated",
                th.network_steps,
                r.end_time_s
            );
        }
    }
    if a.coast_down {
        thermal_pairs()?;
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
        outln!("one RHS evaluation (contact, {label}, drag on): {ns:.1} ns");
    }
    Ok(())
}

/// One row of the bench table: the last column is the force model's evaluations per
/// accepted step, computed + reused (the stepper's stages, the guards, the monitor; reused
/// ones are served by `DropSystem`'s memo of the step end and midpoint).
fn print_row(name: &str, wall_ms: f64, r: &DropReport, evals: ModelEvals) {
    let note = if r.stop_reason == StopReason::WhirlDecided {
        " (whirl decided)"
    } else {
        ""
    };
    outln!(
        "{:<36} {:>10.2} {:>11} {:>9} {:>8} {:>7} {:>12.0} {:>16}{note}",
        name,
        wall_ms,
        r.stats.rhs_evals,
        r.stats.steps,
        r.stats.rejected,
        r.stats.events,
        wall_ms * 1e6 / r.stats.rhs_evals as f64,
        format!(
            "{:.2} + {:.2}",
            evals.computed as f64 / r.stats.steps as f64,
            evals.reused as f64 / r.stats.steps as f64
        )
    );
}

/// CPU time of the calling thread (s), from `/proc/thread-self/schedstat` (Linux; its first
/// field is the time on CPU in ns). On a shared machine the wall time counts the other jobs'
/// share too; this does not. Read by hand rather than through a crate: one file, one number.
fn thread_cpu_s() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Runs one long thermal drop (to `duration_s` or the scene's stop speed) and prints its
/// table row, its work per simulated second and its CPU time.
fn long_thermal_run(name: &str, scene: &Scene, duration_s: f64) -> anyhow::Result<DropReport> {
    let opts = DropOptions {
        duration_s,
        ..Default::default()
    };
    let mut count = EvalCount::default();
    let (t, c) = (Instant::now(), thread_cpu_s());
    let r = simulate_observed(scene, &opts, &mut count)?;
    let wall = t.elapsed().as_secs_f64();
    let cpu = c.zip(thread_cpu_s()).map(|(a, b)| b - a);
    print_row(name, wall * 1e3, &r, count.0);
    let th = r.thermal.as_ref().expect("a thermal scene");
    let per_60 = |x: f64| x * 60.0 / r.end_time_s;
    outln!(
        "    {:.2} s simulated ({:?}): {:.0} dynamic RHS evaluations and {:.0} network steps per simulated second; \
         CPU {} ({} per 60 s simulated)",
        r.end_time_s,
        r.stop_reason,
        r.stats.rhs_evals as f64 / r.end_time_s,
        th.network_steps as f64 / r.end_time_s,
        cpu.map_or("n/a".into(), |c| format!("{c:.2} s")),
        cpu.map_or("n/a".into(), |c| format!("{:.2} s", per_60(c))),
    );
    Ok(r)
}

/// What the quasi-static race changes in what a thermal run is for: temperatures, thermal
/// load, heat energies, end speed and time.
fn print_thermal_differences(full: &DropReport, draft: &DropReport) {
    let (a, b) = (
        full.thermal.as_ref().expect("thermal"),
        draft.thermal.as_ref().expect("thermal"),
    );
    let (ta, tb) = (a.temperatures_k.as_array(), b.temperatures_k.as_array());
    // The first sample is the release, every node at ambient.
    let rise = a.temperatures_k.hottest_peak_k() - a.series[0].temperatures_k[0];
    let d_t = ta
        .iter()
        .zip(&tb)
        .map(|(x, y)| {
            (x.final_k - y.final_k)
                .abs()
                .max((x.peak_k - y.peak_k).abs())
        })
        .fold(0.0, f64::max);
    let (ha, hb) = (a.heat, b.heat);
    outln!(
        "    draft vs full: largest node temperature difference (final or peak) {:.4} K = {:.1e} of the {:.2} K rise; \
         peak F_th {:.3} vs {:.3} N",
        d_t,
        d_t / rise,
        rise,
        b.peak_thermal_load_n,
        a.peak_thermal_load_n
    );
    outln!(
        "    heat H_s {:.3} vs {:.3} J, H_i {:.3} vs {:.3} J, H_o {:.3} vs {:.3} J; end {:.3} vs {:.3} s, \
         rotor {:.1} vs {:.1} r/min, race {:.1} vs {:.1} r/min",
        hb.h_s_j,
        ha.h_s_j,
        hb.h_i_j,
        ha.h_i_j,
        hb.h_o_j,
        ha.h_o_j,
        draft.end_time_s,
        full.end_time_s,
        draft.features.final_rotor_speed_rpm,
        full.features.final_rotor_speed_rpm,
        draft.features.final_race_speed_rpm,
        full.features.final_race_speed_rpm,
    );
}

/// The long thermal scenes with the full model and with the draft fidelity (quasi-static
/// race at rtol 1e-4), side by side.
fn thermal_pairs() -> anyhow::Result<()> {
    let coast: Scene = serde_json::from_str(COAST_DOWN_SCENE)?;
    let mut coast_60 = coast.clone();
    coast_60.stop_speed_rpm = None;
    let runaway: Scene = serde_json::from_str(RUNAWAY_SCENE)?;
    let scenes = [
        ("coast-down to 1000 r/min", coast),
        ("coast-down, 60 s", coast_60),
        ("runaway, 60 s", runaway),
    ];
    for (name, scene) in scenes {
        let full = long_thermal_run(&format!("{name} (full)"), &scene, 60.0)?;
        let draft = long_thermal_run(
            &format!("{name} (draft)"),
            &Fidelity::Draft.applied(&scene),
            60.0,
        )?;
        print_thermal_differences(&full, &draft);
    }
    Ok(())
}
