//! Whirl probability: for each grid cell (speed, mu, ...), an ensemble of drops over what a
//! real drop does not control, and per cell the probability of whirl with a Wilson interval
//! and percentiles of maximum force and peak heat power; then, per friction coefficient, the
//! speeds where the probability crosses given levels (10, 50, 90 %) with intervals.
//!
//! ## File
//! An ensemble file is a sweep file (name, scene, duration_s, axes; see [`crate::spec`]) with
//! an `ensemble` section and, for `whirlmap adaptive`, an optional `adaptive` section
//! ([`crate::adaptive::AdaptiveParams`]):
//!
//! ```json
//! {"name": "ens", "duration_s": 0.3,
//!  "axes": {"speed_rpm": {"from": 2000, "to": 16000, "steps": 8}, "mu": [0.25, 0.3]},
//!  "ensemble": {"members": 32, "seed": 1,
//!    "unbalance_m": {"uniform": {"from": 0, "to": 5e-6}},
//!    "unbalance_phase_rad": {"uniform": {"from": 0, "to": 6.283185307179586}},
//!    "orbit_radius_m": {"normal": {"mean": 5e-6, "sd": 3e-6, "min": 0, "max": 2e-5}},
//!    "race_speed_rad_s": {"fixed": 0}}}
//! ```
//!
//! Each quantity is optional; an absent one keeps the cell scene's value. The release is a
//! random point of the rotor's orbit in the AMB before the failure: a circular synchronous
//! (forward, at the spin speed) orbit of radius `orbit_radius_m` about the housing centre,
//! at the angle `orbit_phase_rad` (uniform over a turn unless given), so the geometric centre
//! starts at `r (cos phi, sin phi)` with velocity `Omega r (-sin phi, cos phi)`
//! ([`Scene::release_offset_m`], [`Scene::release_velocity_m_s`]). The unbalance phase and
//! the orbit phase are drawn independently (a limitation: in a real AMB they are tied by the
//! unbalance response).
//!
//! ## Random numbers
//! Each member's numbers come from its own generator, seeded by hashing (spec seed, the
//! cell's inputs by axis name, member index, quantity name): results do not depend on thread
//! count, on the order cells run in, on the order the spec lists its axes in, on the grid
//! around the cell (a cell at the same inputs gets the
//! same members in another grid, which the adaptive search relies on), or on which other
//! quantities are drawn. The generator is SplitMix64 ([`SplitMix64`]), hand-written so the
//! numbers are fixed by this file, not by a crate's version (rand's samplers changed their
//! streams between releases); it is a few lines, passes BigCrush, and a member draws at most
//! a few numbers per quantity. Normal draws are Box-Muller, truncated by rejection.
//!
//! ## Statistics
//! Failed drops are counted and left out. P(whirl) = whirl members / ok members, with the
//! Wilson score interval at `confidence` ([`wilson`]). Percentiles (p10, p50, p90) of
//! `max_contact_force_n` and `peak_heat_power_w` over the ok members, whirl members included
//! (their values are up to the whirl stopping rule), by linear interpolation between order
//! statistics ([`percentile`]).
//!
//! ## Contours
//! Cells are grouped by every input but `speed_rpm` (for a speed x mu grid: one group per
//! mu) and sorted by speed. For each level L, the crossing speed is the first upward crossing
//! of L by P(whirl), linear between adjacent cells ([`first_crossing`]). Its interval comes
//! from the same construction on the Wilson bounds: the upper bound crosses L first (the
//! lower end of the interval), the lower bound last (the upper end). A missing end means the
//! crossing lies below the lowest (or above the highest) speed of the grid. This band is an
//! approximate, pointwise construction, not a simultaneous confidence interval on the
//! crossing speed. `non_monotone` flags a group whose P falls by more than both intervals
//! allow (the upper bound at a higher speed below the lower bound at a lower speed).

use crate::classify::OrbitClass;
use crate::spec::{check_output_dir, Axes, SpecError, SweepSpec};
use crate::sweep::{run_case, Inputs, SweepError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use whirlmap_core::scene::fnv1a64;
use whirlmap_core::Scene;
pub use whirlmap_results::ensemble::{percentile, CellStats, Drawn, MemberRecord, Percentiles};
use whirlmap_results::manifest::{EnsembleManifest, SortedKeys};

/// Per-cell statistics as CSV.
pub const CELLS_CSV: &str = whirlmap_results::files::CELLS_CSV_FILE;

/// The most cells an ensemble (or an adaptive map's fine grid) may have: every cell is held
/// in memory with its scene while it runs (1e6 cells took 1.7 GB; this bound, some 350 MB).
pub const MAX_CELLS: usize = 200_000;
pub use whirlmap_results::contours::{ContourGroup, ContoursFile, LevelCrossing};
pub use whirlmap_results::files::{CELLS_FILE, CONTOURS_FILE, MANIFEST_FILE, MEMBERS_FILE};

/// SplitMix64 (Steele, Lea, Flood 2014): a 64-bit state advanced by a Weyl sequence and
/// mixed by a fixed finaliser. Hand-written for stable streams (see the module doc).
#[derive(Debug, Clone)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started at `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Standard normal (Box-Muller; one of the pair is used).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]: ln is finite
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Most rejection draws of one truncated normal value (see [`Dist::validate`], which keeps
/// the acceptance probability above about 0.4 %, so this is never reached in practice).
const MAX_REJECTIONS: usize = 100_000;

/// A distribution declared in the file.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Dist {
    /// Always this value: `{"fixed": 0}`.
    Fixed(f64),
    /// Uniform on [from, to): `{"uniform": {"from": 0, "to": 1e-5}}`.
    Uniform {
        /// Lower end.
        from: f64,
        /// Upper end (>= from).
        to: f64,
    },
    /// Normal with mean and standard deviation, truncated to [min, max] (by rejection):
    /// `{"normal": {"mean": 5e-6, "sd": 2e-6, "min": 0, "max": 2e-5}}`.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (>= 0).
        sd: f64,
        /// Lower bound (<= mean).
        min: f64,
        /// Upper bound (>= mean).
        max: f64,
    },
}

impl Dist {
    /// Checks the parameters; the error names `field`.
    pub fn validate(&self, field: &str) -> Result<(), SpecError> {
        let bad = |value: String, allowed: &str| {
            Err(SpecError::Invalid {
                field: field.to_string(),
                value,
                allowed: allowed.to_string(),
            })
        };
        match *self {
            Dist::Fixed(v) if !v.is_finite() => bad(v.to_string(), "a finite number"),
            Dist::Uniform { from, to } if !(from.is_finite() && to.is_finite() && from <= to) => {
                bad(format!("[{from}, {to}]"), "finite from <= to")
            }
            Dist::Normal { mean, sd, min, max }
                if !([mean, sd, min, max].iter().all(|v| v.is_finite())
                    && sd >= 0.0
                    && min <= mean
                    && mean <= max
                    && (sd == 0.0 || max - min >= 0.01 * sd)) =>
            {
                bad(
                    format!("mean {mean}, sd {sd}, min {min}, max {max}"),
                    "finite, sd >= 0, min <= mean <= max, max - min >= 0.01 sd",
                )
            }
            _ => Ok(()),
        }
    }

    /// The smallest and largest value a draw can take.
    pub fn support(&self) -> (f64, f64) {
        match *self {
            Dist::Fixed(v) => (v, v),
            Dist::Uniform { from, to } => (from, to),
            Dist::Normal { mean, sd: 0.0, .. } => (mean, mean),
            Dist::Normal { min, max, .. } => (min, max),
        }
    }

    /// One draw.
    pub fn sample(&self, rng: &mut SplitMix64) -> f64 {
        match *self {
            Dist::Fixed(v) => v,
            Dist::Uniform { from, to } => from + (to - from) * rng.uniform(),
            Dist::Normal { mean, sd: 0.0, .. } => mean,
            Dist::Normal { mean, sd, min, max } => {
                for _ in 0..MAX_REJECTIONS {
                    let v = mean + sd * rng.normal();
                    if (min..=max).contains(&v) {
                        return v;
                    }
                }
                mean // unreachable for validated parameters (acceptance >= ~0.4 %)
            }
        }
    }
}

fn default_confidence() -> f64 {
    0.95
}

fn default_levels() -> Vec<f64> {
    vec![0.1, 0.5, 0.9]
}

/// The `ensemble` section: members per cell, the seed and what is drawn.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnsembleParams {
    /// Drops per cell, [1, 100000].
    pub members: usize,
    /// Seed of the whole ensemble (any unsigned 64-bit integer).
    pub seed: u64,
    /// Unbalance eccentricity (m); absent: the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unbalance_m: Option<Dist>,
    /// Unbalance angle at release (rad); absent: the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unbalance_phase_rad: Option<Dist>,
    /// Radius of the AMB orbit the rotor is released from (m), >= 0; absent: the scene's
    /// release offset and velocity are kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit_radius_m: Option<Dist>,
    /// Angle of the release point on that orbit (rad); absent: uniform over a turn.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit_phase_rad: Option<Dist>,
    /// Race spin at release (rad/s); absent: the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub race_speed_rad_s: Option<Dist>,
    /// Confidence of the Wilson intervals, (0, 1). Default 0.95.
    #[serde(default = "default_confidence")]
    pub confidence: f64,
    /// Probability levels of the contours, each in (0, 1). Default [0.1, 0.5, 0.9].
    #[serde(default = "default_levels")]
    pub levels: Vec<f64>,
}

/// An ensemble (and adaptive) file: a sweep grid plus the `ensemble` and `adaptive` sections.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnsembleSpec {
    /// Name: the default output folder is `results/<name>`.
    pub name: String,
    /// The base scene (the paper's with the file's overrides).
    #[serde(default)]
    pub scene: Scene,
    /// Simulated time of every drop (s).
    pub duration_s: f64,
    /// The grid axes, as in a sweep file.
    pub axes: Axes,
    /// The ensemble; required by `whirlmap ensemble`, optional for `whirlmap adaptive`
    /// (without it every corner is one drop).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<EnsembleParams>,
    /// The adaptive search (`whirlmap adaptive`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<crate::adaptive::AdaptiveParams>,
    /// Fidelity preset applied to the base scene, as in a sweep file; absent: the scene's own
    /// settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fidelity: Option<whirlmap_core::Fidelity>,
}

fn invalid(field: &str, value: impl ToString, allowed: &str) -> SpecError {
    SpecError::Invalid {
        field: field.to_string(),
        value: value.to_string(),
        allowed: allowed.to_string(),
    }
}

impl EnsembleParams {
    /// Checks members, confidence, levels and every distribution (with the orbit radius
    /// and unbalance supports checked against each cell scene by [`EnsembleSpec::cells`]).
    pub fn validate(&self) -> Result<(), SpecError> {
        if !(1..=100_000).contains(&self.members) {
            return Err(invalid("ensemble.members", self.members, "[1, 100000]"));
        }
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return Err(invalid("ensemble.confidence", self.confidence, "(0, 1)"));
        }
        if self.levels.is_empty() {
            return Err(invalid("ensemble.levels", "[]", "at least one level"));
        }
        for (i, l) in self.levels.iter().enumerate() {
            if !(*l > 0.0 && *l < 1.0) {
                return Err(invalid("ensemble.levels", l, "each in (0, 1)"));
            }
            if self.levels[..i].contains(l) {
                return Err(invalid("ensemble.levels", l, "each level once"));
            }
        }
        for (name, d) in self.dists() {
            if let Some(d) = d {
                d.validate(&format!("ensemble.{name}"))?;
            }
        }
        if let Some(d) = &self.orbit_radius_m {
            if d.support().0 < 0.0 {
                return Err(invalid(
                    "ensemble.orbit_radius_m",
                    d.support().0,
                    "a support >= 0 m",
                ));
            }
        }
        Ok(())
    }

    fn dists(&self) -> [(&'static str, Option<Dist>); 5] {
        [
            ("unbalance_m", self.unbalance_m),
            ("unbalance_phase_rad", self.unbalance_phase_rad),
            ("orbit_radius_m", self.orbit_radius_m),
            ("orbit_phase_rad", self.orbit_phase_rad),
            ("race_speed_rad_s", self.race_speed_rad_s),
        ]
    }

    /// The member's scene: `cell` with its draws applied, and what was drawn. The numbers
    /// depend only on (seed, `inputs`, `member`, quantity), the inputs by axis name: not on
    /// the order the spec lists its axes in.
    pub fn member_scene(&self, cell: &Scene, inputs: &Inputs, member: usize) -> (Scene, Drawn) {
        let mut by_name = inputs.0.clone();
        by_name.sort_by(|a, b| a.0.cmp(&b.0));
        let base = format!(
            "whirlmap-ensemble|{}|{}|{member}",
            self.seed,
            serde_json::to_string(&Inputs(by_name)).expect("inputs serialise")
        );
        let draw = |name: &str, d: &Dist| {
            let mut rng = SplitMix64::new(fnv1a64(format!("{base}|{name}").as_bytes()));
            d.sample(&mut rng)
        };
        let mut s = cell.clone();
        if let Some(d) = &self.unbalance_m {
            s.unbalance_m = draw("unbalance_m", d);
        }
        if let Some(d) = &self.unbalance_phase_rad {
            s.unbalance_phase_rad = draw("unbalance_phase_rad", d);
        }
        if let Some(d) = &self.orbit_radius_m {
            let r = draw("orbit_radius_m", d);
            let phi = match &self.orbit_phase_rad {
                Some(p) => draw("orbit_phase_rad", p),
                None => draw(
                    "orbit_phase_rad",
                    &Dist::Uniform {
                        from: 0.0,
                        to: std::f64::consts::TAU,
                    },
                ),
            };
            let (sin, cos) = phi.sin_cos();
            let w = s.spin_rad_s();
            s.release_offset_m = [r * cos, r * sin];
            s.release_velocity_m_s = [-w * r * sin, w * r * cos];
        }
        if let Some(d) = &self.race_speed_rad_s {
            s.race_speed_rad_s = draw("race_speed_rad_s", d);
        }
        let drawn = Drawn {
            unbalance_m: s.unbalance_m,
            unbalance_phase_rad: s.unbalance_phase_rad,
            release_offset_m: s.release_offset_m,
            release_velocity_m_s: s.release_velocity_m_s,
            race_speed_rad_s: s.race_speed_rad_s,
        };
        (s, drawn)
    }

    /// Checks that the widest draws still give a valid scene for `cell` (unbalance and
    /// orbit radius at their largest, race speed at its largest magnitude).
    pub fn check_cell(&self, cell: &Scene) -> Result<(), whirlmap_core::InvalidParameter> {
        let mut s = cell.clone();
        let far = |d: &Dist| {
            let (lo, hi) = d.support();
            if lo.abs() > hi.abs() {
                lo
            } else {
                hi
            }
        };
        if let Some(d) = &self.unbalance_m {
            s.unbalance_m = far(d);
        }
        if let Some(d) = &self.orbit_radius_m {
            let r = d.support().1;
            s.release_offset_m = [r, 0.0];
            s.release_velocity_m_s = [0.0, s.spin_rad_s() * r];
        }
        if let Some(d) = &self.race_speed_rad_s {
            s.race_speed_rad_s = far(d);
        }
        s.validate()
    }
}

/// One cell of the grid: its index, inputs and scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Row-major index in the grid.
    pub index: usize,
    /// Axis values.
    pub inputs: Inputs,
    /// The cell's scene (before the draws).
    pub scene: Scene,
}

impl EnsembleSpec {
    /// The sweep part of the file (for its grid and validation).
    pub fn sweep_spec(&self) -> SweepSpec {
        SweepSpec {
            name: self.name.clone(),
            scene: self.scene.clone(),
            duration_s: self.duration_s,
            axes: self.axes.clone(),
            critical: None,
            charts: Vec::new(),
            orbits: None,
            fidelity: self.fidelity,
            probability: None,
        }
    }

    /// Checks the grid, the ensemble section (if any) against every cell, and the adaptive
    /// section (if any); returns the cells.
    pub fn cells(&self) -> Result<Vec<Cell>, SpecError> {
        // The contours are speeds at which P(whirl) crosses each level: along a speed axis.
        if !self.axes.0.iter().any(|a| a.name == "speed_rpm") {
            let names: Vec<&str> = self.axes.0.iter().map(|a| a.name.as_str()).collect();
            return Err(SpecError::Invalid {
                field: "axes".into(),
                value: if names.is_empty() {
                    "(none)".into()
                } else {
                    names.join(", ")
                },
                allowed: "a speed_rpm axis among them: the probability contours are release \
                          speeds"
                    .into(),
            });
        }
        // The cells are held in memory (about 2 kB each): counted before they are built.
        let n = self.sweep_spec().grid()?.len();
        if n > MAX_CELLS {
            return Err(SpecError::Invalid {
                field: "axes".into(),
                value: format!("{n} cells"),
                allowed: format!("at most {MAX_CELLS} cells (an ensemble holds every cell)"),
            });
        }
        if let Some(e) = &self.ensemble {
            let drops = n.saturating_mul(e.members);
            if drops > crate::spec::MAX_POINTS {
                return Err(SpecError::Invalid {
                    field: "ensemble.members".into(),
                    value: format!("{} members x {n} cells = {drops} drops", e.members),
                    allowed: format!(
                        "at most {} drops, as a sweep's grid points (fewer members or cells)",
                        crate::spec::MAX_POINTS
                    ),
                });
            }
        }
        let points = self.sweep_spec().points()?;
        if let Some(e) = &self.ensemble {
            e.validate()?;
        }
        if let Some(a) = &self.adaptive {
            a.validate(self)?;
        }
        let mut cells = Vec::with_capacity(points.len());
        for p in points {
            let inputs = Inputs(p.inputs.clone());
            if let Some(e) = &self.ensemble {
                e.check_cell(&p.scene)
                    .map_err(|source| SpecError::InvalidScene {
                        index: p.index,
                        inputs: format!(
                            "{} with the widest ensemble draws",
                            serde_json::to_string(&inputs).unwrap_or_default()
                        ),
                        source,
                    })?;
            }
            cells.push(Cell {
                index: p.index,
                inputs,
                scene: p.scene,
            });
        }
        Ok(cells)
    }
}

/// Reads and validates an ensemble file (parse errors carry line and column).
pub fn load(path: impl AsRef<Path>) -> Result<EnsembleSpec, SpecError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| SpecError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let spec: EnsembleSpec =
        whirlmap_core::json::from_str(&text).map_err(|source| SpecError::Parse {
            path: path.to_path_buf(),
            source,
        })?;
    spec.cells()?;
    Ok(spec)
}

/// The two-sided z value for `confidence` (e.g. 1.959964 for 0.95): the standard normal
/// quantile at (1 + confidence) / 2, by Acklam's rational approximation (relative error
/// below 1.2e-9, ample for an interval's width; std has no erf to refine it with).
pub fn z_for_confidence(confidence: f64) -> f64 {
    normal_quantile(0.5 * (1.0 + confidence))
}

/// Standard normal quantile (Acklam's algorithm), `p` in (0, 1).
fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The Wilson score interval for `k` successes in `n` trials at normal quantile `z`:
/// `(p + z^2/2n -/+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)`, with `p = k/n`. `(0, 1)` for
/// `n = 0` (nothing known).
pub fn wilson(k: usize, n: usize, z: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let (k, n) = (k as f64, n as f64);
    let p = k / n;
    let z2 = z * z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = z / denom * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// Summarises one cell's members (in member order) at normal quantile `z`.
pub fn cell_stats(index: usize, inputs: &Inputs, members: &[MemberRecord], z: f64) -> CellStats {
    let ok: Vec<&MemberRecord> = members.iter().filter(|m| m.class.is_some()).collect();
    let whirl = ok
        .iter()
        .filter(|m| m.class.is_some_and(OrbitClass::is_whirl))
        .count();
    let mut classes = BTreeMap::new();
    for m in &ok {
        if let Some(c) = m.class {
            *classes.entry(c.name().to_string()).or_insert(0) += 1;
        }
    }
    let (p_lo, p_hi) = wilson(whirl, ok.len(), z);
    let forces: Vec<f64> = ok.iter().filter_map(|m| m.max_contact_force_n).collect();
    let powers: Vec<f64> = ok.iter().filter_map(|m| m.peak_heat_power_w).collect();
    CellStats {
        index,
        inputs: inputs.0.iter().cloned().collect(),
        members: members.len(),
        ok: ok.len(),
        failed: members.len() - ok.len(),
        whirl,
        p_whirl: if ok.is_empty() {
            f64::NAN
        } else {
            whirl as f64 / ok.len() as f64
        },
        p_lo,
        p_hi,
        classes,
        max_contact_force_n: Percentiles::of(&forces),
        peak_heat_power_w: Percentiles::of(&powers),
    }
}

/// Runs one member (never panics: a failure is data).
pub fn run_member(
    params: &EnsembleParams,
    cell: &Cell,
    member: usize,
    duration_s: f64,
) -> MemberRecord {
    let (scene, drawn) = params.member_scene(&cell.scene, &cell.inputs, member);
    let point = crate::spec::Point {
        index: cell.index,
        inputs: cell.inputs.0.clone(),
        scene,
    };
    let r = run_case(&point, duration_s);
    MemberRecord {
        cell: cell.index,
        member,
        inputs: cell.inputs.clone(),
        drawn,
        scene_hash: r.scene_hash,
        class: r.record.as_ref().map(|d| d.class),
        max_contact_force_n: r.record.as_ref().map(|d| d.max_contact_force_n),
        peak_heat_power_w: r.record.as_ref().map(|d| d.peak_heat_power_w),
        error: r.error.map(|e| format!("{}: {}", e.kind, e.message)),
    }
}

/// Runs every member of `cells` in parallel on the current rayon pool and returns the
/// records in (cell, member) order, whatever the thread count. The members are one pool of
/// work (no batches: a thread that is free takes the next member), so a slow drop holds up
/// only its own thread. `progress` is called, from the worker threads, with (members done,
/// members in all) after each member.
pub fn run_members(
    params: &EnsembleParams,
    cells: &[Cell],
    duration_s: f64,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<MemberRecord> {
    let members = params.members;
    let total = cells.len() * members;
    let done = AtomicUsize::new(0);
    // Every record is kept for the statistics anyway: collect in order, no writer needed.
    (0..total)
        .into_par_iter()
        .map(|k| {
            let r = run_member(params, &cells[k / members], k % members, duration_s);
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            r
        })
        .collect()
}

/// Where the piecewise-linear `p(speed)` first reaches `level`: `Ok(speed)`, or
/// `Err(true)` if already at or above it at the lowest speed, `Err(false)` if never.
/// Points with a non-finite value are skipped.
pub fn first_crossing(speeds: &[f64], p: &[f64], level: f64) -> Result<f64, bool> {
    let pts: Vec<(f64, f64)> = speeds
        .iter()
        .zip(p)
        .filter(|(_, v)| v.is_finite())
        .map(|(s, v)| (*s, *v))
        .collect();
    let i = pts.iter().position(|(_, v)| *v >= level).ok_or(false)?;
    if i == 0 {
        return Err(true);
    }
    let (s0, p0) = pts[i - 1];
    let (s1, p1) = pts[i];
    Ok(s0 + (level - p0) / (p1 - p0) * (s1 - s0))
}

/// The probability contours of `cells` at `levels` (see the module doc).
pub fn contours(cells: &[CellStats], levels: &[f64]) -> Vec<ContourGroup> {
    let mut groups: BTreeMap<String, (BTreeMap<String, f64>, Vec<&CellStats>)> = BTreeMap::new();
    for c in cells {
        let mut key = c.inputs.clone();
        key.remove("speed_rpm");
        let text = serde_json::to_string(&key).unwrap_or_default();
        groups.entry(text).or_insert((key, Vec::new())).1.push(c);
    }
    let mut out: Vec<ContourGroup> = groups
        .into_values()
        .map(|(inputs, mut cs)| {
            cs.sort_by(|a, b| speed(a).total_cmp(&speed(b)));
            let speeds: Vec<f64> = cs.iter().map(|c| speed(c)).collect();
            let p: Vec<f64> = cs.iter().map(|c| c.p_whirl).collect();
            let lo: Vec<f64> = cs.iter().map(|c| c.p_lo).collect();
            let hi: Vec<f64> = cs.iter().map(|c| c.p_hi).collect();
            let non_monotone = cs
                .iter()
                .enumerate()
                .any(|(i, a)| a.ok > 0 && cs[i + 1..].iter().any(|b| b.ok > 0 && b.p_hi < a.p_lo));
            let levels = levels
                .iter()
                .map(|&level| {
                    let centre = first_crossing(&speeds, &p, level);
                    let from = first_crossing(&speeds, &hi, level);
                    let to = first_crossing(&speeds, &lo, level);
                    let note = match centre {
                        Ok(s) => format!("P reaches {level} at {s:.0} r/min"),
                        Err(true) => format!("P >= {level} already at the lowest speed"),
                        Err(false) => format!("P stays below {level} in the range"),
                    };
                    LevelCrossing {
                        level,
                        speed_rpm: centre.ok(),
                        speed_lo_rpm: from.ok(),
                        speed_hi_rpm: to.ok(),
                        note,
                    }
                })
                .collect();
            ContourGroup {
                inputs,
                speeds_rpm: speeds,
                p_whirl: p.iter().map(|v| v.is_finite().then_some(*v)).collect(),
                levels,
                non_monotone,
            }
        })
        .collect();
    out.sort_by(|a, b| {
        let ka: Vec<f64> = a.inputs.values().copied().collect();
        let kb: Vec<f64> = b.inputs.values().copied().collect();
        ka.iter()
            .zip(&kb)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

fn speed(c: &CellStats) -> f64 {
    c.inputs.get("speed_rpm").copied().unwrap_or(f64::NAN)
}

/// What an ensemble run did.
#[derive(Debug, Clone, PartialEq)]
pub struct EnsembleOutcome {
    /// Cells.
    pub cells: usize,
    /// Drops run.
    pub drops: usize,
    /// Drops that failed.
    pub failed: usize,
    /// Drops a `--resume` took from the folder's `members.jsonl` instead of running them
    /// (counted in `drops`).
    pub resumed: usize,
    /// The per-cell statistics.
    pub stats: Vec<CellStats>,
    /// The contours.
    pub contours: ContoursFile,
    /// Files written.
    pub written: Vec<PathBuf>,
}

fn write_file(path: &Path, text: &str, written: &mut Vec<PathBuf>) -> Result<(), SweepError> {
    crate::folder::write_atomic(path, text.as_bytes())?;
    written.push(path.to_path_buf());
    Ok(())
}

fn cells_csv(stats: &[CellStats]) -> String {
    let mut out = String::new();
    let names: Vec<String> = stats
        .first()
        .map(|c| c.inputs.keys().cloned().collect())
        .unwrap_or_default();
    let mut header = vec!["index".to_string()];
    header.extend(names.iter().cloned());
    header.extend(
        [
            "members",
            "ok",
            "failed",
            "whirl",
            "p_whirl",
            "p_lo",
            "p_hi",
            "max_force_p10_n",
            "max_force_p50_n",
            "max_force_p90_n",
            "peak_heat_p10_w",
            "peak_heat_p50_w",
            "peak_heat_p90_w",
        ]
        .map(String::from),
    );
    out.push_str(&header.join(","));
    out.push('\n');
    let num = |v: f64| {
        if v.is_finite() {
            v.to_string()
        } else {
            String::new()
        }
    };
    for c in stats {
        let mut row = vec![c.index.to_string()];
        row.extend(names.iter().map(|n| num(c.inputs[n])));
        row.extend([c.members, c.ok, c.failed, c.whirl].map(|v| v.to_string()));
        let (f, h) = (&c.max_contact_force_n, &c.peak_heat_power_w);
        row.extend(
            [
                c.p_whirl, c.p_lo, c.p_hi, f.p10, f.p50, f.p90, h.p10, h.p50, h.p90,
            ]
            .map(num),
        );
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// Runs the ensemble of `spec` (which must have an `ensemble` section) with `threads`
/// workers (`None`: rayon's default) and writes `members.jsonl`, `cells.jsonl`, `cells.csv`,
/// `contours.json` and `manifest.json` to `out_dir`. Every file but the manifest is
/// byte-identical for any thread count.
///
/// The manifest is written first (`complete` false), and each member's record is appended
/// to `members.jsonl` in (cell, member) order as soon as it and every member before it are
/// done (`MemberWriter`), so a killed run keeps every record it wrote. With `resume`, the
/// members the folder already holds are kept and only the rest run: the folder's manifest
/// must name the same spec, model version and whirlmap version ([`resumable_members`]); a
/// folder with no members starts anew. The result is the same, byte for byte, as one run
/// from the start.
pub fn run_ensemble(
    spec: &EnsembleSpec,
    out_dir: &Path,
    threads: Option<usize>,
    show_progress: bool,
    resume: bool,
) -> Result<EnsembleOutcome, SweepError> {
    let pool = crate::pool::pool(threads).map_err(|e| SweepError::ThreadPool(e.to_string()))?;
    pool.install(|| run_ensemble_here(spec, out_dir, show_progress, resume))
}

/// At most this long between syncs of `members.jsonl` while members are being written (a
/// power loss loses at most the last second's records; a kill loses none that were written).
const SYNC_EVERY: Duration = Duration::from_secs(1);

/// The reorder window per worker thread, as the sweep's grid has it: a worker takes member
/// `k` only while `k < written + WINDOW_PER_THREAD x threads`, so the records done but held
/// back by a slower member before them (lost if the run is killed) stay few.
const WINDOW_PER_THREAD: usize = 16;

/// Appends member records to `members.jsonl` in order as they complete: the worker that
/// completes the first missing member writes it and every done member after it, with one
/// `write_all` (no user-space buffer, so a kill loses none), and a syncing thread outside
/// the pool syncs the file at most [`SYNC_EVERY`] after a write. Runs on the threads of the
/// current rayon pool (also from one of its threads, as a sweep's extras call it), each
/// worker taking the next member from a shared counter.
///
/// A worker waits (blocking its pool thread) only while the first unwritten member runs on
/// another worker: that member's drop never calls back into rayon, so it always ends and
/// wakes the waiting ones. A panic in a member stops the others taking members (the
/// [`StopOnPanic`] guard) and is re-raised once they return.
struct MemberWriter {
    path: PathBuf,
    state: Mutex<WriterState>,
    moved: std::sync::Condvar,
    /// Written since the last sync.
    dirty: std::sync::atomic::AtomicBool,
}

struct WriterState {
    file: std::fs::File,
    /// The next member not yet taken by a worker.
    next: usize,
    /// Done members waiting for one before them.
    waiting: BTreeMap<usize, MemberRecord>,
    /// Every record written, resumed ones first: members `0..records.len()`.
    records: Vec<MemberRecord>,
    /// Take no more members: an error (kept here) or a panic.
    stop: bool,
    error: Option<SweepError>,
}

/// Stops the other workers when the one holding it panics.
struct StopOnPanic<'a>(&'a MemberWriter);

impl Drop for StopOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.lock().stop = true;
            self.0.moved.notify_all();
        }
    }
}

impl MemberWriter {
    /// Runs members `from..total` (`run(k)` for member `k`) with `workers` threads, appending
    /// to `file`, whose first `from` records are `kept`. Returns every record in order.
    fn run(
        path: PathBuf,
        file: std::fs::File,
        kept: Vec<MemberRecord>,
        total: usize,
        workers: usize,
        run: &(dyn Fn(usize) -> MemberRecord + Sync),
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Vec<MemberRecord>, SweepError> {
        let from = kept.len();
        let window = WINDOW_PER_THREAD * workers.max(1);
        let syncing = file
            .try_clone()
            .map_err(|e| crate::folder::output_error(&path, e))?;
        let w = MemberWriter {
            path,
            state: Mutex::new(WriterState {
                file,
                next: from,
                waiting: BTreeMap::new(),
                records: kept,
                stop: false,
                error: None,
            }),
            moved: std::sync::Condvar::new(),
            dirty: std::sync::atomic::AtomicBool::new(false),
        };
        let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
        std::thread::scope(|scope| {
            // The syncing thread: at most a second after a write, until the workers are done.
            let w = &w;
            scope.spawn(move || loop {
                let last = !matches!(
                    done_rx.recv_timeout(SYNC_EVERY),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout)
                );
                if w.dirty.swap(false, Ordering::AcqRel) {
                    if let Err(e) = syncing.sync_data() {
                        let mut st = w.lock();
                        st.stop = true;
                        st.error
                            .get_or_insert(crate::folder::output_error(&w.path, e));
                        drop(st);
                        w.moved.notify_all();
                    }
                }
                if last {
                    break;
                }
            });
            let _done = done_tx;
            (0..workers.max(1))
                .into_par_iter()
                .for_each(|_| w.work(total, window, run, progress));
        });
        let mut st = w.state.into_inner().unwrap_or_else(|e| e.into_inner());
        match st.error.take() {
            Some(e) => Err(e),
            None => Ok(st.records),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, WriterState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// One worker: take the next member (within the window), run it, hand it in.
    fn work(
        &self,
        total: usize,
        window: usize,
        run: &(dyn Fn(usize) -> MemberRecord + Sync),
        progress: &(dyn Fn(usize, usize) + Sync),
    ) {
        let _guard = StopOnPanic(self);
        loop {
            let k = {
                let mut st = self.lock();
                while !st.stop && st.next < total && st.next >= st.records.len() + window {
                    st = self.moved.wait(st).unwrap_or_else(|e| e.into_inner());
                }
                if st.stop || st.next >= total {
                    return;
                }
                st.next += 1;
                st.next - 1
            };
            let record = run(k);
            let done = {
                let mut st = self.lock();
                st.waiting.insert(k, record);
                if let Err(e) = self.write_ready(&mut st) {
                    st.stop = true;
                    st.error.get_or_insert(e);
                }
                st.records.len()
            };
            self.moved.notify_all();
            progress(done, total);
        }
    }

    /// Writes every waiting record that follows the written ones without a gap.
    fn write_ready(&self, st: &mut WriterState) -> Result<(), SweepError> {
        use std::io::Write;
        let mut text = String::new();
        while let Some(r) = st.waiting.remove(&st.records.len()) {
            text.push_str(&serde_json::to_string(&r).expect("records serialise"));
            text.push('\n');
            st.records.push(r);
        }
        if text.is_empty() {
            return Ok(());
        }
        st.file
            .write_all(text.as_bytes())
            .map_err(|e| crate::folder::output_error(&self.path, e))?;
        self.dirty.store(true, Ordering::Release);
        Ok(())
    }
}

/// The manifest of a run of `spec` over `cells`.
fn manifest(
    spec: &EnsembleSpec,
    cells: usize,
    drops: usize,
    failed: usize,
    complete: bool,
    wall_time_s: f64,
) -> EnsembleManifest<&EnsembleSpec> {
    EnsembleManifest {
        cells,
        complete,
        drops,
        failed,
        git_commit: Some(crate::build_info::GIT_COMMIT.to_string()),
        model_version: whirlmap_core::MODEL_VERSION,
        preset_solver: spec.fidelity.map(|f| f.applied(&spec.scene).solver),
        spec: SortedKeys(spec),
        threads: rayon::current_num_threads(),
        wall_time_s,
        whirlmap_version: crate::build_info::VERSION.to_string(),
    }
}

/// The members a `--resume` keeps from `out_dir`, and the length in bytes of
/// `members.jsonl` they fill: every whole line (a last line cut short by a kill is dropped),
/// each of which must be the record of the member at its position (cell `k / members`, member
/// `k % members`, with the inputs, drawn values and scene hash this spec gives it).
/// Refused (exit 2) when a whole line is not that record, or the folder's manifest is not an
/// ensemble's, is unreadable, names another spec, model version or build (whirlmap version and
/// commit), or is missing while members are there.
/// A folder with neither has nothing to keep.
pub fn resumable_members(
    spec: &EnsembleSpec,
    params: &EnsembleParams,
    cells: &[Cell],
    out_dir: &Path,
) -> Result<(Vec<MemberRecord>, u64), SweepError> {
    let members_path = out_dir.join(MEMBERS_FILE);
    let bytes = match std::fs::read(&members_path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(crate::folder::output_error(&members_path, e)),
    };
    let refuse = |why: String| {
        SweepError::Refused(format!(
            "cannot resume the ensemble in {}: {why}. Use --overwrite to replace it, or choose \
             another --out",
            out_dir.display()
        ))
    };
    let text = match std::fs::read_to_string(out_dir.join(MANIFEST_FILE)) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && bytes.is_empty() => {
            return Ok((Vec::new(), 0))
        }
        Err(e) => {
            return Err(refuse(format!(
                "it holds members but no readable manifest.json saying which spec they belong \
                 to ({e})"
            )))
        }
    };
    // Also refuses another command's manifest (a sweep's), which the ensemble's would replace.
    let m: EnsembleManifest<serde_json::Value> = serde_json::from_str(&text).map_err(|e| {
        refuse(format!(
            "its manifest.json is not an ensemble's or is unreadable ({e})"
        ))
    })?;
    let this = serde_json::to_value(spec).expect("specs serialise");
    if m.spec.0 != this {
        let diffs = crate::folder::value_differences(&m.spec.0, &this);
        return Err(refuse(format!(
            "its members belong to another spec ({})",
            diffs.join("; ")
        )));
    }
    if m.model_version != whirlmap_core::MODEL_VERSION {
        return Err(refuse(format!(
            "its members were computed with model version {}, this whirlmap has {}",
            m.model_version,
            whirlmap_core::MODEL_VERSION
        )));
    }
    if let Some(old) =
        crate::build_info::other_build(Some(&m.whirlmap_version), m.git_commit.as_deref())
    {
        return Err(refuse(format!(
            "its members were computed by whirlmap {old}, this is {}: members of two builds \
             would be mixed (resume it with that build)",
            crate::build_info::DESCRIPTION
        )));
    }
    let total = cells.len() * params.members;
    let mut kept = Vec::new();
    let mut len = 0usize;
    for line in bytes.split_inclusive(|b| *b == b'\n') {
        let k = kept.len();
        // A line cut short by a kill (no newline) is dropped; the run goes on from it.
        if line.last() != Some(&b'\n') {
            break;
        }
        let place = format!("line {} of {MEMBERS_FILE}", k + 1);
        if k >= total {
            return Err(refuse(format!(
                "{place} is one member more than the spec's {total}"
            )));
        }
        let r = serde_json::from_slice::<MemberRecord>(line)
            .map_err(|e| refuse(format!("{place} is not a member record ({e})")))?;
        let cell = &cells[k / params.members];
        let member = k % params.members;
        let (scene, drawn) = params.member_scene(&cell.scene, &cell.inputs, member);
        let same = r.cell == cell.index
            && r.member == member
            && r.inputs == cell.inputs
            && r.drawn == drawn
            && r.scene_hash == scene.hash_hex();
        if !same {
            return Err(refuse(format!(
                "{place} is not the member this spec runs there (cell {}, member {member}, \
                 scene {})",
                cell.index,
                scene.hash_hex()
            )));
        }
        kept.push(r);
        len += line.len();
    }
    Ok((kept, len as u64))
}

/// [`run_ensemble`] on the current rayon pool (so it can share a pool with other work, as a
/// sweep's extras do).
pub fn run_ensemble_here(
    spec: &EnsembleSpec,
    out_dir: &Path,
    show_progress: bool,
    resume: bool,
) -> Result<EnsembleOutcome, SweepError> {
    let cells = spec.cells()?;
    let params = spec
        .ensemble
        .as_ref()
        .ok_or_else(|| invalid("ensemble", "(missing)", "an ensemble section"))?;
    check_output_dir(out_dir)?;
    let start = Instant::now();
    let total = cells.len() * params.members;
    let (kept, kept_len) = if resume {
        resumable_members(spec, params, &cells, out_dir)?
    } else {
        (Vec::new(), 0)
    };
    let resumed = kept.len();
    // First the members file, cut to what is kept (nothing, unless resuming); then the
    // manifest that says which spec they belong to; then what an earlier run derived from its
    // members goes (written anew at the end). A kill between any two steps leaves a folder
    // whose manifest matches its members.
    let members_path = out_dir.join(MEMBERS_FILE);
    let file = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .truncate(false)
        .open(&members_path)
        .and_then(|mut f| {
            use std::io::Seek;
            f.set_len(kept_len)?;
            f.seek(std::io::SeekFrom::End(0))?;
            f.sync_all()?;
            Ok(f)
        })
        .map_err(|e| crate::folder::output_error(&members_path, e))?;
    crate::folder::sync_dir(out_dir);
    let m = manifest(spec, cells.len(), total, 0, false, 0.0);
    crate::folder::write_atomic(&out_dir.join(MANIFEST_FILE), m.to_text().as_bytes())?;
    let mut written = Vec::new();
    for name in [CELLS_FILE, CELLS_CSV, CONTOURS_FILE] {
        let p = out_dir.join(name);
        match std::fs::remove_file(&p) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(crate::folder::output_error(&p, e))
            }
            _ => {}
        }
    }
    let last = Mutex::new(Instant::now());
    let progress = |done: usize, total: usize| {
        if !show_progress {
            return;
        }
        let mut last = last.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() >= Duration::from_secs(5) || done == total {
            *last = Instant::now();
            let resumed = if resumed > 0 {
                format!(" ({resumed} resumed)")
            } else {
                String::new()
            };
            crate::sweep::progress_line(&format!(
                "ensemble {}: {done}/{total} drops{resumed}, {:.0} s",
                spec.name,
                start.elapsed().as_secs_f64()
            ));
        }
    };
    let run = |k: usize| {
        run_member(
            params,
            &cells[k / params.members],
            k % params.members,
            spec.duration_s,
        )
    };
    let members = MemberWriter::run(
        members_path.clone(),
        file,
        kept,
        total,
        rayon::current_num_threads(),
        &run,
        &progress,
    )?;
    written.push(members_path);
    let z = z_for_confidence(params.confidence);
    let stats: Vec<CellStats> = cells
        .iter()
        .zip(members.chunks(params.members))
        .map(|(c, ms)| cell_stats(c.index, &c.inputs, ms, z))
        .collect();
    let contours_file = ContoursFile {
        name: spec.name.clone(),
        members: params.members,
        confidence: params.confidence,
        groups: contours(&stats, &params.levels),
    };
    let mut text = String::new();
    for c in &stats {
        text.push_str(&serde_json::to_string(c).expect("records serialise"));
        text.push('\n');
    }
    write_file(&out_dir.join(CELLS_FILE), &text, &mut written)?;
    write_file(&out_dir.join(CELLS_CSV), &cells_csv(&stats), &mut written)?;
    let text = serde_json::to_string_pretty(&contours_file).expect("contours serialise");
    write_file(
        &out_dir.join(CONTOURS_FILE),
        &format!("{text}\n"),
        &mut written,
    )?;
    let failed = members.iter().filter(|m| m.class.is_none()).count();
    let m = manifest(
        spec,
        cells.len(),
        total,
        failed,
        true,
        start.elapsed().as_secs_f64(),
    );
    write_file(&out_dir.join(MANIFEST_FILE), &m.to_text(), &mut written)?;
    Ok(EnsembleOutcome {
        cells: cells.len(),
        drops: members.len(),
        failed,
        resumed,
        stats,
        contours: contours_file,
        written,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stand-in record for member `k`.
    fn fake(k: usize) -> MemberRecord {
        MemberRecord {
            cell: k / 3,
            member: k % 3,
            inputs: Inputs(vec![("mu".into(), 0.1)]),
            drawn: Drawn {
                unbalance_m: 0.0,
                unbalance_phase_rad: 0.0,
                release_offset_m: [0.0; 2],
                release_velocity_m_s: [0.0; 2],
                race_speed_rad_s: 0.0,
            },
            scene_hash: format!("{k:016x}"),
            class: None,
            max_contact_force_n: Some(k as f64),
            peak_heat_power_w: None,
            error: None,
        }
    }

    fn temp_file(name: &str) -> PathBuf {
        let p = std::env::temp_dir().join(format!("whirlmap-{}-{name}", std::process::id()));
        let _ = std::fs::remove_file(&p);
        p
    }

    /// Members of uneven cost, on four threads, while another task keeps one of the pool's
    /// threads busy (as the critical search does beside a sweep's ensemble): the file holds
    /// every record once, in order, after the kept ones.
    #[test]
    fn the_member_writer_appends_in_order_within_its_window() {
        let path = temp_file("writer-order.jsonl");
        let kept: Vec<MemberRecord> = (0..5).map(fake).collect();
        let mut head = String::new();
        for r in &kept {
            head.push_str(&serde_json::to_string(r).unwrap());
            head.push('\n');
        }
        std::fs::write(&path, &head).unwrap();
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        let running = AtomicUsize::new(0);
        let furthest = AtomicUsize::new(0);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let records = pool.install(|| {
            let (records, _) = rayon::join(
                || {
                    MemberWriter::run(
                        path.clone(),
                        file,
                        kept,
                        200,
                        4,
                        &|k| {
                            running.fetch_add(1, Ordering::SeqCst);
                            furthest.fetch_max(k, Ordering::SeqCst);
                            // Every seventh member is slow.
                            let ms = if k % 7 == 0 { 3 } else { 0 };
                            std::thread::sleep(Duration::from_millis(ms));
                            running.fetch_sub(1, Ordering::SeqCst);
                            fake(k)
                        },
                        &|done, total| assert!(done <= total),
                    )
                },
                || std::thread::sleep(Duration::from_millis(50)),
            );
            records.unwrap()
        });
        assert_eq!(records, (0..200).map(fake).collect::<Vec<_>>());
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<MemberRecord> = text
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines, records);
        assert_eq!(running.load(Ordering::SeqCst), 0);
        assert_eq!(furthest.load(Ordering::SeqCst), 199);
        let _ = std::fs::remove_file(&path);
    }

    /// A file that cannot be written stops the workers (no hang) and the error comes back.
    #[test]
    fn a_write_error_stops_the_members_and_is_returned() {
        let path = temp_file("writer-error.jsonl");
        std::fs::write(&path, "").unwrap();
        let read_only = std::fs::File::open(&path).unwrap();
        let ran = AtomicUsize::new(0);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let r = pool.install(|| {
            MemberWriter::run(
                path.clone(),
                read_only,
                Vec::new(),
                10_000,
                2,
                &|k| {
                    ran.fetch_add(1, Ordering::SeqCst);
                    fake(k)
                },
                &|_, _| {},
            )
        });
        assert!(matches!(r, Err(SweepError::Io { .. })), "{r:?}");
        // At most the members in flight when the first write failed, and the window.
        assert!(ran.load(Ordering::SeqCst) <= 2 + WINDOW_PER_THREAD * 2);
        let _ = std::fs::remove_file(&path);
    }

    /// A panic in one member stops the others and reaches the caller instead of leaving
    /// the waiting workers blocked.
    #[test]
    fn a_panicking_member_is_re_raised_not_waited_for() {
        let path = temp_file("writer-panic.jsonl");
        let file = std::fs::File::create(&path).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            pool.install(|| {
                MemberWriter::run(
                    path.clone(),
                    file,
                    Vec::new(),
                    1000,
                    2,
                    &|k| {
                        if k == 3 {
                            panic!("member 3");
                        }
                        fake(k)
                    },
                    &|_, _| {},
                )
            })
        }));
        assert!(r.is_err());
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn wilson_matches_hand_computed_values() {
        let z = 1.959_963_984_540_054;
        // k = 5 of 10: centre 0.5, half width z/(1 + z^2/10) sqrt(0.025 + z^2/400).
        let (lo, hi) = wilson(5, 10, z);
        assert!(
            (lo - 0.236_593).abs() < 1e-6 && (hi - 0.763_407).abs() < 1e-6,
            "{lo} {hi}"
        );
        // k = 0 of 10: [0, (z^2/10) / (1 + z^2/10)] = [0, 0.277533].
        let (lo, hi) = wilson(0, 10, z);
        assert!(lo.abs() < 1e-15, "{lo}");
        assert!((hi - 0.277_533).abs() < 1e-6, "{hi}");
        // k = n: the mirror image.
        let (lo, hi) = wilson(10, 10, z);
        assert!(
            (lo - 0.722_467).abs() < 1e-6 && (hi - 1.0).abs() < 1e-12,
            "{lo} {hi}"
        );
        // k = 1 of 20: [0.008881, 0.236131].
        let (lo, hi) = wilson(1, 20, z);
        assert!(
            (lo - 0.008_881).abs() < 1e-6 && (hi - 0.236_131).abs() < 1e-6,
            "{lo} {hi}"
        );
        assert_eq!(wilson(0, 0, z), (0.0, 1.0));
    }

    #[test]
    fn z_values_are_the_normal_quantiles() {
        assert!((z_for_confidence(0.95) - 1.959_963_984_540_054).abs() < 1e-8);
        assert!((z_for_confidence(0.90) - 1.644_853_626_951_472).abs() < 1e-8);
        assert!((z_for_confidence(0.99) - 2.575_829_303_548_901).abs() < 1e-8);
        assert!((z_for_confidence(0.999) - 3.290_526_731_491_926).abs() < 1e-8);
    }

    #[test]
    fn percentiles_interpolate_between_order_statistics() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(percentile(&v, 0.5), 3.0);
        assert!((percentile(&v, 0.1) - 1.4).abs() < 1e-12);
        assert!((percentile(&v, 0.9) - 4.6).abs() < 1e-12);
        assert_eq!(percentile(&[7.0], 0.9), 7.0);
        assert!(percentile(&[], 0.5).is_nan());
        let p = Percentiles::of(&[5.0, f64::NAN, 1.0, 3.0]);
        assert_eq!((p.p10, p.p50, p.p90), (1.4, 3.0, 4.6));
    }

    #[test]
    fn distributions_stay_in_their_bounds_and_have_the_right_moments() {
        let n = 20_000;
        let mut rng = SplitMix64::new(42);
        let u = Dist::Uniform { from: 2.0, to: 5.0 };
        let xs: Vec<f64> = (0..n).map(|_| u.sample(&mut rng)).collect();
        assert!(xs.iter().all(|x| (2.0..5.0).contains(x)));
        let mean = xs.iter().sum::<f64>() / n as f64;
        assert!((mean - 3.5).abs() < 0.03, "{mean}"); // sd of the mean: 0.006
        let d = Dist::Normal {
            mean: 1.0,
            sd: 2.0,
            min: 0.0,
            max: 3.0,
        };
        let xs: Vec<f64> = (0..n).map(|_| d.sample(&mut rng)).collect();
        assert!(xs.iter().all(|x| (0.0..=3.0).contains(x)));
        // Truncated to [mean - sd/2, mean + sd]: the mean moves up; and both ends are hit.
        assert!(xs.iter().any(|x| *x < 0.05) && xs.iter().any(|x| *x > 2.95));
        let wide = Dist::Normal {
            mean: 10.0,
            sd: 1.0,
            min: -100.0,
            max: 100.0,
        };
        let xs: Vec<f64> = (0..n).map(|_| wide.sample(&mut rng)).collect();
        let m = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64;
        assert!(
            (m - 10.0).abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{m} {var}"
        );
        assert_eq!(Dist::Fixed(3.0).sample(&mut rng), 3.0);
    }

    #[test]
    fn invalid_distributions_are_named() {
        let e = Dist::Uniform { from: 2.0, to: 1.0 }
            .validate("ensemble.unbalance_m")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("ensemble.unbalance_m") && e.contains("[2, 1]"),
            "{e}"
        );
        let e = Dist::Normal {
            mean: 0.0,
            sd: 1.0,
            min: 1.0,
            max: 2.0,
        }
        .validate("x")
        .unwrap_err()
        .to_string();
        assert!(e.contains("min <= mean"), "{e}");
        assert!(Dist::Fixed(f64::INFINITY).validate("x").is_err());
    }

    #[test]
    fn member_draws_depend_only_on_seed_inputs_and_member() {
        let p = EnsembleParams {
            members: 4,
            seed: 9,
            unbalance_m: Some(Dist::Uniform {
                from: 0.0,
                to: 1e-5,
            }),
            unbalance_phase_rad: None,
            orbit_radius_m: Some(Dist::Fixed(1e-5)),
            orbit_phase_rad: None,
            race_speed_rad_s: Some(Dist::Uniform {
                from: -5.0,
                to: 5.0,
            }),
            confidence: 0.95,
            levels: vec![0.5],
        };
        let scene = Scene::paper();
        let inputs = Inputs(vec![("speed_rpm".into(), 8000.0), ("mu".into(), 0.3)]);
        let (a, da) = p.member_scene(&scene, &inputs, 2);
        let (b, _) = p.member_scene(&scene, &inputs, 2);
        assert_eq!(a, b);
        let (c, _) = p.member_scene(&scene, &inputs, 3);
        assert_ne!(a.unbalance_m, c.unbalance_m);
        // The axes in the other order: the same cell, the same members.
        let swapped = Inputs(vec![("mu".into(), 0.3), ("speed_rpm".into(), 8000.0)]);
        assert_eq!(p.member_scene(&scene, &swapped, 2), (a.clone(), da));
        let other = Inputs(vec![("mu".into(), 0.3), ("speed_rpm".into(), 9000.0)]);
        assert_ne!(
            p.member_scene(&scene, &other, 2).0.unbalance_m,
            a.unbalance_m
        );
        let mut q = p.clone();
        q.seed = 10;
        assert_ne!(
            q.member_scene(&scene, &inputs, 2).0.unbalance_m,
            a.unbalance_m
        );
        // On the orbit: radius 10 um, synchronous tangential velocity.
        let [x, y] = da.release_offset_m;
        let [vx, vy] = da.release_velocity_m_s;
        assert!((x.hypot(y) - 1e-5).abs() < 1e-18);
        assert!((vx.hypot(vy) - scene.spin_rad_s() * 1e-5).abs() < 1e-12);
        assert!((x * vx + y * vy).abs() < 1e-15, "velocity is tangential");
        assert!(x * vy - y * vx > 0.0, "forward (with the spin)");
        // Another quantity drawn or not does not change this one's stream.
        q = p.clone();
        q.race_speed_rad_s = None;
        assert_eq!(
            q.member_scene(&scene, &inputs, 2).0.unbalance_m,
            a.unbalance_m
        );
        a.validate().unwrap();
    }

    fn stats(speed: f64, whirl: usize, n: usize) -> CellStats {
        let (p_lo, p_hi) = wilson(whirl, n, 1.96);
        CellStats {
            index: 0,
            inputs: [("speed_rpm".to_string(), speed), ("mu".to_string(), 0.3)]
                .into_iter()
                .collect(),
            members: n,
            ok: n,
            failed: 0,
            whirl,
            p_whirl: whirl as f64 / n as f64,
            p_lo,
            p_hi,
            classes: BTreeMap::new(),
            max_contact_force_n: Percentiles::of(&[]),
            peak_heat_power_w: Percentiles::of(&[]),
        }
    }

    #[test]
    fn contours_interpolate_crossings_and_bracket_them_with_the_wilson_bounds() {
        let cells = vec![
            stats(4000.0, 0, 20),
            stats(2000.0, 0, 20),
            stats(6000.0, 10, 20),
            stats(8000.0, 20, 20),
        ];
        let g = contours(&cells, &[0.1, 0.5, 0.9]);
        assert_eq!(g.len(), 1);
        let g = &g[0];
        assert_eq!(g.speeds_rpm, vec![2000.0, 4000.0, 6000.0, 8000.0]);
        assert!(!g.non_monotone);
        // 0.5 is reached exactly at 6000; 0.1 at 4000 + 0.2 * 2000; 0.9 at 6000 + 0.8 * 2000.
        assert_eq!(g.levels[1].speed_rpm, Some(6000.0));
        assert!((g.levels[0].speed_rpm.unwrap() - 4400.0).abs() < 1e-9);
        assert!((g.levels[2].speed_rpm.unwrap() - 7600.0).abs() < 1e-9);
        for l in &g.levels {
            let s = l.speed_rpm.unwrap();
            assert!(l.speed_lo_rpm.is_none_or(|lo| lo < s), "{l:?}");
            assert!(l.speed_hi_rpm.is_none_or(|hi| hi > s), "{l:?}");
        }
        // 50 %: the upper bound (0.16 at 4000, 0.70 at 6000) crosses first, the lower bound
        // (0.30 at 6000, 0.84 at 8000) last; 90 %: the lower bound never reaches it.
        let half = &g.levels[1];
        assert!(half.speed_lo_rpm.unwrap() > 4000.0 && half.speed_hi_rpm.unwrap() < 8000.0);
        assert_eq!(g.levels[2].speed_hi_rpm, None);
        // The upper bound at 0/20 is 0.16 > 0.1: the 10 % interval starts below the range.
        let g = contours(&[stats(2000.0, 0, 20), stats(4000.0, 20, 20)], &[0.1]);
        assert_eq!(g[0].levels[0].speed_lo_rpm, None);
        // Falling probability is flagged.
        let g = contours(&[stats(2000.0, 20, 20), stats(4000.0, 0, 20)], &[0.5]);
        assert!(g[0].non_monotone);
        assert_eq!(
            g[0].levels[0].speed_rpm, None,
            "already above at the lowest"
        );
    }
}
