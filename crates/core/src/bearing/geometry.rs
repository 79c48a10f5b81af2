//! The touchdown bearing pair: two rows of a 71908 CD face to face, every number with its
//! source, and the catalogue ratings recomputed from the standards' own formulas.
//!
//! Sources:
//! - \[Table 3\] the paper's Table 3: 71908, bore 40 mm, outside diameter 62 mm, width
//!   12 mm, balls 5.5 mm. The pitch diameter is taken as the mean of bore and outside
//!   diameter, 51 mm, as the scene's Palmgren drag does (`Scene::pitch_diameter_m`).
//! - \[Table 4\] the paper's Table 4: the lumped race-on-balls stiffness
//!   `k2 = 2.47e5 N/mm^1.5 = 7.811e9 N/m^1.5`, zero internal clearance.
//! - \[SKF\] SKF super-precision bearings: suffix CD is the 15° contact angle (ACD is 25°).
//! - \[ISO 281\] ISO 281:2007, *Rolling bearings — Dynamic load ratings and rating life*:
//!   `C_r = b_m f_c (i cos α)^0.7 Z^(2/3) D_w^1.8` (N, mm; `D_w <= 25.4 mm`), `b_m = 1.3`,
//!   `f_c` from its Table 2 (linear interpolation); a face-to-face pair of identical
//!   single-row angular contact bearings is rated as one double-row bearing, `i = 2`.
//! - \[ISO 76\] ISO 76:2006, *Rolling bearings — Static load ratings*: `C_0r` is the static
//!   radial load that produces 4200 MPa at the centre of the most heavily loaded ball-raceway
//!   contact (ball bearings other than self-aligning), with `Q_max = 5 F_r / (i Z cos α)`;
//!   its `f_0` table is that definition evaluated for `r_i = 0.52 D_w`, `r_e = 0.53 D_w`.
//! - \[Harris\] Harris & Kotzalas, *Essential Concepts of Bearing Technology*, 5th ed.
//!   (2006), ch. 2 (conformity, `γ`), ch. 6 (Hertz), ch. 10 (kinematic speeds); bearing
//!   steel `E = 208 GPa`, `ν = 0.3` (AISI 52100, as in `thermal::params`).
//!
//! What no source here gives for a 71908 CD (the catalogue tables list ratings, not the
//! internal design): the ball count and the groove conformities. They are documented
//! choices, see [`BearingPair::paper_71908_cd`].

use super::hertz::{series_stiffness_n_per_m1_5, PointContact, Race};
use crate::error::InvalidParameter;
use crate::scene::{approx, check_field, num};
use serde::{Deserialize, Serialize};

/// Harris's radial integral for zero clearance, `J_r(0.5) = (1/2π) ∫_{-π/2}^{π/2} cos^2.5 ψ
/// dψ = Γ(7/4) / (2 √π Γ(9/4))` (Harris & Kotzalas ch. 7, tabulated there as 0.2288).
pub const RADIAL_INTEGRAL_ZERO_CLEARANCE: f64 = 0.228_827_929_050_544;

/// ISO 76's limiting contact pressure for ball bearings other than self-aligning (Pa): the
/// static load rating is the load that produces it at the most heavily loaded contact.
pub const ISO76_BALL_LIMIT_PRESSURE_PA: f64 = 4.2e9;

/// Allowed ball diameter (m): a tenth of a millimetre to 100 mm.
pub const BALL_DIAMETER_RANGE_M: [f64; 2] = [1e-4, 0.1];
/// Allowed pitch diameter (m): 1 mm to 10 m (the scene's own `pitch_diameter_m` is at most
/// 10 m).
pub const PITCH_DIAMETER_RANGE_M: [f64; 2] = [1e-3, 10.0];
/// Allowed Young's modulus of balls and rings (Pa): polymers (about 1 GPa) to ceramics and
/// carbides (silicon nitride 310 GPa, tungsten carbide about 700 GPa).
pub const YOUNG_MODULUS_RANGE_PA: [f64; 2] = [1e9, 1e12];
/// Allowed lumped stiffness (N/m^1.5): a force at 1 um of 1e-3 N to 1e10 N, the range the
/// scene allows its race-on-balls support ([`crate::scene::SUPPORT_FORCE_AT_1UM_N`]).
pub const LUMPED_STIFFNESS_RANGE_N_PER_M1_5: [f64; 2] = [1e6, 1e19];
/// Allowed basic load ratings, dynamic and static (N): the scene's range for its static
/// load rating (`static_load_rating_n`).
pub const LOAD_RATING_RANGE_N: [f64; 2] = [1.0, 1e8];
/// Allowed static limit on the contact pressure (Pa): 0.1 GPa to 10 GPa (ISO 76's is 4.2
/// GPa for ball bearings, 4.0 GPa for roller bearings).
pub const LIMIT_PRESSURE_RANGE_PA: [f64; 2] = [1e8, 1e10];

/// ISO 281:2007's rating factor `b_m` for radial ball bearings (its Table 1).
pub const ISO281_BM_RADIAL_BALL: f64 = 1.3;

/// ISO 281:2007 Table 2, `f_c` for single-row radial contact groove ball bearings and
/// single- and double-row angular contact groove ball bearings, against
/// `γ = D_w cos α / D_pw` (intermediate values by linear interpolation, as the standard says).
const ISO281_FC_TABLE: [(f64, f64); 11] = [
    (0.05, 46.7),
    (0.06, 49.1),
    (0.07, 51.1),
    (0.08, 52.8),
    (0.09, 54.3),
    (0.10, 55.5),
    (0.12, 57.5),
    (0.14, 58.8),
    (0.16, 59.6),
    (0.18, 59.9),
    (0.20, 59.9),
];

/// ISO 281's `f_c` at `gamma` by linear interpolation in its Table 2; `None` outside the
/// tabulated range `[0.05, 0.20]` carried here.
pub fn iso281_fc(gamma: f64) -> Option<f64> {
    let t = &ISO281_FC_TABLE;
    if !(gamma >= t[0].0 && gamma <= t[t.len() - 1].0) {
        return None;
    }
    for w in t.windows(2) {
        let ((g0, f0), (g1, f1)) = (w[0], w[1]);
        if gamma <= g1 {
            return Some(f0 + (f1 - f0) * (gamma - g0) / (g1 - g0));
        }
    }
    None
}

/// The touchdown bearing pair: geometry, material, ratings and the lumped stiffness the
/// dynamics use. SI units; every field is documented with its default and source.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BearingPair {
    /// Ball diameter `D` (m). Default 5.5 mm \[Table 3\]. Allowed [1e-4, 0.1] m, and the
    /// balls of one row must fit on the pitch circle without overlapping:
    /// `balls_per_row * ball_diameter_m < pi * pitch_diameter_m`.
    pub ball_diameter_m: f64,
    /// Pitch diameter `d_m` (m). Default 51 mm, the mean of bore and outside diameter
    /// \[Table 3\], as the scene's drag model takes it. Allowed [1e-3, 10] m and larger than
    /// `ball_diameter_m`.
    pub pitch_diameter_m: f64,
    /// Balls per row `Z`. Default 22: not in the paper or the catalogue tables; the pitch
    /// circle (π d_m = 160 mm) filled with 5.5 mm balls at the spacing of caged angular
    /// contact bearings (about 1.3 ball diameters), as the thermal model assumes
    /// (`thermal::params`). With it ISO 76 gives `C_0 = 10.4 kN` per bearing, matching the
    /// 10 kN order of a 71908 catalogue entry the scene uses for the drag torque. Allowed
    /// [3, 1000], and the balls must fit on the pitch circle (see `ball_diameter_m`).
    pub balls_per_row: u32,
    /// Rows `i`. Default 2: two 71908 CD face to face. Allowed [1, 8].
    pub rows: u32,
    /// Nominal contact angle `α` (rad). Default 15° (suffix CD \[SKF\]). Taken as constant:
    /// zero clearance and no axial load keep it at its nominal value (Harris ch. 7 for small
    /// displacements). Allowed [0, 1.4) rad (radial and angular contact).
    pub contact_angle_rad: f64,
    /// Inner groove conformity `f_i = r_i / D`. Default 0.52: ISO 281's and ISO 76's rating
    /// basis (`r_i <= 0.52 D_w`) \[ISO 281\], the usual value of angular contact ball
    /// bearings. Allowed (0.5, 1).
    pub inner_conformity: f64,
    /// Outer groove conformity `f_o = r_o / D`. Default 0.53: ISO 281's and ISO 76's rating
    /// basis (`r_e <= 0.53 D_w`) \[ISO 281\]. Allowed (0.5, 1).
    pub outer_conformity: f64,
    /// Young's modulus of balls and rings (Pa). Default 208e9, AISI 52100 \[Harris\].
    /// Allowed [1e9, 1e12] Pa (polymers to ceramics).
    pub young_modulus_pa: f64,
    /// Poisson's ratio of balls and rings. Default 0.3 \[Harris\]. Allowed [0, 0.5).
    pub poisson_ratio: f64,
    /// The lumped radial stiffness the dynamics use, `F = k2 r^1.5` (N/m^1.5). Default
    /// 7.811e9 \[Table 4\]. The per-ball stiffness follows from it
    /// ([`BearingPair::ball_stiffness_from_lumped_n_per_m1_5`]). Allowed [1e6, 1e19]
    /// N/m^1.5: a force at 1 um of [1e-3, 1e10] N, the scene's range for the support
    /// stiffness `support_stiffness_n_per_m_e`.
    pub lumped_stiffness_n_per_m1_5: f64,
    /// Basic dynamic load rating `C` of the pair (N), the ISO 281 `C_r` with `i = 2`
    /// \[ISO 281\]. Default 19 470 N: ISO 281's formula for this geometry
    /// ([`BearingPair::iso281_dynamic_rating_n`]); one row alone is 11 980 N. Allowed
    /// [1, 1e8] N, as the scene's `static_load_rating_n`.
    pub dynamic_rating_n: f64,
    /// Basic static load rating `C_0` of the pair (N), ISO 76 with `i = 2` \[ISO 76\].
    /// Default 20 740 N: ISO 76's definition for this geometry
    /// ([`BearingPair::iso76_static_rating_n`]); one row alone is 10 370 N. Allowed
    /// [1, 1e8] N.
    pub static_rating_n: f64,
    /// The static limit on the maximum contact pressure (Pa). Default 4.2e9 \[ISO 76\].
    /// Allowed [1e8, 1e10] Pa.
    pub static_limit_pressure_pa: f64,
}

impl Default for BearingPair {
    fn default() -> Self {
        BearingPair::paper_71908_cd()
    }
}

impl BearingPair {
    /// The paper's touchdown bearing: two 71908 CD face to face, the defaults of every
    /// field above.
    pub fn paper_71908_cd() -> Self {
        BearingPair {
            ball_diameter_m: 5.5e-3,
            pitch_diameter_m: 0.051,
            balls_per_row: 22,
            rows: 2,
            contact_angle_rad: 15f64.to_radians(),
            inner_conformity: 0.52,
            outer_conformity: 0.53,
            young_modulus_pa: 208e9,
            poisson_ratio: 0.3,
            lumped_stiffness_n_per_m1_5: 7.811e9,
            dynamic_rating_n: 19_470.0,
            static_rating_n: 20_740.0,
            static_limit_pressure_pa: ISO76_BALL_LIMIT_PRESSURE_PA,
        }
    }

    /// Checks every field against its own allowed range ([`BearingPair::validate_fields`]),
    /// then the geometry: the ball is smaller than the pitch diameter, and the balls of one
    /// row fit on the pitch circle without overlapping,
    /// `balls_per_row * ball_diameter_m < pi * pitch_diameter_m`. The error names the first
    /// bad field by its dotted key in the scene (`bearing.rows`), with its value and the
    /// allowed range.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        self.validate_fields()?;
        if !(self.ball_diameter_m < self.pitch_diameter_m) {
            return Err(InvalidParameter::new(
                "bearing.pitch_diameter_m",
                num(self.pitch_diameter_m),
                &format!(
                    "> bearing.ball_diameter_m = {} m (the balls' centres lie on the pitch \
                     circle)",
                    num(self.ball_diameter_m)
                ),
            ));
        }
        let z = self.balls_per_row as f64;
        let circumference = std::f64::consts::PI * self.pitch_diameter_m;
        if !(z * self.ball_diameter_m < circumference) {
            return Err(InvalidParameter::new(
                "bearing.ball_diameter_m",
                num(self.ball_diameter_m),
                &format!(
                    "< pi * bearing.pitch_diameter_m / bearing.balls_per_row = pi * {} / {} = \
                     {} m: the balls of one row must fit on the pitch circle without \
                     overlapping (balls_per_row * ball_diameter_m < pi * pitch_diameter_m)",
                    num(self.pitch_diameter_m),
                    self.balls_per_row,
                    approx(circumference / z)
                ),
            ));
        }
        // A rating left at the default pair's value on a geometry its formula does not
        // cover cannot follow the geometry ([`BearingPair::with_ratings_of_its_geometry`]).
        let d = BearingPair::paper_71908_cd();
        if self.dynamic_rating_n == d.dynamic_rating_n && self.iso281_dynamic_rating_n().is_none() {
            return Err(InvalidParameter::new(
                "bearing.dynamic_rating_n",
                num(self.dynamic_rating_n),
                "the pair's own rating: 19470 N is the default pair's, and ISO 281's formula, \
                 from which it would follow this geometry, does not cover it (balls above \
                 25.4 mm, or D cos(alpha) / d_m outside [0.05, 0.2]); set the catalogue rating",
            ));
        }
        Ok(())
    }

    /// Checks each field against its own allowed range (listed under `bearing.` in
    /// [`crate::schema::FIELD_RANGES`]), not the geometry between fields
    /// ([`BearingPair::validate`] adds it); the error names the field as `bearing.<field>`.
    pub fn validate_fields(&self) -> Result<(), InvalidParameter> {
        let check = |field: &str, v: f64, ok: bool, allowed: &str| {
            check_field(&format!("bearing.{field}"), v, ok, allowed)
        };
        let within = |v: f64, [lo, hi]: [f64; 2]| (lo..=hi).contains(&v);
        check(
            "ball_diameter_m",
            self.ball_diameter_m,
            within(self.ball_diameter_m, BALL_DIAMETER_RANGE_M),
            "[1e-4, 0.1] m",
        )?;
        check(
            "pitch_diameter_m",
            self.pitch_diameter_m,
            within(self.pitch_diameter_m, PITCH_DIAMETER_RANGE_M),
            "[1e-3, 10] m",
        )?;
        if !(3..=1000).contains(&self.balls_per_row) {
            return Err(InvalidParameter::new(
                "bearing.balls_per_row",
                self.balls_per_row,
                "[3, 1000]",
            ));
        }
        if !(1..=8).contains(&self.rows) {
            return Err(InvalidParameter::new("bearing.rows", self.rows, "[1, 8]"));
        }
        check(
            "contact_angle_rad",
            self.contact_angle_rad,
            self.contact_angle_rad >= 0.0 && self.contact_angle_rad < 1.4,
            "[0, 1.4) rad (radial and angular contact)",
        )?;
        for (name, f) in [
            ("inner_conformity", self.inner_conformity),
            ("outer_conformity", self.outer_conformity),
        ] {
            check(name, f, f > 0.5 && f < 1.0, "(0.5, 1)")?;
        }
        check(
            "young_modulus_pa",
            self.young_modulus_pa,
            within(self.young_modulus_pa, YOUNG_MODULUS_RANGE_PA),
            "[1e9, 1e12] Pa",
        )?;
        check(
            "poisson_ratio",
            self.poisson_ratio,
            (0.0..0.5).contains(&self.poisson_ratio),
            "[0, 0.5)",
        )?;
        check(
            "lumped_stiffness_n_per_m1_5",
            self.lumped_stiffness_n_per_m1_5,
            within(
                self.lumped_stiffness_n_per_m1_5,
                LUMPED_STIFFNESS_RANGE_N_PER_M1_5,
            ),
            "[1e6, 1e19] N/m^1.5 (a force at 1 um of [1e-3, 1e10] N, the scene's range for \
             support_stiffness_n_per_m_e)",
        )?;
        for (name, v) in [
            ("dynamic_rating_n", self.dynamic_rating_n),
            ("static_rating_n", self.static_rating_n),
        ] {
            check(name, v, within(v, LOAD_RATING_RANGE_N), "[1, 1e8] N")?;
        }
        check(
            "static_limit_pressure_pa",
            self.static_limit_pressure_pa,
            within(self.static_limit_pressure_pa, LIMIT_PRESSURE_RANGE_PA),
            "[1e8, 1e10] Pa",
        )?;
        Ok(())
    }

    /// `γ = D cos α / d_m` (Harris ch. 2).
    pub fn gamma(&self) -> f64 {
        self.ball_diameter_m * self.contact_angle_rad.cos() / self.pitch_diameter_m
    }

    /// The ball-inner raceway contact ([`PointContact::ball_in_groove`]).
    pub fn inner_contact(&self) -> PointContact {
        self.contact(Race::Inner, self.inner_conformity)
    }

    /// The ball-outer raceway contact ([`PointContact::ball_in_groove`]).
    pub fn outer_contact(&self) -> PointContact {
        self.contact(Race::Outer, self.outer_conformity)
    }

    fn contact(&self, race: Race, conformity: f64) -> PointContact {
        PointContact::ball_in_groove(
            race,
            self.ball_diameter_m,
            self.pitch_diameter_m,
            self.contact_angle_rad,
            conformity,
            self.young_modulus_pa,
            self.poisson_ratio,
        )
    }

    /// Ball passes over one point of the inner raceway per revolution of the inner ring
    /// relative to the fixed outer ring, per row: `Z/2 (1 + γ)` (Harris ch. 10, ball-pass
    /// frequency of the inner raceway in pure rolling; the cage turns at `(1 - γ)/2` of the
    /// inner ring's speed). The ball-pass frequency is this times `|n_race|` (rev/s).
    pub fn inner_ball_passes_per_revolution(&self) -> f64 {
        0.5 * self.balls_per_row as f64 * (1.0 + self.gamma())
    }

    /// The per-ball stiffness `K_n` (N/m^1.5, `Q = K_n δ^1.5` along the contact line) whose
    /// ball set reproduces the lumped `k2`:
    /// `K_n = k2 / (i Z J_r(0.5) cos^2.5 α)` (see [`super::load`] for the derivation).
    pub fn ball_stiffness_from_lumped_n_per_m1_5(&self) -> f64 {
        self.lumped_stiffness_n_per_m1_5
            / (self.rows as f64
                * self.balls_per_row as f64
                * RADIAL_INTEGRAL_ZERO_CLEARANCE
                * self.contact_angle_rad.cos().powf(2.5))
    }

    /// The per-ball stiffness of this geometry by Hertz: the inner and outer contacts in
    /// series ([`series_stiffness_n_per_m1_5`]) (N/m^1.5).
    pub fn hertz_ball_stiffness_n_per_m1_5(&self) -> f64 {
        series_stiffness_n_per_m1_5(
            self.inner_contact().stiffness_n_per_m1_5(),
            self.outer_contact().stiffness_n_per_m1_5(),
        )
    }

    /// The lumped stiffness that a real pair of this geometry has by Hertz,
    /// `i Z J_r(0.5) cos^2.5 α K_n,Hertz` (N/m^1.5), to compare with the paper's `k2`.
    pub fn hertz_lumped_stiffness_n_per_m1_5(&self) -> f64 {
        self.rows as f64
            * self.balls_per_row as f64
            * RADIAL_INTEGRAL_ZERO_CLEARANCE
            * self.contact_angle_rad.cos().powf(2.5)
            * self.hertz_ball_stiffness_n_per_m1_5()
    }

    /// The ball load (N) at which the more severe raceway contact reaches the static limit
    /// pressure `static_limit_pressure_pa`.
    pub fn static_limit_ball_load_n(&self) -> f64 {
        let p = self.static_limit_pressure_pa;
        self.inner_contact()
            .load_at_pressure_n(p)
            .min(self.outer_contact().load_at_pressure_n(p))
    }

    /// ISO 76's basic static radial load rating of this pair (N), by the standard's own
    /// definition: `C_0 = i Z cos α Q_lim / 5`, `Q_lim` the ball load that produces 4200 MPa
    /// at the more severe raceway contact (Hertz, [`PointContact`]), `5` ISO 76's
    /// `Q_max = 5 F_r / (i Z cos α)`. For the ISO 76 conformities (0.52/0.53) this is the
    /// standard's `f_0 i Z D_w² cos α`.
    pub fn iso76_static_rating_n(&self) -> f64 {
        let q = self
            .inner_contact()
            .load_at_pressure_n(ISO76_BALL_LIMIT_PRESSURE_PA)
            .min(
                self.outer_contact()
                    .load_at_pressure_n(ISO76_BALL_LIMIT_PRESSURE_PA),
            );
        self.rows as f64 * self.balls_per_row as f64 * self.contact_angle_rad.cos() * q / 5.0
    }

    /// This pair with each rating left at the default pair's value replaced by its formula's
    /// value for this geometry and material (ISO 281 for `C`, ISO 76 for `C_0`), when that
    /// differs from the formula's value for the default pair: the defaults are those formulas'
    /// values for the default pair, and a geometry change left them behind (the damage stayed
    /// at the default pair's rating whatever the rows, balls or contact angle). A rating set
    /// to anything else is the user's, a catalogue's, and is kept.
    pub fn with_ratings_of_its_geometry(mut self) -> Self {
        let d = BearingPair::paper_71908_cd();
        let moved = |own: f64, default: f64| (own - default).abs() > 1e-9 * default;
        if self.dynamic_rating_n == d.dynamic_rating_n {
            if let (Some(own), Some(default)) =
                (self.iso281_dynamic_rating_n(), d.iso281_dynamic_rating_n())
            {
                if moved(own, default) {
                    self.dynamic_rating_n = own;
                }
            }
        }
        if self.static_rating_n == d.static_rating_n {
            let (own, default) = (self.iso76_static_rating_n(), d.iso76_static_rating_n());
            if moved(own, default) {
                self.static_rating_n = own;
            }
        }
        self
    }

    /// ISO 281's basic dynamic radial load rating of this pair (N),
    /// `b_m f_c (i cos α)^0.7 Z^(2/3) D_w^1.8` with `D_w` in mm (`D_w <= 25.4 mm`).
    /// `None` if `γ` is outside the `f_c` range carried here or `D_w > 25.4 mm`.
    pub fn iso281_dynamic_rating_n(&self) -> Option<f64> {
        let dw_mm = self.ball_diameter_m * 1e3;
        if dw_mm > 25.4 {
            return None;
        }
        let fc = iso281_fc(self.gamma())?;
        Some(
            ISO281_BM_RADIAL_BALL
                * fc
                * (self.rows as f64 * self.contact_angle_rad.cos()).powf(0.7)
                * (self.balls_per_row as f64).powf(2.0 / 3.0)
                * dw_mm.powf(1.8),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_the_ratings_are_the_standards_formulas() {
        let p = BearingPair::paper_71908_cd();
        p.validate().unwrap();
        let c = p.iso281_dynamic_rating_n().unwrap();
        let c0 = p.iso76_static_rating_n();
        assert!((p.dynamic_rating_n / c - 1.0).abs() < 5e-4, "C {c}");
        assert!((p.static_rating_n / c0 - 1.0).abs() < 5e-4, "C0 {c0}");
        // One row: the pair's C is 2^0.7 times, its C0 twice.
        let one = BearingPair {
            rows: 1,
            ..p.clone()
        };
        let c1 = one.iso281_dynamic_rating_n().unwrap();
        assert!((c / c1 - 2f64.powf(0.7)).abs() < 1e-12);
        assert!((c0 / one.iso76_static_rating_n() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn fc_interpolates_and_refuses_outside_its_table() {
        assert_eq!(iso281_fc(0.10), Some(55.5));
        assert!((iso281_fc(0.11).unwrap() - 56.5).abs() < 1e-12);
        assert_eq!(iso281_fc(0.01), None);
        assert_eq!(iso281_fc(0.5), None);
    }

    #[test]
    fn validation_names_the_field() {
        let p = BearingPair {
            inner_conformity: 0.5,
            ..BearingPair::default()
        };
        assert_eq!(p.validate().unwrap_err().field, "bearing.inner_conformity");
        let p = BearingPair {
            balls_per_row: 2,
            ..BearingPair::default()
        };
        assert_eq!(p.validate().unwrap_err().field, "bearing.balls_per_row");
    }

    #[test]
    fn every_field_has_a_range_and_the_messages_name_the_dotted_field() {
        let d = BearingPair::default();
        let rows = BearingPair {
            rows: 0,
            ..d.clone()
        }
        .validate()
        .unwrap_err();
        assert_eq!(rows.to_string(), "invalid bearing.rows = 0: allowed [1, 8]");
        // Ratings that make the damage infinite are refused.
        for (p, field) in [
            (
                BearingPair {
                    dynamic_rating_n: 1e-300,
                    ..d.clone()
                },
                "bearing.dynamic_rating_n",
            ),
            (
                BearingPair {
                    static_rating_n: 1e300,
                    ..d.clone()
                },
                "bearing.static_rating_n",
            ),
            (
                BearingPair {
                    static_limit_pressure_pa: 1.0,
                    ..d.clone()
                },
                "bearing.static_limit_pressure_pa",
            ),
            (
                BearingPair {
                    young_modulus_pa: 1e-300,
                    ..d.clone()
                },
                "bearing.young_modulus_pa",
            ),
            (
                BearingPair {
                    lumped_stiffness_n_per_m1_5: 1e-300,
                    ..d.clone()
                },
                "bearing.lumped_stiffness_n_per_m1_5",
            ),
        ] {
            let e = p.validate().unwrap_err();
            assert_eq!(e.field, field, "{e}");
            assert!(e.to_string().contains("allowed ["), "{e}");
        }
    }

    #[test]
    fn the_ball_and_the_pitch_circle_are_named_together() {
        let d = BearingPair::default();
        let e = BearingPair {
            pitch_diameter_m: 0.001,
            ..d.clone()
        }
        .validate()
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "invalid bearing.pitch_diameter_m = 0.001: allowed > bearing.ball_diameter_m = \
             0.0055 m (the balls' centres lie on the pitch circle)"
        );
    }

    #[test]
    fn the_balls_of_a_row_must_fit_on_the_pitch_circle() {
        let d = BearingPair::default();
        // 22 balls of 50 mm on a 51 mm pitch circle (160 mm round).
        let big = BearingPair {
            ball_diameter_m: 0.05,
            ..d.clone()
        };
        let e = big.validate().unwrap_err();
        assert_eq!(e.field, "bearing.ball_diameter_m", "{e}");
        let text = e.to_string();
        assert!(
            text.contains("= 0.05:")
                && text.contains("pi * 0.051 / 22 = 0.00728 m")
                && text.contains("balls_per_row * ball_diameter_m < pi * pitch_diameter_m"),
            "{text}"
        );
        // 200 balls of 10 mm.
        let many = BearingPair {
            balls_per_row: 200,
            ball_diameter_m: 0.01,
            ..d.clone()
        };
        let e = many.validate().unwrap_err().to_string();
        assert!(e.contains("pi * 0.051 / 200"), "{e}");
        // Just fitting is allowed: 29 balls of 5.5 mm take 159.5 mm of 160.2 mm.
        BearingPair {
            balls_per_row: 29,
            ..d.clone()
        }
        .validate()
        .unwrap();
        let e = BearingPair {
            balls_per_row: 30,
            ..d
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.field, "bearing.ball_diameter_m");
    }

    /// Another geometry with the default pair's ratings takes its formulas' ratings; a rating
    /// of its own (a catalogue's) is kept, and the default pair keeps the defaults.
    #[test]
    fn another_geometry_takes_its_own_ratings_unless_given() {
        let three_rows = BearingPair {
            rows: 3,
            ..BearingPair::default()
        };
        three_rows.validate().unwrap();
        let run = three_rows.clone().with_ratings_of_its_geometry();
        assert_eq!(
            run.dynamic_rating_n,
            three_rows.iso281_dynamic_rating_n().unwrap()
        );
        assert_eq!(run.static_rating_n, three_rows.iso76_static_rating_n());
        assert!(run.dynamic_rating_n > 25_000.0 && run.static_rating_n > 30_000.0);
        let catalogue = BearingPair {
            dynamic_rating_n: 25_000.0,
            ..three_rows
        }
        .with_ratings_of_its_geometry();
        assert_eq!(catalogue.dynamic_rating_n, 25_000.0);
        assert_eq!(
            BearingPair::default().with_ratings_of_its_geometry(),
            BearingPair::default()
        );
        // A conformity ISO 281 does not depend on keeps C; ISO 76's C0 moves.
        let conformity = BearingPair {
            inner_conformity: 0.515,
            ..BearingPair::default()
        }
        .with_ratings_of_its_geometry();
        assert_eq!(conformity.dynamic_rating_n, 19_470.0);
        // Balls beyond ISO 281's formula with the default rating: refused, with the reason.
        let e = BearingPair {
            ball_diameter_m: 0.03,
            pitch_diameter_m: 0.3,
            ..BearingPair::default()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.field, "bearing.dynamic_rating_n");
        assert!(e.to_string().contains("does not cover it"), "{e}");
    }
}
