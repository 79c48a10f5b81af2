//! Stability at the extremes: a matrix of scenes at the edges of the supported input ranges,
//! each of which must finish with finite results and a passing energy audit, or fail with a
//! typed solver error within its step budget. Never NaN, never a hang.
//!
//! The reduced matrix runs in CI (`tests/extremes.rs`); the full one is
//! `cargo run --release --example extremes`, whose results
//! docs/accuracy.md#stability-at-the-extremes records.

use crate::run::{run_drop, DropFailure};
use serde::Serialize;
use std::time::Instant;
use whirlmap_core::{DropOptions, DropReport, Scene};

/// One point of the matrix.
#[derive(Debug, Clone)]
pub struct ExtremePoint {
    /// What is extreme, e.g. `speed 100000 r/min`.
    pub name: String,
    /// The scene.
    pub scene: Scene,
    /// Simulated time (s).
    pub duration_s: f64,
}

/// What a point gave.
#[derive(Debug, Clone, Serialize)]
pub struct ExtremeOutcome {
    /// The point's name.
    pub name: String,
    /// Simulated time asked for (s).
    pub duration_s: f64,
    /// `ok`, or the typed error kind (`step_budget`, `step_size_underflow`, ...).
    pub status: String,
    /// Simulated time reached (s), when it finished.
    pub end_time_s: Option<f64>,
    /// Step attempts (accepted + rejected), when it finished.
    pub attempts: Option<u64>,
    /// Energy audit residual, when it finished.
    pub residual_rel: Option<f64>,
    /// The bound the residual was held to.
    pub residual_bound: Option<f64>,
    /// Wall time (ms).
    pub wall_ms: f64,
    /// Violations of the contract (empty when the point passes).
    pub problems: Vec<String>,
}

fn point(name: impl Into<String>, duration_s: f64, f: impl FnOnce(&mut Scene)) -> ExtremePoint {
    let mut scene = Scene::paper();
    f(&mut scene);
    ExtremePoint {
        name: name.into(),
        scene,
        duration_s,
    }
}

/// The matrix: every axis of the issue one at a time at its extremes (and, in the full
/// matrix, intermediate levels), plus corners where extremes meet. `full` adds levels,
/// longer runs and the 60 s drop; the reduced matrix keeps CI under a minute.
pub fn matrix(full: bool) -> Vec<ExtremePoint> {
    let d = if full { 1.0 } else { 0.03 };
    let mut v = Vec::new();
    let pick = |reduced: &[f64], all: &[f64]| if full { all.to_vec() } else { reduced.to_vec() };
    for s in pick(
        &[0.0, 100_000.0],
        &[0.0, 1.0, 1000.0, 30_000.0, 60_000.0, 100_000.0],
    ) {
        v.push(point(format!("speed {s} r/min"), d, |sc| sc.speed_rpm = s));
    }
    for m in pick(&[0.0, 2.0], &[0.0, 0.5, 1.0, 2.0]) {
        v.push(point(format!("mu {m}"), d, |sc| sc.mu_dynamic = m));
    }
    for c in pick(&[1e-6, 5e-3], &[1e-6, 1e-5, 1e-3, 5e-3]) {
        v.push(point(format!("clearance {c} m"), d, |sc| {
            sc.clearance_m = c
        }));
    }
    for k in pick(&[1e-3, 1e3], &[1e-3, 1e-2, 1e2, 1e3]) {
        v.push(point(format!("stiffness x{k} (both)"), d, |sc| {
            sc.contact_stiffness_n_per_m_e *= k;
            sc.support_stiffness_n_per_m_e *= k;
        }));
    }
    for c in pick(&[0.0, 100.0], &[0.0, 0.1, 10.0, 100.0]) {
        v.push(point(format!("damping x{c} (both)"), d, |sc| {
            sc.contact_damping_n_s_per_m *= c;
            sc.support_damping_n_s_per_m *= c;
        }));
    }
    for m in pick(&[0.01, 100.0], &[0.01, 0.1, 10.0, 100.0]) {
        v.push(point(format!("masses x{m} (rotor, race)"), d, |sc| {
            sc.rotor_mass_kg *= m;
            sc.rotor_polar_moi_kg_m2 *= m;
            sc.race_mass_kg *= m;
            sc.race_polar_moi_kg_m2 *= m;
        }));
    }
    for e in pick(&[100e-6], &[1e-6, 10e-6, 100e-6]) {
        v.push(point(format!("unbalance {e} m"), d, |sc| {
            sc.unbalance_m = e
        }));
    }
    v.push(point("duration 1 ms", 1e-3, |_| {}));
    // Corners: extremes that meet.
    v.push(point("speed 100000 r/min, mu 2", d, |sc| {
        sc.speed_rpm = 100_000.0;
        sc.mu_dynamic = 2.0;
    }));
    v.push(point("clearance 1 um, unbalance 10 um, mu 2", d, |sc| {
        sc.clearance_m = 1e-6;
        sc.unbalance_m = 10e-6;
        sc.mu_dynamic = 2.0;
    }));
    // The stiffest corner: about 8 million attempts per simulated second.
    let d_stiff = if full { 0.1 } else { 0.01 };
    v.push(point(
        "stiffness x1000, damping 0, race mass x0.01",
        d_stiff,
        |sc| {
            sc.contact_stiffness_n_per_m_e *= 1e3;
            sc.support_stiffness_n_per_m_e *= 1e3;
            sc.contact_damping_n_s_per_m = 0.0;
            sc.support_damping_n_s_per_m = 0.0;
            sc.race_mass_kg *= 0.01;
            sc.race_polar_moi_kg_m2 *= 0.01;
        },
    ));
    v.push(point("draft preset, speed 100000 r/min, mu 2", d, |sc| {
        whirlmap_core::Fidelity::Draft.apply(sc);
        sc.speed_rpm = 100_000.0;
        sc.mu_dynamic = 2.0;
    }));
    if full {
        v.push(point(
            "stiffness x0.001, clearance 5 mm, masses x100",
            1.0,
            |sc| {
                sc.contact_stiffness_n_per_m_e *= 1e-3;
                sc.support_stiffness_n_per_m_e *= 1e-3;
                sc.clearance_m = 5e-3;
                sc.rotor_mass_kg *= 100.0;
                sc.rotor_polar_moi_kg_m2 *= 100.0;
            },
        ));
        v.push(point("duration 60 s (paper scene)", 60.0, |_| {}));
        v.push(point("duration 60 s, draft preset", 60.0, |sc| {
            whirlmap_core::Fidelity::Draft.apply(sc)
        }));
    }
    v
}

/// The energy audit bound of the extremes contract. The audit's residual is integration
/// error, relative to the largest energy in play: about rtol of that energy, plus the error
/// of the race's elastic energy, which is integrated to `race_atol_scale` times looser
/// absolute tolerances: relative to the clearance, its position tolerance is
/// `rtol * race_atol_scale * position_scale_m / clearance_m` of the drop energy m_r g s.
/// The bound is 10 times both (at the standard numerics and speed 0, where m_r g s is the
/// scale, the measured residual is 4.1e-3 against a bound of 7.7e-3; with spin, 1e-5 or
/// less against 1e-3).
pub fn audit_bound(s: &Scene, r: &DropReport) -> f64 {
    let e = &r.energy;
    let drop_energy = s.rotor_mass_kg * s.load_share * s.gravity_m_s2 * s.clearance_m;
    let scale = e
        .initial_j
        .abs()
        .max(e.final_j.abs())
        .max((e.friction_heat_j + e.damping_loss_j + e.drag_work_j).abs())
        .max(drop_energy);
    let v = &s.solver;
    let race = v.rtol * v.race_atol_scale * v.position_scale_m / s.clearance_m;
    10.0 * v.rtol + 10.0 * race * drop_energy / scale
}

/// Runs one point and checks the contract.
pub fn run_point(p: &ExtremePoint) -> ExtremeOutcome {
    let opts = DropOptions {
        duration_s: p.duration_s,
        ..Default::default()
    };
    let t = Instant::now();
    let out = run_drop(&p.scene, &opts);
    let wall_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut o = ExtremeOutcome {
        name: p.name.clone(),
        duration_s: p.duration_s,
        status: String::new(),
        end_time_s: None,
        attempts: None,
        residual_rel: None,
        residual_bound: None,
        wall_ms,
        problems: Vec::new(),
    };
    let r = match out {
        Err(DropFailure::Panic(m)) => {
            o.status = "panic".into();
            o.problems.push(format!("simulate panicked: {m}"));
            return o;
        }
        Err(DropFailure::Solve(e)) => {
            o.status = e.kind().into();
            if matches!(e, whirlmap_core::SolveError::Invalid(_)) {
                o.problems.push(format!("a valid scene was rejected: {e}"));
            }
            return o;
        }
        Ok(r) => r,
    };
    o.status = "ok".into();
    o.end_time_s = Some(r.end_time_s);
    let attempts = r.stats.steps + r.stats.rejected;
    o.attempts = Some(attempts);
    o.residual_rel = Some(r.energy.residual_rel);
    let bound = audit_bound(&p.scene, &r);
    o.residual_bound = Some(bound);
    let f = &r.features;
    let e = &r.energy;
    for (what, v) in [
        ("first_contact_force_n", f.first_contact_force_n),
        ("max_contact_force_n", f.max_contact_force_n),
        ("peak_friction_power_w", f.peak_friction_power_w),
        ("peak_heat_power_w", f.peak_heat_power_w),
        ("contact_time_s", f.contact_time_s),
        ("net_whirl_turns", f.net_whirl_turns),
        ("whirl_frequency_hz", f.whirl_frequency_hz),
        ("window.contact_duty", f.window.stats.contact_duty),
        ("final_rotor_speed_rpm", f.final_rotor_speed_rpm),
        ("final_race_speed_rpm", f.final_race_speed_rpm),
        ("initial_j", e.initial_j),
        ("final_j", e.final_j),
        ("friction_heat_j", e.friction_heat_j),
        ("damping_loss_j", e.damping_loss_j),
        ("drag_work_j", e.drag_work_j),
        ("residual_rel", e.residual_rel),
        ("end_time_s", r.end_time_s),
    ] {
        if !v.is_finite() {
            o.problems.push(format!("{what} = {v}"));
        }
    }
    if r.final_state.iter().any(|v| !v.is_finite()) {
        o.problems.push("non-finite final state".into());
    }
    if attempts > p.scene.solver.max_step_attempts {
        o.problems.push(format!("over the step budget: {attempts}"));
    }
    if !(e.residual_rel < bound) {
        o.problems.push(format!(
            "energy audit residual {:e} > bound {bound:e}",
            e.residual_rel
        ));
    }
    o
}
