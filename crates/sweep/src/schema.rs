//! JSON Schemas of the files the sweep crate reads: sweep files ([`SweepSpec`]) and
//! ensemble files ([`EnsembleSpec`]), derived from the types they are read with. Their
//! `scene` is the scene's own schema ([`whirlmap_core::schema::scene_schema`]), with the
//! unit, allowed range and source of every field.

use crate::ensemble::EnsembleSpec;
use crate::spec::SweepSpec;
use serde_json::Value;

/// The schema of `T`, whose `scene` field and the scene's nested types are replaced by the
/// annotated scene schema.
fn with_scene_schema<T: schemars::JsonSchema>() -> Value {
    let mut root = serde_json::to_value(schemars::schema_for!(T)).unwrap_or_default();
    let mut scene = whirlmap_core::schema::scene_schema();
    let scene_defs = scene
        .as_object_mut()
        .and_then(|m| m.remove("$defs"))
        .unwrap_or_default();
    if let Some(m) = scene.as_object_mut() {
        m.remove("$schema");
    }
    if let Some(Value::Object(defs)) = root.get_mut("$defs") {
        defs.insert("Scene".to_string(), scene);
        if let Value::Object(sd) = scene_defs {
            defs.extend(sd);
        }
    }
    root
}

/// The JSON Schema of a sweep file (draft 2020-12).
pub fn sweep_schema() -> Value {
    with_scene_schema::<SweepSpec>()
}

/// The JSON Schema of an ensemble file (`whirlmap ensemble` and `whirlmap adaptive`).
pub fn ensemble_schema() -> Value {
    with_scene_schema::<EnsembleSpec>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sweep_schema_holds_the_annotated_scene_and_the_spec_fields() {
        let s = sweep_schema();
        for key in [
            "name",
            "scene",
            "duration_s",
            "axes",
            "critical",
            "charts",
            "probability",
        ] {
            assert!(s["properties"].get(key).is_some(), "{key} missing");
        }
        let scene = &s["$defs"]["Scene"];
        assert_eq!(scene["properties"]["clearance_m"]["x-unit"], "m");
        assert!(s["$defs"]["SolverSettings"]["properties"]["rtol"]["maximum"].is_number());
        assert!(s["$defs"]["AxisValues"]["oneOf"].is_array());
        // every committed sweep file has only keys the schema lists at the top level
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../sweeps");
        let props = s["properties"].as_object().unwrap();
        for name in ["paper.json", "nightly.json", "smoke.json"] {
            let text = std::fs::read_to_string(format!("{dir}/{name}")).unwrap();
            let v: Value = serde_json::from_str(&text).unwrap();
            for k in v.as_object().unwrap().keys() {
                assert!(props.contains_key(k), "{name}: {k} not in the schema");
            }
        }
        let e = ensemble_schema();
        assert!(e["properties"].get("ensemble").is_some());
        assert!(e["$defs"].get("Dist").is_some());
    }
}
