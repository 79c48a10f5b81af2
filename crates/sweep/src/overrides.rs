//! Scene overrides by name: `--set key=value` on the command line, and (later) sweep axes
//! over any scene parameter. Keys are the scene's JSON field names; nested fields use dots
//! (`solver.rtol`). Values are JSON (`1e-4`, `true`, `null`, `{"regularised":{...}}`); a
//! bare word such as `switched` is taken as a string.

use serde_json::Value;
use thiserror::Error;
use whirlmap_core::Scene;

/// Why an override could not be applied.
#[derive(Debug, Error)]
pub enum OverrideError {
    /// Not of the form `key=value`.
    #[error("expected key=value, got `{0}`")]
    Syntax(String),
    /// The key is not a scene parameter.
    #[error("unknown scene parameter `{key}`; known: {known}")]
    UnknownKey {
        /// The key as given.
        key: String,
        /// The known keys at that level, comma-separated.
        known: String,
    },
    /// The value has the wrong type for the key.
    #[error("invalid value for `{key}`: {reason}")]
    BadValue {
        /// The key as given.
        key: String,
        /// What serde said.
        reason: String,
    },
}

/// Parses `key=value` and applies it to `scene`.
pub fn apply_assignment(scene: &mut Scene, assignment: &str) -> Result<(), OverrideError> {
    let (key, value) = assignment
        .split_once('=')
        .ok_or_else(|| OverrideError::Syntax(assignment.to_string()))?;
    let value: Value = serde_json::from_str(value.trim())
        .unwrap_or_else(|_| Value::String(value.trim().to_string()));
    apply(scene, key.trim(), value)
}

/// Fields the canonical JSON leaves out while they hold their default (so scene hashes of
/// older records stay valid) are still settable: put their defaults back in.
fn show_optional_fields(root: &mut Value) {
    if let Value::Object(m) = root {
        m.entry("quasi_static_race").or_insert(Value::Bool(false));
        m.entry("support_damping_isotropic")
            .or_insert(Value::Bool(false));
        m.entry("stop_speed_rpm").or_insert(Value::Null);
        for key in ["release_offset_m", "release_velocity_m_s"] {
            m.entry(key).or_insert(serde_json::json!([0.0, 0.0]));
        }
        m.entry("race_speed_rad_s")
            .or_insert(serde_json::json!(0.0));
        if let Some(Value::Object(solver)) = m.get_mut("solver") {
            solver
                .entry("method")
                .or_insert(Value::String("dopri5".into()));
            solver
                .entry("free_flight_gap_bound")
                .or_insert(Value::Bool(false));
            solver
                .entry("race_atol_scale")
                .or_insert(serde_json::json!(1.0));
        }
    }
}

/// Sets the scene parameter `key` (dotted for nested fields) to `value`.
pub fn apply(scene: &mut Scene, key: &str, value: Value) -> Result<(), OverrideError> {
    let mut root = serde_json::to_value(&*scene).expect("a scene serialises");
    show_optional_fields(&mut root);
    let mut node = &mut root;
    let parts: Vec<&str> = key.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let obj = match node {
            Value::Object(m) => m,
            _ => {
                return Err(OverrideError::UnknownKey {
                    key: key.to_string(),
                    known: String::new(),
                });
            }
        };
        // Optional scene fields are absent from the JSON while at their default.
        let optional = i == 0 && Scene::OPTIONAL_FIELDS.contains(part);
        if !obj.contains_key(*part) && !optional {
            let mut known = obj.keys().cloned().collect::<Vec<_>>();
            if i == 0 {
                known.extend(Scene::OPTIONAL_FIELDS.iter().map(|k| k.to_string()));
            }
            let known = known.join(", ");
            return Err(OverrideError::UnknownKey {
                key: key.to_string(),
                known,
            });
        }
        if i + 1 == parts.len() {
            obj.insert(part.to_string(), value.clone());
            break;
        }
        // An optional section that is absent (e.g. `thermal` on a drop without it) has no
        // sub-keys to set: say so instead of failing deeper.
        let Some(next) = obj.get_mut(*part) else {
            return Err(OverrideError::UnknownKey {
                key: key.to_string(),
                known: format!("none (`{part}` is not set in this scene: set it whole first, e.g. `--set {part}={{}}`, or use --thermal)"),
            });
        };
        node = next;
    }
    *scene = serde_json::from_value(root).map_err(|e| OverrideError::BadValue {
        key: key.to_string(),
        reason: e.to_string(),
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use whirlmap_core::FrictionLaw;

    #[test]
    fn optional_fields_are_settable_and_absent_sections_are_an_error_not_a_panic() {
        let mut s = Scene::paper();
        apply_assignment(&mut s, "stop_speed_rpm=1000").unwrap();
        assert_eq!(s.stop_speed_rpm, Some(1000.0));
        apply_assignment(&mut s, "race_speed_rad_s=5").unwrap();
        assert_eq!(s.race_speed_rad_s, 5.0);
        apply_assignment(&mut s, "quasi_static_race=true").unwrap();
        assert!(s.quasi_static_race);
        let err = apply_assignment(&mut s, "thermal.macro_step_s=0.01").unwrap_err();
        assert!(err.to_string().contains("thermal"), "{err}");
        apply_assignment(&mut s, "thermal={}").unwrap();
        apply_assignment(&mut s, "thermal.macro_step_s=0.002").unwrap();
        assert_eq!(s.thermal.as_ref().unwrap().macro_step_s, 0.002);
    }

    #[test]
    fn sets_flat_nested_and_enum_fields() {
        let mut s = Scene::paper();
        apply_assignment(&mut s, "clearance_m=2e-4").unwrap();
        apply_assignment(&mut s, "solver.rtol = 1e-7").unwrap();
        apply_assignment(&mut s, r#"friction_law={"regularised":{"v_eps_m_s":0.01}}"#).unwrap();
        apply_assignment(&mut s, "mu_static=0.4").unwrap();
        apply_assignment(&mut s, "quasi_static_race=true").unwrap();
        apply_assignment(&mut s, "solver.method=dop853").unwrap();
        assert!(s.quasi_static_race);
        assert_eq!(s.solver.method, whirlmap_core::Method::Dop853);
        apply_assignment(&mut s, "quasi_static_race=false").unwrap();
        apply_assignment(&mut s, "solver.method=dopri5").unwrap();
        let text = serde_json::to_string(&s).unwrap();
        assert!(
            !text.contains("quasi_static_race") && !text.contains("method"),
            "defaults of the optional fields stay out of the canonical JSON: {text}"
        );
        assert_eq!(s.clearance_m, 2e-4);
        assert_eq!(s.solver.rtol, 1e-7);
        assert_eq!(s.friction_law, FrictionLaw::Regularised { v_eps_m_s: 0.01 });
        assert_eq!(s.mu_static, Some(0.4));
        apply_assignment(&mut s, "friction_law=switched").unwrap();
        assert_eq!(s.friction_law, FrictionLaw::Switched);
        apply_assignment(&mut s, "release_offset_m=[1e-5, -2e-5]").unwrap();
        apply_assignment(&mut s, "race_speed_rad_s=12.5").unwrap();
        assert_eq!(s.release_offset_m, [1e-5, -2e-5]);
        assert_eq!(s.race_speed_rad_s, 12.5);
        let e = apply_assignment(&mut s, "race_sped=1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("race_speed_rad_s"),
            "optional keys are listed: {e}"
        );
    }

    #[test]
    fn unknown_keys_and_bad_values_are_named() {
        let mut s = Scene::paper();
        let e = apply_assignment(&mut s, "clearence_m=1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("clearence_m") && e.contains("clearance_m"),
            "{e}"
        );
        let e = apply_assignment(&mut s, "rotor_mass_kg=heavy")
            .unwrap_err()
            .to_string();
        assert!(e.contains("rotor_mass_kg"), "{e}");
        assert!(matches!(
            apply_assignment(&mut s, "rotor_mass_kg"),
            Err(OverrideError::Syntax(_))
        ));
        assert_eq!(
            s,
            Scene::paper(),
            "failed overrides leave the scene unchanged"
        );
    }
}
