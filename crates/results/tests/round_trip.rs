//! Rows read back through the typed layer are written again to the very same bytes.

use std::path::{Path, PathBuf};
use whirlmap_results::critical::{critical_json, read_critical};
use whirlmap_results::files::{CRITICAL_FILE, POINTS_FILE};
use whirlmap_results::orbit::OrbitFile;
use whirlmap_results::point::{load_points, read_records, PointRecord, PointStatus, Status};

fn paper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../results/paper")
}

#[test]
fn committed_point_records_round_trip_byte_for_byte() {
    let text = std::fs::read_to_string(paper().join(POINTS_FILE)).unwrap();
    let records = read_records(&paper()).unwrap();
    assert!(records.torn.is_none());
    assert_eq!(records.rows.len(), text.lines().count());
    for ((n, r), line) in records.rows.iter().zip(text.lines()) {
        assert_eq!(r.to_line(), line, "line {n}");
    }
    // The charts' view of the same file agrees on every point.
    let rows = load_points(&paper()).unwrap();
    assert_eq!(rows.len(), records.rows.len());
    for (row, (_, r)) in rows.iter().zip(&records.rows) {
        assert_eq!(row.key, r.key);
        assert_eq!(row.status == PointStatus::Ok, r.status == Status::Ok);
        assert_eq!(
            row.max_contact_force_n,
            r.record.as_ref().map(|d| d.max_contact_force_n)
        );
    }
}

#[test]
fn failed_points_round_trip() {
    let line = r#"{"key":"0123456789abcdef","index":3,"inputs":{"speed_rpm":8000.0,"mu":0.1},"scene_hash":"abc","duration_s":0.05,"model_version":5,"status":"failed","error":{"kind":"step_budget","message":"too many steps"}}"#;
    let r: PointRecord = serde_json::from_str(line).unwrap();
    assert_eq!(r.inputs.0[0].0, "speed_rpm", "inputs keep the file's order");
    assert_eq!(r.to_line(), line);
}

#[test]
fn committed_critical_rows_round_trip_byte_for_byte() {
    let text = std::fs::read_to_string(paper().join(CRITICAL_FILE)).unwrap();
    let rows = read_critical(&paper()).unwrap().unwrap();
    assert!(!rows.is_empty());
    assert_eq!(critical_json(&rows), text);
    assert!(read_critical(Path::new("/nonexistent")).unwrap().is_none());
}

#[test]
fn orbit_files_keep_sorted_keys_and_round_trip() {
    let orbit = serde_json::from_str(r#"{"clearance_m":0.0002,"samples":[]}"#).unwrap();
    let f = OrbitFile::new(
        8000.0,
        0.3,
        whirlmap_core::classify::OrbitClass::Pendulum,
        orbit,
    );
    let text = f.to_json();
    assert!(text.starts_with(r#"{"class":"pendulum","mu":0.3,"orbit":{"clearance_m":0.0002"#));
    assert!(text.ends_with(r#""speed_rpm":8000.0}"#), "{text}");
    let back: OrbitFile = serde_json::from_str(&text).unwrap();
    assert_eq!(back.to_json(), text);
    assert_eq!(
        back.class_label(),
        whirlmap_core::classify::OrbitClass::Pendulum.label()
    );
}
