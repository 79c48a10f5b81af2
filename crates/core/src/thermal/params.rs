//! Every number the thermal model needs beyond the dynamic scene: materials, geometry the paper
//! does not give, convection, lubricant, and the coupling settings. Plain data in SI units,
//! each field documented with unit, default, allowed range and source; validated once.
//!
//! Sources quoted below:
//! - \[ASM\] ASM Handbook Vol. 1, *Properties and Selection: Irons, Steels* (1990): AISI 52100
//!   bearing steel 46.6 W/(m K), 475 J/(kg K), 7810 kg/m^3, 11.9e-6 1/K (20-100 C); carbon and
//!   low-alloy shaft steels (AISI 1045/4140) about 44.5 W/(m K), 475 J/(kg K), 7850 kg/m^3.
//! - \[Harris\] T. A. Harris, M. N. Kotzalas, *Rolling Bearing Analysis*, 5th ed. (2006),
//!   Ch. 15 (friction heat, contact-cage speeds) and App. (steel: E = 208 GPa, nu = 0.3).
//! - \[Incropera\] F. P. Incropera et al., *Fundamentals of Heat and Mass Transfer*, 6th ed.,
//!   Table 1.1 (free convection of gases 2-25 W/(m^2 K), forced 25-250) and Table A.5
//!   (engine oil at 300 K: 0.145 W/(m K), 1909 J/(kg K), 884 kg/m^3).
//! - \[SKF\] SKF rolling bearings catalogue (2018): 71908 CD: d = 40, D = 62, B = 12 mm, contact
//!   angle 15 deg (suffix CD; ACD is 25 deg); grease fill 25-35 % of the free space.
//! - [Table 3] the paper's Table 3 (71908: 40 x 62 x 12 mm, balls 5.5 mm).

use crate::error::InvalidParameter;
use serde::{Deserialize, Serialize};

/// The thermal model's parameters (paper Sec. 3, eqs. 18-31). A scene switches the thermal
/// model on by carrying one of these (`"thermal": {}` takes every default). Beyond each
/// field's range, the heat network they make with the scene must be one the exact step can
/// take ([`crate::thermal::network::Network::check_rates`]).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ThermalParams {
    // ---- coupling ------------------------------------------------------------------------
    /// Macro step of the two-time-scale coupling (s): the dynamics run this long with the
    /// thermal load frozen while their heat is integrated, then the network advances exactly
    /// over it with the averaged heat and the thermal load (eq. 30) is updated. Default 1 ms:
    /// 70 times below the fastest network time constant at the defaults (the inner lubricant
    /// node, about 0.07 s), and about 80 dynamic steps long. Allowed [1e-6, 1] s.
    pub macro_step_s: f64,
    /// Ambient temperature T_inf, also every node's temperature at release (K). Default
    /// 293.15 (20 C). Allowed (0, 2000].
    pub ambient_temperature_k: f64,

    // ---- rotor (shaft) node, eq. 19 ------------------------------------------------------
    /// Thermal conductivity of the rotor lambda_s (W/(m K)). Default 44.5, shaft steel \[ASM\].
    /// Allowed (0, 1e4] W/(m K).
    pub rotor_conductivity_w_m_k: f64,
    /// Specific heat of the rotor C_ps (J/(kg K)). Default 475, steel \[ASM\].
    /// Allowed (0, 1e5] J/(kg K).
    pub rotor_specific_heat_j_kg_k: f64,
    /// Density of the rotor (kg/m^3). Default 7850, steel \[ASM\].
    /// Allowed (0, 1e5] kg/m^3.
    pub rotor_density_kg_m3: f64,
    /// Length L_s of the journal section lumped into the rotor node, also the conduction length
    /// of R_sac in Table 1 (m). Not in the paper: default 50 mm, about four bearing widths of
    /// journal on either side of the touchdown location. Allowed (0, 10].
    pub rotor_node_length_m: f64,
    /// Convection coefficient h_s at the rotor's free end (W/(m^2 K)), R_sav in Table 1.
    /// Default 30: a slowly rotating shaft in still air, between free and forced convection
    /// [Incropera Table 1.1]. Allowed [0, 1e5].
    pub rotor_convection_w_m2_k: f64,

    // ---- bearing steel (races and balls), eqs. 20-24, 26-28 -------------------------------
    /// Conductivity of races and balls lambda_i = lambda_e = lambda_b (W/(m K)). Default 46.6,
    /// AISI 52100 \[ASM\].
    /// Allowed (0, 1e4] W/(m K).
    pub bearing_conductivity_w_m_k: f64,
    /// Specific heat of races and balls (J/(kg K)). Default 475, AISI 52100 \[ASM\].
    /// Allowed (0, 1e5] J/(kg K).
    pub bearing_specific_heat_j_kg_k: f64,
    /// Density of the balls (kg/m^3), for their mass. Default 7810, AISI 52100 \[ASM\].
    /// Allowed (0, 1e5] kg/m^3.
    pub bearing_density_kg_m3: f64,
    /// Linear expansion coefficient xi of races and balls (1/K), eqs. 26-28. Default 11.9e-6,
    /// AISI 52100, 20-100 C \[ASM\].
    pub bearing_expansion_per_k: f64,
    /// Poisson's ratio nu of the races, eqs. 26-27. Default 0.3, bearing steel \[Harris\].
    /// Allowed [0, 0.5).
    pub bearing_poisson_ratio: f64,

    // ---- bearing geometry (Table 3 and catalogue) -----------------------------------------
    /// Bearing width W = B (m). Table 3: 12 mm. The network models one 71908, the bearing the
    /// dynamic model lumps (its race mass, Table 2's 0.048 kg, is one inner race).
    /// Allowed (0, 10] m.
    pub bearing_width_m: f64,
    /// Outer diameter D of the outer race (m). Table 3: 62 mm; r_o = D/2.
    pub outer_diameter_m: f64,
    /// Ball diameter (m). Table 3: 5.5 mm; r_b = half of it. Raceway radii are
    /// r_i = d_m/2 - r_b and r_e = d_m/2 + r_b with d_m the scene's pitch diameter.
    /// Allowed (0, 10] m (and inside the raceways).
    pub ball_diameter_m: f64,
    /// Number of balls z (Table 1's z and n). Not in the paper or the catalogue tables:
    /// default 22, the pitch circle (pi d_m = 160 mm) filled with 5.5 mm balls at the
    /// spacing of caged angular-contact bearings (about 1.3 ball diameters). Allowed [3, 200].
    pub ball_count: u32,
    /// Outer race mass m_o (kg), eq. 24. Not in the paper: default 0.055 kg, the steel annulus
    /// between D = 62 mm and the raceway diameter over B (48 g) plus shoulders, in the
    /// proportion Table 2's inner race (0.048 kg) bears to its own annulus.
    /// Allowed (0, 1e6] kg.
    pub outer_race_mass_kg: f64,
    /// Initial contact angle alpha_0 of eq. 29 (deg). Default 15, the 71908 CD \[SKF\].
    /// Allowed [0, 90).
    pub contact_angle_deg: f64,

    // ---- lubricant nodes, eqs. 21, 23 ------------------------------------------------------
    /// Lubricant conductivity lambda_l (W/(m K)). Default 0.145, mineral oil at 300 K
    /// [Incropera Table A.5].
    /// Allowed (0, 1e4] W/(m K).
    pub lubricant_conductivity_w_m_k: f64,
    /// Lubricant specific heat C_pL (J/(kg K)). Default 1909 [Incropera Table A.5].
    /// Allowed (0, 1e5] J/(kg K).
    pub lubricant_specific_heat_j_kg_k: f64,
    /// Lubricant mass of each lubricant node m_Li = m_Le (kg). Default 1 g: a 30 % grease
    /// fill \[SKF\] of the 71908's free space (about 7 cm^3), split between the two contacts.
    /// Allowed (0, 1e6] kg.
    pub lubricant_mass_kg: f64,
    /// Convection coefficient h_l from the ball set and lubricant to the air (W/(m^2 K)),
    /// R_La in Table 1. Default 20 [Incropera Table 1.1]. Allowed [0, 1e5].
    pub lubricant_convection_w_m2_k: f64,

    // ---- housing node, eqs. 24-25 ----------------------------------------------------------
    /// Housing outer radius r_h (m). Not in the paper: default 50 mm, a steel bush 19 mm thick
    /// around the 62 mm outer race. Allowed (r_o, 10].
    pub housing_outer_radius_m: f64,
    /// Housing length L_h (m). Default 24 mm: the two face-to-face 71908 of one location.
    /// Allowed (0, 10] m.
    pub housing_length_m: f64,
    /// Housing conductivity lambda_h (W/(m K)). Default 44.5, steel \[ASM\].
    /// Allowed (0, 1e4] W/(m K).
    pub housing_conductivity_w_m_k: f64,
    /// Housing specific heat C_ph (J/(kg K)). Default 475, steel \[ASM\].
    /// Allowed (0, 1e5] J/(kg K).
    pub housing_specific_heat_j_kg_k: f64,
    /// Housing density (kg/m^3), for its mass. Default 7850, steel \[ASM\].
    /// Allowed (0, 1e5] kg/m^3.
    pub housing_density_kg_m3: f64,
    /// Convection coefficient h_h of the housing surfaces (W/(m^2 K)), R_hav and R_hrv in
    /// Table 1. Default 10, free convection in air [Incropera Table 1.1]. Allowed [0, 1e5].
    pub housing_convection_w_m2_k: f64,

    // ---- heat partition (eqs. 15-17, 19-24) -------------------------------------------------
    /// Share of the rotor-race rub heat H_s that enters the rotor node (the rest enters the
    /// inner race). Default 0.5, the H_r/2 of eqs. 19-20. Allowed [0, 1].
    pub rub_heat_to_rotor: f64,
    /// Share of each ball-race contact's heat (H_i, H_o) that enters that contact's lubricant
    /// node; the rest is split equally between the race and the balls. Default 1/3. The
    /// printed eqs. 20-24 give race, lubricant and balls H_i/2 each (1.5 H_i in all), which
    /// creates energy; equal thirds are the nearest reading that conserves it. Allowed [0, 1].
    pub contact_heat_to_lubricant: f64,

    // ---- thermally induced load, eqs. 29-31 -------------------------------------------------
    /// Hertzian stiffness k of eq. 30 (N/m^1.5); `null` takes the scene's race-on-balls
    /// stiffness k2 (Table 4, 7.811e9 N/m^1.5), the ball-race contact whose interference
    /// eq. 29 measures.
    pub induced_load_stiffness_n_per_m15: Option<f64>,
    /// Interference of the mounting fit added to eq. 29's thermal interference (m): a tight
    /// fit or preload. Default 0 (the paper's F_th starts at zero). Allowed [0, 1e-3].
    pub fit_interference_m: f64,
}

impl Default for ThermalParams {
    fn default() -> Self {
        Self {
            macro_step_s: 1e-3,
            ambient_temperature_k: 293.15,
            rotor_conductivity_w_m_k: 44.5,
            rotor_specific_heat_j_kg_k: 475.0,
            rotor_density_kg_m3: 7850.0,
            rotor_node_length_m: 0.05,
            rotor_convection_w_m2_k: 30.0,
            bearing_conductivity_w_m_k: 46.6,
            bearing_specific_heat_j_kg_k: 475.0,
            bearing_density_kg_m3: 7810.0,
            bearing_expansion_per_k: 11.9e-6,
            bearing_poisson_ratio: 0.3,
            bearing_width_m: 0.012,
            outer_diameter_m: 0.062,
            ball_diameter_m: 5.5e-3,
            ball_count: 22,
            outer_race_mass_kg: 0.055,
            contact_angle_deg: 15.0,
            lubricant_conductivity_w_m_k: 0.145,
            lubricant_specific_heat_j_kg_k: 1909.0,
            lubricant_mass_kg: 1e-3,
            lubricant_convection_w_m2_k: 20.0,
            housing_outer_radius_m: 0.05,
            housing_length_m: 0.024,
            housing_conductivity_w_m_k: 44.5,
            housing_specific_heat_j_kg_k: 475.0,
            housing_density_kg_m3: 7850.0,
            housing_convection_w_m2_k: 10.0,
            rub_heat_to_rotor: 0.5,
            contact_heat_to_lubricant: 1.0 / 3.0,
            induced_load_stiffness_n_per_m15: None,
            fit_interference_m: 0.0,
        }
    }
}

impl ThermalParams {
    /// Checks every field against its allowed range; the error names the first that fails
    /// as `thermal.<field>`. Geometry that depends on the scene (raceways between the race
    /// bore and the outer diameter) is checked by [`ThermalParams::validate_with`].
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        fn check(field: &str, v: f64, ok: bool, allowed: &str) -> Result<(), InvalidParameter> {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(InvalidParameter::new(
                    &format!("thermal.{field}"),
                    crate::scene::num(v),
                    allowed,
                ))
            }
        }
        let conv = "[0, 1e5] W/(m^2 K)";
        // Upper ends well beyond any material or bearing (diamond conducts about 2e3 W/(m K),
        // hydrogen stores 1.4e4 J/(kg K), osmium weighs 2.3e4 kg/m^3): a value past them is
        // a typing or unit slip, and would make the heat network's rates overflow.
        let conductivity = (1e4, "(0, 1e4] W/(m K)");
        let specific_heat = (1e5, "(0, 1e5] J/(kg K)");
        let density = (1e5, "(0, 1e5] kg/m^3");
        let length = (10.0, "(0, 10] m");
        let mass = (1e6, "(0, 1e6] kg");
        let bounded = [
            (
                "rotor_conductivity_w_m_k",
                self.rotor_conductivity_w_m_k,
                conductivity,
            ),
            (
                "rotor_specific_heat_j_kg_k",
                self.rotor_specific_heat_j_kg_k,
                specific_heat,
            ),
            ("rotor_density_kg_m3", self.rotor_density_kg_m3, density),
            (
                "bearing_conductivity_w_m_k",
                self.bearing_conductivity_w_m_k,
                conductivity,
            ),
            (
                "bearing_specific_heat_j_kg_k",
                self.bearing_specific_heat_j_kg_k,
                specific_heat,
            ),
            ("bearing_density_kg_m3", self.bearing_density_kg_m3, density),
            ("bearing_width_m", self.bearing_width_m, length),
            ("ball_diameter_m", self.ball_diameter_m, length),
            ("outer_race_mass_kg", self.outer_race_mass_kg, mass),
            (
                "lubricant_conductivity_w_m_k",
                self.lubricant_conductivity_w_m_k,
                conductivity,
            ),
            (
                "lubricant_specific_heat_j_kg_k",
                self.lubricant_specific_heat_j_kg_k,
                specific_heat,
            ),
            ("lubricant_mass_kg", self.lubricant_mass_kg, mass),
            ("housing_length_m", self.housing_length_m, length),
            (
                "housing_conductivity_w_m_k",
                self.housing_conductivity_w_m_k,
                conductivity,
            ),
            (
                "housing_specific_heat_j_kg_k",
                self.housing_specific_heat_j_kg_k,
                specific_heat,
            ),
            ("housing_density_kg_m3", self.housing_density_kg_m3, density),
        ];
        for (name, v, (max, allowed)) in bounded {
            check(name, v, v > 0.0 && v <= max, allowed)?;
        }
        check(
            "macro_step_s",
            self.macro_step_s,
            (1e-6..=1.0).contains(&self.macro_step_s),
            "[1e-6, 1] s",
        )?;
        check(
            "ambient_temperature_k",
            self.ambient_temperature_k,
            self.ambient_temperature_k > 0.0 && self.ambient_temperature_k <= 2000.0,
            "(0, 2000] K",
        )?;
        check(
            "rotor_node_length_m",
            self.rotor_node_length_m,
            self.rotor_node_length_m > 0.0 && self.rotor_node_length_m <= 10.0,
            "(0, 10] m",
        )?;
        for (name, v) in [
            ("rotor_convection_w_m2_k", self.rotor_convection_w_m2_k),
            (
                "lubricant_convection_w_m2_k",
                self.lubricant_convection_w_m2_k,
            ),
            ("housing_convection_w_m2_k", self.housing_convection_w_m2_k),
        ] {
            check(name, v, (0.0..=1e5).contains(&v), conv)?;
        }
        check(
            "bearing_expansion_per_k",
            self.bearing_expansion_per_k,
            (0.0..=1e-3).contains(&self.bearing_expansion_per_k),
            "[0, 1e-3] 1/K",
        )?;
        check(
            "bearing_poisson_ratio",
            self.bearing_poisson_ratio,
            (0.0..0.5).contains(&self.bearing_poisson_ratio),
            "[0, 0.5)",
        )?;
        if !(3..=200).contains(&self.ball_count) {
            return Err(InvalidParameter::new(
                "thermal.ball_count",
                self.ball_count,
                "[3, 200]",
            ));
        }
        check(
            "contact_angle_deg",
            self.contact_angle_deg,
            (0.0..90.0).contains(&self.contact_angle_deg),
            "[0, 90) deg",
        )?;
        check(
            "housing_outer_radius_m",
            self.housing_outer_radius_m,
            self.housing_outer_radius_m > 0.5 * self.outer_diameter_m
                && self.housing_outer_radius_m <= 10.0,
            &format!(
                "(outer_diameter_m / 2, 10] m = ({}, 10] m",
                crate::scene::approx(0.5 * self.outer_diameter_m)
            ),
        )?;
        check(
            "outer_diameter_m",
            self.outer_diameter_m,
            self.outer_diameter_m > 0.0,
            "> 0 and finite (and below 2 * housing_outer_radius_m)",
        )?;
        for (name, v) in [
            ("rub_heat_to_rotor", self.rub_heat_to_rotor),
            ("contact_heat_to_lubricant", self.contact_heat_to_lubricant),
        ] {
            check(name, v, (0.0..=1.0).contains(&v), "[0, 1]")?;
        }
        if let Some(k) = self.induced_load_stiffness_n_per_m15 {
            check(
                "induced_load_stiffness_n_per_m15",
                k,
                k > 0.0,
                "> 0 and finite (or null for the scene's support stiffness)",
            )?;
        }
        check(
            "fit_interference_m",
            self.fit_interference_m,
            (0.0..=1e-3).contains(&self.fit_interference_m),
            "[0, 1e-3] m",
        )?;
        Ok(())
    }

    /// [`ThermalParams::validate`] plus the checks that need the scene's geometry: the inner
    /// raceway `d_m/2 - r_b` must lie outside the race bore, the outer raceway `d_m/2 + r_b`
    /// inside the outer radius, and the lubricant films of Table 1 must have positive area.
    pub fn validate_with(
        &self,
        race_bore_radius_m: f64,
        pitch_diameter_m: f64,
    ) -> Result<(), InvalidParameter> {
        self.validate()?;
        let r_b = 0.5 * self.ball_diameter_m;
        let r_i = 0.5 * pitch_diameter_m - r_b;
        let r_e = 0.5 * pitch_diameter_m + r_b;
        if !(r_i > race_bore_radius_m) {
            return Err(InvalidParameter::new(
                "thermal.ball_diameter_m",
                self.ball_diameter_m,
                &format!(
                    "< pitch_diameter_m - 2 * race bore radius = {} - 2 * {} = {} m (the inner \
                     raceway must lie outside the bore)",
                    crate::scene::num(pitch_diameter_m),
                    crate::scene::num(race_bore_radius_m),
                    crate::scene::approx(pitch_diameter_m - 2.0 * race_bore_radius_m)
                ),
            ));
        }
        if !(r_e < 0.5 * self.outer_diameter_m) {
            return Err(InvalidParameter::new(
                "thermal.outer_diameter_m",
                self.outer_diameter_m,
                &format!(
                    "> pitch_diameter_m + thermal.ball_diameter_m = {} + {} = {} m (outside the \
                     outer raceway; set thermal.outer_diameter_m with a new pitch_diameter_m)",
                    crate::scene::num(pitch_diameter_m),
                    crate::scene::num(self.ball_diameter_m),
                    crate::scene::approx(2.0 * r_e)
                ),
            ));
        }
        let z = self.ball_count as f64;
        let film_i = 2.0 * std::f64::consts::PI * r_i * self.bearing_width_m
            - z * std::f64::consts::PI * r_b * r_b;
        if !(film_i > 0.0) {
            return Err(InvalidParameter::new(
                "thermal.ball_count",
                self.ball_count,
                "small enough that the inner lubricant film of Table 1 (2 pi r_i W - z pi r_b^2) is positive",
            ));
        }
        Ok(())
    }
}
