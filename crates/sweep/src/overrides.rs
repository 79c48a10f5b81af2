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
    #[error("unknown scene parameter `{key}`{}; known: {known}", did_you_mean_text(suggestion.as_deref()))]
    UnknownKey {
        /// The key as given.
        key: String,
        /// The closest known key, when one is close enough to be a misspelling.
        suggestion: Option<String>,
        /// The known keys at that level, comma-separated.
        known: String,
    },
    /// The key goes on past a value that has no fields (`solver.rtol.x`).
    #[error("unknown scene parameter `{key}`: {hint}")]
    NotASection {
        /// The key as given.
        key: String,
        /// What the value before the extra part is, and how to set it.
        hint: String,
    },
    /// The value has the wrong type for the key.
    #[error("invalid value for `{key}`: {reason}")]
    BadValue {
        /// The key as given.
        key: String,
        /// What the field takes, in words, or serde's message (a section's, an enum's).
        reason: String,
    },
}

/// The known name closest to `given`, when it is close enough to be a misspelling of it
/// (Jaro-Winkler similarity of at least 0.8: `clearence_m` gives `clearance_m`, `rtl`
/// gives `rtol`; a name unlike every known one gives `None`).
pub fn did_you_mean<'a>(given: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    known
        .into_iter()
        .map(|k| (strsim::jaro_winkler(given, k), k))
        .filter(|(score, _)| *score >= 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, k)| k)
}

/// " (did you mean `x`?)" or nothing.
fn did_you_mean_text(suggestion: Option<&str>) -> String {
    suggestion
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default()
}

/// serde's message about a scene or sweep file, for its user: a "did you mean" added to an
/// `unknown field `x`, expected one of `a`, `b`` message (a misspelt key), and Rust's type
/// names in an `expected ...` put in words (`expected f64` reads `expected a number`,
/// `expected u64` `expected a whole number, 0 or more`, `expected a boolean` `expected true
/// or false`); any other message is returned as it is.
pub fn with_suggestion(message: &str) -> String {
    let message = with_range(&plain_types(message));
    const MARK: &str = "unknown field `";
    let Some(start) = message.find(MARK).map(|i| i + MARK.len()) else {
        return message;
    };
    // Split at a char boundary (the marker's end), whatever the key holds.
    let (head, rest) = message.split_at(start);
    let Some((given, tail)) = rest.split_once('`') else {
        return message;
    };
    let known: Vec<&str> = tail.split('`').skip(1).step_by(2).collect();
    let Some(best) = did_you_mean(given, known) else {
        return message;
    };
    // The suggestion first, beside the misspelt key, and the position before the long list
    // of known keys: `unknown field `clearence_m` (did you mean `clearance_m`?) at line 1
    // column 14; expected one of ...`.
    let list = tail.trim_start_matches(", ");
    match list.rfind(" at line ") {
        Some(at) => format!(
            "{head}{given}` (did you mean `{best}`?){}; {}",
            &list[at..],
            &list[..at]
        ),
        None => format!("{head}{given}` (did you mean `{best}`?); {list}"),
    }
}

/// A message about a scene field's value (`` `thermal.ball_count`: invalid value: integer
/// `-3`, expected a whole number, 0 or more at line 1 column 27``) with the field's own
/// allowed range added (`; allowed [3, 200]`): the type's range is wider than the field's.
/// The path may start at the scene (a scene file) or above it (`scene.` in a sweep spec).
fn with_range(message: &str) -> String {
    let Some(rest) = message.strip_prefix('`') else {
        return message.to_string();
    };
    let Some((path, tail)) = rest.split_once("`: ") else {
        return message.to_string();
    };
    if !(tail.starts_with("invalid value") || tail.starts_with("invalid type")) {
        return message.to_string();
    }
    let key = path.strip_prefix("scene.").unwrap_or(path);
    match whirlmap_core::schema::range_text(key) {
        Some(range) => {
            let unit = whirlmap_core::schema::unit_of(key);
            let unit = if unit == "1" {
                String::new()
            } else {
                format!(" {unit}")
            };
            format!("{message}; allowed {range}{unit}")
        }
        None => message.to_string(),
    }
}

/// Rust's type names in serde's `expected ...` put in words (see [`with_suggestion`]).
fn plain_types(message: &str) -> String {
    [
        ("expected f64", "expected a number"),
        ("expected u64", "expected a whole number, 0 or more"),
        ("expected usize", "expected a whole number, 0 or more"),
        ("expected u32", "expected a whole number, 0 or more"),
        ("expected a boolean", "expected true or false"),
    ]
    .into_iter()
    .fold(message.to_string(), |m, (rust, words)| {
        m.replace(rust, words)
    })
}

/// Parses `key=value` and applies it to `scene`.
pub fn apply_assignment(scene: &mut Scene, assignment: &str) -> Result<(), OverrideError> {
    let (key, value) = assignment
        .split_once('=')
        .ok_or_else(|| OverrideError::Syntax(assignment.to_string()))?;
    let (key, text) = (key.trim(), value.trim());
    // `nan`, `inf`, `1e400`: numbers JSON cannot hold, refused with the field's range when
    // the key is a number field (an unknown key says so first; another field, an enum's,
    // reads the text as it would any other).
    if let Ok(x) = text.parse::<f64>() {
        let numeric = match apply(&mut scene.clone(), key, Value::from(0.0)) {
            Ok(()) => true,
            Err(e @ (OverrideError::UnknownKey { .. } | OverrideError::NotASection { .. })) => {
                return Err(e)
            }
            Err(_) => false,
        };
        if !x.is_finite() && numeric {
            return Err(OverrideError::BadValue {
                key: key.to_string(),
                reason: format!(
                    "{text} is not a finite number; allowed {}",
                    finite_range(scene, key)
                ),
            });
        }
    }
    let mut value: Value =
        serde_json::from_str(text).unwrap_or_else(|_| Value::String(text.to_string()));
    // `-0` is 0, as the number flags read it: echoed and hashed as 0.
    if value
        .as_f64()
        .is_some_and(|x| x == 0.0 && x.is_sign_negative())
    {
        value = Value::from(0.0);
    }
    apply(scene, key, value)
}

/// The range [`Scene::validate`] allows for the number `key`, in its own words, found by
/// setting the largest finite values of either sign; "a finite number" when the key is not a
/// number or the validation says nothing of it.
pub fn finite_range(scene: &Scene, key: &str) -> String {
    for extreme in [f64::MAX, -f64::MAX] {
        let mut s = scene.clone();
        if apply(&mut s, key, Value::from(extreme)).is_err() {
            break;
        }
        if let Err(e) = s.validate() {
            if e.field == key {
                return e.allowed;
            }
        }
    }
    "a finite number".to_string()
}

/// Sets the scene parameter `key` (dotted for nested fields) to `value`.
pub fn apply(scene: &mut Scene, key: &str, value: Value) -> Result<(), OverrideError> {
    let mut root = serde_json::to_value(&*scene).expect("a scene serialises");
    set_value(&mut root, key, value)?;
    let parsed: Scene = serde_json::from_value(root.clone()).map_err(|e| {
        // Only on the way out: the value given and the scene's own at `key` (unchanged).
        let shown = match get_value(&root, key) {
            Some(Value::String(text)) => text.clone(),
            Some(other) => other.to_string(),
            None => String::new(),
        };
        let before = serde_json::to_value(&*scene).expect("a scene serialises");
        OverrideError::BadValue {
            key: key.to_string(),
            reason: wrong_type_reason(scene, key, get_value(&before, key), &shown)
                .unwrap_or_else(|| e.to_string()),
        }
    })?;
    // A list where the scene has an object would be read by position.
    whirlmap_core::json::check_objects(&root, &parsed).map_err(|reason| {
        OverrideError::BadValue {
            key: key.to_string(),
            reason,
        }
    })?;
    *scene = parsed;
    Ok(())
}

/// The value at the dotted `key` in `root`, if it is there (an optional field at its
/// default is absent).
fn get_value<'v>(root: &'v Value, key: &str) -> Option<&'v Value> {
    key.split('.').try_fold(root, |node, part| node.get(part))
}

/// Whether `value` at `key` makes a scene as [`apply`] takes it (of the right kind, and no
/// list read as a section by position; its range is not checked).
fn parses(scene: &Scene, key: &str, value: Value) -> bool {
    let mut root = serde_json::to_value(scene).expect("a scene serialises");
    if set_value(&mut root, key, value).is_err() {
        return false;
    }
    serde_json::from_value::<Scene>(root.clone())
        .is_ok_and(|parsed| whirlmap_core::json::check_objects(&root, &parsed).is_ok())
}

/// What a value of the wrong kind for `key` should have been, in the user's words, from the
/// kinds the field takes (tried with probe values through [`parses`], so an optional field
/// absent at its default is covered too, and a section is never offered a list): `abc` is
/// not a number, with the field's allowed range; `1.5` is not a whole number written in
/// digits (a count); `maybe` is not true or false; `[1,x]` is not a list of 2 numbers, with
/// an example; each saying when null is allowed too. `None` for the other kinds (a section,
/// an enum's unknown variant), whose serde message names the known fields or the choices.
fn wrong_type_reason(
    scene: &Scene,
    key: &str,
    before: Option<&Value>,
    shown: &str,
) -> Option<String> {
    // A section keeps serde's message, which names an unknown field and the known ones.
    if matches!(before, Some(Value::Object(_))) {
        return None;
    }
    let or_null = if parses(scene, key, Value::Null) {
        " (or null for none)"
    } else {
        ""
    };
    if parses(scene, key, Value::from(0.0)) {
        return Some(format!(
            "`{shown}` is not a number{or_null}; allowed {}",
            finite_range(scene, key)
        ));
    }
    if parses(scene, key, Value::from(0_u64)) {
        // A count: the validation's words for 0 give its range when 0 is not allowed. JSON
        // reads `1e6` and `2.0` as fractions, so the message asks for digits.
        let mut s = scene.clone();
        let allowed = match apply(&mut s, key, Value::from(0_u64)).map(|()| s.validate()) {
            Ok(Err(e)) if e.field == key => e.allowed,
            _ => ">= 0".to_string(),
        };
        let example = before.map_or_else(|| "1000".to_string(), Value::to_string);
        return Some(format!(
            "`{shown}` is not a whole number written in digits (e.g. `{example}`){or_null}; \
             allowed {allowed}"
        ));
    }
    if parses(scene, key, Value::Bool(false)) {
        return Some(format!("`{shown}` is not `true` or `false`{or_null}"));
    }
    let example = match before {
        Some(Value::Array(items)) if items.iter().all(Value::is_number) => {
            Value::Array(items.clone())
        }
        _ => (1..=4)
            .map(|n| Value::Array(vec![Value::from(0.0); n]))
            .find(|v| parses(scene, key, v.clone()))?,
    };
    let n = example.as_array().map_or(0, Vec::len);
    let numbers = if n == 1 { "number" } else { "numbers" };
    Some(format!(
        "`{shown}` is not a list of {n} {numbers}{or_null}; write it as `{example}`"
    ))
}

/// Sets `key` (dotted for nested fields) to `value` in `root`, a scene as JSON (from
/// `serde_json::to_value`), checking the key as [`apply`] does but not the value: the
/// caller deserialises the scene once after setting every key (a sweep's grid point).
pub fn set_value(root: &mut Value, key: &str, value: Value) -> Result<(), OverrideError> {
    let mut node = root;
    let parts: Vec<&str> = key.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let obj = match node {
            Value::Object(m) => m,
            other => {
                let parent = parts[..i].join(".");
                return Err(OverrideError::NotASection {
                    key: key.to_string(),
                    hint: match other {
                        Value::Array(items) => format!(
                            "`{parent}` is a list of {}: set it whole, e.g. `--set {parent}={}`",
                            items.len(),
                            Value::Array(items.clone())
                        ),
                        _ => format!("`{parent}` is a single value: it has no fields"),
                    },
                });
            }
        };
        // Optional scene fields are absent from the JSON while at their default; setting one
        // inserts it (absent and default deserialise alike).
        let path = parts[..=i].join(".");
        let optional = Scene::OPTIONAL_FIELDS.contains(&path.as_str());
        if !obj.contains_key(*part) && !optional {
            let parent = parts[..i].join(".");
            let mut known = obj.keys().cloned().collect::<Vec<_>>();
            for f in Scene::OPTIONAL_FIELDS {
                let (dir, name) = f.rsplit_once('.').unwrap_or(("", f));
                if dir == parent && !known.iter().any(|k| k == name) {
                    known.push(name.to_string());
                }
            }
            let suggestion = did_you_mean(part, known.iter().map(String::as_str)).map(|best| {
                if parent.is_empty() {
                    best.to_string()
                } else {
                    format!("{parent}.{best}")
                }
            });
            let known = known.join(", ");
            return Err(OverrideError::UnknownKey {
                key: key.to_string(),
                suggestion,
                known,
            });
        }
        if i + 1 == parts.len() {
            obj.insert(part.to_string(), value);
            return Ok(());
        }
        // An optional section that is absent (e.g. `thermal` on a drop without it) has no
        // sub-keys to set: say so instead of failing deeper.
        let Some(next) = obj.get_mut(*part) else {
            // `whirlmap drop` has a flag that switches each optional section on; the other
            // optional fields are values (a number, a list), set whole.
            let known = match *part {
                "thermal" | "bearing" => format!(
                    "none (`{part}` is not set in this scene: set it whole first, e.g. \
                     `--set {part}={{}}`, or pass --{part} to `whirlmap drop`)"
                ),
                _ => format!(
                    "none (`{part}` is a value, not a section: set it whole, \
                     `--set {part}=VALUE`; `whirlmap scene --schema` gives its form)"
                ),
            };
            return Err(OverrideError::UnknownKey {
                key: key.to_string(),
                suggestion: None,
                known,
            });
        };
        node = next;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use whirlmap_core::FrictionLaw;

    #[test]
    fn a_key_past_a_value_says_what_the_value_is() {
        let mut s = Scene::paper();
        let e = apply_assignment(&mut s, "solver.rtol.x=1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`solver.rtol` is a single value: it has no fields"),
            "{e}"
        );
        let e = apply_assignment(&mut s, "release_offset_m.0=1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`release_offset_m` is a value, not a section"),
            "{e}"
        );
        assert!(!e.contains("={}"), "{e}");
        s.release_offset_m = [1e-5, 0.0];
        let e = apply_assignment(&mut s, "release_offset_m.0=1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`release_offset_m` is a list of 2: set it whole, e.g. `--set release_offset_m=[0.00001,0.0]`"),
            "{e}"
        );
    }

    #[test]
    fn a_number_json_cannot_hold_is_refused_with_the_fields_range() {
        let mut s = Scene::paper();
        for (set, says) in [
            (
                "clearance_m=nan",
                "nan is not a finite number; allowed (0, 0.1] m",
            ),
            (
                "solver.rtol=1e400",
                "1e400 is not a finite number; allowed (0, 1e-2]",
            ),
            (
                "speed_rpm=-inf",
                "-inf is not a finite number; allowed [-1e6, 1e6] r/min",
            ),
            (
                "unbalance_phase_rad=NaN",
                "NaN is not a finite number; allowed a finite number",
            ),
        ] {
            let e = apply_assignment(&mut s, set).unwrap_err().to_string();
            assert!(e.contains(says), "{set}: {e}");
        }
        assert_eq!(s, Scene::paper(), "nothing was set");
        // The key is checked first; a field that is not a number reads the text as text.
        let e = apply_assignment(&mut s, "clearnce_m=nan")
            .unwrap_err()
            .to_string();
        assert!(e.contains("did you mean `clearance_m`"), "{e}");
        let e = apply_assignment(&mut s, "solver.method=inf")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown variant `inf`"), "{e}");
    }

    #[test]
    fn a_value_of_the_wrong_kind_says_what_the_field_takes() {
        let mut s = Scene::paper();
        for (set, says) in [
            (
                "solver.rtol=abc",
                "`abc` is not a number; allowed (0, 1e-2]",
            ),
            (
                "clearance_m=\"wide\"",
                "`wide` is not a number; allowed (0, 0.1] m",
            ),
            (
                "clearance_m=[1,2]",
                "`[1,2]` is not a number; allowed (0, 0.1] m",
            ),
            // An optional number at its default is absent from the scene's JSON.
            (
                "race_speed_rad_s=fast",
                "`fast` is not a number; allowed [-1e5, 1e5] rad/s",
            ),
            (
                "solver.max_step_attempts=abc",
                "`abc` is not a whole number written in digits (e.g. `20000000`); allowed >= 1",
            ),
            (
                "solver.max_step_attempts=1.5",
                "`1.5` is not a whole number written in digits (e.g. `20000000`); allowed >= 1",
            ),
            (
                "solver.max_step_attempts=-1",
                "`-1` is not a whole number written in digits (e.g. `20000000`); allowed >= 1",
            ),
            ("drag_enabled=maybe", "`maybe` is not `true` or `false`"),
            ("drag_enabled=1", "`1` is not `true` or `false`"),
            (
                "release_offset_m=[1,x]",
                "`[1,x]` is not a list of 2 numbers; write it as `[0.0,0.0]`",
            ),
            (
                "release_offset_m=[1,2,3]",
                "`[1,2,3]` is not a list of 2 numbers; write it as `[0.0,0.0]`",
            ),
        ] {
            let e = apply_assignment(&mut s, set).unwrap_err().to_string();
            let key = set.split('=').next().unwrap();
            assert!(
                e.contains(&format!("`{key}`")) && e.contains(says),
                "{set}: {e}"
            );
            assert!(
                !e.contains("f64") && !e.contains("invalid type"),
                "{set}: {e}"
            );
        }
        assert_eq!(s, Scene::paper(), "nothing was set");
        // An optional number says that null is allowed too.
        let e = apply_assignment(&mut s, "stop_speed_rpm=slow")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`slow` is not a number (or null for none); allowed"),
            "{e}"
        );
        // A section, present or absent, keeps serde's message: it is never offered a list
        // (serde would read one by position), and a misspelt key inside it is named.
        for (set, says) in [
            ("solver=abc", "expected struct SolverSettings"),
            ("thermal=abc", "expected struct ThermalParams"),
            (r#"solver={"rtoll":1e-6}"#, "unknown field `rtoll`"),
            (
                r#"thermal={"macro_stp_s":1e-3}"#,
                "unknown field `macro_stp_s`",
            ),
        ] {
            let e = apply_assignment(&mut s, set).unwrap_err().to_string();
            assert!(e.contains(says) && !e.contains("list of"), "{set}: {e}");
        }
        // An enum keeps serde's message, which lists the choices.
        let e = apply_assignment(&mut s, "solver.method=fast")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unknown variant `fast`") && e.contains("rodas4"),
            "{e}"
        );
    }

    #[test]
    fn minus_zero_is_set_as_zero() {
        let mut s = Scene::paper();
        apply_assignment(&mut s, "speed_rpm=-0.0").unwrap();
        assert!(s.speed_rpm == 0.0 && s.speed_rpm.is_sign_positive());
        let mut z = Scene::paper();
        apply_assignment(&mut z, "speed_rpm=0").unwrap();
        assert_eq!(s.hash_hex(), z.hash_hex());
    }

    #[test]
    fn a_misspelt_key_gets_the_closest_known_one() {
        let mut s = Scene::paper();
        let e = apply_assignment(&mut s, "clearence_m=1e-4").unwrap_err();
        assert!(
            e.to_string().contains("(did you mean `clearance_m`?)"),
            "{e}"
        );
        let e = apply_assignment(&mut s, "solver.rtl=1e-4").unwrap_err();
        assert!(
            e.to_string().contains("(did you mean `solver.rtol`?)"),
            "{e}"
        );
        let e = apply_assignment(&mut s, "zzzz=1").unwrap_err();
        assert!(!e.to_string().contains("did you mean"), "{e}");
        // serde's message for a scene or sweep file
        let text = r#"{"clearence_m": 1e-4}"#;
        let err = whirlmap_core::json::from_str::<Scene>(text).unwrap_err();
        // A key holding backticks, the marker and non-ASCII text: no panic, the text kept.
        let odd = format!(
            "unknown field `clearence_m` `clearance_m` {} unknown field `x`, expected one of \
             `clearance_m`, `mu_dynamic` at line 1 column 9",
            "é".repeat(600)
        );
        assert!(with_suggestion(&odd).contains(&"é".repeat(600)));
        let m = with_suggestion(&err.to_string());
        assert!(
            m.starts_with(
                "unknown field `clearence_m` (did you mean `clearance_m`?) at line 1 column \
                 14; expected one of `speed_rpm`, "
            ),
            "{m}"
        );
        assert!(m.ends_with("`bearing`"), "{m}");
        assert_eq!(with_suggestion("expected value"), "expected value");
        // A value of the wrong type in a file: the field's path, the value, and the type in
        // words.
        let text = r#"{"solver": {"rtol": "x"}, "drag_enabled": 1}"#;
        let err = whirlmap_core::json::from_str::<Scene>(text).unwrap_err();
        let said = with_suggestion(&err.to_string());
        assert!(
            said.contains("solver.rtol") && said.contains("\"x\", expected a number"),
            "{said}"
        );
        let text = r#"{"drag_enabled": 1}"#;
        let err = whirlmap_core::json::from_str::<Scene>(text).unwrap_err();
        let said = with_suggestion(&err.to_string());
        assert!(
            said.contains("drag_enabled") && said.contains("expected true or false"),
            "{said}"
        );
        let text = r#"{"solver": {"max_events": -3}}"#;
        let err = whirlmap_core::json::from_str::<Scene>(text).unwrap_err();
        let said = with_suggestion(&err.to_string());
        assert!(
            said.contains("expected a whole number, 0 or more"),
            "{said}"
        );
        // ... and the field's own range, narrower than the type's, with its unit if any.
        assert!(said.ends_with("; allowed >= 1"), "{said}");
        let text = r#"{"solver": {"rtol": "x"}}"#;
        let err = whirlmap_core::json::from_str::<Scene>(text).unwrap_err();
        assert!(with_suggestion(&err.to_string()).ends_with("; allowed (0, 0.01]"));
        let text = r#"{"thermal": {"bearing_width_m": "x"}}"#;
        let err = whirlmap_core::json::from_str::<Scene>(text).unwrap_err();
        assert!(with_suggestion(&err.to_string()).ends_with("; allowed (0, 10] m"));
        // In a sweep spec the path starts above the scene; a key with no range is left.
        assert!(
            with_suggestion("`scene.thermal.ball_count`: invalid value: integer `-3`")
                .ends_with("allowed [3, 200]")
        );
        let other = "`axes.mu.steps`: invalid value: integer `-2`, expected u64";
        assert!(!with_suggestion(other).contains("allowed"));
    }

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
        assert!(err.to_string().contains("pass --thermal"), "{err}");
        // Each section's hint names its own flag.
        let err = apply_assignment(&mut s, "bearing.rows=3").unwrap_err();
        assert!(
            err.to_string().contains("--set bearing={}")
                && err.to_string().contains("pass --bearing")
                && !err.to_string().contains("--thermal"),
            "{err}"
        );
        apply_assignment(&mut s, "thermal={}").unwrap();
        apply_assignment(&mut s, "thermal.macro_step_s=0.002").unwrap();
        assert_eq!(s.thermal.as_ref().unwrap().macro_step_s, 0.002);
        // Every listed field, nested ones too, is settable from a scene that omits it.
        for (key, value) in [
            ("support_damper", "\"radial_only\""),
            ("release_velocity_m_s", "[0, -1e-3]"),
            ("solver.free_flight_gap_bound", "false"),
            ("solver.race_atol_scale", "100"),
            ("solver.method", "ros34pw2"),
        ] {
            let mut t = Scene::paper();
            apply_assignment(&mut t, &format!("{key}={value}")).unwrap();
            assert_ne!(t, Scene::paper(), "{key}");
        }
        // A misspelt nested key lists the solver's optional fields as well.
        let e = apply_assignment(&mut s, "solver.race_atol=10")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("race_atol_scale") && e.contains("rtol") && !e.contains("clearance_m"),
            "{e}"
        );
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
        apply_assignment(&mut s, "solver.method=ros34pw2").unwrap();
        let text = serde_json::to_string(&s).unwrap();
        assert!(
            !text.contains("quasi_static_race") && text.contains(r#""method":"ros34pw2""#),
            "an optional field at its default stays out of the canonical JSON, every solver \
             setting is in it: {text}"
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
