//! Fidelity presets: named trade-offs between speed and accuracy, chosen from the measured
//! work-precision curve of `whirlmap accuracy` (README, "Speed against accuracy").
//!
//! A preset sets only what is numerics or a documented reduced model: the tolerance, the
//! Runge-Kutta pair, and whether the race's translation is treated as massless. It leaves the
//! physics a user chose (friction law, drag, every parameter) alone. Without a preset a drop
//! runs with the scene's own settings, which is what every earlier output used.

use crate::error::InvalidParameter;
use crate::scene::{Method, Scene};
use serde::{Deserialize, Serialize};

/// A named speed/accuracy trade-off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// Fast screening: massless race translation (`quasi_static_race`), rtol 1e-4. About 15x
    /// fewer RHS evaluations than `standard`; forces about 1 % high (the race's mass is
    /// missing from the impacts) and whirl frequencies off by up to tens of percent.
    Draft,
    /// Design work: the full paper model at rtol 1e-5 (the scene default), whose force and
    /// heat errors are far below 0.1 % in every measured case.
    Standard,
    /// The full paper model at rtol 1e-9 with DOPRI5 (the reference of the accuracy study,
    /// where DOP853 at rtol 1e-10 confirms it).
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
            .ok_or_else(|| InvalidParameter::new("fidelity", text, "draft, standard, reference"))
    }

    /// The relative tolerance of the preset.
    pub fn rtol(self) -> f64 {
        match self {
            Fidelity::Draft => 1e-4,
            Fidelity::Standard => 1e-5,
            Fidelity::Reference => 1e-9,
        }
    }

    /// Whether the preset treats the race's translation as massless.
    pub fn quasi_static_race(self) -> bool {
        matches!(self, Fidelity::Draft)
    }

    /// Sets the preset's numerics and reduced model on `scene`.
    pub fn apply(self, scene: &mut Scene) {
        scene.solver.rtol = self.rtol();
        scene.solver.method = Method::Dopri5;
        scene.quasi_static_race = self.quasi_static_race();
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
}
