//! `solver.race_velocity_atol_from_force`: while the contact carries load, the race's velocity
//! tolerance is widened to `rtol F_n / max(c1, c2)`, the size of a velocity error that moves the
//! contact damper's force (eq. 7) by `rtol` of the contact force.
// `!(x < bound)` so a NaN fails.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use whirlmap_core::model::{ix, DropSystem, Mode, Slip, N};
use whirlmap_core::ode::OdeSystem;
use whirlmap_core::{simulate, DropOptions, DropReport, Fidelity, Scene};

/// A state with the rotor pressed `delta` into the race straight below the centre, both at
/// rest (the race at its static sag), in contact mode.
fn pressed(s: &Scene, delta_m: f64) -> (DropSystem, [f64; N]) {
    let mut sys = DropSystem::new(s);
    let mut y = sys.initial_state(0.0);
    y[ix::YR] = y[ix::YB] - s.clearance_m - delta_m;
    sys.mode = Mode {
        contact: true,
        support: true,
        slip: Slip::Slipping(1.0),
    };
    (sys, y)
}

/// Free flight keeps the tolerances; a loaded contact widens exactly the race's two velocity
/// components to `rtol F_n / max(c1, c2)`; a lightly loaded one, where that is below the base, keeps
/// them (the tolerance is never narrowed); with the option off, the radial-only support
/// damper or no support damping nothing changes.
#[test]
fn only_the_race_velocity_is_widened_and_only_as_far_as_the_contact_force_allows() {
    let s = Scene::paper();
    let rtol = s.solver.rtol;
    // The larger of the two dampers that read the race's velocity (c1 here).
    let c = s.contact_damping_n_s_per_m.max(s.support_damping_n_s_per_m);
    let base = [1e-9; N];

    let mut sys = DropSystem::new(&s);
    let y = sys.initial_state(1000.0);
    assert_eq!(sys.loosened_atol(0.0, &y, &base), None, "free flight");

    // About the first impact's force (2 um into the contact: ~1 kN).
    let (sys, y) = pressed(&s, 2e-6);
    let f_n = sys.forces(&y).normal_n;
    assert!(f_n > 500.0, "{f_n}");
    let wide = sys
        .loosened_atol(0.0, &y, &base)
        .expect("widened in contact");
    for i in 0..N {
        let expected = if i == ix::VXB || i == ix::VYB {
            rtol * f_n / c
        } else {
            base[i]
        };
        assert_eq!(wide[i], expected, "component {i}");
    }

    // A contact mode whose force has turned negative (the rotor lifting off, before the guard
    // ends the mode): nothing to widen, and no negative tolerance.
    let (sys, y) = pressed(&s, -1e-7);
    assert!(sys.forces(&y).normal_n < 0.0);
    assert_eq!(sys.loosened_atol(0.0, &y, &base), None, "negative force");

    // A force whose rtol share is below the base: nothing to widen.
    let (sys, y) = pressed(&s, 1e-12);
    let f_n = sys.forces(&y).normal_n;
    assert!(rtol * f_n / c < 1e-9, "{f_n}");
    assert_eq!(sys.loosened_atol(0.0, &y, &base), None, "light contact");

    // The option off (as in the draft and reference presets).
    let mut off = s.clone();
    off.solver.race_velocity_atol_from_force = false;
    let (sys, y) = pressed(&off, 2e-6);
    assert_eq!(sys.loosened_atol(0.0, &y, &base), None, "option off");
    // The radial-only damper leaves the race's tangential vibration undamped: not widened.
    let mut radial = s.clone();
    radial.support_damper = whirlmap_core::SupportDamper::RadialOnly;
    let (sys, y) = pressed(&radial, 2e-6);
    assert_eq!(
        sys.loosened_atol(0.0, &y, &base),
        None,
        "radial-only damper"
    );
    // Nor with no support damping at all.
    let mut undamped = s.clone();
    undamped.support_damping_n_s_per_m = 0.0;
    let (sys, y) = pressed(&undamped, 2e-6);
    assert_eq!(sys.loosened_atol(0.0, &y, &base), None, "c2 = 0");
    for f in [Fidelity::Draft, Fidelity::Reference] {
        assert!(!f.solver().race_velocity_atol_from_force, "{f}");
    }
    assert!(Fidelity::Standard.solver().race_velocity_atol_from_force);
}

fn run(s: &Scene) -> DropReport {
    simulate(s, &DropOptions::default()).unwrap()
}

/// At the standard numerics, with and without the option, a pendulum drop and a whirl drop
/// stay within the accuracy budget of the reference (first and maximum contact force and
/// peak heat power within 0.1 %, whirl frequency within 1 %, the same class), and the option
/// takes fewer steps: the race's velocity no longer sets the step in sustained contact.
/// (Both cases are well conditioned: moving the release point by 1 nm changes these outputs
/// by less than 1e-5, results/accuracy/accuracy.md.)
#[test]
fn the_widened_tolerance_keeps_the_budget_and_takes_fewer_steps() {
    for (speed, mu) in [(8000.0, 0.1), (8000.0, 0.4)] {
        let mut s = Scene::paper();
        s.speed_rpm = speed;
        s.mu_dynamic = mu;
        let reference = run(&Fidelity::Reference.applied(&s));
        let mut steps = Vec::new();
        for on in [false, true] {
            let mut t = s.clone();
            t.solver.race_velocity_atol_from_force = on;
            let r = run(&t);
            let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
            let (f, g) = (&r.features, &reference.features);
            for (what, e) in [
                (
                    "first force",
                    rel(f.first_contact_force_n, g.first_contact_force_n),
                ),
                (
                    "max force",
                    rel(f.max_contact_force_n, g.max_contact_force_n),
                ),
                ("peak heat", rel(f.peak_heat_power_w, g.peak_heat_power_w)),
            ] {
                assert!(e < 1e-3, "mu {mu} option {on}: {what} off by {e:e}");
            }
            assert_eq!(r.verdict.class, reference.verdict.class, "mu {mu} {on}");
            if g.whirl_frequency_hz.abs() > 10.0 {
                let e = rel(f.whirl_frequency_hz, g.whirl_frequency_hz);
                assert!(
                    e < 1e-2,
                    "mu {mu} option {on}: whirl frequency off by {e:e}"
                );
            }
            steps.push(r.stats.steps);
        }
        assert!(
            steps[1] < steps[0],
            "mu {mu}: {} steps with the option against {} without",
            steps[1],
            steps[0]
        );
    }
}
