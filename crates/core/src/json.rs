//! Reading user JSON strictly.
//!
//! serde's derived structs accept a JSON list as well as an object and read the list by
//! position: a scene file `[1000, 0.1]` would set the first two fields (`speed_rpm`,
//! `mu_dynamic`), and `--set 'thermal=[0.5]'` the thermal model's first field. Nothing about
//! that is intended. [`check_objects`] finds every place where the input holds a list and
//! the parsed value is a struct (or a struct variant), and [`from_str`] parses with that
//! check, so such input is refused with its path.

use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::Value;

/// Refuses `given` (the input as JSON) where it holds a list at a place that `parsed` (the
/// value serde made of it) serialises as an object: a struct read by position. The error
/// names the place (`thermal`, `critical.speed_rpm`, or the top level) and shows the list.
pub fn check_objects<T: Serialize>(given: &Value, parsed: &T) -> Result<(), String> {
    let shape = serde_json::to_value(parsed).map_err(|e| e.to_string())?;
    walk(given, &shape, "")
}

fn walk(given: &Value, shape: &Value, path: &str) -> Result<(), String> {
    match (given, shape) {
        (Value::Array(items), Value::Object(_)) => {
            let mut shown = Value::Array(items.clone()).to_string();
            if shown.len() > 60 {
                shown.truncate(57);
                shown.push_str("...");
            }
            let place = if path.is_empty() {
                "the top level".to_string()
            } else {
                format!("`{path}`")
            };
            Err(format!(
                "{place} must be a JSON object {{\"name\": value, ...}}, not a list ({shown}): \
                 a list would be read by position"
            ))
        }
        (Value::Object(g), Value::Object(s)) => {
            for (k, v) in g {
                if let Some(sv) = s.get(k) {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    walk(v, sv, &p)?;
                }
            }
            Ok(())
        }
        (Value::Array(g), Value::Array(s)) => {
            for (i, (gv, sv)) in g.iter().zip(s).enumerate() {
                walk(gv, sv, &format!("{path}[{i}]"))?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// `text` without a leading byte-order mark, which some Windows editors write before JSON
/// (RFC 8259, section 8.1, lets a reader skip it).
pub fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// Parses `text` as a `T`, then refuses a list wherever `T` has a struct
/// ([`check_objects`]). A field's error names the field by its dotted path before serde's
/// message, which keeps its line and column: `` `solver.rtol`: invalid type: string "x",
/// expected f64 at line 1 column 23 ``. A leading byte-order mark (which some Windows
/// editors write) is skipped, as JSON readers may (RFC 8259, section 8.1).
pub fn from_str<T: DeserializeOwned + Serialize>(text: &str) -> Result<T, serde_json::Error> {
    let text = without_bom(text);
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // A whole file that is a list (`[]`) fails inside serde as a struct read by position
        // ("invalid length 0, expected struct SweepSpec with 9 elements"): said plainly.
        match serde_json::from_str::<Value>(text) {
            Ok(Value::Array(_)) => <serde_json::Error as serde::de::Error>::custom(
                "the top level must be a JSON object {\"name\": value, ...}, not a list",
            ),
            _ => with_path(e),
        }
    })?;
    de.end()?;
    let given: Value = serde_json::from_str(text)?;
    check_objects(&given, &parsed).map_err(<serde_json::Error as serde::de::Error>::custom)?;
    Ok(parsed)
}

/// serde's error with the field's path in front of it; one at the top level, an unknown
/// top-level key (serde names it) or the end of the input as it is. A syntax error inside a
/// field is named too (`` `clearance_m`: number out of range ``); inside a field, serde_json's
/// "trailing characters" means a list longer than the field's fixed length, and says so.
fn with_path(e: serde_path_to_error::Error<serde_json::Error>) -> serde_json::Error {
    let path = e.path().to_string();
    let inner = e.into_inner();
    // serde names an unknown key itself; only a nested one needs its parents.
    let says_itself = !path.contains('.') && inner.to_string().starts_with("unknown field");
    // A syntax error between keys (a missing comma) has no field yet: its path ends in `?`.
    let between_keys = inner.is_syntax() && path.split('.').any(|p| p == "?");
    if path == "." || path.is_empty() || says_itself || inner.is_eof() || between_keys {
        inner
    } else if inner.is_syntax() && inner.to_string().starts_with("trailing characters") {
        <serde_json::Error as serde::de::Error>::custom(format!(
            "`{path}`: more values than the field holds ({inner})"
        ))
    } else {
        <serde_json::Error as serde::de::Error>::custom(format!("`{path}`: {inner}"))
    }
}

/// Reads a number that may have been written as `null`: serde_json writes a NaN (or an
/// infinity) as `null`, so a field that may hold NaN reads `null` back as NaN.
pub fn f64_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    use serde::Deserialize;
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scene;

    #[test]
    fn a_byte_order_mark_is_skipped_and_columns_count_from_the_text() {
        let s: Scene = from_str("\u{feff}{\"speed_rpm\": 4000}").unwrap();
        assert_eq!(s.speed_rpm, 4000.0);
        let with = from_str::<Scene>("\u{feff}{\"speed_rpm\": \"x\"}").unwrap_err();
        let without = from_str::<Scene>("{\"speed_rpm\": \"x\"}").unwrap_err();
        assert_eq!(with.to_string(), without.to_string());
    }

    #[test]
    fn a_file_that_is_a_list_is_said_to_be_one() {
        for text in ["[]", "[1000, 0.1]", "[{}]"] {
            let m = from_str::<Scene>(text).unwrap_err().to_string();
            assert!(
                m.starts_with("the top level must be a JSON object"),
                "{text}: {m}"
            );
        }
    }

    #[test]
    fn a_number_out_of_range_and_a_list_too_long_name_their_field() {
        let e = |text: &str| from_str::<Scene>(text).unwrap_err().to_string();
        let m = e(r#"{"clearance_m": 1e400}"#);
        assert!(
            m.starts_with("`clearance_m`: number out of range at line 1"),
            "{m}"
        );
        let m = e(r#"{"solver": {"rtol": -1e999}}"#);
        assert!(m.starts_with("`solver.rtol`: number out of range"), "{m}");
        let m = e(r#"{"release_offset_m": [1e-5, 0, 0]}"#);
        assert!(
            m.starts_with("`release_offset_m`: more values than the field holds (trailing"),
            "{m}"
        );
        // A syntax error between keys names no field (there is none yet).
        let m = e(r#"{"solver": {"rtol": 1e-4 "x": 1}}"#);
        assert!(m.starts_with("expected `,` or `}` at line 1"), "{m}");
    }

    #[test]
    fn lists_for_structs_are_refused_with_their_path_and_arrays_pass() {
        let e = from_str::<Scene>("[1000, 0.1]").unwrap_err().to_string();
        assert!(e.contains("top level") && e.contains("[1000,0.1]"), "{e}");
        let e = from_str::<Scene>(r#"{"thermal": [0.5]}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`thermal`") && e.contains("not a list"), "{e}");
        let e = from_str::<Scene>(r#"{"friction_law": {"regularised": [0.01]}}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`friction_law.regularised`"), "{e}");
        // Fields that are lists stay lists.
        let s = from_str::<Scene>(r#"{"release_offset_m": [1e-5, 0], "speed_rpm": 1000}"#).unwrap();
        assert_eq!(s.release_offset_m, [1e-5, 0.0]);
        assert_eq!(s.speed_rpm, 1000.0);
        // A wrong value names its field, nested ones by their dotted path, and keeps the
        // place in the text.
        let e = from_str::<Scene>(r#"{"clearance_m": "abc"}"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("`clearance_m`: invalid type") && e.contains("column"),
            "{e}"
        );
        let e = from_str::<Scene>(r#"{"solver": {"rtol": "x"}}"#)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("`solver.rtol`: invalid type"), "{e}");
        let e = from_str::<Scene>(r#"{"solver": {"rtoll": 1e-6}}"#)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`solver.rtoll`") && e.contains("unknown field"),
            "{e}"
        );
        // Text after the value is still refused.
        assert!(from_str::<Scene>("{} x").is_err());
        // serde alone reads the list by position: the reason for the check.
        let by_position: Scene = serde_json::from_str("[1000, 0.1]").unwrap();
        assert_eq!(by_position.speed_rpm, 1000.0);
    }
}
