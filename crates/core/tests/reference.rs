//! The independent integrator and the reduced model on real drops.

use whirlmap_core::{simulate, DropOptions, Method, Scene};

/// A drop of exactly `duration_s` (the classifier's extension off: these tests compare
/// integrators and models over the same span).
fn drop(scene: &Scene, duration_s: f64) -> whirlmap_core::DropReport {
    let mut scene = scene.clone();
    scene.classification.max_extension_s = 0.0;
    simulate(
        &scene,
        &DropOptions {
            duration_s,
            ..Default::default()
        },
    )
    .unwrap()
}

#[test]
fn dop853_confirms_dopri5_on_the_first_impacts() {
    let mut s = Scene::paper();
    s.mu_dynamic = 0.3;
    s.solver.rtol = 1e-9;
    let a = drop(&s, 0.02);
    s.solver.method = Method::Dop853;
    let b = drop(&s, 0.02);
    let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
    let (fa, fb) = (&a.features, &b.features);
    let errs = [
        rel(fa.first_contact_force_n, fb.first_contact_force_n),
        rel(fa.max_contact_force_n, fb.max_contact_force_n),
        rel(fa.peak_heat_power_w, fb.peak_heat_power_w),
    ];
    eprintln!("DOPRI5 vs DOP853 at rtol 1e-9: {errs:?}");
    // Measured here (and in the accuracy study): 4.3e-7 in the forces, 8.8e-7 in peak heat
    // at mu 0.3 (the study's DOPRI5-vs-DOP853 gap at rtol 1e-10 is 1e-11 to 1e-7). The bound
    // is about 6 times the largest measured value.
    assert!(errs.iter().all(|e| *e < 5e-6), "{errs:?}");
    assert_eq!(a.stats.events, b.stats.events, "the same mode switches");
    // Eighth order takes far fewer steps for the same tolerance. Measured: 1.93x fewer with
    // the isotropic support damper (2579 against 1339 steps; more than 2x with the
    // radial-only damper, whose undamped race ringing costs the lower order more). The
    // bound, 1.5x, is a property of the order, not of this drop; the steppers' harness
    // (`tests/steppers.rs`) checks the order itself.
    assert!(
        b.stats.steps * 3 < a.stats.steps * 2,
        "{:?} {:?}",
        a.stats,
        b.stats
    );
}

#[test]
fn quasi_static_race_closes_the_energy_audit_and_lands_near_the_full_model() {
    let mut s = Scene::paper();
    s.solver.rtol = 1e-7;
    let full = drop(&s, 0.05);
    s.quasi_static_race = true;
    let qs = drop(&s, 0.05);
    // The split damper dissipates exactly c1 delta'^2 + c2 r'^2: the audit closes to
    // integration error.
    assert!(qs.energy.residual_rel < 1e-7, "{:?}", qs.energy);
    // Without the race's 48 g in the impact the peak is higher, by about the mass ratio.
    let rel = qs.features.first_contact_force_n / full.features.first_contact_force_n - 1.0;
    assert!(rel > 0.0 && rel < 0.02, "{rel}");
    // The race centre never moves in the state: its displacement lives in the split.
    assert_eq!(qs.final_state[3], 0.0);
    assert_eq!(qs.final_state[4], 0.0);
}
