//! The rotor-race-support model of the paper's Sec. 2 as an [`OdeSystem`].
//!
//! Frame and signs (docs/model.md#frame-and-signs): x horizontal, y up, gravity `-g` on both
//! bodies, counter-clockwise angles positive. Contact geometry is relative
//! (docs/model.md#contact-geometry): `d = O_r - O_b`, `n = d/|d|`, `t = (-n_y, n_x)`, contact
//! angle `alpha = atan2(d_y, d_x)`, penetration `delta = |d| - s`. Slip velocity
//! `v_rel = (v_r - v_b).t + omega_r r_r - omega_b R_b` (eq. 9's rolling condition is
//! `v_rel = 0`). The rotor gets `-F_n n - F_t t` and the torque `-F_t r_r` (eqs. 1-3); the race
//! gets `+F_n n + F_t t` and `+F_t R_b` (Newton's third law; printed eqs. 4-6 give the race
//! friction the rotor's sign, read as a typo: docs/model.md#newtons-third-law-at-the-contact),
//! plus the ball support force and the Palmgren drag torque.

pub mod drag;
mod energy;
mod forces;
pub mod friction;
pub mod hertz;
mod jacobian;
mod memo;
pub mod modes;
mod pow;
mod pow_tables;
pub mod quasi_static;
mod state;

use crate::ode::{OdeSystem, StiffJacobian, MAX_GUARDS};
use crate::scene::{Scene, SupportDamper};
pub use forces::Forces;
pub use friction::{Friction, Slip};
use memo::ForceCache;
pub use memo::ModelEvals;
pub use modes::Guard;
pub use state::{ix, Mode, N};
use std::cell::RefCell;

/// The scene prepared for the right-hand side (SI, load share applied).
#[derive(Debug, Clone)]
pub struct DropSystem {
    m_r: f64,
    j_r: f64,
    r_r: f64,
    r_b: f64,
    s: f64,
    e: f64,
    phase: f64,
    m_b: f64,
    j_b: f64,
    g: f64,
    k1: f64,
    e1: f64,
    c1: f64,
    k2: f64,
    e2: f64,
    c2: f64,
    /// Tangential support damping (N s/m): c2 with the isotropic support damper (the
    /// default), 0 with `radial_only` (see [`crate::scene::SupportDamper`]).
    c2_t: f64,
    /// The friction law of the rotor-race contact and its coefficients.
    friction: Friction,
    drag: Option<drag::Palmgren>,
    omega_eps: f64,
    /// Whether the stiff Jacobian holds the terms a Rosenbrock method needs for its order
    /// (RODAS4, Rodas5P): the accumulators' rows and the sticking constraint's slopes. A W-method
    /// (ROS34PW2) keeps its order without them and is handed the cheaper matrix.
    exact_jacobian: bool,
    free_max_step: f64,
    free_gap_bound: bool,
    f_ref: f64,
    f_ref_b: f64,
    /// Reduced model: massless race translation (series springs), when the scene asks.
    series: Option<quasi_static::SeriesSprings>,
    /// The current mode; the driver switches it at located events.
    pub mode: Mode,
    /// Thermally induced bearing load F_th (N), eq. 30, added to the ball-support load in the
    /// Palmgren load torque (eq. 31). Zero unless the scene's thermal model sets it; the
    /// macro-step coupling ([`crate::thermal`]) updates it between macro steps.
    pub thermal_load_n: f64,
    /// The last two evaluations of [`DropSystem::forces`], see [`ForceCache`].
    cache: RefCell<ForceCache>,
    /// `solver.rtol` when the race's velocity tolerance is widened in contact
    /// (`solver.race_velocity_atol_from_force` on, and both dampers acting: see
    /// [`OdeSystem::loosened_atol`]), `None` otherwise.
    widen_rtol: Option<f64>,
}

impl DropSystem {
    /// Prepares a validated scene.
    pub fn new(scene: &Scene) -> Self {
        let m_r = scene.rotor_mass_kg * scene.load_share;
        // Tangential support damping: c2 with the isotropic damper, 0 with `radial_only`.
        let c2_t = match scene.support_damper {
            SupportDamper::Isotropic => scene.support_damping_n_s_per_m,
            SupportDamper::RadialOnly => 0.0,
        };
        let m_b = scene.race_mass_kg;
        let g = scene.gravity_m_s2;
        Self {
            m_r,
            j_r: scene.rotor_polar_moi_kg_m2 * scene.load_share,
            r_r: scene.rotor_radius_m(),
            r_b: scene.race_bore_radius_m(),
            s: scene.clearance_m,
            e: scene.unbalance_m,
            phase: scene.unbalance_phase_rad,
            m_b,
            j_b: scene.race_polar_moi_kg_m2,
            g,
            k1: scene.contact_stiffness_n_per_m_e,
            e1: scene.contact_exponent,
            c1: scene.contact_damping_n_s_per_m,
            k2: scene.support_stiffness_n_per_m_e,
            e2: scene.support_exponent,
            c2: scene.support_damping_n_s_per_m,
            c2_t,
            friction: Friction::new(scene.friction_law, scene.mu_dynamic, scene.mu_static()),
            drag: scene.drag_enabled.then_some(drag::Palmgren {
                f0: scene.palmgren_f0,
                nu0_mm2_s: scene.lubricant_viscosity_mm2_s,
                dm_mm: scene.pitch_diameter_m * 1e3,
                c0_n: scene.static_load_rating_n,
            }),
            omega_eps: scene.drag_zero_speed_rad_s,
            exact_jacobian: scene.solver.method.needs_exact_jacobian(),
            free_max_step: scene.solver.free_flight_max_step_s,
            free_gap_bound: scene.solver.free_flight_gap_bound,
            f_ref: (m_r * g).max(1e-3),
            f_ref_b: (m_b * g).max(1e-6),
            series: scene.quasi_static_race.then(|| {
                quasi_static::SeriesSprings::new(
                    scene.contact_stiffness_n_per_m_e,
                    scene.contact_exponent,
                    scene.support_stiffness_n_per_m_e,
                    scene.support_exponent,
                )
            }),
            mode: Mode {
                contact: false,
                support: true,
                slip: Slip::Slipping(1.0),
            },
            thermal_load_n: 0.0,
            cache: RefCell::new(ForceCache::default()),
            // Without a damper on the race in every direction (the radial-only law, or c2 = 0)
            // its vibration is undamped: its velocity errors would not decay, so nothing is
            // widened (measured: the radial-only study's maximum force missed the budget by
            // 2.4e-3 with it). Without a contact damper the argument has no force to hold.
            widen_rtol: (scene.solver.race_velocity_atol_from_force
                && c2_t > 0.0
                && scene.contact_damping_n_s_per_m > 0.0)
                .then_some(scene.solver.rtol),
        }
    }

    /// The release state (docs/model.md#release-state): rotor centre at the housing centre at
    /// rest with spin Omega; race at rest at its static sag on the balls, `(m_b g / k2)^(1/e2)`
    /// below centre.
    /// Also sets the initial mode (rotor free, race on its support). Without gravity the race
    /// starts centred, where its zero-clearance support carries no force yet, and it is on
    /// its support all the same: the balls push it back as soon as it moves (starting it off
    /// its support there, the support's guard started at zero, and before model version 10,
    /// which watches a guard from zero, the race ran free of its balls for the whole drop).
    pub fn initial_state(&mut self, spin_rad_s: f64) -> [f64; N] {
        let mut y = [0.0; N];
        y[ix::WR] = spin_rad_s;
        if self.series.is_none() {
            y[ix::YB] = -(self.m_b * self.g / self.k2).powf(1.0 / self.e2);
        }
        self.mode = Mode {
            contact: false,
            support: true,
            slip: Slip::Slipping(1.0),
        };
        y
    }

    /// Rotor-race clearance s (m).
    pub fn clearance_m(&self) -> f64 {
        self.s
    }

    /// A force scale for energy and guard normalisation: the rotor's weight share (N).
    pub fn weight_n(&self) -> f64 {
        self.f_ref
    }
}

impl OdeSystem<N> for DropSystem {
    type Guard = Guard;

    fn rhs(&self, _t: f64, y: &[f64; N], dy: &mut [f64; N]) {
        dy[ix::XR] = y[ix::VXR];
        dy[ix::YR] = y[ix::VYR];
        dy[ix::TR] = y[ix::WR];
        dy[ix::XB] = y[ix::VXB];
        dy[ix::YB] = y[ix::VYB];
        dy[ix::TB] = y[ix::WB];
        self.with_forces(y, |f| {
            dy[ix::VXR..=ix::WB].copy_from_slice(&f.acc);
            dy[ix::E_FRIC] = f.friction_power_w;
            dy[ix::E_DAMP] = f.damping_power_w;
            dy[ix::E_DRAG] = f.bearing_power_w;
        });
    }

    /// Guards: 0 contact (onset when free, loss when in contact), 1 support (release or
    /// re-seat), 2 friction (slip velocity reversal while slipping; friction demand above
    /// `mu_s F_n` while sticking).
    fn guards(&self, _t: f64, y: &[f64; N], g: &mut [f64; MAX_GUARDS]) -> usize {
        self.with_forces(y, |f| self.guards_of(f, g))
    }

    /// See `DropSystem::fill_stiff_jacobian_at` (`jacobian.rs`).
    fn stiff_jacobian(&self, _t: f64, y: &[f64; N]) -> Option<StiffJacobian> {
        let mut sj = StiffJacobian::over(&[]);
        self.fill_stiff_jacobian_at(y, &mut sj);
        Some(sj)
    }

    /// See `DropSystem::fill_stiff_jacobian_at` (`jacobian.rs`).
    fn fill_stiff_jacobian(&self, _t: f64, y: &[f64; N], out: &mut StiffJacobian) {
        self.fill_stiff_jacobian_at(y, out);
    }

    /// In free flight with `solver.free_flight_gap_bound`: the larger of the fixed cap and a
    /// quarter of a lower bound on the time until the contact can close, from the gap
    /// `s - |d|`, the relative speed and a bound on the relative acceleration (twice the
    /// present one plus g plus the unbalance's `e omega^2`). A guard cannot cross before that
    /// time, so no contact is stepped over; far from the race the steps grow freely.
    fn max_step_at(&self, _t: f64, y: &[f64; N]) -> f64 {
        let cap = self.max_step();
        if self.mode.contact || !self.free_gap_bound {
            return cap;
        }
        let f = self.forces(y);
        let gap = -f.delta_m;
        if gap <= 0.0 {
            return cap;
        }
        let w = (y[ix::VXR] - y[ix::VXB]).hypot(y[ix::VYR] - y[ix::VYB]);
        let a_rel = (f.acc[0] - f.acc[3]).hypot(f.acc[1] - f.acc[4]);
        let a = 2.0 * a_rel + self.g + self.e * y[ix::WR] * y[ix::WR];
        let t_close = 2.0 * gap / (w + (w * w + 2.0 * a * gap).sqrt());
        cap.max(0.25 * t_close)
    }

    /// With `solver.race_velocity_atol_from_force`, while the contact carries load: the
    /// race's velocity tolerances widened (never narrowed) to `rtol F_n / max(c1, c2)`,
    /// `F_n` the contact force at the step's start (eq. 7). The race's velocity enters the
    /// normal contact force only through the contact damper's term `c1 delta_dot` of eq. 7,
    /// and the ball support force (about `F_n` in contact) through the support damper's
    /// `c2`, so an error of that size moves either damper's force by at most `rtol F_n` (and
    /// the rotor's trajectory, through the race's momentum, by m_b/m_r of what the same
    /// error on the rotor would). As the force falls towards a lift-off the tolerance
    /// tightens back to the base. docs/accuracy.md#the-races-velocity-tolerance-in-contact.
    fn loosened_atol(&self, _t: f64, y: &[f64; N], base: &[f64; N]) -> Option<[f64; N]> {
        let rtol = self.widen_rtol?;
        if !self.mode.contact {
            return None;
        }
        let wide = rtol * self.with_forces(y, |f| f.normal_n) / self.c1.max(self.c2);
        if !(wide > base[ix::VXB].min(base[ix::VYB])) {
            return None;
        }
        let mut atol = *base;
        atol[ix::VXB] = atol[ix::VXB].max(wide);
        atol[ix::VYB] = atol[ix::VYB].max(wide);
        Some(atol)
    }

    fn max_step(&self) -> f64 {
        if self.mode.contact {
            f64::INFINITY
        } else {
            self.free_max_step
        }
    }
}
