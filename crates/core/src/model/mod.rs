//! The rotor-race-support model of the paper's Sec. 2 as an [`OdeSystem`].
//!
//! Frame and signs (MODEL-NOTES): x horizontal, y up, gravity `-g` on both bodies,
//! counter-clockwise angles positive. Contact geometry is relative: `d = O_r - O_b`,
//! `n = d/|d|`, `t = (-n_y, n_x)`, contact angle `alpha = atan2(d_y, d_x)`, penetration
//! `delta = |d| - s`. Slip velocity `v_rel = (v_r - v_b).t + omega_r r_r - omega_b R_b`
//! (eq. 9's rolling condition is `v_rel = 0`). The rotor gets `-F_n n - F_t t` and the torque
//! `-F_t r_r` (eqs. 1-3); the race gets `+F_n n + F_t t` and `+F_t R_b` (Newton's third law;
//! printed eqs. 4-6 give the race friction the rotor's sign, read as a typo), plus the ball
//! support force and the Palmgren drag torque.

pub mod drag;
pub mod friction;
pub mod hertz;
pub mod modes;
pub mod quasi_static;

use crate::ode::{OdeSystem, StiffJacobian, MAX_GUARDS};
use crate::scene::{FrictionLaw, Scene, SupportDamper};
pub use friction::Slip;
pub use modes::{Guard, Mode};
use nalgebra::{Matrix2, Vector2};
use std::cell::RefCell;

/// State layout: rotor (x, y, theta), race (x, y, theta), their rates, then three energy
/// accumulators integrated with the state so the energy audit sees the same error control.
pub mod ix {
    /// Rotor geometric centre x (m).
    pub const XR: usize = 0;
    /// Rotor geometric centre y (m).
    pub const YR: usize = 1;
    /// Rotor rotation angle (rad).
    pub const TR: usize = 2;
    /// Race centre x (m).
    pub const XB: usize = 3;
    /// Race centre y (m).
    pub const YB: usize = 4;
    /// Race rotation angle (rad).
    pub const TB: usize = 5;
    /// Rotor centre velocity x (m/s).
    pub const VXR: usize = 6;
    /// Rotor centre velocity y (m/s).
    pub const VYR: usize = 7;
    /// Rotor spin (rad/s).
    pub const WR: usize = 8;
    /// Race velocity x (m/s).
    pub const VXB: usize = 9;
    /// Race velocity y (m/s).
    pub const VYB: usize = 10;
    /// Race spin (rad/s).
    pub const WB: usize = 11;
    /// Friction heat at the rotor-race contact, integral of H_s = F_t v_rel (J), eq. 17.
    pub const E_FRIC: usize = 12;
    /// Energy dissipated by the two contact dampers (J).
    pub const E_DAMP: usize = 13;
    /// Work of the Palmgren drag torque, integral of M |omega_b| (J): the bearing's heat.
    pub const E_DRAG: usize = 14;
}
/// State dimension.
pub const N: usize = 15;

/// Everything the model computes at one state in one mode.
#[derive(Debug, Clone, Copy, Default)]
pub struct Forces {
    /// Contact normal n (unit, from race centre towards rotor centre).
    pub n: Vector2<f64>,
    /// Contact tangent t = (-n_y, n_x).
    pub t: Vector2<f64>,
    /// |O_r - O_b| (m).
    pub dist_m: f64,
    /// Penetration delta = |d| - s (m).
    pub delta_m: f64,
    /// Penetration rate (m/s).
    pub delta_dot_m_s: f64,
    /// Slip velocity at the contact (m/s).
    pub v_rel_m_s: f64,
    /// Normal force F_n (N), eq. 7 (0 unless the contact is active).
    pub normal_n: f64,
    /// Eq. 7's force before the never-pull switch (N); continued to delta < 0 for guards.
    pub normal_raw_n: f64,
    /// Friction force F_t on the race along +t (N); the rotor gets its opposite.
    pub friction_n: f64,
    /// While sticking: the friction that keeps v_rel = 0 (N).
    pub friction_required_n: f64,
    /// Ball support force magnitude (N), pushing the race towards the housing centre.
    pub support_n: f64,
    /// Support force before the never-pull switch (N).
    pub support_raw_n: f64,
    /// Palmgren drag torque on the race (N m, signed, opposing omega_b).
    pub drag_torque_n_m: f64,
    /// H_s = F_t v_rel (W), eq. 17.
    pub friction_power_w: f64,
    /// Bearing drag power M |omega_b| (W): the bearing's share of eq. 14's H.
    pub bearing_power_w: f64,
    /// Damper power (W) of both contacts.
    pub damping_power_w: f64,
    /// Accelerations: rotor (x, y, theta), race (x, y, theta).
    pub acc: [f64; 6],
}

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
    mu_d: f64,
    mu_s: f64,
    law: FrictionLaw,
    drag: Option<drag::Palmgren>,
    omega_eps: f64,
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
}

/// A two-entry memo of [`DropSystem::forces`], keyed on the exact bits of the state, the mode
/// and the thermal load.
///
/// One accepted step evaluates the model at the same two states several times: the step end
/// (the stepper's last stage or its end-point derivative, the driver's guards, the monitor's
/// sample, the next step's Jacobian) and the step midpoint on the interpolant (the driver's
/// guards, the monitor's sample). The model is a pure function of those keys, so a hit returns
/// exactly what a fresh evaluation would: results are bit-identical with and without it.
/// No crate offers a memo keyed on float bits with a fixed two-slot, allocation-free store.
#[derive(Debug, Clone, Default)]
struct ForceCache {
    slots: [CacheEntry; 2],
    /// The slot the next miss overwrites (the older one).
    next: usize,
    /// Evaluations not served by the memo.
    misses: u64,
    /// Evaluations served by the memo.
    hits: u64,
}

#[derive(Debug, Clone, Copy, Default)]
struct CacheEntry {
    y: [f64; N],
    /// `None` while the slot is empty.
    mode: Option<Mode>,
    thermal_load_n: f64,
    forces: Forces,
}

impl CacheEntry {
    #[inline]
    fn matches(&self, y: &[f64; N], mode: Mode, thermal_load_n: f64) -> bool {
        self.mode == Some(mode)
            && self
                .y
                .iter()
                .zip(y)
                .all(|(a, b)| a.to_bits() == b.to_bits())
            && self.thermal_load_n.to_bits() == thermal_load_n.to_bits()
    }
}

/// How often the model was evaluated in one drop (the figure benchmarks report besides the
/// stepper's RHS count).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ModelEvals {
    /// Evaluations of the force model actually computed.
    pub computed: u64,
    /// Requests answered from the two-entry memo (same state, mode and load bits).
    pub reused: u64,
}

impl DropSystem {
    /// Prepares a validated scene.
    pub fn new(scene: &Scene) -> Self {
        let m_r = scene.rotor_mass_kg * scene.load_share;
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
            c2_t: match scene.support_damper {
                SupportDamper::Isotropic => scene.support_damping_n_s_per_m,
                SupportDamper::RadialOnly => 0.0,
            },
            mu_d: scene.mu_dynamic,
            mu_s: scene.mu_static(),
            law: scene.friction_law,
            drag: scene.drag_enabled.then_some(drag::Palmgren {
                f0: scene.palmgren_f0,
                nu0_mm2_s: scene.lubricant_viscosity_mm2_s,
                dm_mm: scene.pitch_diameter_m * 1e3,
                c0_n: scene.static_load_rating_n,
            }),
            omega_eps: scene.drag_zero_speed_rad_s,
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
        }
    }

    /// How many force-model evaluations were computed and how many were reused so far.
    pub fn model_evals(&self) -> ModelEvals {
        let c = self.cache.borrow();
        ModelEvals {
            computed: c.misses,
            reused: c.hits,
        }
    }

    /// The release state (MODEL-NOTES): rotor centre at the housing centre at rest with spin
    /// Omega; race at rest at its static sag on the balls, `(m_b g / k2)^(1/e2)` below centre.
    /// Also sets the initial mode (rotor free, race on its support).
    pub fn initial_state(&mut self, spin_rad_s: f64) -> [f64; N] {
        let mut y = [0.0; N];
        y[ix::WR] = spin_rad_s;
        if self.series.is_none() {
            y[ix::YB] = -(self.m_b * self.g / self.k2).powf(1.0 / self.e2);
        }
        self.mode = Mode {
            contact: false,
            support: self.g > 0.0,
            slip: Slip::Slipping(1.0),
        };
        y
    }

    /// Rotor-race clearance s (m).
    pub fn clearance_m(&self) -> f64 {
        self.s
    }

    /// Whether the friction mode can switch (switched law with friction present).
    fn friction_switches(&self) -> bool {
        matches!(self.law, FrictionLaw::Switched) && self.mu_d > 0.0
    }

    /// Accelerations for given contact forces (eqs. 1-6 solved for the second derivatives).
    ///
    /// Rotor with unbalance: generalised coordinates are the geometric centre and the angle;
    /// the mass centre is at `O_r + e (cos psi, sin psi)`, `psi = theta + phase`. Lagrange's
    /// equations give eqs. 1-2 as printed and, eliminating the centre accelerations,
    /// `J theta'' = tau + e (F_x sin psi - F_y cos psi)` with `tau = -F_t r_r` and `F` the
    /// contact force on the rotor. Printed eq. 3 writes `- m g e cos theta` for the last term:
    /// the same thing when the contact carries the weight (`F_y = m g`), which is the
    /// approximation the paper made; we keep the exact form.
    #[inline]
    fn accelerations(&self, y: &[f64; N], f: &Forces, ft: f64, support: Vector2<f64>) -> [f64; 6] {
        // The contact force on the race; the rotor gets its opposite.
        let fc = f.normal_n * f.n + ft * f.t;
        let tau = -ft * self.r_r;
        let (ax_r, ay_r, al_r);
        if self.e == 0.0 {
            al_r = tau / self.j_r;
            ax_r = -fc.x / self.m_r;
            ay_r = -fc.y / self.m_r - self.g;
        } else {
            let (sp, cp) = (y[ix::TR] + self.phase).sin_cos();
            let w2 = y[ix::WR] * y[ix::WR];
            al_r = (tau + self.e * (-fc.x * sp + fc.y * cp)) / self.j_r;
            ax_r = -fc.x / self.m_r + self.e * (al_r * sp + w2 * cp);
            ay_r = -fc.y / self.m_r - self.g - self.e * (al_r * cp - w2 * sp);
        }
        let (ax_b, ay_b) = if self.series.is_some() {
            // Massless race translation: the race centre stays at the housing centre in
            // the state; its displacement lives in the series split.
            (0.0, 0.0)
        } else {
            let a = (fc + support) / self.m_b;
            (a.x, a.y - self.g)
        };
        let al_b = (ft * self.r_b + f.drag_torque_n_m) / self.j_b;
        [ax_r, ay_r, al_r, ax_b, ay_b, al_b]
    }

    /// d(v_rel)/dt for given accelerations (differentiating eq. 9's slip velocity; the
    /// tangent turns with the contact angle, `t' = -(v_t/|d|) n`).
    #[inline]
    fn slip_acceleration(&self, f: &Forces, v_t: f64, a: &[f64; 6]) -> f64 {
        Vector2::new(a[0] - a[3], a[1] - a[4]).dot(&f.t) - v_t * f.delta_dot_m_s / f.dist_m
            + a[2] * self.r_r
            - a[5] * self.r_b
    }

    /// All forces, powers and accelerations at `y` in the current mode (memoised: the last
    /// two distinct requests are answered without recomputation, bit-identically).
    pub fn forces(&self, y: &[f64; N]) -> Forces {
        self.with_forces(y, |f| *f)
    }

    /// Runs `op` on [`DropSystem::forces`] at `y` without copying the whole [`Forces`] out
    /// of the memo (the right-hand side and the guards read a few fields of it). The memo
    /// stays borrowed while `op` runs, so `op` must not evaluate this system again.
    #[inline]
    pub fn with_forces<R>(&self, y: &[f64; N], op: impl FnOnce(&Forces) -> R) -> R {
        let (mode, load) = (self.mode, self.thermal_load_n);
        let mut c = self.cache.borrow_mut();
        for i in 0..2 {
            if c.slots[i].matches(y, mode, load) {
                c.hits += 1;
                return op(&c.slots[i].forces);
            }
        }
        let i = c.next;
        c.next = 1 - i;
        c.misses += 1;
        let e = &mut c.slots[i];
        self.fill_forces(y, mode, &mut e.forces);
        e.y = *y;
        e.mode = Some(mode);
        e.thermal_load_n = load;
        op(&e.forces)
    }

    /// All forces, powers and accelerations at `y` in mode `mode`.
    pub fn forces_in(&self, y: &[f64; N], mode: Mode) -> Forces {
        let mut f = Forces::default();
        self.fill_forces(y, mode, &mut f);
        f
    }

    /// [`DropSystem::forces_in`], written into `out` (the memo's slot) instead of returned:
    /// a returned [`Forces`] is copied once more on the way.
    fn fill_forces(&self, y: &[f64; N], mode: Mode, out: &mut Forces) {
        *out = Forces::default();
        let f = out;
        // d = O_r - O_b, n = d / |d|, t = (-n_y, n_x), w = v_r - v_b.
        let d = Vector2::new(y[ix::XR] - y[ix::XB], y[ix::YR] - y[ix::YB]);
        let dist = d.norm();
        f.dist_m = dist;
        f.n = if dist > 0.0 {
            d / dist
        } else {
            Vector2::new(0.0, -1.0)
        };
        f.t = Vector2::new(-f.n.y, f.n.x);
        let w = Vector2::new(y[ix::VXR] - y[ix::VXB], y[ix::VYR] - y[ix::VYB]);
        f.delta_m = dist - self.s;
        f.delta_dot_m_s = w.dot(&f.n);
        let v_t = w.dot(&f.t);
        f.v_rel_m_s = v_t + y[ix::WR] * self.r_r - y[ix::WB] * self.r_b;
        // Quasi-static race: the series springs' force and the split damper (see
        // `quasi_static`); otherwise eq. 7 between rotor and race.
        let mut c_contact = self.c1;
        if let Some(ss) = &self.series {
            let sp = ss.split(f.delta_m);
            let w = sp.w_contact;
            c_contact = self.c1 * w * w + self.c2 * (1.0 - w) * (1.0 - w);
            f.normal_raw_n = sp.force_n + c_contact * f.delta_dot_m_s;
        } else {
            f.normal_raw_n =
                hertz::raw_force(self.k1, self.e1, self.c1, f.delta_m, f.delta_dot_m_s);
        }
        if mode.contact {
            f.normal_n = f.normal_raw_n;
        }

        // Ball support: isotropic, zero clearance, eq. 7 with e = 3/2 and c2.
        let b = Vector2::new(y[ix::XB], y[ix::YB]);
        let r = b.norm();
        let mut support_vec = Vector2::zeros();
        let mut r_dot = 0.0;
        let mut tangential_power_w = 0.0;
        if self.series.is_some() {
            // The support carries the contact force; its guard never fires.
            f.support_raw_n = self.f_ref_b;
            f.support_n = f.normal_n.max(0.0);
        } else if r > 0.0 {
            let nb = b / r;
            let vb = Vector2::new(y[ix::VXB], y[ix::VYB]);
            r_dot = vb.dot(&nb);
            f.support_raw_n = hertz::raw_force(self.k2, self.e2, self.c2, r, r_dot);
            if mode.support {
                f.support_n = f.support_raw_n;
                support_vec = -f.support_n * nb;
                if self.c2_t > 0.0 {
                    // Isotropic damper: c2 also on the race velocity across nb.
                    let vt = vb - r_dot * nb;
                    support_vec -= self.c2_t * vt;
                    tangential_power_w = self.c2_t * vt.norm_squared();
                }
            }
        }

        // Palmgren drag (eqs. 11-13) on the race, P1 = the support force; eq. 31 adds the
        // thermally induced load (exactly 0.0 without a thermal model, so no bit changes).
        let wb = y[ix::WB];
        if let Some(p) = &self.drag {
            let m = p.torque_n_m(wb, f.support_n + self.thermal_load_n);
            let dir = drag::direction(wb, self.omega_eps);
            f.drag_torque_n_m = -m * dir;
            f.bearing_power_w = m * dir * wb;
        }

        // Friction, eq. 8, or the rolling constraint of eqs. 9-10 while sticking.
        let ft = if !mode.contact {
            0.0
        } else {
            match (self.law, mode.slip) {
                (FrictionLaw::Regularised { v_eps_m_s }, _) => {
                    self.mu_d * f.normal_n * (f.v_rel_m_s / v_eps_m_s).tanh()
                }
                (FrictionLaw::Switched, Slip::Slipping(sign)) => self.mu_d * f.normal_n * sign,
                (FrictionLaw::Switched, Slip::Sticking) => {
                    // v_rel' is affine in F_t: solve v_rel' = 0.
                    let a0 = self.accelerations(y, f, 0.0, support_vec);
                    let a1 = self.accelerations(y, f, 1.0, support_vec);
                    let s0 = self.slip_acceleration(f, v_t, &a0);
                    let s1 = self.slip_acceleration(f, v_t, &a1);
                    -s0 / (s1 - s0)
                }
            }
        };
        if mode.contact && mode.slip == Slip::Sticking {
            f.friction_required_n = ft;
        }
        f.friction_n = ft;
        f.friction_power_w = ft * f.v_rel_m_s;
        f.damping_power_w = if mode.contact {
            c_contact * f.delta_dot_m_s * f.delta_dot_m_s
        } else {
            0.0
        } + if mode.support {
            self.c2 * r_dot * r_dot + tangential_power_w
        } else {
            0.0
        };
        f.acc = self.accelerations(y, f, ft, support_vec);
    }

    /// Mechanical energy (J): kinetic, gravitational (zero at y = 0) and the elastic energy
    /// of the contacts active in `mode`.
    pub fn mechanical_energy(&self, y: &[f64; N], mode: Mode) -> f64 {
        let (mut vcx, mut vcy, mut yc) = (y[ix::VXR], y[ix::VYR], y[ix::YR]);
        if self.e != 0.0 {
            let (sp, cp) = (y[ix::TR] + self.phase).sin_cos();
            vcx -= self.e * y[ix::WR] * sp;
            vcy += self.e * y[ix::WR] * cp;
            yc += self.e * sp;
        }
        let ke_r =
            0.5 * self.m_r * (vcx * vcx + vcy * vcy) + 0.5 * self.j_r * y[ix::WR] * y[ix::WR];
        let ke_b = 0.5 * self.m_b * (y[ix::VXB].powi(2) + y[ix::VYB].powi(2))
            + 0.5 * self.j_b * y[ix::WB].powi(2);
        let pe = self.g * (self.m_r * yc + self.m_b * y[ix::YB]);
        let mut el = 0.0;
        if let Some(ss) = &self.series {
            if mode.contact {
                let dist = (y[ix::XR].powi(2) + y[ix::YR].powi(2)).sqrt();
                el += ss.energy_j(&ss.split(dist - self.s));
            }
            return ke_r + ke_b + pe + el;
        }
        if mode.contact {
            let dist = ((y[ix::XR] - y[ix::XB]).powi(2) + (y[ix::YR] - y[ix::YB]).powi(2)).sqrt();
            el += hertz::elastic_energy(self.k1, self.e1, dist - self.s);
        }
        if mode.support {
            let r = (y[ix::XB].powi(2) + y[ix::YB].powi(2)).sqrt();
            el += hertz::elastic_energy(self.k2, self.e2, r);
        }
        ke_r + ke_b + pe + el
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

    /// The stiff part of the Jacobian for the linearly implicit stepper: the two Hertz
    /// contacts' normal forces (eq. 7, spring and damper, with the turning of the contact
    /// normal), the friction that follows them (eq. 8; the regularised law's slope in the
    /// slip velocity too), over the translations, their rates and the two spins. Left out,
    /// because they are not stiff: gravity, the unbalance terms, Palmgren drag, and the
    /// sticking constraint's dependence on the state.
    fn stiff_jacobian(&self, _t: f64, y: &[f64; N]) -> Option<StiffJacobian> {
        use ix::*;
        // Blocks of the stiff set: rotor position 0..2, race position 2..4, rotor velocity
        // 4..6, race velocity 6..8, then the rotor's (8) and the race's (9) spin.
        const QR: usize = 0;
        const QB: usize = 2;
        const VR: usize = 4;
        const VB: usize = 6;
        const SR: usize = 8;
        const SB: usize = 9;
        let mut sj = StiffJacobian::over(&[XR, YR, XB, YB, VXR, VYR, VXB, VYB, WR, WB]);
        // The four positions' rows are exactly q' = v (eqs. 1-6): the stepper eliminates them.
        sj.kinematic = 4;
        let j = &mut sj.jac;
        j.fixed_view_mut::<4, 4>(QR, VR).fill_with_identity();
        let f = self.forces(y);
        // t = R n with R the quarter turn.
        let quarter = Matrix2::new(0.0, -1.0, 1.0, 0.0);
        if self.mode.contact && f.dist_m > 0.0 {
            let (n, t, dist) = (f.n, f.t, f.dist_m);
            let w = Vector2::new(y[VXR] - y[VXB], y[VYR] - y[VYB]);
            // P = I - n n^T: how n turns with d; R P: how t turns.
            let p = Matrix2::identity() - n * n.transpose();
            let rp = quarter * p;
            let pw = p * w;
            let (kd, c) = match &self.series {
                Some(ss) => {
                    // Series springs: dF/dd = F / (a/e1 + b/e2); the split damper's weight
                    // w = (a/e1) / (a/e1 + b/e2) moves with d too (its slope times delta_dot
                    // joins the stiffness).
                    let sp = ss.split(f.delta_m);
                    let (pp, q) = (ss.inv_e1(), ss.inv_e2());
                    let (a, b, fa) = (sp.delta_m, sp.support_m, sp.force_n.abs());
                    let denom = a * pp + b * q;
                    let wc = sp.w_contact;
                    let c = self.c1 * wc * wc + self.c2 * (1.0 - wc) * (1.0 - wc);
                    let kd = if denom > 0.0 && fa > 0.0 {
                        let k = fa / denom;
                        let dw = pp * q * a * b * (pp - q) * k / (fa * denom * denom);
                        let dc = 2.0 * (self.c1 * wc - self.c2 * (1.0 - wc)) * dw;
                        k + dc * f.delta_dot_m_s
                    } else {
                        0.0
                    };
                    (kd, c)
                }
                None => {
                    let d = f.delta_m.max(0.0);
                    let kd = if d > 0.0 {
                        self.k1 * self.e1 * hertz::signed_pow(d, self.e1) / d
                    } else {
                        0.0
                    };
                    (kd, self.c1)
                }
            };
            let (fnn, ft) = (f.normal_n, f.friction_n);
            // Gradients of F_n (eq. 7) over d = p_r - p_b and w = v_r - v_b.
            let dfn_dd = kd * n + (c / dist) * pw;
            let dfn_dw = c * n;
            // Friction: d F_t over d, w and the two spins.
            let (mut dft_dd, mut dft_dw, mut dft_dwr, mut dft_dwb) =
                (Vector2::zeros(), Vector2::zeros(), 0.0, 0.0);
            match (self.law, self.mode.slip) {
                (FrictionLaw::Regularised { v_eps_m_s }, _) => {
                    let th = (f.v_rel_m_s / v_eps_m_s).tanh();
                    let slope = self.mu_d * fnn * (1.0 - th * th) / v_eps_m_s;
                    // v_rel depends on d through the turning tangent: (R P)^T w / |d|.
                    let dv_dd = rp.transpose() * w / dist;
                    dft_dd = self.mu_d * th * dfn_dd + slope * dv_dd;
                    dft_dw = self.mu_d * th * dfn_dw + slope * t;
                    dft_dwr = slope * self.r_r;
                    dft_dwb = -slope * self.r_b;
                }
                (FrictionLaw::Switched, Slip::Slipping(sign)) => {
                    dft_dd = self.mu_d * sign * dfn_dd;
                    dft_dw = self.mu_d * sign * dfn_dw;
                }
                (FrictionLaw::Switched, Slip::Sticking) => {}
            }
            // Force on the race fc = F_n n + F_t t (the rotor gets -fc), over d and w.
            let dfc_dd = n * dfn_dd.transpose()
                + (fnn / dist) * p
                + t * dft_dd.transpose()
                + (ft / dist) * rp;
            let dfc_dw = n * dfn_dw.transpose() + t * dft_dw.transpose();
            let (ir, ib) = (1.0 / self.m_r, 1.0 / self.m_b);
            let mut block = |row: usize, col: usize, m: Matrix2<f64>| {
                let mut v = j.fixed_view_mut::<2, 2>(row, col);
                v += m;
            };
            // Rotor rows: -fc / m_r, with d = p_r - p_b and w = v_r - v_b.
            block(VR, QR, -dfc_dd * ir);
            block(VR, VR, -dfc_dw * ir);
            let race = self.series.is_none();
            if race {
                block(VR, QB, dfc_dd * ir);
                block(VR, VB, dfc_dw * ir);
                block(VB, QR, dfc_dd * ib);
                block(VB, QB, -dfc_dd * ib);
                block(VB, VR, dfc_dw * ib);
                block(VB, VB, -dfc_dw * ib);
            }
            let mut column = |row: usize, col: usize, v: Vector2<f64>| {
                let mut c = j.fixed_view_mut::<2, 1>(row, col);
                c += v;
            };
            column(VR, SR, -t * (dft_dwr * ir));
            column(VR, SB, -t * (dft_dwb * ir));
            if race {
                column(VB, SR, t * (dft_dwr * ib));
                column(VB, SB, t * (dft_dwb * ib));
            }
            // Spin rows: omega_r' = -F_t r_r / J_r, omega_b' = F_t R_b / J_b.
            for (row, scale) in [(SR, -self.r_r / self.j_r), (SB, self.r_b / self.j_b)] {
                let mut r = j.fixed_view_mut::<1, 2>(row, QR);
                r += scale * dft_dd.transpose();
                let mut r = j.fixed_view_mut::<1, 2>(row, VR);
                r += scale * dft_dw.transpose();
                if race {
                    let mut r = j.fixed_view_mut::<1, 2>(row, QB);
                    r -= scale * dft_dd.transpose();
                    let mut r = j.fixed_view_mut::<1, 2>(row, VB);
                    r -= scale * dft_dw.transpose();
                }
                j[(row, SR)] += scale * dft_dwr;
                j[(row, SB)] += scale * dft_dwb;
            }
        }
        if self.series.is_none() && self.mode.support {
            let b = Vector2::new(y[XB], y[YB]);
            let r = b.norm();
            if r > 0.0 {
                let nb = b / r;
                let vb = Vector2::new(y[VXB], y[VYB]);
                let vn = vb.dot(&nb);
                let pb = Matrix2::identity() - nb * nb.transpose();
                let pv = pb * vb;
                let kd = self.k2 * self.e2 * hertz::signed_pow(r, self.e2) / r;
                let fs = f.support_n;
                // The support's force -F_s nb (eq. 7, radial) and its radial damper, over the
                // race position and velocity; then the tangential damper -c2_t (v - nb (nb.v))
                // and its turning with nb.
                let dp = nb * (kd * nb + (self.c2 / r) * pv).transpose() + (fs / r) * pb;
                let ib = 1.0 / self.m_b;
                let tangential_dq = self.c2_t * (pb * vn + nb * pv.transpose()) / (r * self.m_b);
                let mut q = j.fixed_view_mut::<2, 2>(VB, QB);
                q -= dp * ib;
                q += tangential_dq;
                let mut v = j.fixed_view_mut::<2, 2>(VB, VB);
                v -= (self.c2 * ib) * nb * nb.transpose();
                v -= (self.c2_t * ib) * pb;
            }
        }
        Some(sj)
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

    fn max_step(&self) -> f64 {
        if self.mode.contact {
            f64::INFINITY
        } else {
            self.free_max_step
        }
    }
}
