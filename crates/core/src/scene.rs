//! Every parameter of a drop: plain data in SI units, documented field by field with unit,
//! default, allowed range and source, validated once at the boundary.
//!
//! The default scene is the paper's: its Tables 2-4 plus the defaults of
//! docs/model.md#default-scene (`Scene::paper()`); catalogue units (N/mm^1.5, cSt, N mm) are
//! converted here and in [`crate::model::drag`], nowhere else.

use crate::bearing::BearingPair;
use crate::classify::ClassifyParams;
use crate::error::InvalidParameter;
use crate::thermal::ThermalParams;
use serde::{Deserialize, Serialize};

/// How friction at the rotor-race contact is modelled.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum FrictionLaw {
    /// The paper's law: Coulomb slip (eq. 8) with the stick/slip switch of eqs. 9-10, located
    /// as events. While sticking the rolling constraint holds exactly.
    Switched,
    /// `F_t = mu_d F_n tanh(v_rel / v_eps_m_s)`: a cheaper approximation with no stick mode.
    /// Its error against `switched` is measured, not assumed (docs/accuracy.md).
    Regularised {
        /// Slip velocity scale of the tanh (m/s), in (0, 10].
        v_eps_m_s: f64,
    },
}

/// The Runge-Kutta pair a drop is integrated with.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Dormand-Prince 5(4) with 4th-order dense output: the pair of the `reference`
    /// fidelity.
    Dopri5,
    /// Hairer's DOP853, 8(5,3) with 7th-order dense output: the independent reference of
    /// `whirlmap accuracy` (see `ode/dop853.rs` for why it is hand-written).
    Dop853,
    /// ROS34PW2, a linearly implicit Rosenbrock-W method of order 3 (Rang and Angermann
    /// 2005) with an analytic stiff Jacobian: its step is not bounded by the light race's
    /// contact mode (`ode/rosw.rs`). Was the `draft` fidelity's, until RODAS4 at the same
    /// tolerances measured fifty times closer to `reference` for 1.19 times the RHS
    /// evaluations and about the same time (docs/accuracy.md#why-draft-is-rodas4-then-bdf).
    Ros34pw2,
    /// RODAS4, a Rosenbrock method of order 4 (Hairer and Wanner) on the full Jacobian and
    /// the factors of ROS34PW2 (`ode/rodas.rs`): the `draft` fidelity's at rtol 1e-4 until
    /// 2026-11-29, and the `standard` fidelity's (the scene default) until model version 11.
    Rodas4,
    /// Rodas5P, a Rosenbrock method of order 5 (Steinebach 2023) on the full Jacobian and
    /// the factors of RODAS4 (`ode/rodas5p.rs`).
    Rodas5p,
    /// RADAU5, the 3-stage Radau IIA collocation method of order 5 (Hairer and Wanner) on
    /// the full Jacobian, with a simplified Newton iteration (`ode/radau5.rs`).
    Radau5,
    /// BDF, the backward differentiation formulas of orders 1 to `bdf_max_order` (4 by
    /// default, at most 5) with variable order and quasi-constant step size (Shampine and
    /// Reichelt's scheme), on the full Jacobian with
    /// Newton's iteration from the Jacobian at each step's prediction (`ode/bdf.rs`). Alone
    /// it restarts at order 1 after every mode switch.
    Bdf,
    /// RODAS4 after every mode switch, the BDF once the contact has carried for 12 steps and
    /// 2 ms (`ode/rodas_bdf.rs`): RODAS4 takes the impacts, the BDF the rolling and the whirl.
    /// The `standard` fidelity's (the scene default) since model version 12.
    #[default]
    Rodas4Bdf,
    /// As `rodas4_bdf`, with the NDF (Klopfenstein's numerical differentiation formulas, as
    /// `ode15s` and SciPy's `BDF` have them) in place of the BDF: at orders 1-4 a smaller
    /// error constant, so longer steps at the same tolerance, for smaller stability angles at
    /// orders 3 and 4.
    /// On the 1 s pendulum drop 0.90 of `rodas4_bdf`'s instructions, with the same class and
    /// forces on the accuracy study's cases (docs/performance.md#the-ndf-measured).
    Rodas4Ndf,
}

impl Method {
    /// Whether the stepper is a Rosenbrock method, whose order needs the model's exact
    /// Jacobian (every term: the energy integrals' rows, the sticking constraint's slopes, the
    /// drag's), rather than a W-method's stiff approximation or none.
    pub fn needs_exact_jacobian(self) -> bool {
        matches!(
            self,
            Method::Rodas4
                | Method::Rodas5p
                | Method::Radau5
                | Method::Bdf
                | Method::Rodas4Bdf
                | Method::Rodas4Ndf
        )
    }

    /// Whether the stepper takes multistep (BDF or NDF) steps, whose highest order is
    /// `solver.bdf_max_order`.
    pub fn is_multistep(self) -> bool {
        matches!(self, Method::Bdf | Method::Rodas4Bdf | Method::Rodas4Ndf)
    }
}

/// How the race-on-balls damper c2 of Table 4 acts on the race's velocity.
///
/// The lumped support stands for a ball set. Its stiffness is isotropic already (the Hertz
/// law along the displacement is an isotropic potential). Each ball's contact damper acts
/// along its own line; summed over a half-loaded zone the set's damping matrix is
/// `c diag(sum cos^2 psi, sum sin^2 psi)`, equal terms, so a ball set damps the race's
/// tangential motion as much as its radial motion.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SupportDamper {
    /// `c2` on the race's whole velocity (damping matrix `c2 I`): the ball-set argument above.
    /// The default from `MODEL_VERSION` 3.
    #[default]
    Isotropic,
    /// `c2` on the race's radial rate only: eq. 7 read literally for the support, the law
    /// the paper prints. The race's tangential vibration on its support (about 2.85 kHz) is
    /// then undamped and re-excited at every friction switch, so forces move with the
    /// solver tolerance and near-boundary classes flip.
    RadialOnly,
}

/// Integrator settings that change results (so they are part of the scene and its hash).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverSettings {
    /// Relative tolerance. Default 3e-5 (the `standard` fidelity: forces and peak heat power
    /// within 0.1 % of the reference, whirl frequency within 1 %;
    /// docs/accuracy.md#fidelity-presets). Allowed (0, 1e-2].
    pub rtol: f64,
    /// Position scale for the absolute tolerance (m): `atol = rtol * position_scale_m` on
    /// displacements. Default 1e-6 m, so a 1 um penetration is resolved to `rtol`.
    pub position_scale_m: f64,
    /// Largest step in free flight (s), so no contact is stepped over. Default 2e-5 s, a
    /// fraction of the shortest race bounce (about 60 us at the default contact stiffness).
    pub free_flight_max_step_s: f64,
    /// Smallest step before a typed underflow error (s). Default 1e-13 s.
    pub min_step_s: f64,
    /// Step attempts before a typed budget error. Default 20 000 000.
    pub max_step_attempts: u64,
    /// Located mode switches before a typed budget error (chatter guard). Default 2 000 000.
    pub max_events: u64,
    /// The integrator. Default `rodas4_bdf` (the `standard` and `draft` fidelities'): RODAS4
    /// after each mode switch, which takes the impacts, and the variable-order BDF once the
    /// contact has run smoothly for 2 ms (docs/model.md#integrator); `rodas4`, the 4th-order
    /// Rosenbrock method on the model's full Jacobian, whose step is not bounded by the light
    /// race's contact modes (the `draft` fidelity's until 2026-11-29, and the default until
    /// model version 11);
    /// `bdf`, the BDF alone; `rodas4_ndf`, RODAS4 then the NDF (ode15s's formulas) in place
    /// of the BDF (docs/performance.md#the-ndf-measured); `dopri5`, the explicit
    /// Dormand-Prince 5(4) pair (the `reference` fidelity's);
    /// `ros34pw2`, the 3rd-order Rosenbrock-W method; `dop853` the independent reference of
    /// `whirlmap accuracy`; `rodas5p`, the 5th-order Rosenbrock method on RODAS4's Jacobian,
    /// for errors below about 1e-5 (docs/accuracy.md); `radau5`, the 5th-order Radau IIA
    /// collocation method on the same Jacobian, about half of RODAS4's steps on a pendulum
    /// drop at a higher cost per step (docs/performance.md).
    pub method: Method,
    /// In free flight, let the step exceed `free_flight_max_step_s` up to a quarter of a
    /// lower bound on the time until the contact can close (gap, relative speed, and a
    /// bound on the relative acceleration). Default true (the `standard` and `draft`
    /// fidelities'; false in `reference`).
    pub free_flight_gap_bound: bool,
    /// Factor on the absolute tolerances of the race's translation (its centre's position
    /// and velocity). The race centre is a fast variable held by two stiff springs (its own
    /// modes at 3-16 kHz): with its support damped in every direction
    /// (`support_damper = isotropic`, the default) and an L-stable stepper (`rodas4`) its
    /// local errors decay instead of accumulating, and the rotor's absolute tolerances
    /// (`rtol * position_scale_m` on positions, `rtol * sqrt(2 g s) / 100` on velocities)
    /// would bound the implicit step in contact. Default 1 (the `standard` and `reference`
    /// fidelities: `standard` widens only the race's velocity, from the contact force, see
    /// `race_velocity_atol_from_force`); 1000 in `draft`. What a factor costs in accuracy is
    /// measured by `whirlmap accuracy` (docs/accuracy.md#the-races-absolute-tolerance).
    /// Allowed [1, 1e4].
    pub race_atol_scale: f64,
    /// While the rotor-race contact carries load, widen the absolute tolerance of the race's
    /// velocity (never narrow it) to `rtol F_n / max(c1, c2)`: the race's velocity enters the
    /// normal contact force only through the contact damper's term `c1 delta_dot` of eq. 7,
    /// and the support force through `c2`, so an error of that size moves either damper's
    /// force by at most `rtol F_n` in one step, and the tolerance tightens again as the force
    /// falls towards a lift-off. The race's velocity is a fast variable there, whose error in
    /// an L-stable step spanning its modes would otherwise set the step. Not applied with the
    /// `radial_only` support damper (which leaves the race's tangential vibration undamped)
    /// or without damping (`c1` or `c2` zero). Default true (the `standard` fidelity); false
    /// in `draft` and `reference` (docs/accuracy.md#the-races-velocity-tolerance-in-contact).
    pub race_velocity_atol_from_force: bool,
    /// The highest order of the multistep method of `rodas4_bdf`, `rodas4_ndf` and `bdf`
    /// (unused by the other methods). Orders 3 to 5 are not A-stable: each is unstable on a
    /// bounded region of the left half-plane beside the imaginary axis. Rolling in the race,
    /// the rotor and race have lightly damped modes (about 0.3, 1.9 and 15 kHz, damping
    /// ratios 3 to 30 %) on which order 5 is unstable over almost every step size, so its
    /// steps are short and often rejected; at order 4 the 1 s pendulum drop takes 0.72 of
    /// the steps (docs/performance.md#the-bdfs-highest-order). Default 4 (the `standard`
    /// fidelity's, from model version 13); 5 is model version 12's stepper. Allowed [1, 5],
    /// a whole number.
    pub bdf_max_order: u32,
}

// Exact comparison on purpose: only the default is left out of the JSON.

impl Default for SolverSettings {
    /// The `standard` fidelity ([`crate::Fidelity::Standard`]): RODAS4 then BDF at rtol 3e-5
    /// with the free-flight gap bound and the race's velocity tolerance widened from the
    /// contact force (every other tolerance the rotor's), within the accuracy budget with both
    /// its tolerance neighbours within it too, on the main job's grid and on cases with long
    /// bouncing sequences (docs/accuracy.md#fidelity-presets).
    fn default() -> Self {
        Self {
            rtol: 3e-5,
            position_scale_m: 1e-6,
            free_flight_max_step_s: 2e-5,
            min_step_s: 1e-13,
            max_step_attempts: 20_000_000,
            max_events: 2_000_000,
            method: Method::Rodas4Bdf,
            free_flight_gap_bound: true,
            race_atol_scale: 1.0,
            race_velocity_atol_from_force: true,
            bdf_max_order: 4,
        }
    }
}

/// One rotor, one touchdown location, one release. All fields SI unless the name says
/// otherwise. `Scene::default()` is [`Scene::paper`].
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scene {
    // ---- operating point -------------------------------------------------------------
    /// Rotor spin at release (r/min); the sign is the spin direction (counter-clockwise
    /// positive). Default 8000 (Fig. 3). Allowed |speed| <= 1e6.
    pub speed_rpm: f64,
    /// Dynamic (sliding) friction coefficient rotor-race, eq. 8. Default 0.1. Allowed [0, 2].
    pub mu_dynamic: f64,
    /// Static friction coefficient of eq. 10; `null` means equal to `mu_dynamic` (the paper
    /// gives none). Allowed [mu_dynamic, 2].
    pub mu_static: Option<f64>,
    /// Friction law. Default `switched` (the paper's).
    pub friction_law: FrictionLaw,
    /// Gravitational acceleration (m/s^2), acting in -y. Default 9.81. Allowed [0, 1000].
    pub gravity_m_s2: f64,

    // ---- rotor (Table 2) -------------------------------------------------------------
    /// Whole rotor mass (kg). Table 2: 11.5. Allowed [1e-3, 1e6].
    pub rotor_mass_kg: f64,
    /// Whole rotor polar moment of inertia about its mass centre (kg m^2). Table 2: 5.806e-3.
    /// Allowed: a radius of gyration sqrt(J / m) within [0.01, 100] journal radii
    /// ([`Scene::validate_consistency`]).
    pub rotor_polar_moi_kg_m2: f64,
    /// Share of the rotor carried by this touchdown location (two locations, one at each
    /// end, so 0.5; docs/model.md#load-share). Mass and inertia in the equations are scaled
    /// by it. Allowed (0, 1].
    pub load_share: f64,
    /// Rotor journal diameter at the touchdown bearing (m). Table 2: 39.7 mm. Lever arm of
    /// the rotor's friction torque is half of it (eq. 3's r).
    pub rotor_diameter_m: f64,
    /// Mass unbalance eccentricity e of eqs. 1-3 (m). Not given by the paper: default 0.
    /// Allowed [0, clearance_m * 10].
    pub unbalance_m: f64,
    /// Angle of the unbalance at release, from +x, counter-clockwise (rad). Default 0.
    pub unbalance_phase_rad: f64,

    // ---- release state (what a real drop does not control; docs/model.md#release-state) ---
    // Optional: left out of the JSON (and so of the scene hash) while at their defaults, so
    // scenes without them keep their hash and records. See [`Scene::OPTIONAL_FIELDS`].
    /// Rotor geometric centre at release, relative to the housing (race) centre (m).
    /// Default [0, 0] (released at the centre, docs/model.md#release-state). Allowed:
    /// magnitude at most 0.9 * clearance_m, so the release is clear of the race.
    #[serde(skip_serializing_if = "is_zero2")]
    pub release_offset_m: [f64; 2],
    /// Rotor geometric centre velocity at release (m/s), e.g. the AMB orbit's. Default
    /// [0, 0]. Allowed: magnitude at most 100 m/s.
    #[serde(skip_serializing_if = "is_zero2")]
    pub release_velocity_m_s: [f64; 2],
    /// Inner race spin at release (rad/s), counter-clockwise positive. Default 0 (at rest).
    /// Allowed |value| <= 1e5 rad/s.
    #[serde(skip_serializing_if = "is_zero")]
    pub race_speed_rad_s: f64,

    // ---- inner race (Tables 2, 4) ------------------------------------------------------
    /// Inner race mass (kg). Table 2: 0.048. Allowed [1e-5, 1e6].
    pub race_mass_kg: f64,
    /// Inner race polar moment of inertia (kg m^2). Table 2: 2.33e-5. Allowed: a radius of
    /// gyration within [0.01, 100] race bore radii.
    pub race_polar_moi_kg_m2: f64,
    /// Radial clearance between rotor and race bore, s (m). Table 4: 0.15 mm. The race bore
    /// radius is `rotor_diameter_m / 2 + clearance_m` (docs/model.md#lever-arms). Allowed
    /// (0, 0.1].
    pub clearance_m: f64,

    // ---- contacts (Table 4, eq. 7) ------------------------------------------------------
    /// Rotor-race Hertz stiffness k1 (N/m^e). Table 4: 1.988e9 N m^-10/9. Allowed: a force
    /// at 1 um penetration, k1 (1e-6 m)^e, in [1e-2, 1e10] N (Table 4's: 428 N), which also
    /// catches a stiffness kept when the exponent changes ([`Scene::validate_consistency`]).
    pub contact_stiffness_n_per_m_e: f64,
    /// Rotor-race Hertz exponent e of eq. 7. Line contact: 10/9. Allowed [1, 2].
    pub contact_exponent: f64,
    /// Rotor-race contact damping c1 (N s/m). Table 4: 1000. Allowed [0, 1e8].
    pub contact_damping_n_s_per_m: f64,
    /// Race-on-balls lumped radial stiffness k2 (N/m^e). Table 4: 2.47e5 N/mm^1.5 =
    /// 7.811e9 N/m^1.5 (converted here). Zero internal clearance, isotropic
    /// (docs/model.md#ball-support). Allowed: a force at 1 um penetration, k2 (1e-6 m)^e, in
    /// [1e-3, 1e10] N (Table 4's: 7.8 N; 2.47e5 read as N/m^1.5 gives 2.5e-4 N and is
    /// refused).
    pub support_stiffness_n_per_m_e: f64,
    /// Race-on-balls Hertz exponent. Point contact: 3/2. Allowed [1, 2].
    pub support_exponent: f64,
    /// Race-on-balls damping c2 (N s/m). Table 4: 750. Allowed [0, 1e8].
    pub support_damping_n_s_per_m: f64,
    /// How the support damper c2 acts on the race ([`SupportDamper`]). Default
    /// `isotropic` (from `MODEL_VERSION` 3): a ball set damps the race in every direction.
    /// `radial_only` is eq. 7 read literally for the support (the paper's law), which leaves
    /// the race's tangential vibration on its support (about 2.85 kHz) undamped.
    pub support_damper: SupportDamper,

    // ---- Palmgren drag of the touchdown bearing (eqs. 11-13) ------------------------------
    /// Drag torque on the race switched on. Default true.
    pub drag_enabled: bool,
    /// Palmgren f0 (bearing type and lubrication). Default 2 (single-row angular contact,
    /// grease; catalogues give about 1.7 oil mist, 3.3 oil bath, 6.6 oil jet). Allowed [0, 20].
    pub palmgren_f0: f64,
    /// Lubricant kinematic viscosity nu0 (mm^2/s = cSt). Default 22. Allowed [0, 10000].
    pub lubricant_viscosity_mm2_s: f64,
    /// Bearing pitch diameter d_m (m). Default (40 + 62)/2 mm = 51 mm (Table 3). Allowed:
    /// larger than the race bore diameter `rotor_diameter_m + 2 clearance_m`, at most 10 m.
    pub pitch_diameter_m: f64,
    /// Basic static load rating C0 of the bearing (N) in f1 = 0.001 (P0/C0)^0.33. Default
    /// 10 000 N, the order of a 71908 catalogue entry
    /// (docs/model.md#static-load-rating-c0). Allowed [1, 1e8].
    pub static_load_rating_n: f64,
    /// Race speed below which the drag torque is scaled by tanh(omega / this) so it has a
    /// defined, chatter-free value at zero speed (rad/s). Default 0.1 (about 1 r/min).
    pub drag_zero_speed_rad_s: f64,

    // ---- run control ---------------------------------------------------------------------
    /// Consecutive turns of the contact point in one direction, each made with the contact
    /// carried (duty of at least `classification.min_duty` within the turn), after which a
    /// run is stopped as decided whirl: backward whirl grows without bound in a rigid
    /// housing, so a whirl run needs a stopping rule. Turns made before the rotor settles
    /// (a transient whirl that dies out) do not count. Default 5. Allowed [1, 1e6], a whole
    /// number.
    pub whirl_stop_turns: f64,
    /// How a drop's orbit is classified and how long an undecided run is extended
    /// ([`ClassifyParams`]).
    pub classification: ClassifyParams,
    /// Integrator settings.
    pub solver: SolverSettings,

    // ---- reduced models (each default off, and then left out of the JSON) ----------------
    /// Reduced model: the race's *translation* is massless (quasi-static). The race centre
    /// then follows from the force balance between the rotor contact and the ball support
    /// (two Hertz springs in series, see `model/quasi_static.rs`); its rotation keeps its
    /// inertia. This removes the stiff light-race mode (about 16 kHz) that limits the step of
    /// an explicit integrator. Its accuracy cost is measured by `whirlmap accuracy`.
    /// Default false (the paper's model). Omitted from the canonical JSON while false.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub quasi_static_race: bool,
    /// Stop the run once the rotor spin |omega_r| falls below this (r/min): the end of a
    /// coast-down. `null` (default, and left out of the scene's JSON so existing scene hashes
    /// stay as they were): run to the duration. Allowed [0, 1e6] and below the release speed
    /// |speed_rpm| ([`Scene::validate_consistency`]): a run released at or below it would
    /// stop before its first step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_speed_rpm: Option<f64>,
    /// The thermal model (paper Sec. 3, eqs. 14-31); `null` (default, left out of the JSON):
    /// no temperatures, no thermal states, no thermal cost. `{}` takes every default of
    /// [`ThermalParams`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal: Option<ThermalParams>,
    /// The touchdown bearing analysis (ball loads, contact pressure against the static
    /// limit, fatigue damage per drop; [`crate::bearing`]): `null` (default, left out of the
    /// JSON) for none. It reads the race's motion as the drop runs and does not change the
    /// dynamics. `{}` takes the paper's pair (two 71908 CD face to face); its lumped
    /// stiffness is the scene's `support_stiffness_n_per_m_e` when `support_exponent` is 1.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bearing: Option<BearingPair>,
}

impl Default for Scene {
    fn default() -> Self {
        Self::paper()
    }
}

/// Allowed rotor mass (kg): a gram to a thousand tonnes (beyond any rotor, but the
/// physics tests model a rigid wall as a 1e6 kg race).
pub const MASS_RANGE_KG: [f64; 2] = [1e-3, 1e6];
/// Allowed inner race mass (kg).
pub const RACE_MASS_RANGE_KG: [f64; 2] = [1e-5, 1e6];
/// Allowed radius of gyration of each body, as multiples of its radius at the contact (see
/// [`Scene::validate_consistency`]).
pub const GYRATION_RANGE: [f64; 2] = [0.01, 100.0];
/// Allowed rotor-race contact force at 1 um penetration, k1 (1e-6 m)^e1 (N).
pub const CONTACT_FORCE_AT_1UM_N: [f64; 2] = [1e-2, 1e10];
/// Allowed race-on-balls support force at 1 um penetration, k2 (1e-6 m)^e2 (N).
pub const SUPPORT_FORCE_AT_1UM_N: [f64; 2] = [1e-3, 1e10];
/// Largest contact or support damping coefficient (N s/m): 1e5 times Table 4's.
pub const MAX_DAMPING_N_S_PER_M: f64 = 1e8;

/// A number as a person would write it in a message: `1e308` and `1e-300` rather than 309
/// A field's own range check: `Ok` when `v` is finite and `ok`, otherwise the error naming
/// `field`, the value (as [`num`] writes it) and `allowed`.
pub(crate) fn check_field(
    field: &str,
    v: f64,
    ok: bool,
    allowed: &str,
) -> Result<(), InvalidParameter> {
    if v.is_finite() && ok {
        Ok(())
    } else {
        Err(InvalidParameter::new(field, num(v), allowed))
    }
}
/// digits, `0.15` as is.
pub fn num(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e7).contains(&a) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// A derived number for a message, to three significant digits (`45.3`, `4.53e-7`): the
/// bounds and values a check computes, as opposed to [`num`]'s exact echo of an input.
pub(crate) fn approx(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        return v.to_string();
    }
    if (1e-3..1e5).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        let text = format!("{v:.decimals$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        format!("{v:.2e}")
    }
}

/// 2.47e5 N/mm^1.5 in N/m^1.5: 1 N/mm^1.5 = 1000^1.5 N/m^1.5.
const K2_TABLE4_N_PER_M15: f64 = 2.47e5 * 31_622.776_601_683_792;

// Exact comparisons on purpose: only the default (zero) is left out of the JSON.
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}
fn is_zero2(v: &[f64; 2]) -> bool {
    is_zero(&v[0]) && is_zero(&v[1])
}

/// The paper's scene with every field a scene file accepts (see [`Scene::paper_every_field`]).
#[derive(Serialize)]
struct EveryField<'a> {
    #[serde(flatten)]
    scene: &'a Scene,
    release_offset_m: [f64; 2],
    release_velocity_m_s: [f64; 2],
    race_speed_rad_s: f64,
    quasi_static_race: bool,
    stop_speed_rpm: Option<f64>,
    thermal: Option<ThermalParams>,
    bearing: Option<BearingPair>,
}

impl Scene {
    /// The paper's scene as pretty JSON with every field a scene file accepts, as
    /// `whirlmap scene` prints it: the fields a scene may leave out (at their defaults) follow
    /// the rest; with `sections`, the optional thermal model and bearing analysis at their
    /// defaults too (`null` otherwise: off).
    pub fn paper_every_field(sections: bool) -> String {
        let paper = Scene::paper();
        let full = EveryField {
            scene: &paper,
            release_offset_m: paper.release_offset_m,
            release_velocity_m_s: paper.release_velocity_m_s,
            race_speed_rad_s: paper.race_speed_rad_s,
            quasi_static_race: paper.quasi_static_race,
            stop_speed_rpm: paper.stop_speed_rpm,
            thermal: sections.then(ThermalParams::default),
            bearing: sections.then(BearingPair::paper_71908_cd),
        };
        serde_json::to_string_pretty(&full).expect("a scene serialises")
    }
    /// The bearing pair the analysis runs with, if the scene turns it on: the scene's
    /// `bearing`, with its lumped stiffness taken from the support law (k2, eq. 7) when the
    /// support exponent is Hertz's 1.5, so that the ball loads resolve to the force the
    /// dynamics apply, and with ratings left at the default pair's values following its
    /// geometry ([`crate::bearing::BearingPair::with_ratings_of_its_geometry`]).
    pub fn bearing_as_run(&self) -> Option<crate::bearing::BearingPair> {
        let mut pair = self.bearing.clone()?.with_ratings_of_its_geometry();
        if self.support_exponent == 1.5 {
            pair.lumped_stiffness_n_per_m1_5 = self.support_stiffness_n_per_m_e;
        }
        Some(pair)
    }

    /// Fields left out of the serialised scene while at their default (so adding them did
    /// not change existing scene hashes), dotted for nested fields; settable by name all the
    /// same (`--set`). A test checks this is exactly the set of fields the JSON can omit.
    pub const OPTIONAL_FIELDS: &'static [&'static str] = &[
        "release_offset_m",
        "release_velocity_m_s",
        "race_speed_rad_s",
        "quasi_static_race",
        "stop_speed_rpm",
        "thermal",
        "bearing",
    ];

    /// The paper's scene: Tables 2-4 with the defaults of docs/model.md#default-scene,
    /// 8000 r/min, mu 0.1.
    pub fn paper() -> Self {
        Self {
            speed_rpm: 8000.0,
            mu_dynamic: 0.1,
            mu_static: None,
            friction_law: FrictionLaw::Switched,
            gravity_m_s2: 9.81,
            rotor_mass_kg: 11.5,
            rotor_polar_moi_kg_m2: 5.806e-3,
            load_share: 0.5,
            rotor_diameter_m: 39.7e-3,
            unbalance_m: 0.0,
            unbalance_phase_rad: 0.0,
            release_offset_m: [0.0; 2],
            release_velocity_m_s: [0.0; 2],
            race_speed_rad_s: 0.0,
            race_mass_kg: 0.048,
            race_polar_moi_kg_m2: 2.33e-5,
            clearance_m: 0.15e-3,
            contact_stiffness_n_per_m_e: 1.988e9,
            contact_exponent: 10.0 / 9.0,
            contact_damping_n_s_per_m: 1000.0,
            support_stiffness_n_per_m_e: K2_TABLE4_N_PER_M15,
            support_exponent: 1.5,
            support_damping_n_s_per_m: 750.0,
            support_damper: SupportDamper::Isotropic,
            drag_enabled: true,
            palmgren_f0: 2.0,
            lubricant_viscosity_mm2_s: 22.0,
            pitch_diameter_m: 0.051,
            static_load_rating_n: 10_000.0,
            drag_zero_speed_rad_s: 0.1,
            whirl_stop_turns: 5.0,
            classification: ClassifyParams::default(),
            solver: SolverSettings::default(),
            quasi_static_race: false,
            stop_speed_rpm: None,
            thermal: None,
            bearing: None,
        }
    }

    /// The static friction coefficient in force (eq. 10).
    pub fn mu_static(&self) -> f64 {
        self.mu_static.unwrap_or(self.mu_dynamic)
    }
    /// Rotor journal radius r_r (m).
    pub fn rotor_radius_m(&self) -> f64 {
        0.5 * self.rotor_diameter_m
    }
    /// Race bore radius R_b = r_r + s (m).
    pub fn race_bore_radius_m(&self) -> f64 {
        self.rotor_radius_m() + self.clearance_m
    }
    /// Rotor spin at release (rad/s).
    pub fn spin_rad_s(&self) -> f64 {
        self.speed_rpm * std::f64::consts::PI / 30.0
    }

    /// Checks every field against its allowed range, then the fields' consistency with each
    /// other ([`Scene::validate_consistency`]) and the thermal model's; the error names the
    /// first field that fails.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        self.validate_fields()?;
        self.validate_consistency()?;
        if let Some(t) = &self.thermal {
            // The parameters against the geometry, and the heat network they make.
            crate::thermal::ThermalModel::new(self, t)?;
        }
        if let Some(b) = &self.bearing {
            b.validate()?;
            // The pair as the analysis runs it: a rating left at the default follows the
            // geometry and material, and must be in its range too. The error says so, since
            // the user did not write that number.
            if let Some(run) = self.bearing_as_run() {
                run.validate().map_err(|mut e| {
                    let derived = match e.field.as_str() {
                        "bearing.static_rating_n" => Some(("76", run.static_rating_n)),
                        "bearing.dynamic_rating_n" => Some(("281", run.dynamic_rating_n)),
                        _ => None,
                    };
                    if let Some((iso, rating_n)) = derived {
                        e.value = format!(
                            "{} N, the ISO {iso} rating of this geometry and material (the \
                             rating left at its default follows them)",
                            approx(rating_n)
                        );
                        e.allowed = format!(
                            "{}: set {} to the bearing's catalogue rating, or check the \
                             geometry and material (bearing.young_modulus_pa, \
                             bearing.ball_diameter_m, ...)",
                            e.allowed, e.field
                        );
                    }
                    e
                })?;
            }
            // One bearing: the one analysed is the one whose drag the dynamics use (eqs.
            // 11-13 take d_m); a journal larger than the analysed pitch circle went unseen.
            if b.pitch_diameter_m != self.pitch_diameter_m {
                return Err(InvalidParameter::new(
                    "bearing.pitch_diameter_m",
                    num(b.pitch_diameter_m),
                    &format!(
                        "= pitch_diameter_m = {} m, the drag model's pitch diameter of the same \
                         bearing: set both",
                        num(self.pitch_diameter_m)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Checks each field of the scene (not of its thermal model) against its own allowed
    /// range ([`crate::schema::FIELD_RANGES`] lists them).
    pub fn validate_fields(&self) -> Result<(), InvalidParameter> {
        let check = check_field;
        let pos = "> 0 and finite";
        check(
            "speed_rpm",
            self.speed_rpm,
            self.speed_rpm.abs() <= 1e6,
            "[-1e6, 1e6] r/min",
        )?;
        check(
            "mu_dynamic",
            self.mu_dynamic,
            (0.0..=2.0).contains(&self.mu_dynamic),
            "[0, 2]",
        )?;
        if let Some(ms) = self.mu_static {
            check(
                "mu_static",
                ms,
                ms >= self.mu_dynamic && ms <= 2.0,
                &format!(
                    "[mu_dynamic, 2] with mu_dynamic = {} here (or null for mu_dynamic)",
                    num(self.mu_dynamic)
                ),
            )?;
        }
        if let FrictionLaw::Regularised { v_eps_m_s } = self.friction_law {
            check(
                "friction_law.regularised.v_eps_m_s",
                v_eps_m_s,
                v_eps_m_s > 0.0 && v_eps_m_s <= 10.0,
                "(0, 10] m/s",
            )?;
        }
        check(
            "gravity_m_s2",
            self.gravity_m_s2,
            (0.0..=1000.0).contains(&self.gravity_m_s2),
            "[0, 1000] m/s^2",
        )?;
        check(
            "rotor_mass_kg",
            self.rotor_mass_kg,
            (MASS_RANGE_KG[0]..=MASS_RANGE_KG[1]).contains(&self.rotor_mass_kg),
            "[1e-3, 1e6] kg",
        )?;
        check(
            "rotor_polar_moi_kg_m2",
            self.rotor_polar_moi_kg_m2,
            self.rotor_polar_moi_kg_m2 > 0.0,
            pos,
        )?;
        check(
            "load_share",
            self.load_share,
            self.load_share > 0.0 && self.load_share <= 1.0,
            "(0, 1]",
        )?;
        check(
            "rotor_diameter_m",
            self.rotor_diameter_m,
            self.rotor_diameter_m > 0.0 && self.rotor_diameter_m <= 10.0,
            "(0, 10] m",
        )?;
        check(
            "clearance_m",
            self.clearance_m,
            self.clearance_m > 0.0 && self.clearance_m <= 0.1,
            "(0, 0.1] m",
        )?;
        check(
            "unbalance_m",
            self.unbalance_m,
            // Relative slack of 1e-12: 10 * 1e-6 rounds below 1e-5, which rejected a
            // user's exact "unbalance = 10 clearances" (found by the extremes matrix).
            self.unbalance_m >= 0.0 && self.unbalance_m <= 10.0 * self.clearance_m * (1.0 + 1e-12),
            &format!(
                "[0, 10 * clearance_m] m = [0, {}] m",
                approx(10.0 * self.clearance_m)
            ),
        )?;
        check(
            "unbalance_phase_rad",
            self.unbalance_phase_rad,
            true,
            "finite",
        )?;
        let [ox, oy] = self.release_offset_m;
        check(
            "release_offset_m",
            ox.hypot(oy),
            ox.hypot(oy) <= 0.9 * self.clearance_m,
            &format!(
                "magnitude [0, 0.9 * clearance_m] m = [0, {}] m",
                approx(0.9 * self.clearance_m)
            ),
        )?;
        let [vx, vy] = self.release_velocity_m_s;
        check(
            "release_velocity_m_s",
            vx.hypot(vy),
            vx.hypot(vy) <= 100.0,
            "magnitude [0, 100] m/s",
        )?;
        check(
            "race_speed_rad_s",
            self.race_speed_rad_s,
            self.race_speed_rad_s.abs() <= 1e5,
            "[-1e5, 1e5] rad/s",
        )?;
        check(
            "race_mass_kg",
            self.race_mass_kg,
            (RACE_MASS_RANGE_KG[0]..=RACE_MASS_RANGE_KG[1]).contains(&self.race_mass_kg),
            "[1e-5, 1e6] kg",
        )?;
        check(
            "race_polar_moi_kg_m2",
            self.race_polar_moi_kg_m2,
            self.race_polar_moi_kg_m2 > 0.0,
            pos,
        )?;
        check(
            "contact_stiffness_n_per_m_e",
            self.contact_stiffness_n_per_m_e,
            self.contact_stiffness_n_per_m_e > 0.0,
            pos,
        )?;
        check(
            "contact_exponent",
            self.contact_exponent,
            (1.0..=2.0).contains(&self.contact_exponent),
            "[1, 2]",
        )?;
        check(
            "contact_damping_n_s_per_m",
            self.contact_damping_n_s_per_m,
            (0.0..=MAX_DAMPING_N_S_PER_M).contains(&self.contact_damping_n_s_per_m),
            "[0, 1e8] N s/m",
        )?;
        check(
            "support_stiffness_n_per_m_e",
            self.support_stiffness_n_per_m_e,
            self.support_stiffness_n_per_m_e > 0.0,
            pos,
        )?;
        check(
            "support_exponent",
            self.support_exponent,
            (1.0..=2.0).contains(&self.support_exponent),
            "[1, 2]",
        )?;
        check(
            "support_damping_n_s_per_m",
            self.support_damping_n_s_per_m,
            (0.0..=MAX_DAMPING_N_S_PER_M).contains(&self.support_damping_n_s_per_m),
            "[0, 1e8] N s/m",
        )?;
        check(
            "palmgren_f0",
            self.palmgren_f0,
            (0.0..=20.0).contains(&self.palmgren_f0),
            "[0, 20]",
        )?;
        check(
            "lubricant_viscosity_mm2_s",
            self.lubricant_viscosity_mm2_s,
            (0.0..=10_000.0).contains(&self.lubricant_viscosity_mm2_s),
            "[0, 10000] mm^2/s",
        )?;
        check(
            "pitch_diameter_m",
            self.pitch_diameter_m,
            self.pitch_diameter_m > 0.0 && self.pitch_diameter_m <= 10.0,
            "(0, 10] m",
        )?;
        check(
            "static_load_rating_n",
            self.static_load_rating_n,
            (1.0..=1e8).contains(&self.static_load_rating_n),
            "[1, 1e8] N",
        )?;
        check(
            "drag_zero_speed_rad_s",
            self.drag_zero_speed_rad_s,
            self.drag_zero_speed_rad_s > 0.0,
            pos,
        )?;
        check(
            "whirl_stop_turns",
            self.whirl_stop_turns,
            self.whirl_stop_turns >= 1.0
                && self.whirl_stop_turns <= 1e6
                && self.whirl_stop_turns.fract() == 0.0,
            "[1, 1e6], a whole number (whole turns are counted: 2.5 ran as 3)",
        )?;
        let s = &self.solver;
        check(
            "solver.rtol",
            s.rtol,
            s.rtol > 0.0 && s.rtol <= 1e-2,
            "(0, 1e-2]",
        )?;
        check(
            "solver.position_scale_m",
            s.position_scale_m,
            s.position_scale_m > 0.0,
            pos,
        )?;
        check(
            "solver.free_flight_max_step_s",
            s.free_flight_max_step_s,
            s.free_flight_max_step_s > 0.0,
            pos,
        )?;
        check(
            "solver.min_step_s",
            s.min_step_s,
            s.min_step_s > 0.0 && s.min_step_s < s.free_flight_max_step_s,
            "(0, free_flight_max_step_s)",
        )?;
        check(
            "solver.race_atol_scale",
            s.race_atol_scale,
            (1.0..=1e4).contains(&s.race_atol_scale),
            "[1, 1e4]",
        )?;
        if !(1..=5).contains(&s.bdf_max_order) {
            return Err(InvalidParameter::new(
                "solver.bdf_max_order",
                s.bdf_max_order,
                "[1, 5], a whole number",
            ));
        }
        if s.max_step_attempts == 0 {
            return Err(InvalidParameter::new("solver.max_step_attempts", 0, ">= 1"));
        }
        if s.max_events == 0 {
            return Err(InvalidParameter::new("solver.max_events", 0, ">= 1"));
        }
        self.classification.validate()?;
        if let Some(v) = self.stop_speed_rpm {
            check(
                "stop_speed_rpm",
                v,
                (0.0..=1e6).contains(&v),
                "[0, 1e6] r/min",
            )?;
        }
        Ok(())
    }

    /// Physical consistency between fields, each in range on its own (called by
    /// [`Scene::validate`] after the per-field checks):
    /// - the bearing's pitch diameter lies outside the race bore (`pitch_diameter_m` >
    ///   2 x the race bore radius);
    /// - each body's radius of gyration sqrt(J / m) is between 0.01 and 100 times the radius
    ///   at the touchdown contact (the journal radius for the rotor, the race bore radius for
    ///   the race): Table 2's rotor has 1.13, its race 1.10; a moment of inertia in the wrong
    ///   unit (g cm^2, or per unit length) lands far outside;
    /// - each Hertz stiffness, in N/m^e for its exponent e, gives a force at 1 um of
    ///   penetration, k (1e-6 m)^e, of at least 1e-2 N for the rotor-race contact (Table 4's
    ///   k1 = 1.988e9 N/m^(10/9) gives 428 N) and 1e-3 N for the race on its balls
    ///   (k2 = 7.811e9 N/m^1.5 gives 7.8 N), and at most 1e10 N (a rigid wall, as the physics
    ///   tests model one). The unit of k depends on e: k2 = 2.47e5 N/mm^1.5 read as N/m^1.5
    ///   gives 2.5e-4 N and is refused, as is a stiffness kept when its exponent is changed
    ///   (k1 with e = 2 gives 2e-3 N). (k1 in N/mm^(10/9), 2154 times too small, gives 0.2 N:
    ///   inside the range, which must hold the extremes matrix's k x 1e-3, 0.43 N.)
    /// - the stop speed `stop_speed_rpm`, if set, is below the release speed |speed_rpm|:
    ///   otherwise the run would stop at release, with nothing simulated.
    pub fn validate_consistency(&self) -> Result<(), InvalidParameter> {
        if let Some(stop) = self.stop_speed_rpm {
            if !(stop < self.speed_rpm.abs()) {
                return Err(InvalidParameter::new(
                    "stop_speed_rpm",
                    num(stop),
                    &format!(
                        "[0, |speed_rpm|) r/min, below the release speed |speed_rpm| = {} r/min \
                         (a run released at or below its stop speed stops before it starts)",
                        num(self.speed_rpm.abs())
                    ),
                ));
            }
        }
        let bore_d = 2.0 * self.race_bore_radius_m();
        if !(self.pitch_diameter_m > bore_d) {
            return Err(InvalidParameter::new(
                "pitch_diameter_m",
                num(self.pitch_diameter_m),
                &format!(
                    "> the race bore diameter rotor_diameter_m + 2 clearance_m = {} + 2 * {} = \
                     {} m (the bearing's balls run outside its bore: a smaller clearance_m or \
                     rotor_diameter_m, or a larger pitch_diameter_m)",
                    num(self.rotor_diameter_m),
                    num(self.clearance_m),
                    approx(bore_d)
                ),
            ));
        }
        for (field, moi, mass, mass_field, radius, what) in [
            (
                "rotor_polar_moi_kg_m2",
                self.rotor_polar_moi_kg_m2,
                self.rotor_mass_kg,
                "rotor_mass_kg",
                self.rotor_radius_m(),
                "the journal radius rotor_diameter_m / 2",
            ),
            (
                "race_polar_moi_kg_m2",
                self.race_polar_moi_kg_m2,
                self.race_mass_kg,
                "race_mass_kg",
                self.race_bore_radius_m(),
                "the race bore radius",
            ),
        ] {
            let gyration = (moi / mass).sqrt();
            let [lo, hi] = GYRATION_RANGE;
            if !(gyration >= lo * radius && gyration <= hi * radius) {
                return Err(InvalidParameter::new(
                    field,
                    num(moi),
                    &format!(
                        "a radius of gyration sqrt({field} / {mass_field}) within [{lo}, {hi}] \
                         x {what} ({} m), i.e. [{}, {}] kg m^2 with {mass_field} = {}; here {} m",
                        approx(radius),
                        approx(mass * (lo * radius).powi(2)),
                        approx(mass * (hi * radius).powi(2)),
                        num(mass),
                        approx(gyration)
                    ),
                ));
            }
        }
        for (field, k, e, exp_field, [lo, hi], table) in [
            (
                "contact_stiffness_n_per_m_e",
                self.contact_stiffness_n_per_m_e,
                self.contact_exponent,
                "contact_exponent",
                CONTACT_FORCE_AT_1UM_N,
                "Table 4's k1 = 1.988e9 N/m^(10/9) gives 428 N",
            ),
            (
                "support_stiffness_n_per_m_e",
                self.support_stiffness_n_per_m_e,
                self.support_exponent,
                "support_exponent",
                SUPPORT_FORCE_AT_1UM_N,
                "Table 4's k2 = 7.811e9 N/m^1.5 = 2.47e5 N/mm^1.5 gives 7.8 N",
            ),
        ] {
            let f = k * 1e-6_f64.powf(e);
            if !(f >= lo && f <= hi) {
                return Err(InvalidParameter::new(
                    field,
                    num(k),
                    &format!(
                        "a stiffness in N/m^e ({exp_field} e = {}) whose force at 1 um \
                         penetration, k (1e-6 m)^e, is in [{}, {}] N ({table}); here {} N. A \
                         stiffness in N/mm^e is 1000^e times too small",
                        approx(e),
                        num(lo),
                        num(hi),
                        approx(f)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A stable 64-bit FNV-1a hash of the scene's canonical JSON (field order fixed by the
    /// struct, floats printed shortest-round-trip), as 16 hex digits. Stable across Rust
    /// releases, unlike `std::hash::DefaultHasher`.
    pub fn hash_hex(&self) -> String {
        let text = canonical_json(self);
        format!("{:016x}", fnv1a64(text.as_bytes()))
    }
}

/// Every field of `scene` whose value differs from [`Scene::paper`]'s, by dotted key
/// (`solver.rtol`, `classification.window_s`), as JSON values; the operating point
/// (`speed_rpm`, `mu_dynamic`) is left out, since a record carries it on its own. A nested
/// object the default does not have (`thermal`) or whose kind differs (`friction_law`) is
/// one entry. Keys are sorted, so equal scenes give equal maps.
pub fn scene_changes(scene: &Scene) -> std::collections::BTreeMap<String, serde_json::Value> {
    fn walk(
        prefix: &str,
        now: &serde_json::Value,
        base: Option<&serde_json::Value>,
        out: &mut std::collections::BTreeMap<String, serde_json::Value>,
    ) {
        match (now, base) {
            (serde_json::Value::Object(m), Some(serde_json::Value::Object(b))) => {
                for (k, v) in m {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&key, v, b.get(k), out);
                }
            }
            (v, b) if b != Some(v) => {
                out.insert(prefix.to_string(), v.clone());
            }
            _ => {}
        }
    }
    let now = serde_json::to_value(scene).unwrap_or_default();
    let base = serde_json::to_value(Scene::paper()).unwrap_or_default();
    let mut out = std::collections::BTreeMap::new();
    walk("", &now, Some(&base), &mut out);
    out.remove("speed_rpm");
    out.remove("mu_dynamic");
    out
}

/// Canonical text of the scene: serde_json keeps the struct's field order and prints floats
/// in shortest round-trip form, so equal scenes give equal text on every platform.
fn canonical_json<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap_or_default()
}

/// 64-bit FNV-1a.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rating_that_follows_the_geometry_out_of_range_is_refused_by_validate() {
        // Young's modulus at its lower end: each field in range, but the ISO 76 rating the
        // default follows comes out past 1e8 N. Refused before any drop, and said to be derived.
        let mut s = Scene::paper();
        let b = crate::bearing::BearingPair {
            young_modulus_pa: 1e9,
            ..Default::default()
        };
        assert_eq!(b.validate(), Ok(()));
        s.bearing = Some(b);
        let e = s
            .validate()
            .expect_err("the derived static rating is out of range");
        assert_eq!(e.field, "bearing.static_rating_n");
        assert!(e.value.contains("ISO 76 rating of this geometry"), "{e}");
        // A catalogue rating set by the user is the user's, and in range it passes.
        s.bearing.as_mut().unwrap().static_rating_n = 20_000.0;
        assert_eq!(s.validate(), Ok(()));
    }

    #[test]
    fn the_methods_names_are_stable() {
        // Scene files and the record keys name the methods: a rename breaks both.
        let names = [
            (Method::Dopri5, "dopri5"),
            (Method::Dop853, "dop853"),
            (Method::Ros34pw2, "ros34pw2"),
            (Method::Rodas4, "rodas4"),
            (Method::Rodas5p, "rodas5p"),
            (Method::Radau5, "radau5"),
            (Method::Bdf, "bdf"),
            (Method::Rodas4Bdf, "rodas4_bdf"),
            (Method::Rodas4Ndf, "rodas4_ndf"),
        ];
        for (m, name) in names {
            assert_eq!(serde_json::to_string(&m).unwrap(), format!("\"{name}\""));
            assert_eq!(
                serde_json::from_str::<Method>(&format!("\"{name}\"")).unwrap(),
                m
            );
        }
    }

    #[test]
    fn the_bdfs_highest_order_is_checked() {
        for (order, ok) in [(0, false), (1, true), (4, true), (5, true), (6, false)] {
            let mut s = Scene::paper();
            s.solver.bdf_max_order = order;
            match s.validate() {
                Ok(()) => assert!(ok, "{order} accepted"),
                Err(e) => {
                    assert!(!ok, "{order} refused: {e}");
                    assert_eq!(e.field, "solver.bdf_max_order");
                    assert!(e.to_string().contains(&format!("= {order}")), "{e}");
                }
            }
        }
    }

    #[test]
    fn scene_changes_name_exactly_the_fields_that_differ() {
        let mut s = Scene::paper();
        s.speed_rpm = 12_000.0;
        s.mu_dynamic = 0.3;
        assert!(
            scene_changes(&s).is_empty(),
            "speed and mu are carried on their own"
        );
        s.solver.rtol = 1e-7;
        s.support_damper = SupportDamper::RadialOnly;
        s.unbalance_m = 2e-6;
        s.thermal = Some(ThermalParams::default());
        let c = scene_changes(&s);
        let keys: Vec<&str> = c.keys().map(String::as_str).collect();
        assert_eq!(
            keys,
            ["solver.rtol", "support_damper", "thermal", "unbalance_m"]
        );
        assert_eq!(c["solver.rtol"], serde_json::json!(1e-7));
        assert_eq!(c["support_damper"], serde_json::json!("radial_only"));
        assert!(c["thermal"].is_object());
    }

    #[test]
    fn paper_scene_is_valid_and_converts_table4_units() {
        let s = Scene::paper();
        s.validate().unwrap();
        assert!((s.support_stiffness_n_per_m_e - 7.811e9).abs() / 7.811e9 < 1e-3);
        assert!((s.race_bore_radius_m() - 0.020).abs() < 1e-12);
    }

    #[test]
    fn validation_names_field_value_and_range() {
        let mut s = Scene::paper();
        s.clearance_m = -1e-3;
        let e = s.validate().unwrap_err();
        assert_eq!(e.field, "clearance_m");
        assert!(
            e.to_string().contains("-0.001") && e.to_string().contains("(0, 0.1]"),
            "{e}"
        );
        let mut s = Scene::paper();
        s.mu_dynamic = f64::NAN;
        assert_eq!(s.validate().unwrap_err().field, "mu_dynamic");
        let mut s = Scene::paper();
        s.race_mass_kg = 0.0;
        assert_eq!(s.validate().unwrap_err().field, "race_mass_kg");
    }

    #[test]
    fn the_stop_speed_must_be_below_the_release_speed() {
        let mut s = Scene::paper();
        s.stop_speed_rpm = Some(9000.0);
        let e = s.validate().unwrap_err();
        assert_eq!(e.field, "stop_speed_rpm");
        assert!(
            e.to_string().contains("= 9000:") && e.to_string().contains("|speed_rpm| = 8000"),
            "{e}"
        );
        s.stop_speed_rpm = Some(8000.0);
        assert_eq!(s.validate().unwrap_err().field, "stop_speed_rpm");
        s.stop_speed_rpm = Some(7999.0);
        s.validate().unwrap();
        // The spin's sign is its direction: the bound is the magnitude.
        s.speed_rpm = -8000.0;
        s.validate().unwrap();
    }

    #[test]
    fn scene_hash_is_stable_and_sensitive() {
        let a = Scene::paper();
        let mut b = a.clone();
        assert_eq!(a.hash_hex(), b.hash_hex());
        b.mu_dynamic = 0.1000000001;
        assert_ne!(a.hash_hex(), b.hash_hex());
        // Pinned: a change here means every stored record key changes; bump MODEL_VERSION.
        assert_eq!(a.hash_hex().len(), 16);
    }

    #[test]
    fn derived_numbers_in_messages_have_three_digits() {
        assert_eq!(approx(45.312587499999), "45.3");
        assert_eq!(approx(0.0123456), "0.0123");
        assert_eq!(approx(0.04), "0.04");
        assert_eq!(approx(2.0), "2");
        assert_eq!(approx(10.0 / 9.0), "1.11");
        assert_eq!(approx(4.53125875e-7), "4.53e-7");
        assert_eq!(num(1e308), "1e308");
        assert_eq!(num(0.15), "0.15");
    }

    #[test]
    fn unknown_keys_are_rejected() {
        let e = serde_json::from_str::<Scene>(r#"{"clearence_m": 1e-4}"#).unwrap_err();
        assert!(e.to_string().contains("clearence_m"), "{e}");
    }
}
