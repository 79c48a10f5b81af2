//! What a scene accepts, field by field: the allowed range of every numeric field
//! ([`FIELD_RANGES`], checked against [`Scene::validate`](crate::Scene::validate) by a test,
//! so the two cannot drift),
//! the unit read from the field's name ([`unit_of`]), and, with the `schema` feature, the
//! scene's JSON Schema (`scene_schema`): the structure, types, defaults and descriptions
//! derived from the Rust types and their doc comments, with the ranges, units and sources
//! added per field.

#[cfg(feature = "schema")]
use crate::scene::Scene;

/// One end of an allowed range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bound {
    /// The value itself is allowed.
    Inclusive(f64),
    /// Values up to (not including) it are allowed.
    Exclusive(f64),
}

/// The allowed range of one numeric scene field, by dotted key. A side that depends on
/// another field (`unbalance_m <= 10 clearance_m`) is `None` here and stated in the field's
/// doc comment; [`Scene::validate`](crate::Scene::validate) checks it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldRange {
    /// Dotted key, as `--set` takes it.
    pub key: &'static str,
    /// Lower end, if any.
    pub min: Option<Bound>,
    /// Upper end, if any.
    pub max: Option<Bound>,
}

const fn r(key: &'static str, min: Option<Bound>, max: Option<Bound>) -> FieldRange {
    FieldRange { key, min, max }
}
use Bound::{Exclusive as Ex, Inclusive as In};

/// Allowed ranges of the scene's numeric fields (the thermal model's under `thermal.`, the
/// bearing analysis's under `bearing.`), as [`Scene::validate`](crate::Scene::validate),
/// [`crate::ThermalParams::validate`] and [`crate::bearing::BearingPair::validate_fields`]
/// enforce them.
pub const FIELD_RANGES: &[FieldRange] = &[
    r("speed_rpm", Some(In(-1e6)), Some(In(1e6))),
    r("mu_dynamic", Some(In(0.0)), Some(In(2.0))),
    r("mu_static", None, Some(In(2.0))),
    r("gravity_m_s2", Some(In(0.0)), Some(In(1000.0))),
    r("rotor_mass_kg", Some(In(1e-3)), Some(In(1e6))),
    r("rotor_polar_moi_kg_m2", Some(Ex(0.0)), None),
    r("load_share", Some(Ex(0.0)), Some(In(1.0))),
    r("rotor_diameter_m", Some(Ex(0.0)), Some(In(10.0))),
    r("unbalance_m", Some(In(0.0)), None),
    r("race_speed_rad_s", Some(In(-1e5)), Some(In(1e5))),
    r("race_mass_kg", Some(In(1e-5)), Some(In(1e6))),
    r("race_polar_moi_kg_m2", Some(Ex(0.0)), None),
    r("clearance_m", Some(Ex(0.0)), Some(In(0.1))),
    r(
        "friction_law.regularised.v_eps_m_s",
        Some(Ex(0.0)),
        Some(In(10.0)),
    ),
    r("contact_stiffness_n_per_m_e", Some(Ex(0.0)), None),
    r("contact_exponent", Some(In(1.0)), Some(In(2.0))),
    r("contact_damping_n_s_per_m", Some(In(0.0)), Some(In(1e8))),
    r("support_stiffness_n_per_m_e", Some(Ex(0.0)), None),
    r("support_exponent", Some(In(1.0)), Some(In(2.0))),
    r("support_damping_n_s_per_m", Some(In(0.0)), Some(In(1e8))),
    r("palmgren_f0", Some(In(0.0)), Some(In(20.0))),
    r(
        "lubricant_viscosity_mm2_s",
        Some(In(0.0)),
        Some(In(10_000.0)),
    ),
    r("pitch_diameter_m", None, Some(In(10.0))),
    r("static_load_rating_n", Some(In(1.0)), Some(In(1e8))),
    r("drag_zero_speed_rad_s", Some(Ex(0.0)), None),
    r("whirl_stop_turns", Some(In(1.0)), Some(In(1e6))),
    r("stop_speed_rpm", Some(In(0.0)), Some(In(1e6))),
    r("classification.window_s", Some(In(0.02)), Some(In(100.0))),
    r("classification.min_duty", Some(Ex(0.0)), Some(In(1.0))),
    r(
        "classification.max_rocking_range_rad",
        Some(Ex(0.0)),
        Some(In(std::f64::consts::TAU)),
    ),
    r(
        "classification.max_drift_rad",
        Some(Ex(0.0)),
        Some(In(std::f64::consts::PI)),
    ),
    r(
        "classification.whirl_half_turns",
        Some(In(0.5)),
        Some(In(1e6)),
    ),
    r(
        "classification.max_extension_s",
        Some(In(0.0)),
        Some(In(3600.0)),
    ),
    r("solver.rtol", Some(Ex(0.0)), Some(In(1e-2))),
    r("solver.position_scale_m", Some(Ex(0.0)), None),
    r("solver.free_flight_max_step_s", Some(Ex(0.0)), None),
    r("solver.min_step_s", Some(Ex(0.0)), None),
    r("solver.max_step_attempts", Some(In(1.0)), None),
    r("solver.max_events", Some(In(1.0)), None),
    r("solver.race_atol_scale", Some(In(1.0)), Some(In(1e4))),
    r("solver.bdf_max_order", Some(In(1.0)), Some(In(5.0))),
    r("thermal.macro_step_s", Some(In(1e-6)), Some(In(1.0))),
    r(
        "thermal.ambient_temperature_k",
        Some(Ex(0.0)),
        Some(In(2000.0)),
    ),
    r(
        "thermal.rotor_conductivity_w_m_k",
        Some(Ex(0.0)),
        Some(In(1e4)),
    ),
    r(
        "thermal.rotor_specific_heat_j_kg_k",
        Some(Ex(0.0)),
        Some(In(1e5)),
    ),
    r("thermal.rotor_density_kg_m3", Some(Ex(0.0)), Some(In(1e5))),
    r("thermal.rotor_node_length_m", Some(Ex(0.0)), Some(In(10.0))),
    r(
        "thermal.rotor_convection_w_m2_k",
        Some(In(0.0)),
        Some(In(1e5)),
    ),
    r(
        "thermal.bearing_conductivity_w_m_k",
        Some(Ex(0.0)),
        Some(In(1e4)),
    ),
    r(
        "thermal.bearing_specific_heat_j_kg_k",
        Some(Ex(0.0)),
        Some(In(1e5)),
    ),
    r(
        "thermal.bearing_density_kg_m3",
        Some(Ex(0.0)),
        Some(In(1e5)),
    ),
    r(
        "thermal.bearing_expansion_per_k",
        Some(In(0.0)),
        Some(In(1e-3)),
    ),
    r(
        "thermal.bearing_poisson_ratio",
        Some(In(0.0)),
        Some(Ex(0.5)),
    ),
    r("thermal.bearing_width_m", Some(Ex(0.0)), Some(In(10.0))),
    r("thermal.outer_diameter_m", Some(Ex(0.0)), None),
    r("thermal.ball_diameter_m", Some(Ex(0.0)), Some(In(10.0))),
    r("thermal.ball_count", Some(In(3.0)), Some(In(200.0))),
    r("thermal.outer_race_mass_kg", Some(Ex(0.0)), Some(In(1e6))),
    r("thermal.contact_angle_deg", Some(In(0.0)), Some(Ex(90.0))),
    r(
        "thermal.lubricant_conductivity_w_m_k",
        Some(Ex(0.0)),
        Some(In(1e4)),
    ),
    r(
        "thermal.lubricant_specific_heat_j_kg_k",
        Some(Ex(0.0)),
        Some(In(1e5)),
    ),
    r("thermal.lubricant_mass_kg", Some(Ex(0.0)), Some(In(1e6))),
    r(
        "thermal.lubricant_convection_w_m2_k",
        Some(In(0.0)),
        Some(In(1e5)),
    ),
    r("thermal.housing_outer_radius_m", None, Some(In(10.0))),
    r("thermal.housing_length_m", Some(Ex(0.0)), Some(In(10.0))),
    r(
        "thermal.housing_conductivity_w_m_k",
        Some(Ex(0.0)),
        Some(In(1e4)),
    ),
    r(
        "thermal.housing_specific_heat_j_kg_k",
        Some(Ex(0.0)),
        Some(In(1e5)),
    ),
    r(
        "thermal.housing_density_kg_m3",
        Some(Ex(0.0)),
        Some(In(1e5)),
    ),
    r(
        "thermal.housing_convection_w_m2_k",
        Some(In(0.0)),
        Some(In(1e5)),
    ),
    r("thermal.rub_heat_to_rotor", Some(In(0.0)), Some(In(1.0))),
    r(
        "thermal.contact_heat_to_lubricant",
        Some(In(0.0)),
        Some(In(1.0)),
    ),
    r(
        "thermal.induced_load_stiffness_n_per_m15",
        Some(Ex(0.0)),
        None,
    ),
    r("thermal.fit_interference_m", Some(In(0.0)), Some(In(1e-3))),
    r("bearing.ball_diameter_m", Some(In(1e-4)), Some(In(0.1))),
    r("bearing.pitch_diameter_m", Some(In(1e-3)), Some(In(10.0))),
    r("bearing.balls_per_row", Some(In(3.0)), Some(In(1000.0))),
    r("bearing.rows", Some(In(1.0)), Some(In(8.0))),
    r("bearing.contact_angle_rad", Some(In(0.0)), Some(Ex(1.4))),
    r("bearing.inner_conformity", Some(Ex(0.5)), Some(Ex(1.0))),
    r("bearing.outer_conformity", Some(Ex(0.5)), Some(Ex(1.0))),
    r("bearing.young_modulus_pa", Some(In(1e9)), Some(In(1e12))),
    r("bearing.poisson_ratio", Some(In(0.0)), Some(Ex(0.5))),
    r(
        "bearing.lumped_stiffness_n_per_m1_5",
        Some(In(1e6)),
        Some(In(1e19)),
    ),
    r("bearing.dynamic_rating_n", Some(In(1.0)), Some(In(1e8))),
    r("bearing.static_rating_n", Some(In(1.0)), Some(In(1e8))),
    r(
        "bearing.static_limit_pressure_pa",
        Some(In(1e8)),
        Some(In(1e10)),
    ),
];

/// The allowed range of the numeric scene field `key` (dotted) in words, as the scene check
/// states it: `[3, 200]`, `(0, 1e4]`, `>= 1`; `None` for a key not in [`FIELD_RANGES`] or
/// one with neither end.
pub fn range_text(key: &str) -> Option<String> {
    let r = FIELD_RANGES.iter().find(|r| r.key == key)?;
    let n = |v: f64| crate::scene::num(v);
    Some(match (r.min, r.max) {
        (Some(lo), Some(hi)) => {
            let (open, lo) = match lo {
                Bound::Inclusive(v) => ('[', v),
                Bound::Exclusive(v) => ('(', v),
            };
            let (close, hi) = match hi {
                Bound::Inclusive(v) => (']', v),
                Bound::Exclusive(v) => (')', v),
            };
            format!("{open}{}, {}{close}", n(lo), n(hi))
        }
        (Some(Bound::Inclusive(v)), None) => format!(">= {}", n(v)),
        (Some(Bound::Exclusive(v)), None) => format!("> {}", n(v)),
        (None, Some(Bound::Inclusive(v))) => format!("<= {}", n(v)),
        (None, Some(Bound::Exclusive(v))) => format!("< {}", n(v)),
        (None, None) => return None,
    })
}

/// The unit of a field, read from its name's suffix (the project's naming rule: SI units,
/// named where not obvious); `"1"` for a dimensionless number.
pub fn unit_of(key: &str) -> &'static str {
    let name = key.rsplit('.').next().unwrap_or(key);
    const SUFFIXES: &[(&str, &str)] = &[
        ("_n_per_m_e", "N/m^e (e the field's exponent)"),
        ("_n_per_m1_5", "N/m^1.5"),
        ("_n_per_m15", "N/m^1.5"),
        ("_n_s_per_m", "N s/m"),
        ("_kg_m2", "kg m^2"),
        ("_kg_m3", "kg/m^3"),
        ("_j_kg_k", "J/(kg K)"),
        ("_w_m2_k", "W/(m^2 K)"),
        ("_w_m_k", "W/(m K)"),
        ("_mm2_s", "mm^2/s"),
        ("_rad_s", "rad/s"),
        ("_m_s2", "m/s^2"),
        ("_m_s", "m/s"),
        ("_per_k", "1/K"),
        ("_rpm", "r/min"),
        ("_rad", "rad"),
        ("_deg", "deg"),
        ("_pa", "Pa"),
        ("_kg", "kg"),
        ("_m", "m"),
        ("_s", "s"),
        ("_n", "N"),
        ("_k", "K"),
    ];
    SUFFIXES
        .iter()
        .find(|(suffix, _)| name.ends_with(suffix))
        .map(|(_, unit)| *unit)
        .unwrap_or("1")
}

/// Where a field's value comes from, read from its doc comment: the paper's table or
/// equation, a handbook (`[ASM]`, `[Harris]`, `[SKF]`, `[Incropera]`), a standard
/// (`[ISO 281]`, `[ISO 76]`), or whirlmap's own
/// choice (documented in docs/model.md) when the paper gives none.
pub fn source_of(description: &str) -> String {
    // Doc comments escape the brackets of a marker for rustdoc (`\[ASM\]`).
    let description = description.replace('\\', "");
    let mut found: Vec<String> = Vec::new();
    for marker in [
        "[ASM]",
        "[Harris]",
        "[SKF]",
        "[Incropera]",
        "[ISO 281]",
        "[ISO 76]",
    ] {
        if description.contains(marker) {
            found.push(marker.trim_matches(['[', ']']).to_string());
        }
    }
    for (prefix, label) in [
        ("Table ", "the paper's Table "),
        ("eqs. ", "the paper's eqs. "),
        ("eq. ", "the paper's eq. "),
        ("Sec. ", "the paper's Sec. "),
        ("Fig. ", "the paper's Fig. "),
    ] {
        if let Some(i) = description.find(prefix) {
            let rest = &description[i + prefix.len()..];
            let n: String = rest
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '-')
                .collect();
            if !n.is_empty() && !found.iter().any(|f| f.ends_with(&n)) {
                found.push(format!("{label}{n}"));
            }
        }
    }
    if found.is_empty() && description.contains("the paper's") {
        found.push("the paper".to_string());
    }
    if found.is_empty() {
        "not in the paper: whirlmap's default (docs/model.md)".to_string()
    } else {
        found.join("; ")
    }
}

/// The scene's JSON Schema (draft 2020-12), from the Rust types: every field with its type,
/// default and description (the field's doc comment), and added per field `minimum` /
/// `maximum` (or the exclusive forms) from [`FIELD_RANGES`], `x-unit` from [`unit_of`] and
/// `x-source` from [`source_of`]. Editors can validate scene files against it.
#[cfg(feature = "schema")]
pub fn scene_schema() -> serde_json::Value {
    use serde_json::Value;
    let schema = schemars::schema_for!(Scene);
    let mut root = serde_json::to_value(schema).unwrap_or_default();
    // Definitions of the nested structs, by the field of the scene that holds them.
    let nested = [
        ("classification", "ClassifyParams"),
        ("solver", "SolverSettings"),
        ("thermal", "ThermalParams"),
        ("bearing", "BearingPair"),
    ];
    fn annotate(props: &mut serde_json::Map<String, Value>, prefix: &str) {
        for (name, prop) in props.iter_mut() {
            let key = if prefix.is_empty() {
                name.clone()
            } else {
                format!("{prefix}.{name}")
            };
            let Value::Object(p) = prop else { continue };
            let description = p
                .get("description")
                .and_then(Value::as_str)
                .unwrap_or("")
                .to_string();
            let numeric = |t: &Value| t == "number" || t == "integer";
            let is_number = match p.get("type") {
                Some(t @ Value::String(_)) => numeric(t),
                Some(Value::Array(ts)) => ts.iter().any(numeric),
                _ => false,
            };
            let range = FIELD_RANGES.iter().find(|r| r.key == key);
            if let Some(range) = range {
                match range.min {
                    Some(Bound::Inclusive(v)) => {
                        p.insert("minimum".into(), v.into());
                    }
                    Some(Bound::Exclusive(v)) => {
                        p.insert("exclusiveMinimum".into(), v.into());
                    }
                    None => {}
                }
                match range.max {
                    Some(Bound::Inclusive(v)) => {
                        p.insert("maximum".into(), v.into());
                    }
                    Some(Bound::Exclusive(v)) => {
                        p.insert("exclusiveMaximum".into(), v.into());
                    }
                    None => {}
                }
            }
            if is_number || range.is_some() {
                p.insert("x-unit".into(), unit_of(&key).into());
            }
            p.insert("x-source".into(), source_of(&description).into());
        }
    }
    if let Some(Value::Object(props)) = root.get_mut("properties") {
        annotate(props, "");
    }
    // The regularised friction law's field, inside its variant of the enum.
    if let Some(Value::Array(variants)) = root.pointer_mut("/$defs/FrictionLaw/oneOf") {
        for v in variants {
            if let Some(Value::Object(props)) = v.pointer_mut("/properties/regularised/properties")
            {
                annotate(props, "friction_law.regularised");
            }
        }
    }
    for (field, def) in nested {
        if let Some(Value::Object(props)) = root
            .get_mut("$defs")
            .and_then(|d| d.get_mut(def))
            .and_then(|d| d.get_mut("properties"))
        {
            annotate(props, field);
        }
    }
    root
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bearing::BearingPair;
    use crate::scene::Scene;
    use crate::ThermalParams;
    use serde_json::Value;

    /// The scene with `key` set to `v` (through its JSON, as a scene file would), or `None`
    /// when the value does not even parse for the field's type.
    fn with(key: &str, v: f64) -> Option<Scene> {
        let mut s = Scene::paper();
        s.thermal = Some(ThermalParams::default());
        s.bearing = Some(BearingPair::default());
        let mut root = serde_json::to_value(&s).unwrap();
        let mut node = &mut root;
        let parts: Vec<&str> = key.split('.').collect();
        for p in &parts[..parts.len() - 1] {
            // A variant with fields (the regularised friction law) replaces a unit one.
            if !node.is_object() {
                *node = Value::Object(Default::default());
            }
            node = node
                .as_object_mut()
                .unwrap()
                .entry(p.to_string())
                .or_insert_with(|| Value::Object(Default::default()));
        }
        if !node.is_object() {
            *node = Value::Object(Default::default());
        }
        let integer = [
            "ball_count",
            "balls_per_row",
            "bearing.rows",
            "solver.bdf_max_order",
        ];
        let value = if integer.iter().any(|i| key.ends_with(i)) || key.starts_with("solver.max_") {
            if v < 0.0 || v.fract() != 0.0 {
                return None;
            }
            Value::from(v as u64)
        } else {
            Value::from(v)
        };
        node.as_object_mut()
            .unwrap()
            .insert(parts[parts.len() - 1].to_string(), value);
        serde_json::from_value(root).ok()
    }

    /// The per-field checks (a value at a range end may still break a consistency rule
    /// between fields, which [`Scene::validate`](crate::Scene::validate) adds; the ranges are
    /// per field).
    fn check(s: &Scene) -> Result<(), crate::InvalidParameter> {
        s.validate_fields()?;
        s.thermal.as_ref().map_or(Ok(()), ThermalParams::validate)?;
        s.bearing
            .as_ref()
            .map_or(Ok(()), BearingPair::validate_fields)
    }

    fn accepted(key: &str, v: f64) -> bool {
        with(key, v).is_some_and(|s| check(&s).is_ok())
    }

    fn refused_naming(key: &str, v: f64) -> bool {
        match with(key, v) {
            None => true,
            Some(s) => match check(&s) {
                Ok(()) => false,
                Err(e) => e.field == key,
            },
        }
    }

    /// Just inside and just outside a bound.
    fn nudge(v: f64, up: bool) -> f64 {
        let step = if v == 0.0 { 1e-9 } else { v.abs() * 1e-9 };
        if up {
            v + step
        } else {
            v - step
        }
    }

    #[test]
    fn every_range_is_the_one_validation_enforces() {
        for r in FIELD_RANGES {
            let k = r.key;
            match r.min {
                Some(Bound::Inclusive(v)) => {
                    assert!(accepted(k, v), "{k}: its minimum {v} is refused");
                    assert!(
                        refused_naming(k, nudge(v, false)),
                        "{k}: below {v} accepted"
                    );
                }
                Some(Bound::Exclusive(v)) => {
                    assert!(
                        refused_naming(k, v),
                        "{k}: its exclusive minimum {v} accepted"
                    );
                    assert!(accepted(k, nudge(v, true)), "{k}: just above {v} refused");
                }
                None => {}
            }
            match r.max {
                Some(Bound::Inclusive(v)) => {
                    assert!(accepted(k, v), "{k}: its maximum {v} is refused");
                    assert!(refused_naming(k, nudge(v, true)), "{k}: above {v} accepted");
                }
                Some(Bound::Exclusive(v)) => {
                    assert!(
                        refused_naming(k, v),
                        "{k}: its exclusive maximum {v} accepted"
                    );
                    assert!(accepted(k, nudge(v, false)), "{k}: just below {v} refused");
                }
                None => {}
            }
        }
    }

    #[test]
    fn ranges_in_words() {
        assert_eq!(
            range_text("thermal.ball_count").as_deref(),
            Some("[3, 200]")
        );
        assert_eq!(
            range_text("thermal.rotor_conductivity_w_m_k").as_deref(),
            Some("(0, 10000]")
        );
        assert_eq!(
            range_text("solver.max_step_attempts").as_deref(),
            Some(">= 1")
        );
        assert_eq!(range_text("no_such_key"), None);
    }

    #[test]
    fn units_come_from_the_names() {
        assert_eq!(unit_of("speed_rpm"), "r/min");
        assert_eq!(unit_of("clearance_m"), "m");
        assert_eq!(unit_of("support_damping_n_s_per_m"), "N s/m");
        assert_eq!(unit_of("thermal.rotor_conductivity_w_m_k"), "W/(m K)");
        assert_eq!(unit_of("thermal.ambient_temperature_k"), "K");
        assert_eq!(unit_of("mu_dynamic"), "1");
        assert_eq!(unit_of("solver.rtol"), "1");
    }

    #[test]
    fn sources_come_from_the_doc_comments() {
        assert_eq!(
            source_of("Whole rotor mass (kg). Table 2: 11.5."),
            "the paper's Table 2"
        );
        assert_eq!(source_of("Default 46.6, AISI 52100 [ASM]."), "ASM");
        assert_eq!(source_of("Default 46.6, AISI 52100 \\[ASM\\]."), "ASM");
        assert!(source_of("Default 22.").starts_with("not in the paper"));
        assert_eq!(
            source_of("Friction law. Default `switched` (the paper's)."),
            "the paper"
        );
        assert_eq!(
            source_of("Dynamic friction coefficient rotor-race, eq. 8."),
            "the paper's eq. 8"
        );
    }

    #[cfg(feature = "schema")]
    #[test]
    fn the_schema_has_every_field_with_default_range_unit_and_source() {
        let schema = scene_schema();
        let props = schema["properties"].as_object().unwrap();
        let scene = serde_json::to_value(Scene::paper()).unwrap();
        for key in scene.as_object().unwrap().keys() {
            assert!(props.contains_key(key), "{key} missing from the schema");
        }
        for key in Scene::OPTIONAL_FIELDS {
            assert!(props.contains_key(*key), "{key} missing from the schema");
        }
        let speed = &props["speed_rpm"];
        assert_eq!(speed["default"], 8000.0);
        assert_eq!(speed["minimum"], -1e6);
        assert_eq!(speed["x-unit"], "r/min");
        assert!(speed["description"].as_str().unwrap().contains("r/min"));
        let clearance = &props["clearance_m"];
        assert_eq!(clearance["exclusiveMinimum"], 0.0);
        assert_eq!(clearance["x-source"], "the paper's Table 4");
        let rtol = &schema["$defs"]["SolverSettings"]["properties"]["rtol"];
        assert_eq!(rtol["maximum"], 1e-2);
        // The bearing analysis's fields carry theirs too, integers included.
        let bearing = schema["$defs"]["BearingPair"]["properties"]
            .as_object()
            .unwrap();
        let pair = serde_json::to_value(BearingPair::default()).unwrap();
        for key in pair.as_object().unwrap().keys() {
            let p = &bearing[key];
            assert!(p.get("x-unit").is_some(), "bearing.{key}: no unit");
            assert!(p.get("x-source").is_some(), "bearing.{key}: no source");
            assert!(
                p.get("minimum").is_some() || p.get("exclusiveMinimum").is_some(),
                "bearing.{key}: no minimum"
            );
            assert!(
                p.get("maximum").is_some() || p.get("exclusiveMaximum").is_some(),
                "bearing.{key}: no maximum"
            );
        }
        assert_eq!(bearing["balls_per_row"]["minimum"], 3.0);
        let v_eps = &schema["$defs"]["FrictionLaw"]["oneOf"][1]["properties"]["regularised"]
            ["properties"]["v_eps_m_s"];
        assert_eq!(v_eps["exclusiveMinimum"], 0.0, "{v_eps}");
        assert_eq!(v_eps["maximum"], 10.0, "{v_eps}");
        assert_eq!(v_eps["x-unit"], "m/s", "{v_eps}");
        assert_eq!(bearing["balls_per_row"]["maximum"], 1000.0);
        assert_eq!(bearing["rows"]["minimum"], 1.0);
        assert_eq!(bearing["young_modulus_pa"]["x-unit"], "Pa");
        assert_eq!(bearing["lumped_stiffness_n_per_m1_5"]["x-unit"], "N/m^1.5");
        assert_eq!(bearing["dynamic_rating_n"]["x-source"], "ISO 281");
        assert_eq!(
            bearing["ball_diameter_m"]["x-source"],
            "the paper's Table 3"
        );
        // Every bearing field is probed by the range test.
        for key in pair.as_object().unwrap().keys() {
            let dotted = format!("bearing.{key}");
            assert!(
                FIELD_RANGES.iter().any(|r| r.key == dotted),
                "{dotted} has no range"
            );
        }
    }
}
