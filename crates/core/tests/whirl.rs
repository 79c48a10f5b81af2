//! Whirl on real drops: the classifier decides the settled motion, not the transient, and the
//! mechanism behind the friction threshold (docs/whirl-physics.md) holds.

use whirlmap_core::orbit::OrbitSample;
use whirlmap_core::{simulate, DropOptions, OrbitClass, Reason, Scene};

fn scene(speed_rpm: f64, mu: f64) -> Scene {
    let mut s = Scene::paper();
    s.speed_rpm = speed_rpm;
    s.mu_dynamic = mu;
    s
}

fn drop(s: &Scene) -> whirlmap_core::DropReport {
    simulate(s, &DropOptions::default()).expect("the drop runs")
}

/// Transient turns against the spin, then rocking in the bottom of the race: a pendulum with
/// the turns reported as a feature. Both cases were classed whirl or unresolved by counting
/// turns since first touch on unwrapped angles.
#[test]
fn transient_turns_then_rocking_is_pendulum_with_the_turns_as_a_feature() {
    for (speed, mu) in [(4000.0, 0.4), (4200.0, 0.35), (5000.0, 0.35)] {
        let r = drop(&scene(speed, mu));
        let f = &r.features;
        assert_eq!(
            r.verdict.class,
            OrbitClass::Pendulum,
            "{speed} r/min mu {mu}: {:?} {f:?}",
            r.verdict
        );
        assert_eq!(r.verdict.reason, Reason::SettledRocking);
        // The window's circular mean sits at the bottom even after whole turns.
        assert!(f.window.stats.angle_mean_rad.abs() < 0.3, "{f:?}");
        if (speed, mu) != (4200.0, 0.35) {
            assert!(
                f.transient_whirl_turns < -1.0,
                "{speed} r/min mu {mu}: transient turns {}",
                f.transient_whirl_turns
            );
        }
    }
}

/// Sustained whirl is decided by consecutive carried turns and the run stops there.
#[test]
fn sustained_whirl_is_decided_by_consecutive_carried_turns() {
    let r = drop(&scene(8000.0, 0.4));
    assert_eq!(r.verdict.class, OrbitClass::BackwardWhirl);
    assert_eq!(r.verdict.reason, Reason::WhirlTurns);
    assert!(r.end_time_s < 0.2, "stopped early: {}", r.end_time_s);
    assert_eq!(r.features.whirl_streak_turns, -5.0);
    assert!(r.features.whirl_frequency_hz < -50.0);
}

/// The rotor's path relative to the race at two release speeds, sampled at the same times.
fn path(speed_rpm: f64, mu: f64, duration_s: f64) -> Vec<OrbitSample> {
    let mut s = scene(speed_rpm, mu);
    s.classification.max_extension_s = 0.0;
    s.whirl_stop_turns = 1e6;
    let o = DropOptions {
        duration_s,
        orbit_points: Some(2000),
        ..Default::default()
    };
    simulate(&s, &o).unwrap().orbit.unwrap().samples
}

/// While the contact slips, Coulomb friction does not depend on the slip speed, so the
/// rotor's translation is the same at every release speed until the race first rolls: paths
/// at 16 000 and 30 000 r/min agree while both still slip, and the 4000 r/min path leaves
/// them once its race rolls.
#[test]
fn while_the_contact_slips_the_release_speed_does_not_change_the_path() {
    let a = path(16_000.0, 0.35, 0.03);
    let b = path(30_000.0, 0.35, 0.03);
    let c = path(4000.0, 0.35, 0.03);
    let rolls = |s: &[OrbitSample]| {
        s.iter()
            .skip_while(|p| p.contact_force_n <= 0.0)
            .find(|p| p.slip_m_s.abs() < 1e-3)
            .map(|p| p.t_s)
    };
    // At 16 000 r/min the race does not roll within these 30 ms (it rolls at 33 ms).
    assert_eq!(rolls(&a), None);
    let apart =
        |p: &OrbitSample, q: &OrbitSample| (p.x_rel_m - q.x_rel_m).hypot(p.y_rel_m - q.y_rel_m);
    let worst = a
        .iter()
        .zip(&b)
        .map(|(p, q)| apart(p, q))
        .fold(0.0, f64::max);
    // Measured: 1.7e-7 m against a 150 um clearance (the two speeds' error control takes
    // different steps); the speed enters the translation only through the drag torque, which
    // follows the race's speed, the same at both.
    assert!(
        worst < 1e-6,
        "16 000 and 30 000 r/min paths {worst:e} m apart"
    );
    let t_roll = rolls(&c).expect("the 4000 r/min race rolls within 30 ms");
    let before = c
        .iter()
        .zip(&b)
        .filter(|(p, _)| p.t_s < t_roll - 0.5e-3)
        .map(|(p, q)| apart(p, q))
        .fold(0.0, f64::max);
    let after = c
        .iter()
        .zip(&b)
        .filter(|(p, _)| p.t_s > t_roll + 2e-3)
        .map(|(p, q)| apart(p, q))
        .fold(0.0, f64::max);
    eprintln!(
        "16 000 vs 30 000: {worst:e} m; 4000 rolls at {t_roll} s, {before:e} m apart before, {after:e} m after"
    );
    // Measured: 2.4e-6 m before (the bounces amplify the different step sequences), and the
    // paths part once the race rolls.
    assert!(before < 1e-5, "before rolling: {before:e} m apart");
    assert!(
        after > 10.0 * before.max(1e-6),
        "after rolling at {t_roll} s: only {after:e} m apart"
    );
}

/// The friction threshold of the symmetric release does not depend on the speed once the race
/// still slips when the decisive climb comes: between mu 0.31 and 0.315 at 16 000 and
/// 24 000 r/min alike.
#[test]
fn the_friction_threshold_is_the_same_at_two_speeds() {
    for speed in [16_000.0, 24_000.0] {
        let below = drop(&scene(speed, 0.31)).verdict.class;
        let above = drop(&scene(speed, 0.315)).verdict.class;
        assert_eq!(below, OrbitClass::Pendulum, "{speed} r/min mu 0.31");
        assert_eq!(above, OrbitClass::BackwardWhirl, "{speed} r/min mu 0.315");
    }
}
