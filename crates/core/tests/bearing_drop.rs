//! The bearing analysis inside a drop: it reads the race's motion and changes nothing of the
//! dynamics, and its outputs hang together.

use whirlmap_core::bearing::BearingPair;
use whirlmap_core::{simulate, DropOptions, Scene};

fn scene(speed_rpm: f64, mu: f64, bearing: bool) -> Scene {
    let mut s = Scene::paper();
    s.speed_rpm = speed_rpm;
    s.mu_dynamic = mu;
    s.bearing = bearing.then(BearingPair::paper_71908_cd);
    s
}

#[test]
fn the_bearing_analysis_leaves_the_dynamics_unchanged() {
    let opts = DropOptions {
        duration_s: 0.3,
        ..Default::default()
    };
    for (v, mu) in [(4000.0, 0.1), (8000.0, 0.4)] {
        let off = simulate(&scene(v, mu, false), &opts).unwrap();
        let on = simulate(&scene(v, mu, true), &opts).unwrap();
        assert!(off.bearing.is_none());
        assert_eq!(off.final_state, on.final_state, "{v} r/min, mu {mu}");
        assert_eq!(off.stats, on.stats);
        assert_eq!(
            off.features.max_contact_force_n,
            on.features.max_contact_force_n
        );
        assert_eq!(off.verdict.class, on.verdict.class);
        let b = on.bearing.expect("asked for");
        // The pair carries the support force: its peak ball load is Stribeck's share of it
        // (zero clearance: Q_max = F / (i Z J_r cos a), J_r = 0.2288, so about 4.37 F /
        // (i Z cos a)), within the spread of the damper's part.
        let pair = BearingPair::paper_71908_cd();
        let balls = f64::from(pair.rows * pair.balls_per_row);
        let stribeck = b.peak_bearing_load_n / (balls * 0.2288 * pair.contact_angle_rad.cos());
        assert!(
            (b.peak_ball_load_n / stribeck - 1.0).abs() < 0.02,
            "ball load {} against Stribeck {}",
            b.peak_ball_load_n,
            stribeck
        );
        assert!((b.static_safety_factor * b.peak_contact_pressure_pa / 4.2e9 - 1.0).abs() < 1e-12);
        assert!(b.damage_per_drop > 0.0 && b.damage_per_drop.is_finite());
        assert!((b.drops_to_failure * b.damage_per_drop - 1.0).abs() < 1e-9);
    }
}
