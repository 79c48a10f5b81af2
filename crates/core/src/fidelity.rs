//! Fidelity presets: named trade-offs between speed and accuracy, chosen from the measured
//! work-precision studies of `whirlmap accuracy` (`results/accuracy/`,
//! `results/accuracy-draft/`, docs/accuracy.md#fidelity-presets).
//!
//! A preset sets only numerics: the tolerance, the integrator, the free-flight gap bound and
//! the race's tolerance scale (and the full model: it switches the quasi-static race off). It
//! leaves the physics a user chose (friction law, drag, every parameter) alone. Without a
//! preset a drop runs with the scene's own solver settings, whose defaults are `standard`.

use crate::error::InvalidParameter;
use crate::scene::{Method, Scene, SolverSettings};
use serde::{Deserialize, Serialize};

/// A named speed/accuracy trade-off.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// Screening: RODAS4 then BDF (as `standard`'s stepper) with the free-flight gap bound
    /// and the race's absolute tolerances x1000, at rtol 1e-4: the most accurate setting at
    /// its cost in the `draft` study (`results/accuracy-draft/`; RODAS4 alone with the same
    /// numerics until 2026-11-29, whose forces it keeps for 0.58 of its RHS evaluations).
    /// About 0.8 of `standard`'s time, but outside the accuracy budget: on bouncing
    /// sequences its maximum force is off by up to 0.23 % (docs/accuracy.md#fidelity-presets).
    Draft,
    /// Design work, and the scene default: RODAS4 then BDF (RODAS4 after every mode switch, the
    /// BDF of orders up to 4 at a tenth of the tolerance once the contact has run smoothly for
    /// 2 ms; model versions 12 and 13) on the full Jacobian at rtol 3e-5, with the free-flight
    /// gap bound and the race's velocity tolerance widened from the contact force in contact
    /// (every other tolerance the rotor's); within the budget with its tolerance neighbours
    /// within it too, with a margin of two on the worst case (first and maximum contact force
    /// and peak heat power within 0.1 % of `reference`, whirl frequency within 1 %, the same
    /// class away from a transition; docs/accuracy.md#fidelity-presets).
    Standard,
    /// DOPRI5 at rtol 1e-9: the reference of the accuracy and convergence studies (DOP853 at
    /// rtol 1e-10 confirms it to 6e-6).
    Reference,
}

impl Fidelity {
    /// Every preset, cheapest first.
    pub const ALL: [Fidelity; 3] = [Fidelity::Draft, Fidelity::Standard, Fidelity::Reference];

    /// The preset's name as the CLI and spec files spell it.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Draft => "draft",
            Fidelity::Standard => "standard",
            Fidelity::Reference => "reference",
        }
    }

    /// Parses a preset name; the error names the value and the allowed names.
    pub fn parse(text: &str) -> Result<Self, InvalidParameter> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == text)
            .ok_or_else(|| {
                InvalidParameter::new(
                    "fidelity",
                    format!("{text:?}"),
                    "draft, standard, reference",
                )
            })
    }

    /// The relative tolerance of the preset.
    pub fn rtol(self) -> f64 {
        self.solver().rtol
    }

    /// The preset's integrator settings (the rest of [`SolverSettings`] keeps its defaults).
    pub fn solver(self) -> SolverSettings {
        let standard = SolverSettings::default();
        match self {
            Fidelity::Draft => SolverSettings {
                rtol: 1e-4,
                method: Method::Rodas4Bdf,
                free_flight_gap_bound: true,
                race_atol_scale: 1000.0,
                race_velocity_atol_from_force: false,
                ..standard
            },
            Fidelity::Standard => standard,
            Fidelity::Reference => SolverSettings {
                rtol: 1e-9,
                method: Method::Dopri5,
                free_flight_gap_bound: false,
                race_atol_scale: 1.0,
                race_velocity_atol_from_force: false,
                ..standard
            },
        }
    }

    /// The scene keys (dotted, as `--set` takes them) that [`Fidelity::apply`] sets: a value
    /// given for one of them before the preset is applied does not survive it.
    pub const KEYS: [&'static str; 7] = [
        "solver.rtol",
        "solver.method",
        "solver.free_flight_gap_bound",
        "solver.race_atol_scale",
        "solver.race_velocity_atol_from_force",
        "solver.bdf_max_order",
        "quasi_static_race",
    ];

    /// Sets the preset's numerics on `scene` (tolerance, integrator, gap bound, race
    /// tolerance scale, the race's velocity tolerance from the force, the BDF's highest
    /// order), and the full model (`quasi_static_race` off): the keys of [`Fidelity::KEYS`].
    /// The physics a user chose stays as it is.
    pub fn apply(self, scene: &mut Scene) {
        let p = self.solver();
        let s = &mut scene.solver;
        s.rtol = p.rtol;
        s.method = p.method;
        s.free_flight_gap_bound = p.free_flight_gap_bound;
        s.race_atol_scale = p.race_atol_scale;
        s.race_velocity_atol_from_force = p.race_velocity_atol_from_force;
        s.bdf_max_order = p.bdf_max_order;
        scene.quasi_static_race = false;
    }

    /// A copy of `scene` with the preset applied.
    pub fn applied(self, scene: &Scene) -> Scene {
        let mut s = scene.clone();
        self.apply(&mut s);
        s
    }

    /// The next tighter preset, if any (the critical search re-checks boundary cells at it).
    pub fn tighter(self) -> Option<Fidelity> {
        match self {
            Fidelity::Draft => Some(Fidelity::Standard),
            Fidelity::Standard => Some(Fidelity::Reference),
            Fidelity::Reference => None,
        }
    }
}

impl std::fmt::Display for Fidelity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Fidelity {
    type Err = InvalidParameter;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::parse(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_are_named() {
        for f in Fidelity::ALL {
            assert_eq!(Fidelity::parse(f.name()).unwrap(), f);
        }
        let e = Fidelity::parse("fast").unwrap_err();
        assert_eq!(e.field, "fidelity");
        assert!(e.to_string().contains("fast") && e.to_string().contains("draft"));
        // An empty name is shown as one, quoted, not as nothing.
        let e = Fidelity::parse("").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("invalid fidelity = \"\": allowed"),
            "{e}"
        );
    }

    #[test]
    fn standard_is_the_scene_default() {
        assert_eq!(Fidelity::Standard.applied(&Scene::paper()), Scene::paper());
    }

    #[test]
    fn presets_tighten_in_order_and_give_valid_scenes() {
        let mut last = f64::INFINITY;
        for f in Fidelity::ALL {
            assert!(f.rtol() < last);
            last = f.rtol();
            f.applied(&Scene::paper()).validate().unwrap();
        }
        assert_eq!(Fidelity::Draft.tighter(), Some(Fidelity::Standard));
        assert_eq!(Fidelity::Reference.tighter(), None);
    }

    /// `KEYS` is what `apply` sets: a preset changes no other key of a scene, and a value
    /// given for any of its keys before it does not survive it.
    #[test]
    fn the_keys_are_those_a_preset_sets() {
        let other = [
            ("solver.rtol", serde_json::json!(1e-6)),
            ("solver.method", serde_json::json!("dop853")),
            ("solver.free_flight_gap_bound", serde_json::json!(false)),
            ("solver.race_atol_scale", serde_json::json!(7.0)),
            (
                "solver.race_velocity_atol_from_force",
                serde_json::json!(false),
            ),
            ("solver.bdf_max_order", serde_json::json!(2)),
            ("quasi_static_race", serde_json::json!(true)),
        ];
        let keys: Vec<&str> = other.iter().map(|(k, _)| *k).collect();
        assert_eq!(keys, Fidelity::KEYS);
        let paper = Scene::paper();
        for f in Fidelity::ALL {
            let preset = f.applied(&paper);
            for k in crate::scene::scene_changes(&preset).keys() {
                assert!(Fidelity::KEYS.contains(&k.as_str()), "{f:?} sets {k}");
            }
            for (key, value) in &other {
                let mut v = serde_json::to_value(&paper).unwrap();
                let mut at = &mut v;
                for part in key.split('.') {
                    at = &mut at[part];
                }
                *at = value.clone();
                let given: Scene = serde_json::from_value(v).unwrap();
                assert_ne!(given, paper, "{key}");
                assert_eq!(f.applied(&given), preset, "{f:?} keeps {key}");
            }
        }
    }
}
