//! The work-precision study behind `whirlmap accuracy`: representative drops run at a ladder
//! of tolerances and model settings, each measured against a reference solution.
//!
//! The reference of a case is the full model integrated by DOP853 at the tightest tolerance
//! (`reference_rtol`, default 1e-10); DOPRI5 at the same tolerance confirms it, and the
//! difference between the two is reported as the reference's own uncertainty. Every other run
//! is measured against it: relative errors in the first and maximum contact force and the
//! peak heat power, the absolute error in whirl frequency, class agreement, and the cost (RHS
//! evaluations, steps, wall time).
//!
//! A case file (`sweeps/accuracy-cases.json`) names the cases, the tolerance ladder and the
//! settings; scene keys are set by [`crate::overrides::apply`] (dotted for nested fields).

use crate::classify::OrbitClass;
use crate::overrides::{self, OverrideError};
use crate::run::run_drop;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::path::Path;
use std::time::Instant;
use thiserror::Error;
use whirlmap_core::{DropOptions, Fidelity, Method, Scene};

/// Why an accuracy spec is unusable.
#[derive(Debug, Error)]
pub enum AccuracySpecError {
    /// Not readable.
    #[error("cannot read accuracy cases {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Not valid JSON or an unknown key (serde's message has line and column).
    #[error("accuracy cases {path}: {source}")]
    Parse {
        /// The file.
        path: String,
        /// serde_json's error.
        source: serde_json::Error,
    },
    /// A scene override that does not apply.
    #[error("{field}: {source}")]
    Override {
        /// Where (`cases[2].scene`).
        field: String,
        /// The override error.
        source: OverrideError,
    },
    /// A value out of range.
    #[error("{field} = {value}: allowed {allowed}")]
    Range {
        /// The field.
        field: String,
        /// The value as text.
        value: String,
        /// The allowed range.
        allowed: String,
    },
}

/// One representative drop.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSpec {
    /// Short name (`pendulum`, `backward_whirl`, ...).
    pub name: String,
    /// Scene overrides of the paper scene (dotted keys for nested fields).
    #[serde(default)]
    pub scene: Map<String, Value>,
    /// Simulated time (s); default the spec's `duration_s`.
    #[serde(default)]
    pub duration_s: Option<f64>,
}

/// One model/solver setting of the ladder (applied on top of each case's scene).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettingSpec {
    /// Short name (`full`, `quasi_static_race`, `regularised 1e-3`, ...).
    pub name: String,
    /// Scene overrides (dotted keys), e.g. `{"drag_enabled": false}`.
    #[serde(default)]
    pub scene: Map<String, Value>,
    /// Tolerances for this setting; default the spec's ladder.
    #[serde(default)]
    pub rtol: Option<Vec<f64>>,
    /// Record the orbit (trajectory) as `whirlmap drop --orbit` does, to show its cost.
    #[serde(default)]
    pub record_orbit: bool,
}

fn default_name() -> String {
    "accuracy".into()
}
fn default_duration() -> f64 {
    1.0
}
fn default_reference_rtol() -> f64 {
    1e-10
}
fn default_budget() -> u64 {
    4_000_000
}
fn default_perturbation() -> f64 {
    1e-9
}

/// The whole study.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccuracySpec {
    /// Name (for titles).
    #[serde(default = "default_name")]
    pub name: String,
    /// Default simulated time per case (s).
    #[serde(default = "default_duration")]
    pub duration_s: f64,
    /// Tolerance of the reference runs (DOP853, confirmed by DOPRI5).
    #[serde(default = "default_reference_rtol")]
    pub reference_rtol: f64,
    /// The tolerance ladder.
    pub rtol: Vec<f64>,
    /// Step attempts allowed per ladder run (a run over it is reported as failed, not
    /// waited for).
    #[serde(default = "default_budget")]
    pub max_step_attempts: u64,
    /// How far the release point of each case's reference is moved, along x and then along
    /// y, to measure how sensitive the outputs are to a physically negligible change (m).
    /// Default 1e-9 (1 nm, about 1/150 000 of the paper's clearance); 0 skips it.
    #[serde(default = "default_perturbation")]
    pub release_perturbation_m: f64,
    /// The cases.
    pub cases: Vec<CaseSpec>,
    /// The settings.
    pub settings: Vec<SettingSpec>,
}

impl AccuracySpec {
    /// Reads and checks a case file.
    pub fn load(path: &Path) -> Result<Self, AccuracySpecError> {
        let p = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| AccuracySpecError::Read {
            path: p.clone(),
            source,
        })?;
        let spec: Self = whirlmap_core::json::from_str(&text)
            .map_err(|source| AccuracySpecError::Parse { path: p, source })?;
        spec.validate()?;
        Ok(spec)
    }

    /// Checks ranges and that every override applies.
    pub fn validate(&self) -> Result<(), AccuracySpecError> {
        let range = |field: String, v: f64, ok: bool, allowed: &str| {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(AccuracySpecError::Range {
                    field,
                    value: v.to_string(),
                    allowed: allowed.into(),
                })
            }
        };
        range(
            "duration_s".into(),
            self.duration_s,
            self.duration_s > 0.0 && self.duration_s <= 3600.0,
            "(0, 3600] s",
        )?;
        range(
            "release_perturbation_m".into(),
            self.release_perturbation_m,
            (0.0..=1e-6).contains(&self.release_perturbation_m),
            "[0, 1e-6] m",
        )?;
        range(
            "reference_rtol".into(),
            self.reference_rtol,
            self.reference_rtol >= 1e-13 && self.reference_rtol <= 1e-6,
            "[1e-13, 1e-6]",
        )?;
        let ladders = std::iter::once(("rtol".to_string(), &self.rtol)).chain(
            self.settings
                .iter()
                .enumerate()
                .filter_map(|(i, s)| s.rtol.as_ref().map(|r| (format!("settings[{i}].rtol"), r))),
        );
        for (field, ladder) in ladders {
            if ladder.is_empty() {
                return Err(AccuracySpecError::Range {
                    field,
                    value: "[]".into(),
                    allowed: "at least one tolerance".into(),
                });
            }
            for (j, r) in ladder.iter().enumerate() {
                range(
                    format!("{field}[{j}]"),
                    *r,
                    *r > 0.0 && *r <= 1e-2,
                    "(0, 1e-2]",
                )?;
            }
        }
        // Every run's tolerance and step budget are the study's (its ladder, a setting's own
        // ladder, the reference's and the presets' tolerances): one in a case's or a
        // setting's scene would be silently replaced.
        let scenes = self
            .cases
            .iter()
            .enumerate()
            .map(|(i, c)| {
                (
                    format!("cases[{i}]"),
                    &c.scene,
                    "each run's ladder or preset",
                )
            })
            .chain(self.settings.iter().enumerate().map(|(j, st)| {
                let ladder = if st.rtol.is_some() {
                    "the setting's own rtol ladder"
                } else {
                    "the study's rtol ladder"
                };
                (format!("settings[{j}]"), &st.scene, ladder)
            }));
        for (place, scene, ladder) in scenes {
            for (key, by) in [
                ("rtol", ladder),
                ("max_step_attempts", "the study's max_step_attempts"),
            ] {
                let nested = scene
                    .get("solver")
                    .and_then(|v| v.as_object())
                    .and_then(|o| o.get(key));
                if let Some(v) = scene.get(&format!("solver.{key}")).or(nested) {
                    return Err(AccuracySpecError::Range {
                        field: format!("{place}.scene.solver.{key}"),
                        value: v.to_string(),
                        allowed: format!("no value here: {by} sets it"),
                    });
                }
            }
        }
        // Rows are named by case and setting, and a ladder's rungs by their tolerance: each
        // must be told apart.
        let twice = |field: &dyn Fn(usize) -> String, names: Vec<String>| {
            for (i, n) in names.iter().enumerate() {
                if names[..i].contains(n) {
                    return Err(AccuracySpecError::Range {
                        field: field(i),
                        value: n.clone(),
                        allowed: "a value not used before in the list".into(),
                    });
                }
            }
            Ok(())
        };
        let text = |r: &Vec<f64>| r.iter().map(|r| r.to_string()).collect();
        twice(
            &|i| format!("cases[{i}].name"),
            self.cases.iter().map(|c| c.name.clone()).collect(),
        )?;
        twice(
            &|i| format!("settings[{i}].name"),
            self.settings.iter().map(|s| s.name.clone()).collect(),
        )?;
        twice(&|i| format!("rtol[{i}]"), text(&self.rtol))?;
        for (j, st) in self.settings.iter().enumerate() {
            if let Some(r) = &st.rtol {
                twice(&|i| format!("settings[{j}].rtol[{i}]"), text(r))?;
            }
        }
        if self.cases.is_empty() {
            return Err(AccuracySpecError::Range {
                field: "cases".into(),
                value: "[]".into(),
                allowed: "at least one case".into(),
            });
        }
        for (i, c) in self.cases.iter().enumerate() {
            let s = self.case_scene(i)?;
            s.validate().map_err(|e| AccuracySpecError::Range {
                field: format!("cases[{i}].scene.{}", e.field),
                value: e.value,
                allowed: e.allowed,
            })?;
            if let Some(d) = c.duration_s {
                range(
                    format!("cases[{i}].duration_s"),
                    d,
                    d > 0.0 && d <= 3600.0,
                    "(0, 3600] s",
                )?;
            }
            // Every ladder run's scene as it will run, so that no run fails on its input.
            for (j, st) in self.settings.iter().enumerate() {
                for &rtol in st.rtol.as_ref().unwrap_or(&self.rtol) {
                    self.ladder_scene(&s, j, rtol)?.validate().map_err(|e| {
                        AccuracySpecError::Range {
                            field: if e.field == "solver.max_step_attempts" {
                                "max_step_attempts".into()
                            } else {
                                format!("settings[{j}].scene.{} (case {})", e.field, c.name)
                            },
                            value: e.value,
                            allowed: e.allowed,
                        }
                    })?;
                }
            }
        }
        Ok(())
    }

    /// The scene of case `i`'s reference, DOPRI5's (DOP853 runs it with the method
    /// switched): the case's scene at the `reference` preset's numerics (every tolerance the
    /// rotor's, no gap bound), at `reference_rtol`, so a change of the scene defaults does
    /// not move the reference.
    pub fn reference_scene(&self, i: usize) -> Result<Scene, AccuracySpecError> {
        let mut s = Fidelity::Reference.applied(&self.case_scene(i)?);
        s.solver.rtol = self.reference_rtol;
        s.solver.max_step_attempts = s.solver.max_step_attempts.max(50_000_000);
        Ok(s)
    }

    /// The scene of case `i` (paper scene plus the case's overrides).
    pub fn case_scene(&self, i: usize) -> Result<Scene, AccuracySpecError> {
        apply_map(
            Scene::paper(),
            &self.cases[i].scene,
            &format!("cases[{i}].scene"),
        )
    }

    /// The scene of one ladder run: `base` (a case's scene) with setting `j`, at `rtol` and
    /// the study's step budget.
    pub fn ladder_scene(
        &self,
        base: &Scene,
        j: usize,
        rtol: f64,
    ) -> Result<Scene, AccuracySpecError> {
        let mut s = self.setting_scene(base, j)?;
        s.solver.rtol = rtol;
        s.solver.max_step_attempts = self.max_step_attempts;
        Ok(s)
    }

    /// `base` with setting `j` applied.
    pub fn setting_scene(&self, base: &Scene, j: usize) -> Result<Scene, AccuracySpecError> {
        apply_map(
            base.clone(),
            &self.settings[j].scene,
            &format!("settings[{j}].scene"),
        )
    }
}

fn apply_map(
    mut scene: Scene,
    map: &Map<String, Value>,
    field: &str,
) -> Result<Scene, AccuracySpecError> {
    for (k, v) in map {
        overrides::apply(&mut scene, k, v.clone()).map_err(|source| {
            AccuracySpecError::Override {
                field: field.to_string(),
                source,
            }
        })?;
    }
    Ok(scene)
}

/// The measured outputs of one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// Orbit class.
    pub class: OrbitClass,
    /// First impact force (N).
    pub first_contact_force_n: f64,
    /// Maximum contact force (N).
    pub max_contact_force_n: f64,
    /// Peak heat power (W).
    pub peak_heat_power_w: f64,
    /// Whirl frequency (Hz).
    pub whirl_frequency_hz: f64,
    /// Energy audit residual.
    pub energy_residual_rel: f64,
    /// Friction heat over the whole drop (J), the integral of H_s: unlike the peaks above it
    /// depends on the whole stick/slip history (a contact that sticks makes no heat).
    pub friction_heat_j: f64,
    /// RHS evaluations.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Wall time (ms), this machine, one thread per run.
    pub wall_ms: f64,
}

/// Runs one drop and measures it; `Err` carries the failure's kind and message (a solver
/// error, or a panic inside the solver, kind `panic`).
pub fn measure(scene: &Scene, duration_s: f64, record_orbit: bool) -> Result<Measured, String> {
    let opts = DropOptions {
        duration_s,
        orbit_points: record_orbit.then_some(20_000),
        ..Default::default()
    };
    let t = Instant::now();
    let r = run_drop(scene, &opts).map_err(|e| format!("{}: {e}", e.kind()))?;
    let wall_ms = t.elapsed().as_secs_f64() * 1e3;
    let f = &r.features;
    Ok(Measured {
        class: r.verdict.class,
        first_contact_force_n: f.first_contact_force_n,
        max_contact_force_n: f.max_contact_force_n,
        peak_heat_power_w: f.peak_heat_power_w,
        whirl_frequency_hz: f.whirl_frequency_hz,
        energy_residual_rel: r.energy.residual_rel,
        friction_heat_j: r.energy.friction_heat_j,
        rhs_evals: r.stats.rhs_evals,
        steps: r.stats.steps,
        wall_ms,
    })
}

/// Errors of a run against the reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// Relative error of the first impact force.
    pub first_force_rel: f64,
    /// Relative error of the maximum contact force.
    pub max_force_rel: f64,
    /// Relative error of the peak heat power.
    pub peak_heat_rel: f64,
    /// Absolute error of the whirl frequency (Hz).
    pub whirl_frequency_abs_hz: f64,
    /// Relative error of the friction heat over the drop.
    pub friction_heat_rel: f64,
    /// Whether the class agrees.
    pub class_agrees: bool,
}

impl Errors {
    /// `m` against `reference`.
    pub fn of(m: &Measured, reference: &Measured) -> Self {
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
        Self {
            first_force_rel: rel(m.first_contact_force_n, reference.first_contact_force_n),
            max_force_rel: rel(m.max_contact_force_n, reference.max_contact_force_n),
            peak_heat_rel: rel(m.peak_heat_power_w, reference.peak_heat_power_w),
            whirl_frequency_abs_hz: (m.whirl_frequency_hz - reference.whirl_frequency_hz).abs(),
            friction_heat_rel: rel(m.friction_heat_j, reference.friction_heat_j),
            class_agrees: m.class == reference.class,
        }
    }

    /// The largest of the three relative errors of the issue's outputs (first and maximum
    /// force, peak heat power): the y value of the work-precision chart. The friction heat's
    /// error is reported beside it, not in it.
    pub fn worst_rel(&self) -> f64 {
        self.first_force_rel
            .max(self.max_force_rel)
            .max(self.peak_heat_rel)
    }
}

/// One row of the study.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// Setting name (`preset:standard` for the presets).
    pub setting: String,
    /// Tolerance.
    pub rtol: f64,
    /// Measurements, or the failure.
    pub result: Result<(Measured, Errors), String>,
}

/// A case's reference and its confirmation.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Reference {
    /// Case name.
    pub case: String,
    /// DOP853 at the reference tolerance: the values every run is measured against.
    pub dop853: Measured,
    /// DOPRI5 at the same tolerance, full model.
    pub dopri5: Result<Measured, String>,
    /// DOPRI5 against DOP853: the reference's own uncertainty.
    pub agreement: Option<Errors>,
    /// The outputs' sensitivity: the largest change of each (the class: whether it holds)
    /// when the reference's release point moves by the spec's `release_perturbation_m`
    /// along x or along y. An error below it is below what the case's physics can resolve;
    /// `None` when skipped or when a perturbed run failed.
    #[serde(default)]
    pub release_spread: Option<Errors>,
}

impl Errors {
    /// The larger of each error of `self` and `other`; the class agrees only if it does in
    /// both.
    /// A NaN in either stays NaN.
    pub fn max(&self, other: &Errors) -> Errors {
        let worst = |a: f64, b: f64| {
            if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                a.max(b)
            }
        };
        Errors {
            first_force_rel: worst(self.first_force_rel, other.first_force_rel),
            max_force_rel: worst(self.max_force_rel, other.max_force_rel),
            peak_heat_rel: worst(self.peak_heat_rel, other.peak_heat_rel),
            whirl_frequency_abs_hz: worst(
                self.whirl_frequency_abs_hz,
                other.whirl_frequency_abs_hz,
            ),
            friction_heat_rel: worst(self.friction_heat_rel, other.friction_heat_rel),
            class_agrees: self.class_agrees && other.class_agrees,
        }
    }
}

/// Everything the study produced.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Study {
    /// The references, one per case.
    pub references: Vec<Reference>,
    /// The ladder and preset rows, in case, setting, tolerance order.
    pub rows: Vec<Row>,
}

/// Runs the study (cases and runs in parallel over rayon's pool; the order of the result
/// does not depend on the thread count, wall times do).
pub fn run(spec: &AccuracySpec) -> Result<Study, AccuracySpecError> {
    spec.validate()?;
    let mut ref_jobs = Vec::new();
    for (i, c) in spec.cases.iter().enumerate() {
        let s = spec.reference_scene(i)?;
        let d = c.duration_s.unwrap_or(spec.duration_s);
        ref_jobs.push((c.name.clone(), s, d));
    }
    let p = spec.release_perturbation_m;
    let references: Vec<Result<Reference, String>> = ref_jobs
        .par_iter()
        .map(|(name, s, d)| {
            let mut s8 = s.clone();
            s8.solver.method = Method::Dop853;
            let dop853 = measure(&s8, *d, false)
                .map_err(|e| format!("reference of case {name} failed: {e}"))?;
            let dopri5 = measure(s, *d, false);
            let agreement = dopri5.as_ref().ok().map(|m| Errors::of(m, &dop853));
            let release_spread = if p > 0.0 {
                [[p, 0.0], [0.0, p]]
                    .iter()
                    .map(|dxy| {
                        let mut sp = s8.clone();
                        sp.release_offset_m[0] += dxy[0];
                        sp.release_offset_m[1] += dxy[1];
                        measure(&sp, *d, false)
                            .ok()
                            .map(|m| Errors::of(&m, &dop853))
                    })
                    .reduce(|a, b| a.zip(b).map(|(a, b)| a.max(&b)))
                    .flatten()
            } else {
                None
            };
            Ok(Reference {
                case: name.clone(),
                dop853,
                dopri5,
                agreement,
                release_spread,
            })
        })
        .collect();
    let references: Vec<Reference> =
        references
            .into_iter()
            .collect::<Result<_, _>>()
            .map_err(|e| AccuracySpecError::Range {
                field: "cases".into(),
                value: e,
                allowed: "a reference that finishes".into(),
            })?;

    // Ladder jobs: case x setting x rtol, then the presets.
    let mut jobs: Vec<(usize, String, Scene, f64, bool)> = Vec::new();
    for (i, c) in spec.cases.iter().enumerate() {
        let base = spec.case_scene(i)?;
        let d = c.duration_s.unwrap_or(spec.duration_s);
        for (j, st) in spec.settings.iter().enumerate() {
            for &rtol in st.rtol.as_ref().unwrap_or(&spec.rtol) {
                let s = spec.ladder_scene(&base, j, rtol)?;
                jobs.push((i, st.name.clone(), s, d, st.record_orbit));
            }
        }
        for f in Fidelity::ALL {
            jobs.push((
                i,
                format!("preset:{}", f.name()),
                f.applied(&base),
                d,
                false,
            ));
        }
    }
    let rows: Vec<Row> = jobs
        .par_iter()
        .map(|(i, setting, s, d, orbit)| {
            let reference = &references[*i].dop853;
            Row {
                case: spec.cases[*i].name.clone(),
                setting: setting.clone(),
                rtol: s.solver.rtol,
                result: measure(s, *d, *orbit).map(|m| (m, Errors::of(&m, reference))),
            }
        })
        .collect();
    Ok(Study { references, rows })
}

/// The study as CSV, one line per row.
pub fn to_csv(study: &Study) -> String {
    let mut out = String::from(
        "case,setting,rtol,status,class,class_agrees,first_force_rel_err,max_force_rel_err,\
         peak_heat_rel_err,whirl_freq_abs_err_hz,first_contact_force_n,max_contact_force_n,\
         peak_heat_power_w,whirl_frequency_hz,energy_residual_rel,rhs_evals,steps,wall_ms,\
         friction_heat_rel_err,friction_heat_j\n",
    );
    for r in &study.rows {
        match &r.result {
            Ok((m, e)) => out.push_str(&format!(
                "{},{},{:e},ok,{},{},{:e},{:e},{:e},{:e},{},{},{},{},{:e},{},{},{:.3},{:e},{}\n",
                r.case,
                r.setting,
                r.rtol,
                m.class.name(),
                e.class_agrees,
                e.first_force_rel,
                e.max_force_rel,
                e.peak_heat_rel,
                e.whirl_frequency_abs_hz,
                m.first_contact_force_n,
                m.max_contact_force_n,
                m.peak_heat_power_w,
                m.whirl_frequency_hz,
                m.energy_residual_rel,
                m.rhs_evals,
                m.steps,
                m.wall_ms,
                e.friction_heat_rel,
                m.friction_heat_j
            )),
            Err(e) => out.push_str(&format!(
                "{},{},{:e},\"failed: {}\",,,,,,,,,,,,,,,,\n",
                r.case,
                r.setting,
                r.rtol,
                e.replace('"', "'")
            )),
        }
    }
    out
}

fn pct(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{:.1e}", x)
    }
}

/// The study as Markdown: the references with their confirmation, then one table per case.
pub fn to_markdown(study: &Study, spec: &AccuracySpec) -> String {
    let mut out = format!(
        "# Work-precision study `{}`\n\nReference: the full model, DOP853 at rtol {:e}; DOPRI5 at the same \
         tolerance confirms it (its relative differences: the reference's own uncertainty). The last \
         column moves the reference's release point by a physically negligible distance, along x \
         and then along y, and gives the largest change of each output: how well the case's \
         physics determines it. An error below that change is below what any solver can be held \
         to. Errors are relative (forces, heat power, friction heat over the drop) or \
         absolute (whirl frequency, Hz); cost is RHS evaluations, steps and wall time on one thread of this machine.\n\n",
        spec.name, spec.reference_rtol
    );
    out.push_str(&format!(
        "| case | class | first force (N) | max force (N) | peak heat (W) | whirl (Hz) | friction heat (J) | DOP853 RHS evals | DOPRI5 class | DOPRI5 diff first / max / heat / friction heat | release moved {:e} m: change first / max / heat / friction heat / whirl (Hz) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        spec.release_perturbation_m
    ));
    for r in &study.references {
        let m = &r.dop853;
        let (c5, diff) = match (&r.dopri5, &r.agreement) {
            (Ok(d), Some(a)) => (
                d.class.name().to_string(),
                format!(
                    "{} / {} / {} / {}",
                    pct(a.first_force_rel),
                    pct(a.max_force_rel),
                    pct(a.peak_heat_rel),
                    pct(a.friction_heat_rel)
                ),
            ),
            (Err(e), _) => (format!("failed: {e}"), String::new()),
            _ => (String::new(), String::new()),
        };
        let spread = match &r.release_spread {
            Some(a) => format!(
                "{} / {} / {} / {} / {:.1e}{}",
                pct(a.first_force_rel),
                pct(a.max_force_rel),
                pct(a.peak_heat_rel),
                pct(a.friction_heat_rel),
                a.whirl_frequency_abs_hz,
                if a.class_agrees {
                    ""
                } else {
                    " (class changes)"
                }
            ),
            None if spec.release_perturbation_m > 0.0 => "a moved run failed".into(),
            None => "not measured".into(),
        };
        out.push_str(&format!(
            "| {} | {} | {:.2} | {:.2} | {:.1} | {:.3} | {:.4} | {} | {} | {} | {} |\n",
            r.case,
            m.class.name(),
            m.first_contact_force_n,
            m.max_contact_force_n,
            m.peak_heat_power_w,
            m.whirl_frequency_hz,
            m.friction_heat_j,
            m.rhs_evals,
            c5,
            diff,
            spread
        ));
    }
    for reference in &study.references {
        out.push_str(&format!(
            "\n## {}\n\n| setting | rtol | class | first force err | max force err | heat err | whirl err (Hz) | friction heat err | RHS evals | steps | wall (ms) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
            reference.case
        ));
        for r in study.rows.iter().filter(|r| r.case == reference.case) {
            match &r.result {
                Ok((m, e)) => out.push_str(&format!(
                    // `{:e}`: the shortest exact form, so 2.5e-5 stays 2.5e-5.
                    "| {} | {:e} | {}{} | {} | {} | {} | {:.2e} | {} | {} | {} | {:.1} |\n",
                    r.setting,
                    r.rtol,
                    m.class.name(),
                    if e.class_agrees { "" } else { " (differs)" },
                    pct(e.first_force_rel),
                    pct(e.max_force_rel),
                    pct(e.peak_heat_rel),
                    e.whirl_frequency_abs_hz,
                    pct(e.friction_heat_rel),
                    m.rhs_evals,
                    m.steps,
                    m.wall_ms
                )),
                Err(e) => out.push_str(&format!(
                    "| {} | {:e} | failed: {} | | | | | | | | |\n",
                    r.setting, r.rtol, e
                )),
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worst_of_two_errors_keeps_a_nan_and_a_class_change() {
        let e = |x: f64, agrees: bool| Errors {
            first_force_rel: x,
            max_force_rel: 2.0 * x,
            peak_heat_rel: x,
            whirl_frequency_abs_hz: x,
            friction_heat_rel: x,
            class_agrees: agrees,
        };
        let m = e(1e-3, true).max(&e(2e-3, false));
        assert_eq!((m.first_force_rel, m.max_force_rel), (2e-3, 4e-3));
        assert!(!m.class_agrees);
        let n = e(1e-3, true).max(&e(f64::NAN, true));
        assert!(n.first_force_rel.is_nan() && n.friction_heat_rel.is_nan());
    }

    /// The reference runs at the `reference` preset's numerics whatever the scene defaults
    /// and the case's own solver keys say, at the spec's tolerance.
    #[test]
    fn the_reference_is_the_reference_preset_at_the_spec_tolerance() {
        let spec: AccuracySpec = serde_json::from_str(
            r#"{"rtol": [1e-4], "reference_rtol": 1e-11, "settings": [],
                "cases": [{"name": "c", "scene": {"mu_dynamic": 0.3,
                           "solver.race_atol_scale": 300, "solver.method": "rodas4"}}]}"#,
        )
        .unwrap();
        let s = spec.reference_scene(0).unwrap();
        let mut expected = Fidelity::Reference.applied(&spec.case_scene(0).unwrap());
        expected.solver.rtol = 1e-11;
        expected.solver.max_step_attempts = 50_000_000;
        assert_eq!(s, expected);
        assert_eq!(s.mu_dynamic, 0.3);
        assert_eq!(s.solver.race_atol_scale, 1.0);
        assert!(!s.solver.race_velocity_atol_from_force && !s.solver.free_flight_gap_bound);
        assert_eq!(s.solver.method, Method::Dopri5);
    }

    #[test]
    fn errors_are_relative_and_class_is_compared() {
        let m = Measured {
            class: OrbitClass::Pendulum,
            first_contact_force_n: 101.0,
            max_contact_force_n: 200.0,
            peak_heat_power_w: 90.0,
            whirl_frequency_hz: 1.5,
            energy_residual_rel: 0.0,
            friction_heat_j: 3.0,
            rhs_evals: 1,
            steps: 1,
            wall_ms: 0.0,
        };
        let reference = Measured {
            first_contact_force_n: 100.0,
            peak_heat_power_w: 100.0,
            whirl_frequency_hz: 1.0,
            friction_heat_j: 4.0,
            class: OrbitClass::BackwardWhirl,
            ..m
        };
        let e = Errors::of(&m, &reference);
        assert!((e.first_force_rel - 0.01).abs() < 1e-12);
        assert_eq!(e.max_force_rel, 0.0);
        assert!((e.peak_heat_rel - 0.1).abs() < 1e-12);
        assert!((e.whirl_frequency_abs_hz - 0.5).abs() < 1e-12);
        assert!((e.friction_heat_rel - 0.25).abs() < 1e-12);
        assert!(!e.class_agrees);
        assert!((e.worst_rel() - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_bad_override_is_named_with_its_place() {
        let spec: AccuracySpec = serde_json::from_str(
            r#"{"rtol": [1e-4], "cases": [{"name": "a", "scene": {"speed_rpm": 1000}}],
                "settings": [{"name": "x", "scene": {"drag_enabeld": false}}]}"#,
        )
        .unwrap();
        let e = spec.validate().unwrap_err().to_string();
        assert!(
            e.contains("settings[0].scene") && e.contains("drag_enabeld"),
            "{e}"
        );
        let spec: AccuracySpec =
            serde_json::from_str(r#"{"rtol": [0.5], "cases": [], "settings": []}"#).unwrap();
        assert!(spec.validate().unwrap_err().to_string().contains("rtol[0]"));
        let spec: AccuracySpec =
            serde_json::from_str(r#"{"rtol": [1e-4], "cases": [], "settings": []}"#).unwrap();
        assert_eq!(
            spec.validate().unwrap_err().to_string(),
            "cases = []: allowed at least one case"
        );
    }

    #[test]
    fn every_ladder_scene_is_checked_before_a_run() {
        let spec = |setting: &str, top: &str| -> AccuracySpec {
            serde_json::from_str(&format!(
                r#"{{"rtol": [1e-4], {top} "cases": [{{"name": "a", "scene": {{}}}}],
                    "settings": [{{"name": "x", "scene": {setting}}}]}}"#
            ))
            .unwrap()
        };
        let err = |setting: &str, top: &str| spec(setting, top).validate().unwrap_err().to_string();
        let e = err(r#"{"clearance_m": -1}"#, "");
        assert!(
            e.starts_with("settings[0].scene.clearance_m (case a) = -1"),
            "{e}"
        );
        let e = err("{}", r#""max_step_attempts": 0,"#);
        assert!(e.starts_with("max_step_attempts = 0"), "{e}");
        for s in [r#"{"solver.rtol": 5}"#, r#"{"solver": {"rtol": 1e-6}}"#] {
            let e = err(s, "");
            assert!(e.starts_with("settings[0].scene.solver.rtol"), "{e}");
        }
        let e = err(r#"{"solver.rtol": 5}"#, "");
        assert!(e.ends_with("the study's rtol ladder sets it"), "{e}");
        let case: AccuracySpec = serde_json::from_str(
            r#"{"rtol": [1e-4], "cases": [{"name": "a", "scene": {"solver.rtol": 1e-6}}],
                "settings": []}"#,
        )
        .unwrap();
        let e = case.validate().unwrap_err().to_string();
        assert!(e.starts_with("cases[0].scene.solver.rtol = 1e-6"), "{e}");
        assert!(spec(r#"{"solver.method": "dopri5"}"#, "")
            .validate()
            .is_ok());
    }

    #[test]
    fn names_and_tolerances_are_each_given_once() {
        let spec = |text: &str| -> String {
            serde_json::from_str::<AccuracySpec>(text)
                .unwrap()
                .validate()
                .unwrap_err()
                .to_string()
        };
        let e = spec(
            r#"{"rtol": [1e-4], "cases": [{"name": "a", "scene": {}}, {"name": "a", "scene": {}}],
                "settings": []}"#,
        );
        assert!(e.starts_with("cases[1].name = a"), "{e}");
        let e = spec(
            r#"{"rtol": [1e-4, 1e-5, 1e-4], "cases": [{"name": "a", "scene": {}}], "settings": []}"#,
        );
        assert!(e.starts_with("rtol[2] = 0.0001"), "{e}");
        let e = spec(
            r#"{"rtol": [1e-4], "cases": [{"name": "a", "scene": {}}],
                "settings": [{"name": "x", "scene": {}}, {"name": "x", "scene": {}}]}"#,
        );
        assert!(e.starts_with("settings[1].name = x"), "{e}");
    }
}
