//! The lines of `points.jsonl`: [`PointRecord`] as a sweep writes it (read back to the same
//! bytes), [`PointLine`] for readers that take any line with the fields they need, and
//! [`PointRow`], what charts and comparisons use of a point.

use crate::files::POINTS_FILE;
use crate::read::{parse_jsonl, read_bytes, Jsonl, ReadError};
use crate::record::DropRecord;
use serde::de::{MapAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Deserializer, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use whirlmap_core::classify::OrbitClass;

/// Outcome of one point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The drop ran to its end.
    Ok,
    /// The drop failed; see `error`.
    Failed,
}

/// A failed point's error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointError {
    /// Machine-readable kind (`SolveError::kind`, or `panic`).
    pub kind: String,
    /// Human-readable message.
    pub message: String,
}

/// Axis name -> value in the spec's axis order; serialises as a JSON object in that order
/// and reads back in the file's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs(pub Vec<(String, f64)>);

impl Serialize for Inputs {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

impl<'de> Deserialize<'de> for Inputs {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct InOrder;
        impl<'de> Visitor<'de> for InOrder {
            type Value = Inputs;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of axis name -> number")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Inputs, A::Error> {
                let mut v = Vec::with_capacity(map.size_hint().unwrap_or(0));
                while let Some(entry) = map.next_entry::<String, f64>()? {
                    v.push(entry);
                }
                Ok(Inputs(v))
            }
        }
        d.deserialize_map(InOrder)
    }
}

/// One line of `points.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointRecord {
    /// The point's key: 16 hex digits of the scene, duration and model version.
    pub key: String,
    /// Grid index.
    pub index: usize,
    /// Axis values.
    pub inputs: Inputs,
    /// `Scene::hash_hex` of the point's scene.
    pub scene_hash: String,
    /// Simulated time asked for (s).
    pub duration_s: f64,
    /// `whirlmap_core::MODEL_VERSION`.
    pub model_version: u32,
    /// `ok` or `failed`.
    pub status: Status,
    /// The drop record when ok.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record: Option<DropRecord>,
    /// The error when failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<PointError>,
    /// Wall time of the drop (s). Not in `points.jsonl` (it would break byte-identity across
    /// runs); written to `timings.jsonl`. Zero when read back.
    #[serde(skip)]
    pub wall_time_s: f64,
}

impl PointRecord {
    /// The line written to `points.jsonl` (without the newline).
    pub fn to_line(&self) -> String {
        serde_json::to_string(self).expect("records serialise")
    }
}

/// Any line of `points.jsonl` with the fields a reader may need, each optional: records of
/// older versions and hand-made files read as well as a sweep's own ([`PointRecord`]).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
pub struct PointLine {
    /// The point's key.
    #[serde(default)]
    pub key: Option<String>,
    /// Grid index.
    #[serde(default)]
    pub index: Option<u64>,
    /// The inputs, as written.
    #[serde(default)]
    pub inputs: BTreeMap<String, Value>,
    /// `ok` or `failed` (other text is neither).
    #[serde(default)]
    pub status: Option<String>,
    /// The drop record, as written.
    #[serde(default)]
    pub record: Option<Value>,
    /// The error: an object with `message`, or text.
    #[serde(default)]
    pub error: Option<Value>,
    /// Simulated time asked for (s).
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// The model version that ran the point.
    #[serde(default)]
    pub model_version: Option<u64>,
}

impl PointLine {
    /// Whether the line says `ok`.
    pub fn is_ok(&self) -> bool {
        self.status.as_deref() == Some("ok")
    }
}

/// Whether a grid point ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointStatus {
    /// The drop finished and has a record.
    Ok,
    /// The drop failed (or the status is unknown).
    Failed,
}

/// The input names of the speed axis.
pub const SPEED_KEYS: [&str; 1] = ["speed_rpm"];
/// The input names of the friction axis (`mu` first).
pub const MU_KEYS: [&str; 2] = ["mu", "mu_dynamic"];

/// One line of `points.jsonl`, reduced to what charts and comparisons use.
#[derive(Debug, Clone, PartialEq)]
pub struct PointRow {
    /// The point's stable key.
    pub key: String,
    /// The point's index in the sweep, if given.
    pub index: Option<u64>,
    /// The sweep inputs (`speed_rpm`, `mu`, ...), as written.
    pub inputs: BTreeMap<String, Value>,
    /// Whether the drop ran.
    pub status: PointStatus,
    /// Orbit class (ok points whose record names one).
    pub class: Option<OrbitClass>,
    /// Maximum contact force (N), if finite.
    pub max_contact_force_n: Option<f64>,
    /// Peak heat power (W), if finite.
    pub peak_heat_power_w: Option<f64>,
    /// Hottest peak node temperature (K), for records made with the thermal model.
    pub peak_temperature_k: Option<f64>,
    /// Peak Hertz contact pressure of the most loaded ball (Pa), for records made with the
    /// bearing analysis.
    pub peak_contact_pressure_pa: Option<f64>,
    /// The static limit over that pressure, for records made with the bearing analysis.
    pub static_safety_factor: Option<f64>,
    /// Drops of this kind to fatigue failure (L10), for records made with the bearing
    /// analysis; `None` also when the drop did no damage (an infinite life).
    pub drops_to_failure: Option<f64>,
    /// The carried whirl turns after which the run was stopped, for a run stopped as decided
    /// whirl (its damage is that of these turns only).
    pub whirl_stop_turns: Option<f64>,
    /// The error of a failed point, as text.
    pub error: Option<String>,
    /// Simulated time asked for (s), when the record says.
    pub duration_s: Option<f64>,
    /// The model version that ran the point, when the line says.
    pub model_version: Option<u64>,
}

impl PointRow {
    /// The numeric input under the first of `keys` present.
    fn input(&self, keys: &[&str]) -> Option<f64> {
        keys.iter()
            .find_map(|k| self.inputs.get(*k))
            .and_then(Value::as_f64)
    }
    /// Release speed (r/min), if an input.
    pub fn speed_rpm(&self) -> Option<f64> {
        self.input(&SPEED_KEYS)
    }
    /// Friction coefficient, if an input.
    pub fn mu(&self) -> Option<f64> {
        self.input(&MU_KEYS)
    }
}

fn finite(v: Option<&Value>) -> Option<f64> {
    v.and_then(Value::as_f64).filter(|x| x.is_finite())
}

impl From<PointLine> for PointRow {
    fn from(r: PointLine) -> Self {
        let ok = r.is_ok() && r.record.is_some();
        let rec = r.record.as_ref().filter(|_| ok);
        let error = r.error.map(|e| match e {
            Value::String(s) => s,
            other => other
                .get("message")
                .and_then(Value::as_str)
                .map(str::to_string)
                .unwrap_or_else(|| other.to_string()),
        });
        PointRow {
            key: r.key.unwrap_or_default(),
            index: r.index,
            inputs: r.inputs,
            status: if ok {
                PointStatus::Ok
            } else {
                PointStatus::Failed
            },
            class: rec
                .and_then(|v| v.get("class"))
                .and_then(|c| serde_json::from_value(c.clone()).ok()),
            max_contact_force_n: finite(rec.and_then(|v| v.get("max_contact_force_n"))),
            peak_heat_power_w: finite(rec.and_then(|v| v.get("peak_heat_power_w"))),
            peak_temperature_k: rec
                .and_then(|v| v.get("temperatures_k"))
                .and_then(Value::as_object)
                .and_then(|nodes| {
                    nodes
                        .values()
                        .filter_map(|n| finite(n.get("peak")))
                        .reduce(f64::max)
                }),
            peak_contact_pressure_pa: finite(rec.and_then(|v| v.get("peak_contact_pressure_pa"))),
            static_safety_factor: finite(rec.and_then(|v| v.get("static_safety_factor"))),
            drops_to_failure: finite(rec.and_then(|v| v.get("drops_to_failure"))),
            whirl_stop_turns: rec
                .filter(|v| v.get("stop_reason").and_then(Value::as_str) == Some("whirl_decided"))
                .and_then(|v| v.get("features"))
                .and_then(|f| finite(f.get("whirl_streak_turns")))
                .map(f64::abs),
            error,
            duration_s: r.duration_s,
            model_version: r.model_version,
        }
    }
}

/// Reads the lines of `dir/points.jsonl` ([`crate::read::parse_jsonl`]: a torn last line is
/// ignored and reported). A file whose only line is torn holds no record: an error.
pub fn read_point_lines(dir: &Path) -> Result<Jsonl<PointLine>, ReadError> {
    let path = dir.join(POINTS_FILE);
    let j = parse_jsonl::<PointLine>(&path, &read_bytes(&path)?).map_err(|e| match e {
        ReadError::Parse {
            path,
            line,
            message,
        } => ReadError::Parse {
            path,
            line,
            message: format!("not a record of a grid point: {message}"),
        },
        other => other,
    })?;
    if let (true, Some(t)) = (j.rows.is_empty(), &j.torn) {
        return Err(ReadError::Parse {
            path,
            line: t.line,
            message: "not a record of a grid point: a torn line and no record".to_string(),
        });
    }
    Ok(j)
}

/// Reads `dir/points.jsonl` as [`PointRow`]s ([`read_point_lines`]).
pub fn load_points(dir: &Path) -> Result<Vec<PointRow>, ReadError> {
    Ok(read_point_lines(dir)?
        .into_rows()
        .into_iter()
        .map(PointRow::from)
        .collect())
}

/// Reads `dir/points.jsonl` as a sweep's own [`PointRecord`]s, every field checked.
pub fn read_records(dir: &Path) -> Result<Jsonl<PointRecord>, ReadError> {
    let path = dir.join(POINTS_FILE);
    parse_jsonl(&path, &read_bytes(&path)?)
}
