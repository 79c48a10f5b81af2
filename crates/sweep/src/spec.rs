//! Sweep specification: a JSON file naming a grid of drops over scene parameters.
//!
//! ```json
//! {"name": "paper", "scene": {"clearance_m": 1.5e-4}, "duration_s": 1.0,
//!  "axes": {"speed_rpm": {"from": 2000, "to": 10000, "steps": 5}, "mu": [0.1, 0.2, 0.3]},
//!  "critical": {"mu": [0.1, 0.3], "speed_rpm": {"from": 1000, "to": 20000}, "tol_rpm": 50},
//!  "charts": ["orbits", "critical", "max_force", "peak_power", "classes"]}
//! ```
//!
//! - `scene`: any subset of the scene's fields (as printed by `whirlmap scene`); the rest
//!   take the paper's defaults. Unknown keys are rejected.
//! - `axes`: axis name -> a list of values, or `{"from", "to", "steps"}` with `steps` points
//!   including both ends (`steps: 1` is just `from`). `mu` means `mu_dynamic`; any other name
//!   is a scene parameter set by [`crate::overrides::apply`] (dotted for nested fields, e.g.
//!   `solver.max_step_attempts`). Axes keep the order written in the file; the grid is
//!   row-major: the first axis varies slowest, the last fastest.
//! - `critical` (optional): the critical-speed search ([`CriticalSpec`]).
//! - `charts` (optional): chart names out of [`CHART_NAMES`].
//! - `fidelity` (optional): a preset, `draft`, `standard` or `reference`
//!   ([`whirlmap_core::Fidelity`]), applied to the base scene before the axes.
//!
//! Everything is checked by [`load`] before any drop runs; every error names the field and
//! the value. Parse errors carry the file path, line and column.

use crate::overrides::{self, OverrideError};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::fmt;
use std::path::{Path, PathBuf};
use thiserror::Error;
use whirlmap_core::scene::num;
use whirlmap_core::{Fidelity, InvalidParameter, Scene};

/// Chart names a spec may list.
pub const CHART_NAMES: &[&str] = &[
    "orbits",
    "critical",
    "max_force",
    "peak_power",
    "classes",
    "peak_temperature",
    "drops_to_failure",
    "contact_pressure",
];

/// The charts of [`CHART_NAMES`] that are maps over release speed and friction, every one
/// after the orbit panels and Fig. 4: a spec listing one needs a `speed_rpm` and a `mu` axis.
pub const MAP_CHARTS: &[&str] = CHART_NAMES.split_at(2).1;

/// Largest grid a spec may describe (points). The count is checked, with checked arithmetic,
/// before any axis is built; larger grids are refused (exit 2).
pub const MAX_POINTS: usize = 10_000_000;

/// Most friction coefficients a `critical` section may search (each is a search of up to
/// 10 000 scan drops).
pub const MAX_CRITICAL_MU: usize = 1000;

/// Why a sweep spec is unusable. Every variant names the field and the value.
#[derive(Debug, Error)]
pub enum SpecError {
    /// The file could not be read.
    #[error("cannot read sweep spec {path}: {source}")]
    Read {
        /// The spec file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Not valid JSON, an unknown key or a wrong type (serde's message has line and column).
    #[error("sweep spec {path}: {}", crate::overrides::with_suggestion(&source.to_string()))]
    Parse {
        /// The spec file.
        path: PathBuf,
        /// serde_json's error.
        source: serde_json::Error,
    },
    /// The spec has no axes.
    #[error("axes: at least one axis is required")]
    NoAxes,
    /// An axis given as an empty list.
    #[error("axes.{axis}: empty list of values")]
    EmptyAxis {
        /// Axis name.
        axis: String,
    },
    /// An axis range with `steps: 0`.
    #[error("axes.{axis}.steps = 0: need at least 1 point")]
    ZeroSteps {
        /// Axis name.
        axis: String,
    },
    /// A range with `from > to`.
    #[error("{field}: from = {} is greater than to = {}", num(*from), num(*to))]
    ReversedRange {
        /// The range's field (`axes.speed_rpm`, `critical.speed_rpm`).
        field: String,
        /// Lower end as given.
        from: f64,
        /// Upper end as given.
        to: f64,
    },
    /// A value listed twice in an axis or a list of friction coefficients (`0.0` and `-0.0`
    /// are the same value; a range whose ends are equal repeats its one value).
    #[error("{field}: the value {} occurs more than once: each grid value must be distinct (0 and -0 are the same value)", num(*value))]
    DuplicateValue {
        /// The field (`axes.mu`, `critical.mu`, `orbits.mu`, ...).
        field: String,
        /// The repeated value.
        value: f64,
    },
    /// The same scene parameter named by two axes.
    #[error("axes.{axis}: sets the same scene parameter as another axis")]
    DuplicateAxis {
        /// Axis name.
        axis: String,
    },
    /// An axis that is not a scene parameter, or a value of the wrong type for it.
    #[error("axes.{axis}: {source}")]
    Axis {
        /// Axis name.
        axis: String,
        /// The override error (names the key and lists the known ones).
        source: OverrideError,
    },
    /// A friction coefficient outside [0, 2].
    #[error("{field} = {}: friction coefficient must be in [0, 2]", num(*value))]
    MuOutOfRange {
        /// `axes.mu` or `critical.mu`.
        field: String,
        /// The value.
        value: f64,
    },
    /// `duration_s` not in (0, 3600].
    #[error("duration_s = {}: must be > 0 and at most 3600 s", num(*value))]
    Duration {
        /// The value.
        value: f64,
    },
    /// A chart name not in [`CHART_NAMES`].
    #[error("charts: unknown chart `{name}`; known: {known}")]
    UnknownChart {
        /// The name as given.
        name: String,
        /// The known names, comma-separated.
        known: String,
    },
    /// Any other field out of its allowed range.
    #[error("{field} = {value}: allowed {allowed}")]
    Invalid {
        /// The field (dotted path in the spec).
        field: String,
        /// The value as text.
        value: String,
        /// The allowed range in words.
        allowed: String,
    },
    /// An error of a nested section (a sweep's `probability`), named with the section in
    /// front of its field: `probability.duration_s = -1: ...`.
    #[error("{section}{}{source}", if matches!(**source, SpecError::InvalidScene { .. }) { ": " } else { "." })]
    InSection {
        /// The section's field.
        section: String,
        /// The error inside it.
        source: Box<SpecError>,
    },
    /// A grid point whose scene fails validation.
    #[error("grid point {index} ({inputs}): {source}")]
    InvalidScene {
        /// Grid index.
        index: usize,
        /// The point's axis values, `name=value, ...`.
        inputs: String,
        /// Which scene field, its value and its range.
        source: InvalidParameter,
    },
    /// The output folder cannot be created or written.
    #[error("output folder {path} is not writable: {source}")]
    Output {
        /// The folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// A closed interval (the critical-speed search range).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    /// Lower end.
    pub from: f64,
    /// Upper end (>= from).
    pub to: f64,
}

fn default_tol_rpm() -> f64 {
    crate::critical::DEFAULT_TOL_RPM
}

fn default_resolution_rpm() -> f64 {
    crate::critical::DEFAULT_RESOLUTION_RPM
}

/// The critical-speed search ([`crate::critical`]): for each `mu`, the onset of sustained
/// whirl and every whirl interval in `speed_rpm`, scanned on a lattice of `resolution_rpm`
/// and bisected to `tol_rpm`.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CriticalSpec {
    /// Friction coefficients: a list or `{"from", "to", "steps"}` (each in [0, 2], at least
    /// one, none twice).
    pub mu: AxisValues,
    /// Speed range searched (r/min): `from` in [0, 1e6), `to` in (`from`, 1e6].
    pub speed_rpm: RangeSpec,
    /// Lattice step of the scan (r/min), [1, 1e5]. Default 250.
    #[serde(default = "default_resolution_rpm")]
    pub resolution_rpm: f64,
    /// Bisection tolerance (r/min), [0.01, `resolution_rpm`]. Default 25.
    #[serde(default = "default_tol_rpm")]
    pub tol_rpm: f64,
    /// Re-check each onset bracket at the next tighter preset than the sweep's `fidelity`
    /// (which must be `draft` or `standard`), as `whirlmap critical --fidelity` does: the row
    /// records it as `recheck`, and an onset that does not hold there (a bracket the tighter
    /// preset does not confirm, and its onset not found again within `tol_rpm`) leaves it
    /// not converged ([`crate::recheck`]). Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub recheck: bool,
}

impl CriticalSpec {
    /// The friction coefficients, in order.
    pub fn mus(&self) -> Vec<f64> {
        self.mu.values()
    }

    /// The search settings for drops of `duration_s`.
    pub fn options(&self, duration_s: f64) -> crate::critical::CriticalOptions {
        crate::critical::CriticalOptions {
            from_rpm: self.speed_rpm.from,
            to_rpm: self.speed_rpm.to,
            resolution_rpm: self.resolution_rpm,
            tol_rpm: self.tol_rpm,
            duration_s,
        }
    }
}

/// The values of one axis: a list, or `steps` evenly spaced points from `from` to `to`.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisValues {
    /// Explicit values, in order.
    List(Vec<f64>),
    /// `steps` points including both ends.
    Range {
        /// First value.
        from: f64,
        /// Last value (>= from).
        to: f64,
        /// Number of points (>= 1; 1 means just `from`).
        steps: usize,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RangeSteps {
    from: f64,
    to: f64,
    steps: usize,
}

impl AxisValues {
    /// The number of values, without building them.
    pub fn count(&self) -> usize {
        match self {
            AxisValues::List(v) => v.len(),
            AxisValues::Range { steps, .. } => *steps,
        }
    }

    /// Value `i` (`i < count()`), without building the others.
    pub fn value(&self, i: usize) -> f64 {
        match self {
            AxisValues::List(v) => v[i],
            AxisValues::Range { from, to, steps } => {
                let n = *steps;
                if n == 1 {
                    *from
                } else if i + 1 == n {
                    *to
                } else {
                    // Rounded to 12 significant digits, so 0.05 + 2 * 0.05 is written 0.15,
                    // not 0.15000000000000002, in records, keys and CSV.
                    let v = from + (to - from) * (i as f64) / ((n - 1) as f64);
                    format!("{v:.11e}").parse().unwrap_or(v)
                }
            }
        }
    }

    /// The axis's values in order (not validated). Builds them all: check [`Self::count`]
    /// first for a spec from a file.
    pub fn values(&self) -> Vec<f64> {
        (0..self.count()).map(|i| self.value(i)).collect()
    }

    /// The first value that occurs twice (`0.0` and `-0.0` are the same value), if any.
    /// A range with `from < to` is increasing unless its spacing is below the 12 significant
    /// digits its values are rounded to; only then are its values built and compared.
    pub fn first_duplicate(&self) -> Option<f64> {
        match self {
            AxisValues::Range { from, to, steps } if *steps > 1 => {
                let spacing = (to - from) / ((*steps - 1) as f64);
                // Rounding to 12 significant digits moves a value by at most 5e-12 of its
                // magnitude, so a spacing above 2e-11 of the largest keeps them apart.
                if spacing > 2e-11 * from.abs().max(to.abs()) {
                    return None;
                }
                let mut prev = self.value(0);
                for i in 1..*steps {
                    let v = self.value(i);
                    if !(v > prev) {
                        return Some(v);
                    }
                    prev = v;
                }
                None
            }
            AxisValues::Range { .. } => None,
            AxisValues::List(v) => first_duplicate(v),
        }
    }
}

/// The first value of `values` that occurs twice (`0.0` and `-0.0` are the same value).
pub fn first_duplicate(values: &[f64]) -> Option<f64> {
    // + 0.0 turns -0.0 into 0.0, so the two sort together.
    let mut sorted: Vec<f64> = values.iter().map(|v| v + 0.0).collect();
    sorted.sort_by(f64::total_cmp);
    sorted.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

impl<'de> Deserialize<'de> for AxisValues {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        match Value::deserialize(d)? {
            v @ Value::Array(_) => serde_json::from_value::<Vec<f64>>(v)
                .map(AxisValues::List)
                .map_err(|e| de::Error::custom(format!("axis values: {e}"))),
            v @ Value::Object(_) => serde_json::from_value::<RangeSteps>(v)
                .map(|r| AxisValues::Range {
                    from: r.from,
                    to: r.to,
                    steps: r.steps,
                })
                .map_err(|e| de::Error::custom(format!("axis range: {e}"))),
            other => Err(de::Error::custom(format!(
                "axis values must be a list of numbers or {{\"from\", \"to\", \"steps\"}}, got {other}"
            ))),
        }
    }
}

impl Serialize for AxisValues {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            AxisValues::List(v) => v.serialize(s),
            AxisValues::Range { from, to, steps } => {
                let mut m = s.serialize_map(Some(3))?;
                m.serialize_entry("from", from)?;
                m.serialize_entry("to", to)?;
                m.serialize_entry("steps", steps)?;
                m.end()
            }
        }
    }
}

/// One axis: its name as written and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// `mu` or a scene parameter name.
    pub name: String,
    /// The values.
    pub values: AxisValues,
}

impl Axis {
    /// The scene key this axis sets (`mu` -> `mu_dynamic`).
    pub fn scene_key(&self) -> &str {
        if self.name == "mu" {
            "mu_dynamic"
        } else {
            &self.name
        }
    }
}

/// The axes in the order written in the file (a JSON object read entry by entry, so the
/// order does not depend on serde_json's map type). Serialises back as an object in order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Axes(pub Vec<Axis>);

impl<'de> Deserialize<'de> for Axes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Axes;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object of axis name -> values")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Axes, A::Error> {
                let mut axes: Vec<Axis> = Vec::new();
                while let Some(name) = map.next_key::<String>()? {
                    if axes.iter().any(|a| a.name == name) {
                        return Err(de::Error::custom(format!("duplicate axis `{name}`")));
                    }
                    let values = map.next_value::<AxisValues>()?;
                    axes.push(Axis { name, values });
                }
                Ok(Axes(axes))
            }
        }
        d.deserialize_map(V)
    }
}

impl Serialize for Axes {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for a in &self.0 {
            m.serialize_entry(&a.name, &a.values)?;
        }
        m.end()
    }
}

/// A parsed sweep spec.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Sweep name: the default output folder is `results/<name>`. Letters, digits, `_`,
    /// `-` and `.` only.
    pub name: String,
    /// The base scene: the paper's with the file's overrides.
    #[serde(default)]
    pub scene: Scene,
    /// Simulated time of every drop (s), (0, 3600].
    pub duration_s: f64,
    /// The grid axes, in file order.
    pub axes: Axes,
    /// The critical-speed search, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub critical: Option<CriticalSpec>,
    /// Charts to draw after the sweep.
    #[serde(default)]
    pub charts: Vec<String>,
    /// Orbits recorded for the Fig. 3 chart (`orbits` in `charts`); default: 8000 r/min and
    /// the values of the `mu` axis (at most eight).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbits: Option<OrbitsSpec>,
    /// Fidelity preset (`draft`, `standard`, `reference`) applied to the base scene before
    /// the axes (so an axis may still vary `solver.rtol`); absent: the scene's own settings,
    /// as every earlier sweep ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fidelity: Option<Fidelity>,
    /// A whirl-probability ensemble over uncontrolled release conditions on its own
    /// (usually coarser) grid, run into `probability/`; Fig. 4 draws its P(whirl) band.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability: Option<ProbabilitySpec>,
}

/// A sweep's probability ensemble ([`crate::ensemble`]): its grid and what each member draws.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbabilitySpec {
    /// The ensemble's grid (`speed_rpm` and `mu`, as sweep axes).
    pub axes: Axes,
    /// Simulated time of each member (s); default the sweep's `duration_s`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    /// Members per cell, seed, the drawn release conditions and the contour levels.
    pub ensemble: crate::ensemble::EnsembleParams,
}

impl SweepSpec {
    /// The probability section as an ensemble spec (its base scene and fidelity are the
    /// sweep's), named `<name>-probability`.
    pub fn probability_spec(&self) -> Option<crate::ensemble::EnsembleSpec> {
        let p = self.probability.as_ref()?;
        Some(crate::ensemble::EnsembleSpec {
            name: format!("{}-probability", self.name),
            scene: self.scene.clone(),
            duration_s: p.duration_s.unwrap_or(self.duration_s),
            axes: p.axes.clone(),
            ensemble: Some(p.ensemble.clone()),
            adaptive: None,
            fidelity: self.fidelity,
        })
    }

    /// The base scene with the fidelity preset, if any, applied: what every drop of the
    /// sweep, its critical search and its orbits start from.
    pub fn base_scene(&self) -> Scene {
        match self.fidelity {
            Some(f) => f.applied(&self.scene),
            None => self.scene.clone(),
        }
    }
}

/// The Fig. 3 panels: one drop per friction coefficient at one speed, orbit recorded.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitsSpec {
    /// Release speed of every panel (r/min).
    pub speed_rpm: f64,
    /// One panel per friction coefficient, each in [0, 2].
    pub mu: Vec<f64>,
}

/// One grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Row-major index in the grid (first axis slowest).
    pub index: usize,
    /// Axis name -> value, in the spec's axis order.
    pub inputs: Vec<(String, f64)>,
    /// The full scene of this point.
    pub scene: Scene,
}

impl Point {
    /// `name=value, ...` for messages.
    pub fn inputs_text(&self) -> String {
        inputs_text(&self.inputs)
    }
}

fn inputs_text(inputs: &[(String, f64)]) -> String {
    inputs
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A JSON value for an axis value: integral values become JSON integers so integer scene
/// fields (`solver.max_step_attempts`) accept them; float fields accept both.
fn axis_json(v: f64) -> Value {
    if v.fract() == 0.0 && v.abs() < 9.0e15 {
        Value::from(v as i64)
    } else {
        Value::from(v)
    }
}

fn check_mu(field: &str, v: f64) -> Result<(), SpecError> {
    if (0.0..=2.0).contains(&v) {
        Ok(())
    } else {
        Err(SpecError::MuOutOfRange {
            field: field.to_string(),
            value: v,
        })
    }
}

fn check_range(field: &str, from: f64, to: f64) -> Result<(), SpecError> {
    if from > to {
        Err(SpecError::ReversedRange {
            field: field.to_string(),
            from,
            to,
        })
    } else if !(to - from).is_finite() {
        // Each end finite, their span not (-1e308 to 1e308): its steps would be infinite.
        Err(SpecError::Invalid {
            field: field.to_string(),
            value: format!("from {} to {}", num(from), num(to)),
            allowed: "a span to - from below 1.8e308 (the largest finite number)".into(),
        })
    } else {
        Ok(())
    }
}

/// The scene values a spec's `fidelity` preset replaces: each key of [`Fidelity::KEYS`] that
/// the spec's `scene` sets to another value than the preset's, as `(scene.solver.rtol,
/// 1e-6)`, in the order of `KEYS`. Empty without a valid `fidelity` or when `spec` is not an
/// object. The preset is applied to the scene after the file's values, so these have no
/// effect; an axis, applied after the preset, still may vary them. Works on the spec's JSON
/// (a sweep's or an ensemble's), because a parsed scene cannot tell a value written in the
/// file from a default.
pub fn replaced_by_fidelity(spec: &Value) -> Vec<(String, String)> {
    let (Some(Value::String(name)), Some(scene)) = (spec.get("fidelity"), spec.get("scene")) else {
        return Vec::new();
    };
    let Ok(preset) = Fidelity::parse(name) else {
        return Vec::new();
    };
    // The preset's values, as the scene's JSON has them.
    let applied = serde_json::to_value(preset.applied(&Scene::paper())).unwrap_or_default();
    let at = |v: &Value, key: &str| key.split('.').try_fold(v, |v, part| v.get(part)).cloned();
    Fidelity::KEYS
        .iter()
        .filter_map(|key| {
            let given = at(scene, key)?;
            let set = at(&applied, key);
            // 1e-4 and 0.0001 are one number; `"rodas4"` one method.
            let same = match (given.as_f64(), set.as_ref().and_then(Value::as_f64)) {
                (Some(a), Some(b)) => a == b,
                _ => Some(&given) == set.as_ref(),
            };
            (!same).then(|| (format!("scene.{key}"), given.to_string()))
        })
        .collect()
}

/// Reads and parses a spec and checks everything but the grid points' scenes
/// ([`SweepSpec::validate`]: the grid's size first, before any axis is built). A sweep checks
/// the points' scenes itself before it runs ([`crate::sweep::run_sweep`]), one at a time.
pub fn read(path: impl AsRef<Path>) -> Result<SweepSpec, SpecError> {
    let spec = read_unchecked(path.as_ref())?;
    spec.validate()?;
    Ok(spec)
}

/// Reads and parses a spec file, checking nothing beyond its JSON shape.
fn read_unchecked(path: &Path) -> Result<SweepSpec, SpecError> {
    let text = std::fs::read_to_string(path).map_err(|source| SpecError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text).map_err(|source| SpecError::Parse {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads, parses and validates a spec (every grid point's scene included).
pub fn load(path: impl AsRef<Path>) -> Result<SweepSpec, SpecError> {
    let spec = read_unchecked(path.as_ref())?;
    spec.check_points()?;
    Ok(spec)
}

/// Parses spec text (no validation beyond types, unknown keys, and lists where an object
/// belongs: [`whirlmap_core::json::from_str`]).
pub fn parse(text: &str) -> Result<SweepSpec, serde_json::Error> {
    whirlmap_core::json::from_str(text)
}

impl SweepSpec {
    /// Checks everything but the grid points' scenes (see [`SweepSpec::points`]).
    pub fn validate(&self) -> Result<(), SpecError> {
        let name_ok = !self.name.is_empty()
            && self.name != "."
            && self.name != ".."
            && self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
        if !name_ok {
            return Err(SpecError::Invalid {
                field: "name".into(),
                value: format!("{:?}", self.name),
                allowed: "a non-empty folder name of letters, digits, '_', '-', '.'".into(),
            });
        }
        if !(self.duration_s > 0.0 && self.duration_s <= 3600.0) {
            return Err(SpecError::Duration {
                value: self.duration_s,
            });
        }
        if self.axes.0.is_empty() {
            return Err(SpecError::NoAxes);
        }
        // The grid's size first, with checked arithmetic, before any axis is built.
        let mut total: usize = 1;
        for axis in &self.axes.0 {
            let n = axis.values.count();
            if n == 0 {
                return Err(match axis.values {
                    AxisValues::List(_) => SpecError::EmptyAxis {
                        axis: axis.name.clone(),
                    },
                    AxisValues::Range { .. } => SpecError::ZeroSteps {
                        axis: axis.name.clone(),
                    },
                });
            }
            total = match total.checked_mul(n) {
                Some(t) if t <= MAX_POINTS => t,
                _ => {
                    return Err(SpecError::Invalid {
                        field: "axes".into(),
                        value: format!("{} grid points", grid_size_text(&self.axes)),
                        allowed: format!("at most {MAX_POINTS} points"),
                    })
                }
            };
        }
        let mut keys: Vec<&str> = Vec::new();
        for axis in &self.axes.0 {
            let field = format!("axes.{}", axis.name);
            if let AxisValues::Range { from, to, .. } = &axis.values {
                check_range(&field, *from, *to)?;
            }
            let key = axis.scene_key();
            if keys.contains(&key) {
                return Err(SpecError::DuplicateAxis {
                    axis: axis.name.clone(),
                });
            }
            keys.push(key);
            if let Some(value) = axis.values.first_duplicate() {
                return Err(SpecError::DuplicateValue { field, value });
            }
            if key == "mu_dynamic" {
                for i in 0..axis.values.count() {
                    check_mu(&field, axis.values.value(i))?;
                }
            }
            // An unknown name, checked on the base scene with the first value (the value
            // types are checked with every grid point, [`SweepSpec::check_points`]).
            let mut s = self.base_scene();
            overrides::apply(&mut s, key, axis_json(axis.values.value(0))).map_err(|source| {
                SpecError::Axis {
                    axis: axis.name.clone(),
                    source,
                }
            })?;
        }
        if let Some(c) = &self.critical {
            if let AxisValues::Range { steps: 0, .. } = c.mu {
                return Err(SpecError::ZeroSteps {
                    axis: "critical.mu".into(),
                });
            }
            if c.mu.count() > MAX_CRITICAL_MU {
                return Err(SpecError::Invalid {
                    field: "critical.mu".into(),
                    value: format!("{} values", c.mu.count()),
                    allowed: format!("at most {MAX_CRITICAL_MU} friction coefficients"),
                });
            }
            if let AxisValues::Range { from, to, .. } = c.mu {
                check_range("critical.mu", from, to)?;
            }
            if let Some(value) = c.mu.first_duplicate() {
                return Err(SpecError::DuplicateValue {
                    field: "critical.mu".into(),
                    value,
                });
            }
            let mus = c.mus();
            for v in &mus {
                check_mu("critical.mu", *v)?;
            }
            let invalid = |e: InvalidParameter, field: &str| SpecError::Invalid {
                field: format!("critical.{field}"),
                value: e.value,
                allowed: e.allowed,
            };
            crate::critical::check_mus(&mus).map_err(|e| invalid(e, "mu"))?;
            // Each coefficient's scene at the lowest speed searched (a stop speed must lie
            // below every release speed of the search).
            for &mu in &mus {
                let mut s = self.base_scene();
                s.mu_dynamic = mu;
                s.speed_rpm = c.speed_rpm.from;
                s.validate().map_err(|e| SpecError::Invalid {
                    field: format!(
                        "scene.{} (the critical search at mu {}, speed_rpm.from {} r/min)",
                        e.field,
                        num(mu),
                        num(c.speed_rpm.from)
                    ),
                    value: e.value,
                    allowed: e.allowed,
                })?;
            }
            if c.recheck && self.fidelity.and_then(Fidelity::tighter).is_none() {
                return Err(SpecError::Invalid {
                    field: "critical.recheck".into(),
                    value: match self.fidelity {
                        Some(f) => format!("true with fidelity {}", f.name()),
                        None => "true without a fidelity".into(),
                    },
                    allowed: "true only with `fidelity` draft or standard (the re-check runs at \
                              the next tighter preset), or false"
                        .into(),
                });
            }
            crate::critical::check_range(
                c.speed_rpm.from,
                c.speed_rpm.to,
                c.resolution_rpm,
                c.tol_rpm,
            )
            .map_err(|e| {
                let field = match e.field.as_str() {
                    "from_rpm" => "speed_rpm.from",
                    "to_rpm" => "speed_rpm.to",
                    other => other,
                }
                .to_string();
                invalid(e, &field)
            })?;
        }
        if let Some(o) = &self.orbits {
            if o.mu.is_empty() {
                return Err(SpecError::Invalid {
                    field: "orbits.mu".into(),
                    value: "[]".into(),
                    allowed: "at least one value".into(),
                });
            }
            for v in &o.mu {
                check_mu("orbits.mu", *v)?;
            }
            if let Some(value) = first_duplicate(&o.mu) {
                return Err(SpecError::DuplicateValue {
                    field: "orbits.mu".into(),
                    value,
                });
            }
            if !(o.speed_rpm.is_finite() && o.speed_rpm.abs() <= 1e6) {
                return Err(SpecError::Invalid {
                    field: "orbits.speed_rpm".into(),
                    value: num(o.speed_rpm),
                    allowed: "[-1e6, 1e6] r/min".into(),
                });
            }
        }
        // Each orbit panel's scene (the `orbits` section's, or the default panels the
        // `orbits` chart asks for), as the drop will run it.
        if let Some((speed, mus)) = crate::extras::orbit_panels(self) {
            for mu in mus {
                let mut s = self.base_scene();
                s.speed_rpm = speed;
                s.mu_dynamic = mu;
                s.validate().map_err(|e| SpecError::Invalid {
                    field: format!(
                        "scene.{} (the orbit panel at {} r/min, mu {})",
                        e.field,
                        num(speed),
                        num(mu)
                    ),
                    value: e.value,
                    allowed: e.allowed,
                })?;
            }
        }
        if let Some(e) = self.probability_spec() {
            // Grid, draws and every cell with the widest draws.
            e.cells().map_err(|err| SpecError::InSection {
                section: "probability".into(),
                source: Box::new(err),
            })?;
        }
        for (i, c) in self.charts.iter().enumerate() {
            if !CHART_NAMES.contains(&c.as_str()) {
                return Err(SpecError::UnknownChart {
                    name: c.clone(),
                    known: CHART_NAMES.join(", "),
                });
            }
            // As an axis's values: a name twice is a slip (the chart is drawn once).
            if self.charts[..i].contains(c) {
                return Err(SpecError::Invalid {
                    field: "charts".into(),
                    value: c.clone(),
                    allowed: "each chart named once".into(),
                });
            }
            // The grid charts are maps over release speed and friction: without both axes
            // a missing one would be drawn at 0 and any other axis as a slice of it.
            let grid_chart = MAP_CHARTS.contains(&c.as_str());
            let has_axis =
                |keys: &[&str]| self.axes.0.iter().any(|a| keys.contains(&a.name.as_str()));
            if grid_chart
                && !(has_axis(&whirlmap_results::point::SPEED_KEYS)
                    && has_axis(&whirlmap_results::point::MU_KEYS))
            {
                let names: Vec<&str> = self.axes.0.iter().map(|a| a.name.as_str()).collect();
                return Err(SpecError::Invalid {
                    field: "charts".into(),
                    value: c.clone(),
                    allowed: format!(
                        "a map over release speed and friction, which needs the axes \
                         `speed_rpm` and `mu` (a one-value axis, `\"mu\": [0.4]`, draws one \
                         row); the axes are {}",
                        names.join(", ")
                    ),
                });
            }
            // A chart of a model the scene does not run would be silently left out.
            let axis_sets = |section: &str| {
                self.axes
                    .0
                    .iter()
                    .any(|a| a.name == section || a.name.starts_with(&format!("{section}.")))
            };
            let needs = match c.as_str() {
                "peak_temperature" => Some(("thermal", self.base_scene().thermal.is_some())),
                "drops_to_failure" | "contact_pressure" => {
                    Some(("bearing", self.base_scene().bearing.is_some()))
                }
                _ => None,
            };
            if let Some((section, on)) = needs {
                if !on && !axis_sets(section) {
                    return Err(SpecError::Invalid {
                        field: "charts".into(),
                        value: c.clone(),
                        allowed: format!(
                            "a chart of the {section} model only with `scene.{section}` set \
                             (the records carry nothing to draw without it)"
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Number of grid points (saturating at `usize::MAX`; [`SweepSpec::validate`] refuses
    /// more than [`MAX_POINTS`]).
    pub fn len(&self) -> usize {
        self.axes
            .0
            .iter()
            .try_fold(1usize, |t, a| t.checked_mul(a.values.count()))
            .unwrap_or(usize::MAX)
    }

    /// Whether the grid is empty (only for an invalid spec).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The axis values of grid point `index` (row-major: the last axis varies fastest), in
    /// axis order, computed from the index alone.
    pub fn inputs_at(&self, index: usize) -> Vec<(String, f64)> {
        let mut rest = index;
        let mut inputs = vec![(String::new(), 0.0); self.axes.0.len()];
        for (k, axis) in self.axes.0.iter().enumerate().rev() {
            let n = axis.values.count().max(1);
            inputs[k] = (axis.name.clone(), axis.values.value(rest % n));
            rest /= n;
        }
        inputs
    }

    /// Grid point `index` with its scene, built and validated. `base` is
    /// `serde_json::to_value(self.base_scene())`, made once by the caller ([`Grid`]).
    fn point_from(&self, base: &Value, index: usize) -> Result<Point, SpecError> {
        let inputs = self.inputs_at(index);
        let mut root = base.clone();
        for (axis, (_, v)) in self.axes.0.iter().zip(&inputs) {
            overrides::set_value(&mut root, axis.scene_key(), axis_json(*v)).map_err(|source| {
                SpecError::Axis {
                    axis: axis.name.clone(),
                    source,
                }
            })?;
        }
        let scene: Scene = match serde_json::from_value(root) {
            Ok(s) => s,
            Err(_) => {
                // Find the axis whose value the scene does not take, for the message.
                let mut scene = self.base_scene();
                for (axis, (_, v)) in self.axes.0.iter().zip(&inputs) {
                    overrides::apply(&mut scene, axis.scene_key(), axis_json(*v)).map_err(
                        |source| SpecError::Axis {
                            axis: axis.name.clone(),
                            source,
                        },
                    )?;
                }
                scene
            }
        };
        scene.validate().map_err(|source| SpecError::InvalidScene {
            index,
            inputs: inputs_text(&inputs),
            source,
        })?;
        Ok(Point {
            index,
            inputs,
            scene,
        })
    }

    /// The grid, for building its points one at a time ([`Grid::point`]); validates the spec
    /// (not the points: [`SweepSpec::check_points`]).
    pub fn grid(&self) -> Result<Grid<'_>, SpecError> {
        self.validate()?;
        Ok(Grid {
            spec: self,
            base: serde_json::to_value(self.base_scene()).expect("a scene serialises"),
            len: self.len(),
        })
    }

    /// Validates the spec and every grid point's scene, one point at a time (nothing the
    /// size of the grid is kept).
    pub fn check_points(&self) -> Result<(), SpecError> {
        let grid = self.grid()?;
        for index in 0..grid.len() {
            grid.point(index)?;
        }
        Ok(())
    }

    /// Every grid point, row-major (first axis slowest), each scene validated. This holds
    /// the whole grid in memory: for small grids (an ensemble's cells, tests); a sweep
    /// builds each point from its index when it runs it, with [`SweepSpec::grid`].
    pub fn points(&self) -> Result<Vec<Point>, SpecError> {
        let grid = self.grid()?;
        (0..grid.len()).map(|i| grid.point(i)).collect()
    }
}

/// A validated spec's grid: builds any point from its index, so nothing the size of the grid
/// is held ([`SweepSpec::grid`]).
#[derive(Debug, Clone)]
pub struct Grid<'a> {
    spec: &'a SweepSpec,
    /// The base scene as JSON, cloned and edited per point.
    base: Value,
    len: usize,
}

impl Grid<'_> {
    /// The number of grid points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the grid has no points (never, for a validated spec).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Grid point `index` (< `len()`), its scene built and validated.
    pub fn point(&self, index: usize) -> Result<Point, SpecError> {
        self.spec.point_from(&self.base, index)
    }
}

/// `a x b x c` (the axes' counts) for a message about a grid's size, with the product when
/// it fits in 64 bits.
fn grid_size_text(axes: &Axes) -> String {
    let counts: Vec<String> = axes
        .0
        .iter()
        .map(|a| a.values.count().to_string())
        .collect();
    let product = axes
        .0
        .iter()
        .try_fold(1u128, |t, a| t.checked_mul(a.values.count() as u128));
    match product {
        Some(p) if axes.0.len() > 1 => format!("{} = {p}", counts.join(" x ")),
        Some(p) => p.to_string(),
        None => format!("{} (more than 2^128)", counts.join(" x ")),
    }
}

/// Creates `dir` (and parents) and writes and removes a probe file, so an unwritable output
/// folder is reported before any drop runs: a bad path (a file in the way, no permission) as
/// [`SpecError::Output`] (exit 2), a storage failure (a full disk) as
/// [`crate::sweep::SweepError::Io`] (exit 4). The probe is removed whatever happens.
pub fn check_output_dir(dir: &Path) -> Result<(), crate::sweep::SweepError> {
    let err = |source| crate::folder::output_error(dir, source);
    std::fs::create_dir_all(dir).map_err(err)?;
    let probe = dir.join(format!(".whirlmap-probe-{}", std::process::id()));
    let written = std::fs::write(&probe, b"probe");
    let removed = std::fs::remove_file(&probe);
    written.map_err(err)?;
    match removed {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(err(e)),
        _ => Ok(()),
    }
}

#[cfg(feature = "schema")]
impl schemars::JsonSchema for AxisValues {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "AxisValues".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "description": "The values of one axis: a list, in order, or `steps` evenly \
                            spaced points from `from` to `to` (both included).",
            "oneOf": [
                {"type": "array", "items": {"type": "number"}, "minItems": 1},
                {
                    "type": "object",
                    "properties": {
                        "from": {"type": "number"},
                        "to": {"type": "number"},
                        "steps": {"type": "integer", "minimum": 1}
                    },
                    "required": ["from", "to", "steps"],
                    "additionalProperties": false
                }
            ]
        })
    }
}

#[cfg(feature = "schema")]
impl schemars::JsonSchema for Axes {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Axes".into()
    }
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let values = generator.subschema_for::<AxisValues>();
        schemars::json_schema!({
            "description": "Axis name (`speed_rpm`, `mu`, or any numeric scene field by dotted \
                            key) -> its values; the grid is every combination, the first axis \
                            varying slowest.",
            "type": "object",
            "minProperties": 1,
            "additionalProperties": values
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{
        "name": "t",
        "scene": {"clearance_m": 2e-4, "solver": {"rtol": 1e-6}},
        "duration_s": 0.05,
        "axes": {"speed_rpm": {"from": 1000, "to": 3000, "steps": 3}, "mu": [0.1, 0.3]},
        "critical": {"mu": [0.1], "speed_rpm": {"from": 1000, "to": 9000}},
        "charts": ["orbits", "classes"]
    }"#;

    fn with(f: impl FnOnce(&mut Value)) -> Result<SweepSpec, String> {
        let mut v: Value = serde_json::from_str(GOOD).unwrap();
        f(&mut v);
        let spec = parse(&v.to_string()).map_err(|e| e.to_string())?;
        spec.validate().map_err(|e| e.to_string())?;
        spec.points().map_err(|e| e.to_string())?;
        Ok(spec)
    }

    fn err(f: impl FnOnce(&mut Value)) -> String {
        with(f).expect_err("should be rejected")
    }

    #[test]
    fn a_fidelity_preset_sets_the_base_scene_and_a_bad_one_is_named() {
        let spec = with(|v| v["fidelity"] = "draft".into()).unwrap();
        let p = &spec.points().unwrap()[0];
        assert_eq!(p.scene.solver, Fidelity::Draft.solver());
        assert_eq!(p.scene.solver.rtol, Fidelity::Draft.rtol());
        let plain = with(|_| {}).unwrap();
        assert_eq!(plain.points().unwrap()[0].scene.solver.rtol, 1e-6);
        let e = err(|v| v["fidelity"] = "fast".into());
        assert!(e.contains("fast") && e.contains("draft"), "{e}");
    }

    #[test]
    fn the_scene_values_a_fidelity_preset_replaces_are_listed() {
        let mut v: Value = serde_json::from_str(GOOD).unwrap();
        // No preset: the file's rtol is used, nothing is replaced.
        assert!(replaced_by_fidelity(&v).is_empty());
        // Nor with a name that is no preset (refused with the spec's own error).
        v["fidelity"] = "fast".into();
        assert!(replaced_by_fidelity(&v).is_empty());
        v["fidelity"] = "draft".into();
        // The preset's own values are not replaced: draft's race tolerance scale (its method,
        // RODAS4 then BDF, replaces the file's RODAS4).
        v["scene"]["solver"]["method"] = "rodas4".into();
        v["scene"]["solver"]["race_atol_scale"] = 1e3.into();
        v["scene"]["quasi_static_race"] = true.into();
        v["scene"]["solver"]["max_step_attempts"] = 40.into();
        let listed = replaced_by_fidelity(&v);
        let want = [
            ("scene.solver.rtol", "1e-6"),
            ("scene.solver.method", "\"rodas4\""),
            ("scene.quasi_static_race", "true"),
        ];
        let want: Vec<(String, String)> = want
            .iter()
            .map(|(k, x)| (k.to_string(), x.to_string()))
            .collect();
        assert_eq!(listed, want);
        // What is listed is what the preset does replace, and nothing else is touched.
        let spec = parse(&v.to_string()).unwrap();
        let base = spec.base_scene();
        assert_eq!(base.solver.rtol, Fidelity::Draft.rtol());
        assert!(!base.quasi_static_race);
        assert_eq!(base.solver.max_step_attempts, 40);
        // Not a spec object, or no scene: nothing.
        assert!(replaced_by_fidelity(&Value::from(3)).is_empty());
        v.as_object_mut().unwrap().remove("scene");
        assert!(replaced_by_fidelity(&v).is_empty());
    }

    #[test]
    fn parses_and_builds_a_row_major_grid_in_file_order() {
        let spec = parse(GOOD).unwrap();
        spec.validate().unwrap();
        assert_eq!(spec.scene.clearance_m, 2e-4);
        assert_eq!(spec.scene.solver.rtol, 1e-6);
        assert_eq!(spec.scene.mu_dynamic, 0.1, "unset fields keep the default");
        let c = spec.critical.as_ref().unwrap();
        assert_eq!(c.tol_rpm, 25.0, "the default");
        assert_eq!(c.resolution_rpm, 250.0, "the default");
        assert_eq!(
            c.speed_rpm,
            RangeSpec {
                from: 1000.0,
                to: 9000.0
            }
        );
        let names: Vec<_> = spec.axes.0.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["speed_rpm", "mu"], "file order, not sorted");
        let p = spec.points().unwrap();
        assert_eq!(p.len(), 6);
        assert_eq!(p[1].index, 1);
        assert_eq!(
            p[1].inputs,
            vec![("speed_rpm".to_string(), 1000.0), ("mu".to_string(), 0.3)]
        );
        assert_eq!(p[1].scene.mu_dynamic, 0.3);
        assert_eq!(p[5].scene.speed_rpm, 3000.0);
        assert_eq!(p[2].scene.speed_rpm, 2000.0);
        assert_eq!(p[2].scene.clearance_m, 2e-4);
        // Serialises back with the axes in file order.
        let text = serde_json::to_string(&spec).unwrap();
        assert!(text.find("speed_rpm\":{").unwrap() < text.find("\"mu\":[").unwrap());
        assert_eq!(parse(&text).unwrap(), spec);
    }

    #[test]
    fn axes_count_before_building_and_find_duplicates() {
        let huge = AxisValues::Range {
            from: 0.0,
            to: 1.0,
            steps: usize::MAX,
        };
        assert_eq!(huge.count(), usize::MAX);
        assert_eq!(
            huge.value(usize::MAX - 1),
            1.0,
            "one value, without the others"
        );
        let e =
            err(|v| v["axes"]["mu"] = serde_json::json!({"from": 0, "to": 1, "steps": u64::MAX}));
        assert!(e.contains("at most 10000000 points"), "{e}");
        assert_eq!(first_duplicate(&[0.0, -0.0]), Some(0.0));
        assert_eq!(first_duplicate(&[0.3, 0.1, 0.2]), None);
        let flat = AxisValues::Range {
            from: 0.2,
            to: 0.2,
            steps: 3,
        };
        assert_eq!(flat.first_duplicate(), Some(0.2));
        let fine = AxisValues::Range {
            from: 0.0,
            to: 1.0,
            steps: 1_000_001,
        };
        assert_eq!(fine.first_duplicate(), None);
        // Spacing below the 12 digits the values are rounded to.
        let tight = AxisValues::Range {
            from: 1000.0,
            to: 1000.0000000001,
            steps: 3,
        };
        assert_eq!(tight.first_duplicate(), Some(1000.0));
    }

    #[test]
    fn ranges_include_both_ends_and_one_step_is_from() {
        let r = AxisValues::Range {
            from: 0.0,
            to: 1.0,
            steps: 5,
        };
        assert_eq!(r.values(), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        let r = AxisValues::Range {
            from: 2.0,
            to: 7.0,
            steps: 1,
        };
        assert_eq!(r.values(), vec![2.0]);
    }

    #[test]
    fn any_scene_parameter_can_be_an_axis_including_integers() {
        let spec = with(|v| {
            v["axes"] = serde_json::json!({"solver.max_step_attempts": [10, 1000], "unbalance_m": [0, 1e-5]});
            // Orbit panels only: the maps need speed and friction axes.
            v["charts"] = serde_json::json!(["orbits"]);
        })
        .unwrap();
        let p = spec.points().unwrap();
        assert_eq!(p[0].scene.solver.max_step_attempts, 10);
        assert_eq!(p[3].scene.unbalance_m, 1e-5);
    }

    #[test]
    fn unknown_keys_and_type_errors_carry_line_and_column() {
        let e = err(|v| v["colour"] = Value::from(1));
        assert!(e.contains("colour") && e.contains("line"), "{e}");
        let e = err(|v| v["scene"]["clearence_m"] = Value::from(1e-4));
        assert!(e.contains("clearence_m") && e.contains("column"), "{e}");
        let e = err(|v| v["duration_s"] = Value::from("long"));
        assert!(e.contains("line"), "{e}");
        let e = err(|v| v["axes"]["mu"] = serde_json::json!({"from": 0, "to": 1, "step": 2}));
        assert!(e.contains("step") && e.contains("line"), "{e}");
        let e = err(|v| v["critical"]["tolerance"] = Value::from(1));
        assert!(e.contains("tolerance"), "{e}");
    }

    #[test]
    fn the_maps_are_the_charts_after_the_orbit_panels_and_fig_4() {
        assert_eq!(&CHART_NAMES[..2], &["orbits", "critical"]);
        assert!(MAP_CHARTS.contains(&"max_force") && MAP_CHARTS.contains(&"contact_pressure"));
        assert_eq!(MAP_CHARTS.len() + 2, CHART_NAMES.len());
    }

    #[test]
    fn each_validation_error_names_the_field_and_value() {
        let e = err(|v| v["axes"]["mu"] = serde_json::json!([]));
        assert!(e.contains("axes.mu") && e.contains("empty"), "{e}");
        let e = err(|v| v["axes"]["mu"] = serde_json::json!({"from": 0, "to": 1, "steps": 0}));
        assert!(e.contains("axes.mu.steps = 0"), "{e}");
        let e = err(|v| {
            v["axes"]["speed_rpm"] = serde_json::json!({"from": 5000, "to": 1000, "steps": 3})
        });
        assert!(e.contains("axes.speed_rpm") && e.contains("5000"), "{e}");
        let e = err(|v| v["charts"] = serde_json::json!(["orbits", "pie"]));
        assert!(e.contains("charts") && e.contains("pie"), "{e}");
        // A map over speed and friction without a speed axis (it was drawn at speed 0).
        let e = err(|v| {
            v["axes"] = serde_json::json!({"clearance_m": [1e-4, 2e-4], "mu": [0.1, 0.3]});
            v["charts"] = serde_json::json!(["critical", "classes"]);
        });
        assert!(
            e.contains("charts = classes")
                && e.contains("`speed_rpm` and `mu`")
                && e.contains("the axes are clearance_m, mu"),
            "{e}"
        );
        // The same with a one-value speed axis: one column, accepted.
        with(|v| {
            v["axes"] = serde_json::json!({"speed_rpm": [8000], "clearance_m": [1e-4, 2e-4],
                                           "mu": [0.1, 0.3]});
            v["charts"] = serde_json::json!(["classes"]);
        })
        .unwrap();
        let e = err(|v| v["axes"]["clearence_m"] = serde_json::json!([1e-4]));
        assert!(
            e.contains("axes.clearence_m") && e.contains("clearance_m"),
            "{e}"
        );
        let e = err(|v| v["axes"]["mu"] = serde_json::json!([0.1, 2.5]));
        assert!(e.contains("axes.mu = 2.5"), "{e}");
        let e = err(|v| v["duration_s"] = Value::from(0.0));
        assert!(e.contains("duration_s = 0"), "{e}");
        let e = err(|v| v["duration_s"] = Value::from(-1.0));
        assert!(e.contains("duration_s = -1"), "{e}");
        let e = err(|v| v["axes"]["clearance_m"] = serde_json::json!([1e-4, -1e-3]));
        assert!(
            e.contains("grid point ") && e.contains("clearance_m = -0.001"),
            "{e}"
        );
        let e = err(|v| v["axes"] = serde_json::json!({}));
        assert!(e.contains("axes"), "{e}");
        let e = err(|v| v["critical"]["mu"] = serde_json::json!([3.0]));
        assert!(e.contains("critical.mu = 3"), "{e}");
        let e = err(|v| v["critical"]["speed_rpm"] = serde_json::json!({"from": 9, "to": 1}));
        assert!(e.contains("critical.speed_rpm"), "{e}");
        let e = err(|v| v["critical"]["tol_rpm"] = Value::from(0));
        assert!(e.contains("critical.tol_rpm = 0"), "{e}");
        // Ranges that would run forever or nothing at all are refused before any drop.
        let e = err(|v| v["critical"]["tol_rpm"] = Value::from(1e-300));
        assert!(e.contains("critical.tol_rpm = 1e-300"), "{e}");
        let e = err(|v| v["critical"]["speed_rpm"] = serde_json::json!({"from": 0, "to": 1e308}));
        assert!(e.contains("critical.speed_rpm.to"), "{e}");
        let e = err(|v| v["critical"]["speed_rpm"] = serde_json::json!({"from": -5, "to": 100}));
        assert!(e.contains("critical.speed_rpm.from = -5"), "{e}");
        let e = err(|v| v["critical"]["resolution_rpm"] = Value::from(0.5));
        assert!(e.contains("critical.resolution_rpm = 0.5"), "{e}");
        let e = err(|v| v["critical"]["mu"] = serde_json::json!([0.3, 0.3]));
        assert!(
            e.contains("critical.mu: the value 0.3 occurs more than once"),
            "{e}"
        );
        // A probability section is checked with the sweep (its draws against every cell).
        let e = err(|v| {
            v["probability"] = serde_json::json!({"axes": {"speed_rpm": [4000], "mu": [0.3]},
                "ensemble": {"members": 0, "seed": 1}})
        });
        assert!(e.contains("probability.ensemble.members = 0"), "{e}");
        let e = err(|v| {
            v["probability"] = serde_json::json!({"axes": {"mu": [0.3]},
                "ensemble": {"members": 2, "seed": 1}})
        });
        assert!(
            e.contains("probability.axes = mu: allowed a speed_rpm axis"),
            "{e}"
        );
        let e = err(|v| v["name"] = Value::from("../x"));
        assert!(e.contains("name"), "{e}");
        let e = err(|v| v["axes"]["mu_dynamic"] = serde_json::json!([0.2]));
        assert!(e.contains("axes.mu_dynamic"), "{e}");
    }

    #[test]
    fn load_names_the_file_and_an_unwritable_folder_is_reported() {
        let dir = std::env::temp_dir().join(format!("whirlmap-spec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.json");
        std::fs::write(&path, "{\"name\": \"x\",\n \"bogus\": 1}").unwrap();
        let e = load(&path).unwrap_err().to_string();
        assert!(e.contains("bad.json") && e.contains("line 2"), "{e}");
        assert!(matches!(
            load(dir.join("missing.json")),
            Err(SpecError::Read { .. })
        ));
        let file = dir.join("a-file");
        std::fs::write(&file, "x").unwrap();
        let e = check_output_dir(&file.join("sub").join("deeper")).unwrap_err();
        assert!(
            matches!(e, crate::sweep::SweepError::Spec(SpecError::Output { .. })),
            "{e}"
        );
        assert_eq!(e.exit_code(), 2);
        // The file above the folder is named, not "Not a directory (os error 20)".
        let named = format!("{} is a file, not a folder", file.display());
        assert!(e.to_string().ends_with(&named), "{e}");
        // The file itself as the folder: said in words, exit 2.
        let e = check_output_dir(&file).unwrap_err();
        assert!(e.to_string().contains("is a file, not a folder"), "{e}");
        assert_eq!(e.exit_code(), 2);
        check_output_dir(&dir.join("out")).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
