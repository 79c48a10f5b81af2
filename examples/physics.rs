//! The physics behind the design charts: what decides whirl under the paper's symmetric
//! release, and how the friction threshold and the onset speed move with the support damping,
//! the load share and an unbalance.
//!
//! ```text
//! cargo run --release --example physics [-- OUT]
//! ```
//!
//! writes `OUT` (default `results/physics`): `study.json` (every number), `summary.md` (the
//! tables the docs quote), and the charts `mechanism`, `threshold_map`, `sensitivity` and
//! `unbalance` (PNG and SVG). About 4 000 drops; a few minutes on two cores.
//!
//! 1. **Mechanism.** Contact-angle traces over the first 80 ms at 16 000 r/min for friction
//!    coefficients around the threshold, and, at mu 0.35, the slip velocity at several
//!    release speeds with the time the race first locks into rolling. While the contact
//!    slips, Coulomb friction `mu F_n` does not depend on the slip speed, so the rotor's
//!    translation is the same at every release speed until the race locks: the study
//!    measures when each path leaves the 30 000 r/min path. The traces run at the
//!    `reference` numerics; the classes at the scene's default (`standard`).
//! 2. **Threshold map.** Class over friction (0.20 to 0.40 in 0.005) and speed (2 000 to
//!    30 000 r/min).
//! 3. **Sensitivities.** The friction threshold at 16 000 r/min (the lowest mu above which
//!    every coefficient scanned whirls) and the onset speed at mu 0.35, 0.4 and 0.5, against
//!    the support damping c2 and the load share.
//! 4. **Unbalance.** The share of 16 unbalance phases that whirl at 8 000 r/min, for
//!    eccentricities of 0, 1, 2 and 5 um.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};
use whirlmap_core::orbit::OrbitSample;
use whirlmap_core::{simulate, DropOptions, Fidelity, OrbitClass, Scene};
use whirlmap_plot::marks::{class_colour, legend, Mark};
use whirlmap_plot::render::{
    draw_mesh, render, with_header, DrawResult, Figure, TITLE_BAND, TITLE_FONT, X_LABEL_AREA,
    Y_LABEL_AREA,
};
use whirlmap_sweep::critical::{critical_rows, CriticalOptions};

/// The paper scene at a speed and friction coefficient.
fn scene(speed_rpm: f64, mu: f64) -> Scene {
    let mut s = Scene::paper();
    s.speed_rpm = speed_rpm;
    s.mu_dynamic = mu;
    s
}

/// The class of a 1 s drop (extended by the classifier if it has not settled).
fn class_of(s: &Scene) -> Option<OrbitClass> {
    let opts = DropOptions::default();
    simulate(s, &opts).ok().map(|r| r.verdict.class)
}

/// A trace of the first `duration_s` with the whirl rule and the extension off, at the
/// `reference` numerics: the traces are compared to 5 um, finer than `standard` resolves
/// (at rtol 3e-5 two paths of the same physics drift 5 um apart within a few bounces).
fn trace(mut s: Scene, duration_s: f64) -> Vec<OrbitSample> {
    Fidelity::Reference.apply(&mut s);
    s.whirl_stop_turns = 1e6;
    s.classification.max_extension_s = 0.0;
    let opts = DropOptions {
        duration_s,
        orbit_points: Some(4000),
        ..Default::default()
    };
    simulate(&s, &opts)
        .expect("the trace drop runs")
        .orbit
        .expect("an orbit was asked for")
        .samples
}

/// The contact angle (deg from the bottom of the race, counter-clockwise positive,
/// unwrapped) of each sample; NaN while the rotor is within half a clearance of the centre.
fn angles_deg(samples: &[OrbitSample], clearance_m: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(samples.len());
    let mut prev: Option<f64> = None;
    let mut acc = 0.0;
    for p in samples {
        if p.x_rel_m.hypot(p.y_rel_m) < 0.5 * clearance_m {
            out.push(f64::NAN);
            continue;
        }
        let raw = p.y_rel_m.atan2(p.x_rel_m) + 0.5 * PI;
        acc = match prev {
            None => (raw + PI).rem_euclid(TAU) - PI,
            Some(q) => acc + (raw - q + PI).rem_euclid(TAU) - PI,
        };
        prev = Some(raw);
        out.push(acc.to_degrees());
    }
    out
}

/// The first time the contact rolls (|slip| below 1 mm/s after the first touch), if any.
fn lock_time(samples: &[OrbitSample]) -> Option<f64> {
    samples
        .iter()
        .skip_while(|p| p.contact_force_n <= 0.0)
        .find(|p| p.slip_m_s.abs() < 1e-3)
        .map(|p| p.t_s)
}

/// The first time two traces' rotor positions relative to the race are more than `tol_m`
/// apart (sampled at the same times).
fn divergence_time(a: &[OrbitSample], b: &[OrbitSample], tol_m: f64) -> Option<f64> {
    a.iter()
        .zip(b)
        .find(|(p, q)| (p.x_rel_m - q.x_rel_m).hypot(p.y_rel_m - q.y_rel_m) > tol_m)
        .map(|(p, _)| p.t_s)
}

#[derive(Serialize)]
struct AngleTrace {
    mu: f64,
    speed_rpm: f64,
    t_ms: Vec<f64>,
    angle_deg: Vec<f64>,
    lock_ms: Option<f64>,
    class: Option<OrbitClass>,
}

#[derive(Serialize)]
struct SlipTrace {
    mu: f64,
    speed_rpm: f64,
    t_ms: Vec<f64>,
    slip_m_s: Vec<f64>,
    lock_ms: Option<f64>,
    diverges_from_30000_ms: Option<f64>,
    class: Option<OrbitClass>,
}

#[derive(Serialize)]
struct Sensitivity {
    parameter: String,
    value: f64,
    /// The lowest mu above which every scanned mu whirls at 16 000 r/min.
    threshold_mu: Option<f64>,
    /// Scanned mu values that whirl below the threshold (islands).
    islands_mu: Vec<f64>,
    /// Onset speed (r/min) at mu 0.35, 0.4, 0.5.
    onset_rpm: Vec<(f64, Option<f64>)>,
}

#[derive(Serialize)]
struct UnbalanceRow {
    unbalance_m: f64,
    mu: f64,
    whirl: usize,
    phases: usize,
}

#[derive(Serialize)]
struct Study {
    angle_traces: Vec<AngleTrace>,
    slip_traces: Vec<SlipTrace>,
    map_mu: Vec<f64>,
    map_speed_rpm: Vec<f64>,
    /// Row-major over speed (slowest) then mu.
    map_class: Vec<Option<OrbitClass>>,
    sensitivities: Vec<Sensitivity>,
    unbalance: Vec<UnbalanceRow>,
}

fn steps(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let v = from + (to - from) * i as f64 / (n - 1) as f64;
            (v * 1e6).round() / 1e6
        })
        .collect()
}

const THRESHOLD_SPEED_RPM: f64 = 16_000.0;

/// Sets one studied parameter on a scene.
type SetParam = Box<dyn Fn(&mut Scene) + Sync>;

/// Draws one chart to a path.
type Draw<'a> = &'a dyn Fn(&Path) -> Result<(), String>;

/// Friction coefficients of the unbalance study.
const UNBALANCE_MUS: [f64; 6] = [0.25, 0.275, 0.3, 0.31, 0.325, 0.35];

/// The friction threshold at 16 000 r/min for scenes made by `make(mu)`: the lowest scanned mu
/// above which every mu whirls, and the scanned values below it that whirl.
fn threshold(make: &(dyn Fn(f64) -> Scene + Sync), mus: &[f64]) -> (Option<f64>, Vec<f64>) {
    let whirl: Vec<bool> = mus
        .par_iter()
        .map(|&mu| class_of(&make(mu)).is_some_and(|c| c.is_whirl()))
        .collect();
    let mut first = None;
    for i in (0..mus.len()).rev() {
        if whirl[i] {
            first = Some(i);
        } else {
            break;
        }
    }
    let islands = match first {
        Some(f) => (0..f).filter(|&i| whirl[i]).map(|i| mus[i]).collect(),
        None => (0..mus.len())
            .filter(|&i| whirl[i])
            .map(|i| mus[i])
            .collect(),
    };
    (first.map(|i| mus[i]), islands)
}

fn main() {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "results/physics".into()),
    );
    std::fs::create_dir_all(&out).expect("the output folder can be made");
    let clearance = Scene::paper().clearance_m;

    // 1. Mechanism.
    eprintln!("mechanism traces");
    let angle_mus = [0.30, 0.31, 0.315, 0.32, 0.35];
    let angle_traces: Vec<AngleTrace> = angle_mus
        .par_iter()
        .map(|&mu| {
            let s = scene(THRESHOLD_SPEED_RPM, mu);
            let samples = trace(s.clone(), 0.08);
            AngleTrace {
                mu,
                speed_rpm: THRESHOLD_SPEED_RPM,
                t_ms: samples.iter().map(|p| p.t_s * 1e3).collect(),
                angle_deg: angles_deg(&samples, clearance),
                lock_ms: lock_time(&samples).map(|t| t * 1e3),
                class: class_of(&s),
            }
        })
        .collect();
    let slip_speeds = [4000.0, 5000.0, 6000.0, 8000.0, 16000.0];
    let reference = trace(scene(30_000.0, 0.35), 0.06);
    let slip_traces: Vec<SlipTrace> = slip_speeds
        .par_iter()
        .map(|&v| {
            let s = scene(v, 0.35);
            let samples = trace(s.clone(), 0.06);
            SlipTrace {
                mu: 0.35,
                speed_rpm: v,
                t_ms: samples.iter().map(|p| p.t_s * 1e3).collect(),
                slip_m_s: samples.iter().map(|p| p.slip_m_s).collect(),
                lock_ms: lock_time(&samples).map(|t| t * 1e3),
                diverges_from_30000_ms: divergence_time(&samples, &reference, 5e-6)
                    .map(|t| t * 1e3),
                class: class_of(&s),
            }
        })
        .collect();

    // 2. Threshold map.
    eprintln!("threshold map");
    let map_mu = steps(0.20, 0.40, 41);
    let map_speed = steps(2000.0, 30_000.0, 15);
    let cells: Vec<(f64, f64)> = map_speed
        .iter()
        .flat_map(|&v| map_mu.iter().map(move |&m| (v, m)))
        .collect();
    let map_class: Vec<Option<OrbitClass>> = cells
        .par_iter()
        .map(|&(v, m)| class_of(&scene(v, m)))
        .collect();

    // 3. Sensitivities.
    eprintln!("sensitivities");
    let scan_mu = steps(0.25, 0.40, 31);
    let onset_mus = [0.35, 0.4, 0.5];
    let onset_opts = CriticalOptions {
        from_rpm: 1000.0,
        to_rpm: 16_000.0,
        resolution_rpm: 250.0,
        tol_rpm: 25.0,
        duration_s: 1.0,
    };
    let mut sensitivities = Vec::new();
    let params: Vec<(&str, f64, SetParam)> = [375.0, 562.5, 750.0, 900.0, 1125.0]
        .into_iter()
        .map(|c2| {
            (
                "support_damping_n_s_per_m",
                c2,
                Box::new(move |s: &mut Scene| s.support_damping_n_s_per_m = c2) as SetParam,
            )
        })
        .chain([0.4, 0.45, 0.5, 0.55, 0.6].into_iter().map(|share| {
            (
                "load_share",
                share,
                Box::new(move |s: &mut Scene| s.load_share = share) as SetParam,
            )
        }))
        .collect();
    for (name, value, set) in &params {
        let make = |mu: f64| {
            let mut s = scene(THRESHOLD_SPEED_RPM, mu);
            set(&mut s);
            s
        };
        let (threshold_mu, islands_mu) = threshold(&make, &scan_mu);
        let mut base = Scene::paper();
        set(&mut base);
        let rows = critical_rows(&base, &onset_mus, &onset_opts).expect("valid settings");
        eprintln!("  {name} = {value}: threshold {threshold_mu:?}");
        sensitivities.push(Sensitivity {
            parameter: name.to_string(),
            value: *value,
            threshold_mu,
            islands_mu,
            onset_rpm: rows.iter().map(|r| (r.mu, r.onset_rpm)).collect(),
        });
    }

    // 4. Unbalance.
    eprintln!("unbalance");
    let phases = 16;
    let unbalance_cases: Vec<(f64, f64, usize)> = [0.0, 1e-6, 2e-6, 5e-6]
        .into_iter()
        .flat_map(|e| {
            UNBALANCE_MUS
                .into_iter()
                .flat_map(move |mu| (0..phases).map(move |k| (e, mu, k)))
        })
        .collect();
    let whirls: Vec<bool> = unbalance_cases
        .par_iter()
        .map(|&(e, mu, k)| {
            let mut s = scene(8000.0, mu);
            s.unbalance_m = e;
            s.unbalance_phase_rad = TAU * k as f64 / phases as f64;
            class_of(&s).is_some_and(|c| c.is_whirl())
        })
        .collect();
    let mut unbalance = Vec::new();
    for (chunk, cases) in whirls.chunks(phases).zip(unbalance_cases.chunks(phases)) {
        unbalance.push(UnbalanceRow {
            unbalance_m: cases[0].0,
            mu: cases[0].1,
            whirl: chunk.iter().filter(|w| **w).count(),
            phases,
        });
    }

    let study = Study {
        angle_traces,
        slip_traces,
        map_mu,
        map_speed_rpm: map_speed,
        map_class,
        sensitivities,
        unbalance,
    };
    write(&out, &study);
}

/// Writes the study's files into `out`.
fn write(out: &Path, study: &Study) {
    std::fs::write(
        out.join("study.json"),
        serde_json::to_string(study).expect("the study serialises"),
    )
    .expect("study.json is written");
    std::fs::write(out.join("summary.md"), summary(study)).expect("summary.md is written");
    let charts: [(&str, (u32, u32), Draw); 4] = [
        ("mechanism", (1000, 900), &|p| {
            render(p, (1000, 900), &Mechanism(study)).map_err(|e| e.to_string())
        }),
        ("threshold_map", (1000, 700), &|p| {
            render(p, (1000, 700), &ThresholdMap(study)).map_err(|e| e.to_string())
        }),
        ("sensitivity", (1000, 800), &|p| {
            render(p, (1000, 800), &SensitivityFigure(study)).map_err(|e| e.to_string())
        }),
        ("unbalance", (1000, 600), &|p| {
            render(p, (1000, 600), &UnbalanceFigure(study)).map_err(|e| e.to_string())
        }),
    ];
    for (stem, _, draw) in charts {
        for ext in ["png", "svg"] {
            let p = out.join(format!("{stem}.{ext}"));
            draw(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            println!("{}", p.display());
        }
    }
}

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("none".to_string(), |x| format!("{x:.digits$}"))
}

/// The tables the docs quote.
fn summary(s: &Study) -> String {
    let mut md = String::from("# Physics study (`cargo run --release --example physics`)\n\n");
    md.push_str("## Mechanism: mu 0.35, paths against the 30 000 r/min path\n\n");
    md.push_str("| release speed (r/min) | race first rolls at (ms) | leaves the 30 000 r/min path at (ms, > 5 um) | class |\n|---|---|---|---|\n");
    for t in &s.slip_traces {
        md.push_str(&format!(
            "| {:.0} | {} | {} | {} |\n",
            t.speed_rpm,
            fmt_opt(t.lock_ms, 1),
            fmt_opt(t.diverges_from_30000_ms, 1),
            t.class.map_or("failed", |c| c.name())
        ));
    }
    md.push_str("\n## Contact-angle traces at 16 000 r/min\n\n| mu | race first rolls at (ms) | class |\n|---|---|---|\n");
    for t in &s.angle_traces {
        md.push_str(&format!(
            "| {} | {} | {} |\n",
            t.mu,
            fmt_opt(t.lock_ms, 1),
            t.class.map_or("failed", |c| c.name())
        ));
    }
    md.push_str("\n## Threshold map (W whirl, . pendulum, b bouncing, u unresolved, x failed)\n\n```\nspeed \\ mu ");
    md.push_str(
        &s.map_mu
            .iter()
            .map(|m| format!("{m}"))
            .collect::<Vec<_>>()
            .join(" "),
    );
    md.push('\n');
    let n = s.map_mu.len();
    for (i, v) in s.map_speed_rpm.iter().enumerate() {
        let row: String = s.map_class[i * n..(i + 1) * n]
            .iter()
            .map(|c| match c {
                Some(c) if c.is_whirl() => 'W',
                Some(OrbitClass::Pendulum) => '.',
                Some(OrbitClass::Bouncing) => 'b',
                Some(_) => 'u',
                None => 'x',
            })
            .collect();
        md.push_str(&format!("{v:>6.0}  {row}\n"));
    }
    md.push_str("```\n\n## Sensitivities\n\nThreshold: the lowest mu (scanned 0.25 to 0.40 in 0.005 at 16 000 r/min) above which every mu whirls; islands: whirling mu below it. Onset: the critical-speed search from 1 000 to 16 000 r/min (lattice 250, tolerance 25 r/min).\n\n| parameter | value | threshold mu | islands | onset at mu 0.35 | onset at mu 0.4 | onset at mu 0.5 |\n|---|---|---|---|---|---|---|\n");
    for r in &s.sensitivities {
        let onset = |mu: f64| {
            r.onset_rpm
                .iter()
                .find(|(m, _)| *m == mu)
                .and_then(|(_, o)| *o)
        };
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            r.parameter,
            r.value,
            fmt_opt(r.threshold_mu, 3),
            if r.islands_mu.is_empty() {
                "-".to_string()
            } else {
                r.islands_mu
                    .iter()
                    .map(|m| format!("{m}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
            fmt_opt(onset(0.35), 0),
            fmt_opt(onset(0.4), 0),
            fmt_opt(onset(0.5), 0),
        ));
    }
    md.push_str("\n## Unbalance at 8 000 r/min: whirling phases of 16\n\n| unbalance (um) |");
    for mu in UNBALANCE_MUS {
        md.push_str(&format!(" mu {mu} |"));
    }
    md.push_str(&format!("\n|---|{}\n", "---|".repeat(UNBALANCE_MUS.len())));
    for chunk in s.unbalance.chunks(UNBALANCE_MUS.len()) {
        md.push_str(&format!("| {} |", chunk[0].unbalance_m * 1e6));
        for r in chunk {
            md.push_str(&format!(" {} |", r.whirl));
        }
        md.push('\n');
    }
    md
}

// ---------------------------------------------------------------------------------------------
// Charts.

const COLOURS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
];

/// Splits `points` into runs without NaN.
fn runs(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![Vec::new()];
    for p in points {
        if p.1.is_finite() {
            out.last_mut().expect("one run").push(p);
        } else if !out.last().expect("one run").is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

struct Mechanism<'a>(&'a Study);

impl Figure for Mechanism<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(
            root,
            TITLE_BAND,
            "What decides whirl: the symmetric release while the race slips",
            TITLE_FONT,
        )?;
        let (top, bottom) = body.split_vertically(body.dim_in_pixel().1 / 2);
        // Top: contact-angle traces at 16 000 r/min.
        let (plot, leg) = top.split_vertically(top.dim_in_pixel().1 - 40);
        const T_END: f64 = 60.0;
        let (a_lo, a_hi) = (-400.0, 120.0);
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(0.0..T_END, a_lo..a_hi)?;
        draw_mesh(
            &mut chart,
            "time after release (ms), 16 000 r/min",
            "contact angle from the bottom (deg)",
            6,
            6,
        )?;
        for (y, text) in [
            (-90.0, "side of the race (-90 deg)"),
            (90.0, "side of the race (+90 deg)"),
        ] {
            chart.draw_series([DashedPathElement::new(
                vec![(0.0, y), (T_END, y)],
                5,
                5,
                RGBColor(120, 120, 120).stroke_width(1),
            )])?;
            chart.draw_series([Text::new(
                text,
                (0.5, y + 4.0),
                whirlmap_plot::render::text_style(13.0),
            )])?;
        }
        let mut entries = Vec::new();
        for (k, t) in self.0.angle_traces.iter().enumerate() {
            let c = COLOURS[k % COLOURS.len()];
            let pts = t
                .t_ms
                .iter()
                .copied()
                .zip(t.angle_deg.iter().copied())
                .filter(|p| p.0 <= T_END);
            for r in runs(pts) {
                chart.draw_series([PathElement::new(
                    r.into_iter()
                        .map(|(x, y)| (x, y.clamp(a_lo, a_hi)))
                        .collect::<Vec<_>>(),
                    c.stroke_width(2),
                )])?;
            }
            // Where the race first rolls on this trace.
            if let Some(l) = t.lock_ms.filter(|l| *l <= T_END) {
                let i = t.t_ms.partition_point(|x| *x < l).min(t.t_ms.len() - 1);
                let a = t.angle_deg[i];
                if a.is_finite() {
                    chart.draw_series([Circle::new((l, a.clamp(a_lo, a_hi)), 5, c.filled())])?;
                }
            }
            entries.push((
                Mark::Line(c),
                format!("mu {} ({})", t.mu, t.class.map_or("failed", |c| c.label())),
            ));
        }
        entries.push((
            Mark::Dot(RGBColor(90, 90, 90)),
            "the race first rolls".into(),
        ));
        legend(&leg, &entries)?;
        // Bottom: slip velocity at mu 0.35 for several speeds.
        let (plot, leg) = bottom.split_vertically(bottom.dim_in_pixel().1 - 40);
        let slip_top = self
            .0
            .slip_traces
            .iter()
            .flat_map(|t| t.slip_m_s.iter().copied())
            .fold(1.0_f64, f64::max)
            * 1.05;
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(0.0..T_END, -1.0..slip_top)?;
        draw_mesh(
            &mut chart,
            "time after release (ms), mu 0.35",
            "slip velocity at the contact (m/s)",
            6,
            6,
        )?;
        let mut entries = Vec::new();
        for (k, t) in self.0.slip_traces.iter().enumerate() {
            let c = COLOURS[k % COLOURS.len()];
            chart.draw_series([PathElement::new(
                t.t_ms
                    .iter()
                    .copied()
                    .zip(t.slip_m_s.iter().map(|v| v.clamp(-1.0, slip_top)))
                    .filter(|p| p.0 <= T_END)
                    .collect::<Vec<_>>(),
                c.stroke_width(2),
            )])?;
            if let Some(l) = t.lock_ms {
                chart.draw_series([Circle::new((l, 0.0), 5, c.filled())])?;
            }
            entries.push((
                Mark::Line(c),
                format!(
                    "{:.0} r/min: rolls at {} ms, {}",
                    t.speed_rpm,
                    fmt_opt(t.lock_ms, 1),
                    t.class.map_or("failed", |c| c.label())
                ),
            ));
        }
        legend(&leg, &entries)
    }
}

struct ThresholdMap<'a>(&'a Study);

impl Figure for ThresholdMap<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let s = self.0;
        let body = with_header(
            root,
            TITLE_BAND,
            "Orbit class over friction and speed, symmetric release",
            TITLE_FONT,
        )?;
        let (plot, leg) = body.split_vertically(body.dim_in_pixel().1 - 40);
        let (dm, dv) = (
            s.map_mu[1] - s.map_mu[0],
            s.map_speed_rpm[1] - s.map_speed_rpm[0],
        );
        let (m0, m1) = (
            s.map_mu[0] - dm / 2.0,
            s.map_mu[s.map_mu.len() - 1] + dm / 2.0,
        );
        let (v0, v1) = (
            s.map_speed_rpm[0] - dv / 2.0,
            s.map_speed_rpm[s.map_speed_rpm.len() - 1] + dv / 2.0,
        );
        let mut chart = ChartBuilder::on(&plot)
            .margin(10)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(m0..m1, v0..v1)?;
        draw_mesh(
            &mut chart,
            "friction coefficient µ (-)",
            "release speed (r/min)",
            10,
            8,
        )?;
        let n = s.map_mu.len();
        chart.draw_series(s.map_class.iter().enumerate().map(|(k, c)| {
            let (m, v) = (s.map_mu[k % n], s.map_speed_rpm[k / n]);
            let colour = c.map_or(RGBColor(0, 0, 0), class_colour);
            Rectangle::new(
                [(m - dm / 2.0, v - dv / 2.0), (m + dm / 2.0, v + dv / 2.0)],
                colour.filled(),
            )
        }))?;
        let seen: Vec<OrbitClass> = OrbitClass::ALL
            .into_iter()
            .filter(|c| s.map_class.contains(&Some(*c)))
            .collect();
        let entries: Vec<(Mark, String)> = seen
            .iter()
            .map(|c| (Mark::Swatch(class_colour(*c)), c.label().to_string()))
            .collect();
        legend(&leg, &entries)
    }
}

struct SensitivityFigure<'a>(&'a Study);

impl Figure for SensitivityFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(
            root,
            TITLE_BAND,
            "Friction threshold and onset speed against support damping and load share",
            TITLE_FONT,
        )?;
        let panels = body.split_evenly((2, 2));
        let groups = [
            ("support_damping_n_s_per_m", "support damping c2 (N s/m)"),
            ("load_share", "load share (-)"),
        ];
        for (col, (name, desc)) in groups.iter().enumerate() {
            let rows: Vec<&Sensitivity> = self
                .0
                .sensitivities
                .iter()
                .filter(|r| r.parameter == *name)
                .collect();
            let (x0, x1) = (
                rows.first().map_or(0.0, |r| r.value),
                rows.last().map_or(1.0, |r| r.value),
            );
            let pad = (x1 - x0) * 0.08;
            // Threshold.
            let mut chart = ChartBuilder::on(&panels[col])
                .margin(14)
                .x_label_area_size(X_LABEL_AREA)
                .y_label_area_size(Y_LABEL_AREA)
                .build_cartesian_2d((x0 - pad)..(x1 + pad), 0.25..0.40)?;
            draw_mesh(&mut chart, desc, "friction threshold µ (-)", 6, 6)?;
            let paper = if *name == "load_share" { 0.5 } else { 750.0 };
            chart.draw_series([DashedPathElement::new(
                vec![(paper, 0.25), (paper, 0.40)],
                5,
                5,
                RGBColor(120, 120, 120).stroke_width(1),
            )])?;
            chart.draw_series([Text::new(
                "paper scene",
                (paper, 0.395),
                whirlmap_plot::render::text_style(13.0),
            )])?;
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter_map(|r| r.threshold_mu.map(|t| (r.value, t)))
                .collect();
            chart.draw_series([PathElement::new(pts.clone(), COLOURS[3].stroke_width(2))])?;
            chart.draw_series(pts.iter().map(|p| Circle::new(*p, 5, COLOURS[3].filled())))?;
            // Onset speeds.
            let mut chart = ChartBuilder::on(&panels[2 + col])
                .margin(14)
                .x_label_area_size(X_LABEL_AREA)
                .y_label_area_size(Y_LABEL_AREA)
                .build_cartesian_2d((x0 - pad)..(x1 + pad), 0.0..8000.0)?;
            draw_mesh(&mut chart, desc, "onset speed (r/min)", 6, 8)?;
            for (k, mu) in [0.35, 0.4, 0.5].into_iter().enumerate() {
                let pts: Vec<(f64, f64)> = rows
                    .iter()
                    .filter_map(|r| {
                        r.onset_rpm
                            .iter()
                            .find(|(m, _)| *m == mu)
                            .and_then(|(_, o)| o.map(|o| (r.value, o)))
                    })
                    .collect();
                let c = COLOURS[k];
                chart.draw_series([PathElement::new(pts.clone(), c.stroke_width(2))])?;
                chart
                    .draw_series(pts.iter().map(|p| Circle::new(*p, 5, c.filled())))?
                    .label(format!("mu {mu}"))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.8))
                .border_style(RGBColor(150, 150, 150))
                .label_font(whirlmap_plot::render::text_style(14.0))
                .draw()?;
        }
        Ok(())
    }
}

struct UnbalanceFigure<'a>(&'a Study);

impl Figure for UnbalanceFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(
            root,
            TITLE_BAND,
            "Share of 16 unbalance phases that whirl at 8 000 r/min",
            TITLE_FONT,
        )?;
        let (plot, leg) = body.split_vertically(body.dim_in_pixel().1 - 40);
        let mut chart = ChartBuilder::on(&plot)
            .margin(14)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(0.24..0.36, -0.02..1.02)?;
        draw_mesh(
            &mut chart,
            "friction coefficient µ (-)",
            "share whirling (-)",
            6,
            6,
        )?;
        let mut entries = Vec::new();
        // Largest unbalance first, so the balanced rotor's line is drawn on top.
        let chunks: Vec<&[UnbalanceRow]> = self.0.unbalance.chunks(UNBALANCE_MUS.len()).collect();
        for (k, chunk) in chunks.iter().enumerate().rev() {
            let c = if k == 0 {
                RGBColor(0, 0, 0)
            } else {
                COLOURS[k % COLOURS.len()]
            };
            let pts: Vec<(f64, f64)> = chunk
                .iter()
                .map(|r| (r.mu, r.whirl as f64 / r.phases as f64))
                .collect();
            if k == 0 {
                chart.draw_series([DashedPathElement::new(
                    pts.clone(),
                    6,
                    4,
                    c.stroke_width(2),
                )])?;
            } else {
                chart.draw_series([PathElement::new(pts.clone(), c.stroke_width(2))])?;
            }
            chart.draw_series(pts.iter().map(|p| Circle::new(*p, 5, c.filled())))?;
        }
        for (k, chunk) in chunks.iter().enumerate() {
            let c = if k == 0 {
                RGBColor(0, 0, 0)
            } else {
                COLOURS[k % COLOURS.len()]
            };
            let mark = if k == 0 {
                Mark::Dashed(c)
            } else {
                Mark::Line(c)
            };
            entries.push((mark, format!("unbalance {} µm", chunk[0].unbalance_m * 1e6)));
        }
        legend(&leg, &entries)
    }
}
