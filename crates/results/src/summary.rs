//! The lines of `summary.csv`: one row per grid point, made from its line of `points.jsonl`
//! ([`SummarySource`], read tolerantly) and written as CSV ([`SummaryRow`]). Numbers keep the
//! form they have in the record (an integer stays an integer), so the summary of a merged
//! result is byte-identical to a single run's.

use serde::de::IgnoredAny;
use serde::Deserialize;
use serde_json::Number;

/// The record fields of a summary row, in column order, after the inputs.
pub const SUMMARY_FIELDS: &[&str] = &[
    "class",
    "first_contact_force_n",
    "max_contact_force_n",
    "peak_friction_power_w",
    "peak_heat_power_w",
    "whirl_frequency_hz",
    "contact_duty",
    "impacts",
    "end_time_s",
];

/// The bearing analysis's fields of a summary row, after [`SUMMARY_FIELDS`]: columns of a
/// sweep whose scene turns the analysis on, absent otherwise (so other summaries keep
/// their columns).
pub const BEARING_FIELDS: &[&str] = &[
    "peak_ball_load_n",
    "peak_contact_pressure_pa",
    "static_safety_factor",
    "damage_per_drop",
    "drops_to_failure",
];

/// What the summary needs of a drop record.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
pub struct SummaryRecord {
    /// Orbit class name.
    #[serde(default)]
    pub class: Option<String>,
    /// First contact force (N).
    #[serde(default)]
    pub first_contact_force_n: Option<Number>,
    /// Maximum contact force (N).
    #[serde(default)]
    pub max_contact_force_n: Option<Number>,
    /// Peak friction power (W).
    #[serde(default)]
    pub peak_friction_power_w: Option<Number>,
    /// Peak heat power (W).
    #[serde(default)]
    pub peak_heat_power_w: Option<Number>,
    /// Whirl frequency (Hz).
    #[serde(default)]
    pub whirl_frequency_hz: Option<Number>,
    /// Contact duty on the final window.
    #[serde(default)]
    pub contact_duty: Option<Number>,
    /// Impacts.
    #[serde(default)]
    pub impacts: Option<Number>,
    /// Simulated end time (s).
    #[serde(default)]
    pub end_time_s: Option<Number>,
    /// Peak load on one ball (N), with the bearing analysis.
    #[serde(default)]
    pub peak_ball_load_n: Option<Number>,
    /// Peak contact pressure (Pa), with the bearing analysis.
    #[serde(default)]
    pub peak_contact_pressure_pa: Option<Number>,
    /// Static safety factor against 4.2 GPa, with the bearing analysis.
    #[serde(default)]
    pub static_safety_factor: Option<Number>,
    /// Fatigue damage of the drop, with the bearing analysis.
    #[serde(default)]
    pub damage_per_drop: Option<Number>,
    /// Drops to fatigue failure (empty when the drop did no damage), with the bearing
    /// analysis.
    #[serde(default)]
    pub drops_to_failure: Option<Number>,
}

/// A point's error: an object with a `message`, or anything else (no message).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum SummaryError {
    /// `{"message": ...}` (other fields ignored).
    Object {
        /// The message, if text.
        #[serde(default)]
        message: Option<String>,
    },
    /// Text or any other value: no message.
    Other(IgnoredAny),
}

/// What the summary needs of a line of `points.jsonl`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
pub struct SummarySource {
    /// `ok` or `failed`.
    #[serde(default)]
    pub status: Option<String>,
    /// The drop record.
    #[serde(default)]
    pub record: Option<SummaryRecord>,
    /// The error of a failed point.
    #[serde(default)]
    pub error: Option<SummaryError>,
}

impl SummarySource {
    /// Reads a line; `None` for a line that is not a record (a missing or torn one).
    pub fn parse(line: &str) -> Option<Self> {
        serde_json::from_str(line).ok()
    }

    /// Whether the point ran ok.
    pub fn is_ok(&self) -> bool {
        self.status.as_deref() == Some("ok")
    }
}

/// One row of `summary.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryRow {
    /// Grid index.
    pub index: usize,
    /// The point's inputs in axis order.
    pub inputs: Vec<f64>,
    /// What its line of `points.jsonl` says; `None` when there is no such line.
    pub source: Option<SummarySource>,
    /// Whether the row has the [`BEARING_FIELDS`] columns.
    pub bearing: bool,
}

impl SummaryRow {
    /// The header: `index`, the axis names, [`SUMMARY_FIELDS`], the [`BEARING_FIELDS`] when
    /// `bearing`, `status`, `error`.
    pub fn header<'a>(axes: impl IntoIterator<Item = &'a str>, bearing: bool) -> String {
        let mut h = vec!["index".to_string()];
        h.extend(axes.into_iter().map(csv_field));
        h.extend(SUMMARY_FIELDS.iter().map(|s| s.to_string()));
        if bearing {
            h.extend(BEARING_FIELDS.iter().map(|s| s.to_string()));
        }
        h.extend(["status".to_string(), "error".to_string()]);
        h.join(",")
    }

    /// The row as a CSV line (without its newline): a missing value is an empty cell, a
    /// non-finite input too.
    pub fn to_csv_line(&self) -> String {
        let mut row = vec![self.index.to_string()];
        row.extend(
            self.inputs
                .iter()
                .map(|x| Number::from_f64(*x).map_or(String::new(), |n| csv_field(&n.to_string()))),
        );
        let rec = self.source.as_ref().and_then(|s| s.record.as_ref());
        let num = |n: Option<&Number>| n.map_or(String::new(), |n| csv_field(&n.to_string()));
        let text = |s: Option<&String>| s.map_or(String::new(), |s| csv_field(s));
        row.push(text(rec.and_then(|r| r.class.as_ref())));
        for n in [
            rec.and_then(|r| r.first_contact_force_n.as_ref()),
            rec.and_then(|r| r.max_contact_force_n.as_ref()),
            rec.and_then(|r| r.peak_friction_power_w.as_ref()),
            rec.and_then(|r| r.peak_heat_power_w.as_ref()),
            rec.and_then(|r| r.whirl_frequency_hz.as_ref()),
            rec.and_then(|r| r.contact_duty.as_ref()),
            rec.and_then(|r| r.impacts.as_ref()),
            rec.and_then(|r| r.end_time_s.as_ref()),
        ] {
            row.push(num(n));
        }
        if self.bearing {
            for n in [
                rec.and_then(|r| r.peak_ball_load_n.as_ref()),
                rec.and_then(|r| r.peak_contact_pressure_pa.as_ref()),
                rec.and_then(|r| r.static_safety_factor.as_ref()),
                rec.and_then(|r| r.damage_per_drop.as_ref()),
                rec.and_then(|r| r.drops_to_failure.as_ref()),
            ] {
                row.push(num(n));
            }
        }
        row.push(text(self.source.as_ref().and_then(|s| s.status.as_ref())));
        let message = match self.source.as_ref().and_then(|s| s.error.as_ref()) {
            Some(SummaryError::Object { message }) => message.as_ref(),
            _ => None,
        };
        row.push(text(message));
        row.join(",")
    }
}

/// A CSV cell: quoted when it holds a comma, a quote or a line break.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The failed points of a sweep's `points.jsonl` lines, in words: how many failed of how
/// many, by error kind (most first), and the first failed point's index, inputs and message:
/// `3 of 4 points failed (event_budget 2, step_budget 1); the first, index 0 (speed_rpm
/// 6000, mu 0.2): event budget of 20 mode switches exhausted at t = 0.0188 s`. `None` when
/// no line is a failed point. Lines that are not records are skipped. Streams: only a line
/// that may be a failed point's is parsed, so a long grid costs no memory.
pub fn failure_summary<S: AsRef<str>>(lines: impl IntoIterator<Item = S>) -> Option<String> {
    // What a failed point's line says of it (`PointRecord`'s fields, the inputs in the axes'
    // order).
    #[derive(Deserialize)]
    struct Failed {
        index: usize,
        inputs: crate::point::Inputs,
        status: crate::point::Status,
        error: Option<crate::point::PointError>,
    }
    let mut kinds: std::collections::BTreeMap<String, usize> = Default::default();
    let (mut total, mut failed) = (0usize, 0usize);
    let mut first: Option<String> = None;
    for line in lines {
        let line = line.as_ref();
        // Records are written compactly: a point's line holds `"status":` once.
        if !line.contains("\"status\":") {
            continue;
        }
        total += 1;
        if !line.contains("\"status\":\"failed\"") {
            continue;
        }
        let Ok(f) = serde_json::from_str::<Failed>(line) else {
            continue;
        };
        if f.status != crate::point::Status::Failed {
            continue;
        }
        failed += 1;
        let kind = f.error.as_ref().map_or("unknown", |e| e.kind.as_str());
        *kinds.entry(kind.to_string()).or_insert(0) += 1;
        if first.is_none() {
            let inputs = (f.inputs.0.iter())
                .map(|(k, x)| format!("{k} {}", whirlmap_core::scene::num(*x)))
                .collect::<Vec<_>>()
                .join(", ");
            let message = f.error.as_ref().map_or(kind, |e| e.message.as_str());
            first = Some(format!(
                "the first, index {} ({inputs}): {message}",
                f.index
            ));
        }
    }
    let first = first?;
    let mut by_kind: Vec<(String, usize)> = kinds.into_iter().collect();
    by_kind.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    let by_kind = by_kind
        .iter()
        .map(|(k, n)| format!("{k} {n}"))
        .collect::<Vec<_>>()
        .join(", ");
    Some(format!(
        "{failed} of {total} points failed ({by_kind}); {first}"
    ))
}

#[cfg(test)]
mod failure_tests {
    use super::failure_summary;

    #[test]
    fn failed_points_are_counted_by_kind_with_the_first_one_named() {
        let text = [
            r#"{"index":0,"inputs":{"speed_rpm":6000.0,"mu":0.2},"status":"failed","error":{"kind":"event_budget","message":"event budget of 20 mode switches exhausted"}}"#,
            r#"{"index":1,"inputs":{"speed_rpm":6000.0,"mu":0.4},"status":"ok","record":{}}"#,
            "torn line",
            r#"{"index":2,"inputs":{"speed_rpm":8000.0,"mu":0.2},"status":"failed","error":{"kind":"step_budget","message":"x"}}"#,
            r#"{"index":3,"inputs":{"speed_rpm":8000.0,"mu":0.4},"status":"failed","error":{"kind":"step_budget","message":"y"}}"#,
        ]
        .join("\n");
        assert_eq!(
            failure_summary(text.lines()).as_deref(),
            Some(
                "3 of 4 points failed (step_budget 2, event_budget 1); the first, index 0 \
                 (speed_rpm 6000, mu 0.2): event budget of 20 mode switches exhausted"
            )
        );
        assert_eq!(failure_summary([r#"{"index":0,"status":"ok"}"#]), None);
        assert_eq!(failure_summary([""]), None);
    }
}
