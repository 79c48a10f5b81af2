//! The optional release state: rotor offset and velocity, race spin at release. Defaults
//! reproduce the release of docs/model.md#release-state exactly; non-defaults are tested by
//! physics.

use std::collections::BTreeSet;
use whirlmap_core::{simulate, DropOptions, Scene};

/// Every dotted key path of a JSON value's objects.
fn paths(v: &serde_json::Value, prefix: &str, out: &mut BTreeSet<String>) {
    if let serde_json::Value::Object(m) = v {
        for (k, x) in m {
            let p = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            paths(x, &p, out);
            out.insert(p);
        }
    }
}

#[test]
fn optional_fields_are_exactly_those_the_json_omits_at_their_default() {
    let s = Scene::paper();
    let mut t = s.clone();
    t.release_offset_m = [1e-6, 0.0];
    t.release_velocity_m_s = [0.0, -1e-3];
    t.race_speed_rad_s = 1.0;
    t.quasi_static_race = true;
    t.stop_speed_rpm = Some(100.0);
    t.thermal = Some(Default::default());
    t.bearing = Some(Default::default());
    t.solver.method = whirlmap_core::Method::Ros34pw2;
    t.solver.free_flight_gap_bound = true;
    t.solver.race_atol_scale = 10.0;
    let (mut a, mut b) = (BTreeSet::new(), BTreeSet::new());
    paths(&serde_json::to_value(&s).unwrap(), "", &mut a);
    paths(&serde_json::to_value(&t).unwrap(), "", &mut b);
    // The keys only the non-default scene has, without those inside a new section.
    let new: BTreeSet<String> = b.difference(&a).cloned().collect();
    let top: BTreeSet<&str> = new
        .iter()
        .filter(|p| !new.iter().any(|q| p.starts_with(&format!("{q}."))))
        .map(String::as_str)
        .collect();
    let listed: BTreeSet<&str> = Scene::OPTIONAL_FIELDS.iter().copied().collect();
    assert_eq!(top, listed);
    // And no field is skipped at its default without being listed: the scene source has
    // one `skip_serializing_if` per listed field (a new one must be added to the list and
    // to the scene above).
    let src = include_str!("../src/scene.rs");
    assert_eq!(
        src.matches("skip_serializing_if").count(),
        Scene::OPTIONAL_FIELDS.len()
    );
}

#[test]
fn default_release_fields_are_left_out_of_the_json_and_the_hash() {
    let s = Scene::paper();
    let mut present = BTreeSet::new();
    paths(&serde_json::to_value(&s).unwrap(), "", &mut present);
    for key in Scene::OPTIONAL_FIELDS {
        assert!(
            !present.contains(*key),
            "{key} must not be serialised at its default"
        );
    }
    let mut t = s.clone();
    t.race_speed_rad_s = 1.0;
    t.release_offset_m = [1e-6, 0.0];
    t.release_velocity_m_s = [0.0, -1e-3];
    let text = serde_json::to_string(&t).unwrap();
    assert!(text.contains("\"race_speed_rad_s\":1.0"), "{text}");
    assert_eq!(serde_json::from_str::<Scene>(&text).unwrap(), t);
    assert_ne!(s.hash_hex(), t.hash_hex());
}

#[test]
fn release_fields_are_validated_by_name() {
    let mut s = Scene::paper();
    s.release_offset_m = [0.0, -0.95 * s.clearance_m];
    assert_eq!(s.validate().unwrap_err().field, "release_offset_m");
    s.release_offset_m = [0.0, -0.85 * s.clearance_m];
    s.validate().unwrap();
    s.release_velocity_m_s = [f64::NAN, 0.0];
    assert_eq!(s.validate().unwrap_err().field, "release_velocity_m_s");
    s.release_velocity_m_s = [0.0, 0.0];
    s.race_speed_rad_s = 2e5;
    let e = s.validate().unwrap_err();
    assert_eq!(e.field, "race_speed_rad_s");
    assert!(e.to_string().contains("1e5"), "{e}");
}

/// Without gravity and far from the race, the rotor centre moves in a straight line at its
/// release velocity, and the race keeps its release spin when drag is off (no torque on it).
#[test]
fn free_flight_from_an_offset_release_is_a_straight_line() {
    let mut s = Scene::paper();
    s.gravity_m_s2 = 0.0;
    s.drag_enabled = false;
    s.release_offset_m = [20e-6, -10e-6];
    s.release_velocity_m_s = [1e-3, 2e-3];
    s.race_speed_rad_s = 50.0;
    // Exactly 0.02 s (no contact, so the classifier would extend the run otherwise).
    s.classification.max_extension_s = 0.0;
    let t = 0.02; // 20-40 um travel: stays clear of the 150 um clearance
    let r = simulate(
        &s,
        &DropOptions {
            duration_s: t,
            ..Default::default()
        },
    )
    .unwrap();
    let y = r.final_state;
    assert!(
        (y[whirlmap_core::model::ix::XR] - (20e-6 + 1e-3 * t)).abs() < 1e-12,
        "x = {}",
        y[0]
    );
    assert!(
        (y[whirlmap_core::model::ix::YR] - (-10e-6 + 2e-3 * t)).abs() < 1e-12,
        "y = {}",
        y[1]
    );
    assert!(
        (y[whirlmap_core::model::ix::WB] - 50.0).abs() < 1e-9,
        "race spin {}",
        y[11]
    );
    assert_eq!(r.features.impacts, 0);
}

/// A release with velocity and race spin still closes the energy audit (the initial energy
/// includes the release kinetic energy). Integrated at the reference fidelity, so the audit
/// resolves the release's translational energy (1.4 mJ, 1.4e-6 of the total).
#[test]
fn energy_audit_closes_with_a_moving_release() {
    let mut s = whirlmap_core::Fidelity::Reference.applied(&Scene::paper());
    s.mu_dynamic = 0.2;
    s.release_offset_m = [30e-6, 10e-6];
    s.release_velocity_m_s = [-0.02, 0.01];
    s.race_speed_rad_s = 100.0;
    let r = simulate(
        &s,
        &DropOptions {
            duration_s: 0.03,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(r.features.impacts > 0);
    assert!(r.energy.residual_rel < 1e-6, "{:?}", r.energy);
}
