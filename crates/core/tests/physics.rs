//! Physics tests of the drop model and its integrator: closed forms, conservation laws,
//! symmetry, convergence and robustness. Every test states what it proves in its name and
//! justifies each tolerance where it is set.
//!
//! Durations are short (0.02-0.3 s) so the whole file runs in a few seconds on two cores;
//! each test says why its duration is what it is.
// Gauss-Legendre nodes to full digits; `!(x < bound)` so a NaN fails.
#![allow(clippy::excessive_precision, clippy::neg_cmp_op_on_partial_ord)]

use std::convert::Infallible;
use std::ops::ControlFlow;
use whirlmap_core::model::friction::stick_or_slip;
use whirlmap_core::model::{ix, DropSystem, Slip, N};
use whirlmap_core::ode::{
    integrate, Dopri5, GuardSet, Observer, OdeSystem, StepControl, StepView, Stop, MAX_GUARDS,
};
use whirlmap_core::{
    simulate, simulate_observed, DropOptions, DropReport, Method, Scene, SolveError, StopReason,
};

// ------------------------------------------------------------------------------------------
// Helpers
// ------------------------------------------------------------------------------------------

/// The paper scene at a given speed and friction coefficient, run for exactly the duration
/// each test asks for (these tests check physics over a fixed span, so the classifier's
/// extension of unsettled runs is off) and integrated by DOPRI5 at rtol 1e-5 with the
/// rotor's absolute tolerances on the race: every bound below was derived for that
/// integration (the invariants hold to integration error, and these bounds resolve it).
/// The default numerics are checked against these invariants with their own bounds in
/// `standard_numerics_keep_the_invariants`.
fn scene(speed_rpm: f64, mu: f64) -> Scene {
    let mut s = Scene::paper();
    s.speed_rpm = speed_rpm;
    s.mu_dynamic = mu;
    s.classification.max_extension_s = 0.0;
    s.solver.method = Method::Dopri5;
    s.solver.rtol = 1e-5;
    s.solver.free_flight_gap_bound = false;
    s.solver.race_atol_scale = 1.0;
    s.solver.race_velocity_atol_from_force = false;
    s
}

fn opts(duration_s: f64) -> DropOptions {
    DropOptions {
        duration_s,
        ..Default::default()
    }
}

fn run(s: &Scene, duration_s: f64) -> DropReport {
    simulate(s, &opts(duration_s)).unwrap_or_else(|e| panic!("drop failed: {e}"))
}

/// |a - b| / max(|a|, |b|, floor).
fn rel(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(floor)
}

/// Masses and inertias as `DropSystem` uses them (load share applied).
struct Bodies {
    m_r: f64,
    j_r: f64,
    m_b: f64,
    j_b: f64,
    e: f64,
    phase: f64,
    g: f64,
}

impl Bodies {
    fn of(s: &Scene) -> Self {
        Self {
            m_r: s.rotor_mass_kg * s.load_share,
            j_r: s.rotor_polar_moi_kg_m2 * s.load_share,
            m_b: s.race_mass_kg,
            j_b: s.race_polar_moi_kg_m2,
            e: s.unbalance_m,
            phase: s.unbalance_phase_rad,
            g: s.gravity_m_s2,
        }
    }

    /// Rotor mass centre position and velocity.
    fn rotor_mass_centre(&self, y: &[f64; N]) -> ([f64; 2], [f64; 2]) {
        let (sp, cp) = (y[ix::TR] + self.phase).sin_cos();
        let w = y[ix::WR];
        (
            [y[ix::XR] + self.e * cp, y[ix::YR] + self.e * sp],
            [y[ix::VXR] - self.e * w * sp, y[ix::VYR] + self.e * w * cp],
        )
    }

    /// Total angular momentum about the housing centre (origin).
    fn angular_momentum(&self, y: &[f64; N]) -> f64 {
        let (c, vc) = self.rotor_mass_centre(y);
        self.m_r * (c[0] * vc[1] - c[1] * vc[0])
            + self.j_r * y[ix::WR]
            + self.m_b * (y[ix::XB] * y[ix::VYB] - y[ix::YB] * y[ix::VXB])
            + self.j_b * y[ix::WB]
    }
}

/// The end of a test-driven drop.
struct Driven {
    y0: [f64; N],
    y: [f64; N],
    t: f64,
}

/// A drop through the real driver (`simulate_observed`) with a test observer tapping every
/// step. Durations are chosen to end before the whirl stopping rule would fire.
fn drive<O: Observer<DropSystem, N>>(scene: &Scene, duration_s: f64, obs: &mut O) -> Driven {
    let y0 = DropSystem::new(scene).initial_state(scene.spin_rad_s());
    let r = simulate_observed(scene, &opts(duration_s), obs)
        .unwrap_or_else(|e| panic!("drop failed: {e}"));
    Driven {
        y0,
        y: r.final_state,
        t: r.end_time_s,
    }
}

/// Gauss-Legendre 5-point nodes and weights on [-1, 1] (exact to degree 9: the step
/// interpolant is degree 4, so a smooth function of it is integrated to far below rtol).
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664_0, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664_0, 0.236_926_885_056_189_1),
];

// ------------------------------------------------------------------------------------------
// 1. Free fall
// ------------------------------------------------------------------------------------------

/// The rotor falls freely from the housing centre; the race sits at its static sag
/// `(m_b g / k2)^(1/e2)` below it, so the gap closes after a fall of `s + sag`.
#[test]
fn free_fall_reaches_the_race_at_the_closed_form_time() {
    let mut mars = scene(8000.0, 0.1);
    mars.gravity_m_s2 = 3.71;
    mars.clearance_m = 0.3e-3;
    let mut heavy_race = scene(3000.0, 0.3);
    heavy_race.race_mass_kg = 0.5;
    heavy_race.support_stiffness_n_per_m_e = 1e9;
    for s in [scene(8000.0, 0.1), mars, heavy_race] {
        let g = s.gravity_m_s2;
        let sag =
            (s.race_mass_kg * g / s.support_stiffness_n_per_m_e).powf(1.0 / s.support_exponent);
        let exact = (2.0 * (s.clearance_m + sag) / g).sqrt();
        // 0.02 s covers the longest fall here (about 12.7 ms at g = 3.71, s = 0.3 mm).
        let r = run(&s, 0.02);
        let t = r.features.first_contact_time_s;
        // Free fall is a quadratic in t, which DOPRI5 and its 4th-order interpolant
        // reproduce exactly; the crossing is located to rounding (4 eps t). So only
        // rounding (~1e-13) separates t from the closed form; 1e-9 leaves room for that and
        // still catches a race not starting at its sag (sag/s is 3e-4 in the paper scene,
        // 2e-2 on the soft support below: it shifts t by half that).
        assert!(
            rel(t, exact, 0.0) < 1e-9,
            "g {g} s {} sag {sag:e}: first touch {t} s, closed form {exact} s",
            s.clearance_m
        );
    }
}

// ------------------------------------------------------------------------------------------
// 2. Undamped Hertz impact
// ------------------------------------------------------------------------------------------

/// A race of 1e6 kg on a support of 1e18 N/m^1.5 is a rigid wall for the 5.75 kg rotor:
/// it sags 46 nm, and the impact impulse J <= 2 m_r v = 0.62 N s can give it at most
/// J^2 / (2 m_b) = 1.9e-7 J of ringing (2.3e-5 of the drop energy) and move it at most
/// J / (m_b omega_b) = 3.4e-11 m (6e-6 of the rotor's penetration). Then closed forms hold:
/// - peak penetration from m g (h + d) = K d^(e+1) / (e+1) (gravity keeps working while
///   the contact compresses), peak force K d^e;
/// - with no damping the rotor rebounds to its release height relative to the race.
fn rigid_wall_scene(damping: f64) -> Scene {
    let mut s = scene(0.0, 0.0);
    s.drag_enabled = false;
    s.contact_damping_n_s_per_m = damping;
    s.support_damping_n_s_per_m = 0.0;
    s.race_mass_kg = 1e6;
    s.race_polar_moi_kg_m2 = 1e3;
    s.support_stiffness_n_per_m_e = 1e18;
    // rtol 1e-8 so that integration error sits well below the 2.3e-5 physical bound above.
    s.solver.rtol = 1e-8;
    s
}

/// Rebound apex of y_rel after the first contact loss, and y_rel at release.
fn rebound(r: &DropReport) -> (f64, f64) {
    let o = r.orbit.as_ref().expect("orbit requested");
    let y_release = o.samples[0].y_rel_m;
    let t_loss = o
        .samples
        .iter()
        .skip_while(|p| p.contact_force_n == 0.0)
        .find(|p| p.contact_force_n == 0.0)
        .expect("the rotor left the race")
        .t_s;
    let apex = o
        .samples
        .iter()
        .filter(|p| p.t_s > t_loss)
        .map(|p| p.y_rel_m)
        .fold(f64::NEG_INFINITY, f64::max);
    (apex, y_release)
}

#[test]
fn undamped_hertz_impact_gives_back_its_energy() {
    let s = rigid_wall_scene(0.0);
    // 14 ms: touch at 5.5 ms, 0.35 ms of contact, apex at about 11.4 ms, and the second
    // touch (about 17 ms) still outside the window, so exactly one impact is seen.
    // Orbit points every 1 us: every step end is recorded (free-flight steps are 20 us).
    let o = DropOptions {
        duration_s: 0.014,
        orbit_points: Some(14_000),
        ..Default::default()
    };
    let r = simulate(&s, &o).unwrap();
    assert_eq!(r.features.impacts, 1, "one impact in the window");

    let b = Bodies::of(&s);
    let sag = (s.race_mass_kg * b.g / s.support_stiffness_n_per_m_e).powf(1.0 / 1.5);
    let h = s.clearance_m + sag;
    let drop_energy = b.m_r * b.g * h;

    // No damper anywhere: the only "damping" entry is the elastic energy left at the
    // located contact loss, K |delta|^(e+1) with |delta| ~ v * 4 eps t ~ 1e-18 m: nil.
    assert!(
        r.energy.damping_loss_j.abs() <= 1e-12 * drop_energy,
        "damping loss {:e} J with no dampers",
        r.energy.damping_loss_j
    );
    // Nothing dissipates, so the mechanical energy (rotor + race, ringing included) must
    // come back whole; the audit's residual_rel divides by the race's 0.27 J of potential
    // energy here, so check against the drop energy instead. Only integration error
    // remains, and it is larger than rtol: F ~ delta^(10/9) is only C^1 at delta = 0, so
    // the first step after onset and the step into the loss are low-order and their error
    // escapes the 5(4) estimate (measured: -1.0e-8 J and +2.7e-8 J in those two steps,
    // 2.0e-6 of the drop energy net, at rtol 1e-8). 1e-5 of the drop energy is 5x that.
    let e = &r.energy;
    let created = e.final_j - e.initial_j + e.friction_heat_j + e.damping_loss_j + e.drag_work_j;
    assert!(
        created.abs() < 1e-5 * drop_energy,
        "energy not given back: {created:e} J of {drop_energy:e} J ({e:?})"
    );

    // Peak force against a rigid wall, gravity included: Newton on
    // f(d) = K d^(e+1)/(e+1) - m g (h + d).
    let (k, e) = (s.contact_stiffness_n_per_m_e, s.contact_exponent);
    let mut d = ((e + 1.0) * drop_energy / k).powf(1.0 / (e + 1.0));
    for _ in 0..50 {
        let f = k * d.powf(e + 1.0) / (e + 1.0) - b.m_r * b.g * (h + d);
        let df = k * d.powf(e) - b.m_r * b.g;
        d -= f / df;
    }
    let f_peak = k * d.powf(e);
    // Race motion <= 3.4e-11 m of 5.8e-6 m penetration changes F ~ d^1.11 by < 1e-5 and
    // rtol 1e-8 adds nothing visible: 1e-4 is 10x that bound.
    let fr = r.features.first_contact_force_n;
    assert!(
        rel(fr, f_peak, 0.0) < 1e-4,
        "peak force {fr} N, rigid-wall closed form {f_peak} N (penetration {d:e} m)"
    );

    // Rebound: deficit <= ringing energy (2.3e-5 h) + apex sampling g dt^2/8 with
    // dt <= 20 us (3.3e-6 h) + race ringing amplitude (2e-7 h): under 2.7e-5 h; 1e-4 h.
    let (apex, y_release) = rebound(&r);
    assert!(
        (apex - y_release).abs() < 1e-4 * h,
        "rebound apex y_rel {apex:e} m vs release {y_release:e} m (drop height {h:e} m)"
    );

    // Control: the same harness sees the loss of the paper's contact damper (c1 = 1000),
    // so the assertions above can fail. A 1000 N s/m damper over ~0.3 ms at ~0.05 m/s
    // takes well over 1 % of the 8.5 mJ drop energy.
    let damped = simulate(&rigid_wall_scene(1000.0), &o).unwrap();
    let (apex_d, _) = rebound(&damped);
    assert!(damped.energy.damping_loss_j > 1e-2 * drop_energy);
    assert!(y_release - apex_d > 1e-2 * h, "damped rebound {apex_d:e}");
    eprintln!(
        "undamped: F {fr:.3} N vs {f_peak:.3} N, rebound deficit {:.2e} h; damped: loss {:.3e} J, deficit {:.3e} h",
        (y_release - apex) / h,
        damped.energy.damping_loss_j,
        (y_release - apex_d) / h
    );
}

// ------------------------------------------------------------------------------------------
// 3. Block on a plane: the stick/slip machinery on a problem with a closed form
// ------------------------------------------------------------------------------------------

/// A block of mass m on a plane, normal force m g, pushed by P(t) = p0 + k t, with Coulomb
/// friction switched like the rotor-race contact. State: x, v, friction heat.
struct Block {
    m: f64,
    g: f64,
    mu_d: f64,
    mu_s: f64,
    p0: f64,
    k: f64,
    slip: Slip,
}

impl Block {
    fn push(&self, t: f64) -> f64 {
        self.p0 + self.k * t
    }
    /// Friction on the block's opponent along +x (the block gets its opposite); while
    /// sticking, the force that keeps v' = 0.
    fn friction(&self, t: f64) -> f64 {
        match self.slip {
            Slip::Slipping(sign) => self.mu_d * self.m * self.g * sign,
            Slip::Sticking => self.push(t),
        }
    }
    fn limit(&self) -> f64 {
        self.mu_s * self.m * self.g
    }
    /// Mode switch after the friction guard fired, as drop.rs does it.
    fn switch(&mut self, t: f64) {
        self.slip = match self.slip {
            Slip::Slipping(_) => stick_or_slip(self.push(t), self.limit()),
            Slip::Sticking => Slip::Slipping(if self.push(t) >= 0.0 { 1.0 } else { -1.0 }),
        };
    }
}

/// The block's one guard: the friction switch.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SlipSwitch;
impl GuardSet for SlipSwitch {
    const ALL: &'static [Self] = &[SlipSwitch];
}

impl OdeSystem<3> for Block {
    type Guard = SlipSwitch;
    fn rhs(&self, t: f64, y: &[f64; 3], dy: &mut [f64; 3]) {
        let f = self.friction(t);
        dy[0] = y[1];
        dy[1] = (self.push(t) - f) / self.m;
        dy[2] = f * y[1];
    }
    fn guards(&self, t: f64, y: &[f64; 3], g: &mut [f64; MAX_GUARDS]) -> usize {
        g[0] = match self.slip {
            Slip::Slipping(sign) => sign * y[1],
            Slip::Sticking => (self.limit() - self.push(t).abs()) / (self.m * self.g),
        };
        1
    }
}

/// Records (t, state) at every accepted step end.
#[derive(Default)]
struct Trace(Vec<(f64, [f64; 3])>);
impl Observer<Block, 3> for Trace {
    type Halt = Infallible;
    fn on_step(&mut self, _: &Block, step: &StepView<'_, 3>) -> ControlFlow<Infallible> {
        self.0.push((step.dense.t1(), step.dense.y1()));
        ControlFlow::Continue(())
    }
}

/// Runs the block to `t_end`, switching at every event; returns event times.
fn run_block(b: &mut Block, y: &mut [f64; 3], t_end: f64, trace: &mut Trace) -> Vec<f64> {
    let ctl = StepControl {
        rtol: 1e-10,
        atol: [1e-12; 3],
        h_min: 1e-14,
        max_attempts: 100_000,
        fixed_step: None,
    };
    let mut st = Dopri5::new(ctl);
    let mut t = 0.0;
    let mut events = Vec::new();
    loop {
        match integrate(&*b, &mut st, &mut t, y, t_end, trace).unwrap() {
            Stop::EndTime => break,
            Stop::Event { .. } => {
                events.push(t);
                b.switch(t);
                assert!(events.len() < 100, "chatter: {events:?}");
            }
            Stop::Halted(never) => match never {},
        }
    }
    events
}

#[test]
fn block_on_a_plane_sticks_then_slips_at_the_closed_form_times() {
    // Stick to slip: at rest, P = k t. Breakaway at t* = mu_s m g / k (0.981 s here); run
    // to 3 s, three times t*, so the slip phase is long and the velocity large.
    let (m, g, mu_d, mu_s, k) = (2.0, 9.81, 0.3, 0.5, 10.0);
    let mut b = Block {
        m,
        g,
        mu_d,
        mu_s,
        p0: 0.0,
        k,
        slip: stick_or_slip(0.0, mu_s * m * g),
    };
    assert_eq!(
        b.slip,
        Slip::Sticking,
        "at rest with no push the block sticks"
    );
    let mut y = [0.0; 3];
    let mut tr = Trace::default();
    let ev = run_block(&mut b, &mut y, 3.0, &mut tr);
    let ts = mu_s * m * g / k;
    // One breakaway and nothing else: after it v' = (k t - mu_d m g)/m > 0 since mu_s > mu_d.
    assert_eq!(ev.len(), 1, "events {ev:?}");
    // The guard is linear in t and located to rounding: 1e-12 relative.
    assert!(rel(ev[0], ts, 0.0) < 1e-12, "breakaway {} vs {ts}", ev[0]);
    assert_eq!(b.slip, Slip::Slipping(1.0));
    let v_exact = |t: f64| (k * (t * t - ts * ts) / 2.0 - mu_d * m * g * (t - ts)) / m;
    let x_exact = |t: f64| {
        (k * (t.powi(3) - ts.powi(3)) / 6.0
            - k * ts * ts * (t - ts) / 2.0
            - mu_d * m * g * (t - ts).powi(2) / 2.0)
            / m
    };
    let v_end = v_exact(3.0);
    for (t, yy) in &tr.0 {
        if *t <= ts {
            // Stuck: exactly at rest (v' = 0 in stick mode).
            assert_eq!(yy[1], 0.0, "moved while stuck at t {t}");
        } else {
            // v is a quadratic and x a cubic in t: DOPRI5 integrates them exactly, so only
            // rounding and the located start (~1e-16 s) remain; 1e-9 of the final speed.
            assert!(
                (yy[1] - v_exact(*t)).abs() < 1e-9 * v_end,
                "t {t}: v {} vs {}",
                yy[1],
                v_exact(*t)
            );
            assert!(
                (yy[0] - x_exact(*t)).abs() < 1e-9 * x_exact(3.0),
                "t {t}: x"
            );
        }
    }
    // Friction heat = mu_d m g * distance slid.
    assert!(rel(y[2], mu_d * m * g * x_exact(3.0), 0.0) < 1e-9);

    // Slip to stick: sliding at v0 with a constant push below mu_d m g (and below mu_s m g):
    // decelerates at (mu_d m g - p0)/m, stops at v0 m / (mu_d m g - p0) and stays stuck.
    // p0 = 0 is the brief's case; p0 > 0 makes the stick test use a non-zero demand.
    for (p0, mu_s) in [(0.0, 0.3), (0.0, 0.5), (0.5 * mu_d * m * g, 0.5)] {
        let v0 = 1.5;
        let mut b = Block {
            m,
            g,
            mu_d,
            mu_s,
            p0,
            k: 0.0,
            slip: Slip::Slipping(1.0),
        };
        let mut y = [0.0, v0, 0.0];
        let mut tr = Trace::default();
        // 2 s: about four times the stopping time (0.51 s with p0 = 0), so a chatter or
        // a creep after the stop would have time to show.
        let ev = run_block(&mut b, &mut y, 2.0, &mut tr);
        let decel = (mu_d * m * g - p0) / m;
        let t_stop = v0 / decel;
        let x_stop = v0 * v0 / (2.0 * decel);
        assert_eq!(ev.len(), 1, "p0 {p0}: one stop, no chatter: {ev:?}");
        assert!(
            rel(ev[0], t_stop, 0.0) < 1e-12,
            "stop {} vs {t_stop}",
            ev[0]
        );
        assert_eq!(b.slip, Slip::Sticking, "p0 {p0} < mu_s m g: stays stuck");
        for (t, yy) in tr.0.iter().filter(|(t, _)| *t > t_stop) {
            // Located to 4 eps t: the residual speed is decel * 4 eps t ~ 1e-15 m/s, and
            // stick mode holds it exactly (v' = 0), so 1e-12 m/s means "at rest".
            assert!(yy[1].abs() < 1e-12, "p0 {p0} t {t}: creeping at {}", yy[1]);
            assert!((yy[0] - x_stop).abs() < 1e-9 * x_stop, "p0 {p0} t {t}: x");
        }
        // The friction heat is the work of the friction over the slide.
        let heat = mu_d * m * g * x_stop;
        assert!(rel(y[2], heat, 0.0) < 1e-9, "heat {} vs {heat}", y[2]);
    }
}

// ------------------------------------------------------------------------------------------
// 4. Energy audit
// ------------------------------------------------------------------------------------------

#[test]
fn energy_audit_closes_on_full_drops() {
    let mut unbalanced = scene(8000.0, 0.2);
    unbalanced.unbalance_m = 20e-6;
    let cases = [
        ("8000 r/min mu 0.1", scene(8000.0, 0.1)),
        ("8000 r/min mu 0.3", scene(8000.0, 0.3)),
        ("3000 r/min mu 0.2", scene(3000.0, 0.2)),
        ("8000 r/min mu 0.2 e 20 um", unbalanced),
        ("8000 r/min mu 0.4 (whirl)", scene(8000.0, 0.4)),
    ];
    for (name, s) in cases {
        // 0.3 s: about a dozen impacts, the race spun up and the pendulum settled; the
        // whirl cases (mu 0.4, and the unbalanced one) stop earlier by the 5-net-turn
        // rule, at 55 and 65 ms.
        let r = run(&s, 0.3);
        let en = r.energy;
        eprintln!("{name}: {en:?} stop {:?}", r.stop_reason);
        for (what, v) in [
            ("initial", en.initial_j),
            ("final", en.final_j),
            ("friction", en.friction_heat_j),
            ("damping", en.damping_loss_j),
            ("drag", en.drag_work_j),
            ("residual", en.residual_rel),
        ] {
            assert!(v.is_finite(), "{name}: {what} = {v}");
        }
        // The residual is integration error only; these drops carry the spin's 1 kJ (or
        // 143 J at 3000 r/min) so rtol-level errors in the ~10 J exchanged are << 1e-6.
        assert!(en.residual_rel < 1e-6, "{name}: {en:?}");
        assert!(en.friction_heat_j >= 0.0, "{name}: {en:?}");
        assert!(en.damping_loss_j >= 0.0, "{name}: {en:?}");
        assert!(en.drag_work_j >= 0.0, "{name}: {en:?}");
        // The spin is not created: the drop ends with less mechanical energy.
        assert!(en.final_j < en.initial_j, "{name}: {en:?}");
    }
    assert_eq!(
        run(&scene(8000.0, 0.4), 0.3).stop_reason,
        StopReason::WhirlDecided
    );
}

// ------------------------------------------------------------------------------------------
// 5. Angular momentum
// ------------------------------------------------------------------------------------------

/// Integrates the external torque about the housing centre on every accepted step:
/// gravity, `-g (m_r x_c + m_b x_b)`, the moment of the contact pair, whose points are
/// `delta n` apart: `-delta F_t`, and the moment of the isotropic support damper's
/// tangential force `-c2 v_t` at the race centre: `-c2 (x_b v_yb - y_b v_xb)` (its radial
/// parts, the Hertz spring and the radial damper, push through the housing centre and have
/// none). The drag is off.
struct TorqueIntegral {
    b: Bodies,
    /// Tangential support damping (N s/m): c2 with the isotropic damper, 0 with radial-only.
    c2_t: f64,
    integral: f64,
    /// The contact-pair part alone, to show the check resolves it.
    pair_integral: f64,
}

impl Observer<DropSystem, N> for TorqueIntegral {
    type Halt = Infallible;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Infallible> {
        let d = step.dense;
        let (t0, t1) = (d.t0(), d.t1());
        let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
        for (xi, w) in GL5 {
            let y = d.eval(mid + half * xi);
            let f = sys.forces(&y);
            let (c, _) = self.b.rotor_mass_centre(&y);
            let pair = -f.delta_m * f.friction_n;
            let damper = if sys.mode.support {
                -self.c2_t * (y[ix::XB] * y[ix::VYB] - y[ix::YB] * y[ix::VXB])
            } else {
                0.0
            };
            let tau = -self.b.g * (self.b.m_r * c[0] + self.b.m_b * y[ix::XB]) + pair + damper;
            self.integral += w * half * tau;
            self.pair_integral += w * half * pair;
        }
        ControlFlow::Continue(())
    }
}

#[test]
fn angular_momentum_is_exchanged_not_created_with_drag_off() {
    let unbalanced = |rpm: f64| {
        let mut s = scene(rpm, 0.1);
        s.unbalance_m = 20e-6;
        s.unbalance_phase_rad = 0.7;
        s
    };
    let mut radial = scene(8000.0, 0.1);
    radial.support_damper = whirlmap_core::SupportDamper::RadialOnly;
    let cases = [
        // 0.3 s: the race spins up to rolling and the pendulum settles: the full exchange.
        ("8000 r/min mu 0.1", scene(8000.0, 0.1), 0.3),
        ("8000 r/min mu 0.1 radial-only support damper", radial, 0.3),
        ("3000 r/min mu 0.3", scene(3000.0, 0.3), 0.3),
        ("3000 r/min mu 0.1 e 20 um", unbalanced(3000.0), 0.3),
        // Whirl cases: 0.05 s ends before `simulate`'s 5-turn stop (53 to 65 ms with drag
        // off), so the driver and `simulate` integrate the same interval.
        ("8000 r/min mu 0.4 whirl", scene(8000.0, 0.4), 0.05),
        ("8000 r/min mu 0.1 e 20 um whirl", unbalanced(8000.0), 0.05),
    ];
    for (name, mut s, dur) in cases {
        s.drag_enabled = false;
        let mut obs = TorqueIntegral {
            b: Bodies::of(&s),
            c2_t: match s.support_damper {
                whirlmap_core::SupportDamper::Isotropic => s.support_damping_n_s_per_m,
                whirlmap_core::SupportDamper::RadialOnly => 0.0,
            },
            integral: 0.0,
            pair_integral: 0.0,
        };
        let run = drive(&s, dur, &mut obs);
        assert_eq!(run.t, dur);

        let l0 = obs.b.angular_momentum(&run.y0);
        let l1 = obs.b.angular_momentum(&run.y);
        let exchanged = (obs.b.j_r * (run.y[ix::WR] - run.y0[ix::WR])).abs();
        let imbalance = (l1 - l0) - obs.integral;
        eprintln!(
            "{name}: L0 {l0:.6e} dL {:.6e} int tau {:.6e} (pair {:.3e}) exchanged {exchanged:.3e} imbalance {imbalance:.3e} ({:.2e})",
            l1 - l0,
            obs.integral,
            obs.pair_integral,
            imbalance.abs() / exchanged
        );
        // The exchange must be real for the check to mean anything.
        assert!(exchanged > 1e-3 * l0.abs(), "{name}: nothing exchanged");
        // Tolerance. With e = 0 every RHS evaluation has R_b J_r w_r' + r_r J_b w_b' = 0,
        // a linear invariant that Runge-Kutta methods keep to rounding, so the spin exchange
        // itself carries no integration error; what does is the orbital part m r x v
        // (<= m_r s v_ref ~ 5e-5 kg m^2/s), held to about rtol (1e-5) of itself: ~5e-10,
        // 1e-7 of the smallest exchange here (7e-3 kg m^2/s); with unbalance the e-terms
        // (e m_r w v ~ 1e-5 kg m^2/s) add the same order. 1e-6 of the exchange is 10x that,
        // and still 25x below the contact-pair moment's integral (printed: 3e-5 to 1.4e-4
        // of the exchange), so dropping that term, a wrong lever arm (s / R_b = 0.75 %) or
        // a race friction with the printed eqs. 4-6 sign (~2x the exchange) all fail.
        assert!(
            imbalance.abs() < 1e-6 * exchanged,
            "{name}: L(T) - L(0) = {:e}, external torque integral {:e}, exchanged {exchanged:e}",
            l1 - l0,
            obs.integral
        );
        assert!(
            imbalance.abs() < 1e-2 * obs.pair_integral.abs(),
            "{name}: the check does not resolve the contact-pair moment ({:e})",
            obs.pair_integral
        );
    }
}

// ------------------------------------------------------------------------------------------
// 6. Force and power signs
// ------------------------------------------------------------------------------------------

/// Samples F_n and F_t v_rel at every accepted step's midpoint and end, and the friction
/// heat at step ends.
#[derive(Default)]
struct SignWatch {
    /// v_ref rtol: the drift speed allowed for v_rel while sticking (see the test).
    v_drift: f64,
    min_fn: f64,
    min_fn_t: f64,
    /// Smallest F_t v_rel outside stick (slipping, or no contact).
    min_power: f64,
    min_power_t: f64,
    /// Largest -F_t v_rel / (|F_t| v_drift) while sticking: > 1 fails.
    max_stick_ratio: f64,
    max_stick_ratio_t: f64,
    stick_samples: u64,
    heat_prev: f64,
    max_heat_drop: f64,
    samples: u64,
}

impl Observer<DropSystem, N> for SignWatch {
    type Halt = Infallible;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Infallible> {
        let d = step.dense;
        for t in [0.5 * (d.t0() + d.t1()), d.t1()] {
            let y = d.eval(t);
            let f = sys.forces(&y);
            self.samples += 1;
            if f.normal_n < self.min_fn {
                self.min_fn = f.normal_n;
                self.min_fn_t = t;
            }
            if sys.mode.contact && sys.mode.slip == Slip::Sticking {
                self.stick_samples += 1;
                let r = -f.friction_power_w / (f.friction_n.abs() * self.v_drift);
                if r > self.max_stick_ratio {
                    self.max_stick_ratio = r;
                    self.max_stick_ratio_t = t;
                }
            } else if f.friction_power_w < self.min_power {
                self.min_power = f.friction_power_w;
                self.min_power_t = t;
            }
        }
        let heat = d.y1()[ix::E_FRIC];
        self.max_heat_drop = self.max_heat_drop.max(self.heat_prev - heat);
        self.heat_prev = heat;
        ControlFlow::Continue(())
    }
}

#[test]
fn normal_force_is_never_negative_and_friction_never_adds_energy() {
    let mut unbalanced = scene(8000.0, 0.2);
    unbalanced.unbalance_m = 20e-6;
    // A stick-to-slip switch where the sticking contact's v_rel has drifted against the
    // friction demand (at 78.7 ms): before the mode-entry rule of `drop.rs`
    // (`slip_along_drift`) the slip started with its guard already negative, unwatched, and
    // the friction ran v_rel to -100 m/s making 1 kJ.
    let mut loose = scene(8000.0, 0.3);
    loose.solver.method = whirlmap_core::Method::Ros34pw2;
    loose.solver.free_flight_gap_bound = true;
    loose.solver.rtol = 3e-4;
    let cases = [
        // Pendulum cases: 0.3 s, through the race's spin-up to rolling (stick phases) and
        // the settling of the pendulum, where the rotor grazes the race.
        ("8000 r/min mu 0.1", scene(8000.0, 0.1), 0.3, true),
        ("3000 r/min mu 0.3", scene(3000.0, 0.3), 0.3, true),
        // Whirl cases: 0.05 s ends before the 5-turn rule would stop `simulate` (55-65 ms).
        ("8000 r/min mu 0.4 whirl", scene(8000.0, 0.4), 0.05, true),
        ("8000 r/min mu 0.2 e 20 um whirl", unbalanced, 0.05, true),
        // The stick-drift and heat-drop bounds below are DOPRI5's at its rtol; ROS34PW2 at
        // rtol 3e-4 drifts more while sticking (measured: 15x the bound, heat falling by
        // 1.2e-7 J), so this case checks the signs of F_n and of the slipping F_t v_rel.
        ("8000 r/min mu 0.3 ROS34PW2 rtol 3e-4", loose, 0.3, false),
    ];
    let mut failures = Vec::new();
    let mut stick_samples = 0;
    for (name, s, dur, stick_bounds) in cases {
        let mut w = SignWatch {
            v_drift: s.solver.rtol * (2.0 * s.gravity_m_s2 * s.clearance_m).sqrt(),
            ..Default::default()
        };
        let run = drive(&s, dur, &mut w);
        assert_eq!(run.t, dur);
        stick_samples += w.stick_samples;
        eprintln!(
            "{name}: {} samples ({} in stick); min F_n {:.3e} N at {:.9} s; min F_t v_rel out of stick {:.3e} W at {:.9} s; stick drift ratio {:.3} at {:.9} s; max heat drop {:.3e} J",
            w.samples, w.stick_samples, w.min_fn, w.min_fn_t, w.min_power, w.min_power_t,
            w.max_stick_ratio, w.max_stick_ratio_t, w.max_heat_drop
        );
        // F_n: inside a contact phase the guard keeps it > 0; at a located loss the
        // truncated step ends within 4 eps t (~3e-16 s) past the zero, where F_n has moved
        // by |dF/dt| * 3e-16 s < 1e-6 N for any |dF/dt| below 3e9 N/s (a 4 kN impact
        // rising in over 1 us). Measured at located losses: ~5e-10 N.
        if w.min_fn < -1e-6 {
            failures.push(format!(
                "{name}: F_n = {:e} N at t = {:.9} s (a contact loss missed inside a step)",
                w.min_fn, w.min_fn_t
            ));
        }
        // F_t v_rel while slipping: the guard keeps sign * v_rel > 0; at a located reversal
        // v_rel is |v_rel'| (< 1e4 m/s^2) * 3e-16 s, times F_t (< 1e3 N): < 1e-9 W. 1e-6 W.
        if w.min_power < -1e-6 {
            failures.push(format!(
                "{name}: F_t v_rel = {:e} W at t = {:.9} s while slipping",
                w.min_power, w.min_power_t
            ));
        }
        // F_t v_rel while sticking: the RHS holds v_rel' = 0 exactly, so v_rel drifts from
        // its located ~0 only by the local error of the (nonlinear) tangential relative
        // velocity, which error control holds to about rtol of the relative speeds; their
        // scale is the impact speed v_ref = sqrt(2 g s) (the solver's own velocity scale;
        // whirl orbits reach ~2 v_ref). So |v_rel| <= rtol v_ref, i.e. F_t v_rel >=
        // -|F_t| rtol v_ref (measured: up to ~0.2 of that, printed as the ratio).
        if stick_bounds && w.max_stick_ratio > 1.0 {
            failures.push(format!(
                "{name}: while sticking F_t v_rel = -{:.2} |F_t| rtol v_ref at t = {:.9} s",
                w.max_stick_ratio, w.max_stick_ratio_t
            ));
        }
        // The accumulated heat never falls by more than its own absolute tolerance
        // (rtol * m_r g s * 1e-2 ~ 8.5e-10 J): a negative Runge-Kutta weight acting on a
        // power that is ~0 in stick is the only way down.
        let atol_e = s.solver.rtol * Bodies::of(&s).m_r * s.gravity_m_s2 * s.clearance_m * 1e-2;
        if stick_bounds && w.max_heat_drop > atol_e {
            failures.push(format!(
                "{name}: friction heat fell by {:e} J",
                w.max_heat_drop
            ));
        }
    }
    // The stick branch must have been exercised for the stick epsilon to mean anything.
    assert!(stick_samples > 100, "no stick phase sampled");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ------------------------------------------------------------------------------------------
// 7. Mirror symmetry
// ------------------------------------------------------------------------------------------

#[test]
fn mirrored_spin_mirrors_the_orbit() {
    // 0.2 s: about 14 impacts and the race spun up: long enough for rounding differences
    // to be amplified if the mirror symmetry were broken anywhere in the model.
    let o = DropOptions {
        duration_s: 0.2,
        orbit_points: Some(4000),
        ..Default::default()
    };
    let a = simulate(&scene(8000.0, 0.2), &o).unwrap();
    let b = simulate(&scene(-8000.0, 0.2), &o).unwrap();
    // The mirrored problem (x -> -x, angles and spins negated) is nearly the same sequence
    // of floating-point operations up to signs (the stick solve evaluates at F_t = +1 in
    // both, so rounding differs), so results agree to rounding amplified by the run:
    // features measured <= 1.4e-13 relative (printed); 1e-6 relative is the brief's bound.
    const TOL: f64 = 1e-6;
    let (fa, fb) = (a.features, b.features);
    for (what, x, y) in [
        (
            "first_contact_force_n",
            fa.first_contact_force_n,
            fb.first_contact_force_n,
        ),
        (
            "max_contact_force_n",
            fa.max_contact_force_n,
            fb.max_contact_force_n,
        ),
        (
            "peak_friction_power_w",
            fa.peak_friction_power_w,
            fb.peak_friction_power_w,
        ),
        (
            "peak_heat_power_w",
            fa.peak_heat_power_w,
            fb.peak_heat_power_w,
        ),
        (
            "friction_heat_j",
            a.energy.friction_heat_j,
            b.energy.friction_heat_j,
        ),
        ("drag_work_j", a.energy.drag_work_j, b.energy.drag_work_j),
        ("net_whirl_turns", fa.net_whirl_turns, fb.net_whirl_turns),
        (
            "whirl_frequency_hz",
            fa.whirl_frequency_hz,
            fb.whirl_frequency_hz,
        ),
        (
            "final_rotor_speed_rpm (mirrored)",
            fa.final_rotor_speed_rpm,
            -fb.final_rotor_speed_rpm,
        ),
        (
            "final_race_speed_rpm (mirrored)",
            fa.final_race_speed_rpm,
            -fb.final_race_speed_rpm,
        ),
    ] {
        eprintln!("mirror {what}: {:.1e}", rel(x, y, 1e-12));
        assert!(rel(x, y, 1e-12) < TOL, "{what}: {x} vs {y}");
    }
    assert_eq!(fa.impacts, fb.impacts);
    let (oa, ob) = (a.orbit.unwrap(), b.orbit.unwrap());
    assert_eq!(oa.samples.len(), ob.samples.len(), "orbit sample count");
    let s = oa.clearance_m;
    let f_scale = fa.max_contact_force_n;
    // Orbit samples are taken at step ends, and the two runs' step sequences drift apart
    // by rounding (measured: 2.4e-9 s by t = 0.2 s), so sample i of one run is compared
    // with sample i of the other a few ns away. The allowance is 1e-6 (of s, of F_max)
    // plus what the orbit moves in that time shift: the local rate (from the neighbouring
    // samples of run a) times |dt|. Times themselves must agree to 1e-6 relative.
    let pa = &oa.samples;
    let mut worst = 0.0f64;
    for (i, (p, q)) in pa.iter().zip(&ob.samples).enumerate() {
        assert!(rel(p.t_s, q.t_s, 1e-9) < TOL, "t {} vs {}", p.t_s, q.t_s);
        let dt = (p.t_s - q.t_s).abs();
        let (mut v, mut fdot) = (0.0f64, 0.0f64);
        for j in [i.saturating_sub(1), i] {
            if let (Some(u), Some(w)) = (pa.get(j), pa.get(j + 1)) {
                let h = w.t_s - u.t_s;
                if h > 0.0 {
                    v = v.max((w.x_rel_m - u.x_rel_m).hypot(w.y_rel_m - u.y_rel_m) / h);
                    fdot = fdot.max((w.contact_force_n - u.contact_force_n).abs() / h);
                }
            }
        }
        let tol_x = TOL * s + v * dt;
        let tol_f = TOL * f_scale + fdot * dt;
        let (dx, dy) = ((p.x_rel_m + q.x_rel_m).abs(), (p.y_rel_m - q.y_rel_m).abs());
        let df = (p.contact_force_n - q.contact_force_n).abs();
        worst = worst.max(dx / tol_x).max(dy / tol_x).max(df / tol_f);
        assert!(
            dx <= tol_x && dy <= tol_x && df <= tol_f,
            "t {} / {}: ({}, {}, {}) vs ({}, {}, {})",
            p.t_s,
            q.t_s,
            p.x_rel_m,
            p.y_rel_m,
            p.contact_force_n,
            q.x_rel_m,
            q.y_rel_m,
            q.contact_force_n
        );
    }
    // The orbit must actually leave the axis for the mirror test to mean anything.
    let max_x = oa
        .samples
        .iter()
        .map(|p| p.x_rel_m.abs())
        .fold(0.0, f64::max);
    assert!(max_x > 1e-2 * s, "orbit never left x = 0");
    eprintln!(
        "mirror: worst orbit difference {worst:.2} of its allowance, max |x_rel| {max_x:.2e} m"
    );

    // Whirl: both stop by the rule with the same signed (relative) whirl frequency.
    // 0.3 s is a cap: the rule fires at about 55 ms.
    let a = run(&scene(8000.0, 0.4), 0.3);
    let b = run(&scene(-8000.0, 0.4), 0.3);
    assert_eq!(a.stop_reason, StopReason::WhirlDecided);
    assert_eq!(b.stop_reason, StopReason::WhirlDecided);
    assert!(a.features.whirl_frequency_hz < 0.0, "backward whirl");
    assert!(
        rel(
            a.features.whirl_frequency_hz,
            b.features.whirl_frequency_hz,
            0.0
        ) < TOL,
        "{} vs {}",
        a.features.whirl_frequency_hz,
        b.features.whirl_frequency_hz
    );
    assert!(rel(a.end_time_s, b.end_time_s, 0.0) < TOL);
}

/// A drop without spin (and without unbalance) is mirror-symmetric about the vertical: it
/// must stay in the vertical plane, the rotor sitting in the race with no slip, no friction,
/// no race spin, and the contact never pulling. The sticking friction is then exactly zero, so
/// at every lift-off the sticking contact's friction guard (`mu_s F_n - |F_t|`) reaches zero
/// together with the contact's (`F_n`): before the driver took simultaneous jumps, the stick
/// ended, the contact stayed closed with its guard violated, pulled the rotor with a negative
/// normal force (-7.8 N at the paper's damper) and a friction `mu F_n` along +t, and the drop
/// left the plane with negative friction heat (-1e-3 J, and 34 W of friction power at zero
/// spin, with a damper of 3e3 N s/m). Without a damper the contact starts with no force, and
/// sticks with a friction guard of exactly zero: a first version of the rule switched that
/// stick to a slip whose own guard started at zero and was never watched (-1788 J of friction
/// heat). The contact dampers are none, the paper's and three stiffer ones, at the default
/// numerics.
#[test]
fn a_drop_without_spin_stays_in_the_vertical_plane() {
    for c1 in [0.0, 1e3, 3e3, 1e4, 1e5] {
        let mut s = Scene::paper();
        s.speed_rpm = 0.0;
        s.contact_damping_n_s_per_m = c1;
        let mut w = SignWatch {
            v_drift: s.solver.rtol * (2.0 * s.gravity_m_s2 * s.clearance_m).sqrt(),
            ..Default::default()
        };
        let run = drive(&s, 1.0, &mut w);
        let y = run.y;
        eprintln!(
            "c1 {c1}: min F_n {:.3e} N at {:.6} s; x_r {:e}, x_b {:e}, spins {:e} {:e}, heat {:e} J",
            w.min_fn, w.min_fn_t, y[ix::XR], y[ix::XB], y[ix::WR], y[ix::WB], y[ix::E_FRIC]
        );
        // The bound on F_n at a located loss is the one derived in
        // `normal_force_is_never_negative_and_friction_never_adds_energy`.
        assert!(
            w.min_fn > -1e-6,
            "c1 {c1}: F_n = {} N at {} s",
            w.min_fn,
            w.min_fn_t
        );
        // Exact symmetry: every horizontal quantity is computed from zeros (measured: 0).
        for (what, v) in [
            ("x_r", y[ix::XR]),
            ("v_x,r", y[ix::VXR]),
            ("x_b", y[ix::XB]),
            ("v_x,b", y[ix::VXB]),
            ("omega_r", y[ix::WR]),
            ("omega_b", y[ix::WB]),
            ("friction heat", y[ix::E_FRIC]),
            ("drag work", y[ix::E_DRAG]),
        ] {
            assert!(
                v.abs() < 1e-12,
                "c1 {c1}: {what} = {v:e} (the drop left the plane)"
            );
        }
    }
}

/// Samples, while the contact sticks, how far the friction that keeps it rolling exceeds
/// eq. 10's static limit `mu_s F_n`, at every accepted step's midpoint and end.
struct StickWatch {
    mu_s: f64,
    /// Largest `|F_t| - mu_s F_n` (N) while sticking, and where.
    max_excess_n: f64,
    max_excess_t: f64,
    stick_samples: u64,
}

impl Observer<DropSystem, N> for StickWatch {
    type Halt = Infallible;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Infallible> {
        if !(sys.mode.contact && sys.mode.slip == Slip::Sticking) {
            return ControlFlow::Continue(());
        }
        let d = step.dense;
        for t in [0.5 * (d.t0() + d.t1()), d.t1()] {
            let f = sys.forces(&d.eval(t));
            self.stick_samples += 1;
            let excess = f.friction_n.abs() - self.mu_s * f.normal_n;
            if excess > self.max_excess_n {
                self.max_excess_n = excess;
                self.max_excess_t = t;
            }
        }
        ControlFlow::Continue(())
    }
}

/// A sticking contact holds eq. 10 (`|F_t| <= mu_s F_n`) for as long as it sticks, also
/// across the race's lift-off from its balls. The isotropic support damper acts only while
/// the race is on its balls, so at a lift-off the race's acceleration jumps, and with it the
/// friction the rolling constraint needs (eq. 9). Before the driver took the jumps of guards
/// sent negative by a jump, a stick whose demand jumped past the limit went on sticking:
/// 0.72 N over it in one of the main job's probability members (2000 r/min, mu 0.45, the
/// drawn release below), which this test replays at the default numerics, with two grid cells.
#[test]
fn sticking_friction_stays_within_the_static_limit() {
    let mut member = Scene::paper();
    member.speed_rpm = 2000.0;
    member.mu_dynamic = 0.45;
    member.unbalance_m = 1.757769620565613e-6;
    member.unbalance_phase_rad = 0.23554645281109138;
    member.release_offset_m = [-3.321985999685223e-6, -3.1635609127539882e-6];
    member.release_velocity_m_s = [0.00066257464817945, -0.0006957551207959494];
    member.race_speed_rad_s = 7.439089156463848;
    let cell = |speed_rpm: f64, mu: f64| {
        let mut s = Scene::paper();
        s.speed_rpm = speed_rpm;
        s.mu_dynamic = mu;
        s
    };
    let mut stick_samples = 0;
    for (name, s, dur) in [
        ("probability member", member, 0.5),
        ("8000 r/min mu 0.1", cell(8000.0, 0.1), 1.0),
        ("4000 r/min mu 0.4", cell(4000.0, 0.4), 0.5),
    ] {
        let f_ref = Bodies::of(&s).m_r * s.gravity_m_s2;
        let mut w = StickWatch {
            mu_s: s.mu_static(),
            max_excess_n: f64::NEG_INFINITY,
            max_excess_t: 0.0,
            stick_samples: 0,
        };
        drive(&s, dur, &mut w);
        eprintln!(
            "{name}: {} samples in stick; largest |F_t| - mu_s F_n {:.3e} N at {:.9} s",
            w.stick_samples, w.max_excess_n, w.max_excess_t
        );
        stick_samples += w.stick_samples;
        // Inside a stick phase the friction guard keeps the excess below zero; at a located
        // stick-to-slip switch the step ends past the zero by the locator's resolution
        // (4 eps t), where the excess has moved by far less than 1e-6 of the weight.
        assert!(
            w.max_excess_n <= 1e-6 * f_ref,
            "{name}: the sticking friction exceeds mu_s F_n by {} N at {} s",
            w.max_excess_n,
            w.max_excess_t
        );
    }
    assert!(stick_samples > 100, "no stick phase sampled");
}

// ------------------------------------------------------------------------------------------
// 8. Convergence in the tolerance
// ------------------------------------------------------------------------------------------

#[test]
fn metrics_converge_as_tolerance_tightens() {
    // Away from the whirl boundary (pendulum cases); 0.3 s, long enough for the race to
    // spin up, so the friction heat includes the whole slip phase.
    for (rpm, mu) in [(8000.0, 0.1), (8000.0, 0.2), (3000.0, 0.1)] {
        let coarse = scene(rpm, mu);
        let mut fine = coarse.clone();
        fine.solver.rtol = coarse.solver.rtol / 100.0;
        let (a, b) = (run(&coarse, 0.3), run(&fine, 0.3));
        // Same regime at both tolerances (pendulum, run to the end), or the comparison
        // below would compare different physics.
        assert_eq!(a.stop_reason, StopReason::DurationReached);
        assert_eq!(b.stop_reason, StopReason::DurationReached);
        for (what, x, y) in [
            (
                "first_contact_force_n",
                a.features.first_contact_force_n,
                b.features.first_contact_force_n,
            ),
            (
                "max_contact_force_n",
                a.features.max_contact_force_n,
                b.features.max_contact_force_n,
            ),
            (
                "peak_friction_power_w",
                a.features.peak_friction_power_w,
                b.features.peak_friction_power_w,
            ),
            (
                "peak_heat_power_w",
                a.features.peak_heat_power_w,
                b.features.peak_heat_power_w,
            ),
            (
                "friction_heat_j",
                a.energy.friction_heat_j,
                b.energy.friction_heat_j,
            ),
        ] {
            let d = rel(x, y, 0.0);
            eprintln!("{rpm} r/min mu {mu}: {what} {x} vs {y} ({d:.2e})");
            // 0.5 %: the brief's bound for "converged"; these are the outputs a design
            // chart is drawn from. Measured (printed): forces and peak powers within 1e-4,
            // friction heat within 4.4e-4 (it integrates over every slip phase).
            assert!(d < 5e-3, "{rpm} r/min mu {mu}: {what} {x} vs {y}");
        }
    }
}

// ------------------------------------------------------------------------------------------
// 9. Extreme inputs
// ------------------------------------------------------------------------------------------

// Measured at default rtol (1e-5), 0.1 s each (`--nocapture` prints them; counts move a
// little as the model code changes). Every input finishes; none returns an error:
//   input              steps  rejected events  stop             residual_rel
//   speed 0            5445   309      168     duration 0.1 s   1.8e-5 (see audit bound)
//   speed 1 r/min      5446   218      151     duration         1.6e-5
//   speed 60000 r/min  5997   259      103     duration         2.4e-12
//   mu 0               5280   217      111     duration         1.7e-10
//   mu 1               5319   251      4       whirl at 43 ms   3.0e-10
//   mu 2               5298   279      2       whirl at 43 ms   4.2e-10
//   clearance 1e-6 m   11238  1319     5       duration         8.8e-13
//   clearance 2e-3 m   5235   138      24      duration         1.2e-9
//   stiffness x100     22214  3866     465     duration         7.9e-11
//   stiffness x0.01    3570   343      25      duration         7.9e-12
//   damping 0 (both)   8103   1128     278     duration         5.3e-9
//   unbalance 50 um    6091   730      215     whirl at 84 ms   8.8e-9
#[test]
fn extreme_inputs_finish_or_fail_typed() {
    let with = |f: &dyn Fn(&mut Scene)| {
        let mut s = scene(8000.0, 0.1);
        f(&mut s);
        s
    };
    let cases: Vec<(&str, Scene)> = vec![
        ("speed 0", with(&|s| s.speed_rpm = 0.0)),
        ("speed 1 r/min", with(&|s| s.speed_rpm = 1.0)),
        ("speed 60000 r/min", with(&|s| s.speed_rpm = 60000.0)),
        ("mu 0", with(&|s| s.mu_dynamic = 0.0)),
        ("mu 1", with(&|s| s.mu_dynamic = 1.0)),
        ("mu 2", with(&|s| s.mu_dynamic = 2.0)),
        ("clearance 1e-6 m", with(&|s| s.clearance_m = 1e-6)),
        ("clearance 2e-3 m", with(&|s| s.clearance_m = 2e-3)),
        (
            "contact stiffness x100",
            with(&|s| s.contact_stiffness_n_per_m_e *= 100.0),
        ),
        (
            "contact stiffness x0.01",
            with(&|s| s.contact_stiffness_n_per_m_e *= 0.01),
        ),
        (
            "damping 0 (both contacts)",
            with(&|s| {
                s.contact_damping_n_s_per_m = 0.0;
                s.support_damping_n_s_per_m = 0.0
            }),
        ),
        ("unbalance 50e-6 m", with(&|s| s.unbalance_m = 50e-6)),
    ];
    let mut failures = Vec::new();
    for (name, s) in cases {
        // 0.1 s: about a dozen impacts at the default clearance; enough to meet the stiff,
        // chattering or whirling regimes these inputs provoke (whirl stops earlier).
        let out = std::panic::catch_unwind(|| simulate(&s, &opts(0.1)));
        let Ok(out) = out else {
            failures.push(format!("{name}: simulate panicked"));
            continue;
        };
        let r = match out {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name}: typed error {} ({e})", e.kind());
                // A valid scene may fail only in the solver, never in validation.
                if matches!(e, SolveError::Invalid(_)) {
                    failures.push(format!("{name}: rejected as invalid: {e}"));
                }
                continue;
            }
        };
        eprintln!(
            "{name}: finished {:?} at {:.4} s, {} steps, {} rejected, {} events, residual {:.1e}",
            r.stop_reason,
            r.end_time_s,
            r.stats.steps,
            r.stats.rejected,
            r.stats.events,
            r.energy.residual_rel
        );
        let f = &r.features;
        for (what, v) in [
            ("first_contact_force_n", f.first_contact_force_n),
            ("max_contact_force_n", f.max_contact_force_n),
            ("max_contact_force_time_s", f.max_contact_force_time_s),
            ("peak_friction_power_w", f.peak_friction_power_w),
            ("peak_heat_power_w", f.peak_heat_power_w),
            ("first_contact_time_s", f.first_contact_time_s),
            ("contact_time_s", f.contact_time_s),
            ("net_whirl_turns", f.net_whirl_turns),
            ("whirl_frequency_hz", f.whirl_frequency_hz),
            ("window.contact_duty", f.window.stats.contact_duty),
            ("final_rotor_speed_rpm", f.final_rotor_speed_rpm),
            ("final_race_speed_rpm", f.final_race_speed_rpm),
            ("initial_j", r.energy.initial_j),
            ("final_j", r.energy.final_j),
            ("friction_heat_j", r.energy.friction_heat_j),
            ("damping_loss_j", r.energy.damping_loss_j),
            ("drag_work_j", r.energy.drag_work_j),
            ("residual_rel", r.energy.residual_rel),
            ("end_time_s", r.end_time_s),
        ] {
            if !v.is_finite() {
                failures.push(format!("{name}: {what} = {v}"));
            }
        }
        if r.stats.steps + r.stats.rejected > s.solver.max_step_attempts {
            failures.push(format!("{name}: over the step budget: {:?}", r.stats));
        }
        // Audit bound. The residual is integration error: error control holds each speed
        // to rtol of itself per step, so the kinetic energy an impact turns over (about
        // the drop energy m_r g s) is audited to a few rtol (measured 1.5-5 rtol at speed
        // 0 for rtol 1e-4 to 1e-9: it scales with rtol, so it is not a leak). The audit
        // divides by the largest energy in play: when the spin's energy is that scale the
        // impact term is negligible and the brief's 1e-6 governs; at speed 0 the scale is
        // m_r g s itself and 1e-6 is below what rtol 1e-5 can deliver, so the bound is
        // 1e-6 + 10 rtol m_r g s / scale (10 rtol: 2x the worst measured ratio).
        let e = &r.energy;
        let drop_energy = s.rotor_mass_kg * s.load_share * s.gravity_m_s2 * s.clearance_m;
        let scale = e
            .initial_j
            .abs()
            .max(e.final_j.abs())
            .max((e.friction_heat_j + e.damping_loss_j + e.drag_work_j).abs())
            .max(drop_energy);
        let bound = 1e-6 + 10.0 * s.solver.rtol * drop_energy / scale;
        if !(e.residual_rel < bound) {
            failures.push(format!(
                "{name}: energy audit residual {:e} > {bound:e} ({e:?})",
                e.residual_rel
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ------------------------------------------------------------------------------------------
// 10. The paper's first impact
// ------------------------------------------------------------------------------------------

#[test]
fn first_impact_is_near_the_papers_900_newtons() {
    // 0.02 s: the first impact (touch at 5.5 ms, merged episodes within 0.5 ms) is over.
    let r = run(&scene(8000.0, 0.1), 0.02);
    let f = r.features.first_contact_force_n;
    // The paper reads "about 900 N" off a plot; 10 % is the brief's band.
    assert!((f - 900.0).abs() < 0.1 * 900.0, "first impact {f} N");
}

// ------------------------------------------------------------------------------------------
// 11. The default numerics
// ------------------------------------------------------------------------------------------

/// Watches the friction heat accumulator: it may never fall (friction only dissipates).
#[derive(Default)]
struct HeatWatch {
    last: f64,
    max_drop_j: f64,
}

impl Observer<DropSystem, N> for HeatWatch {
    type Halt = Infallible;
    fn on_step(&mut self, _sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Infallible> {
        let e = step.dense.y1()[ix::E_FRIC];
        self.max_drop_j = self.max_drop_j.max(self.last - e);
        self.last = e;
        ControlFlow::Continue(())
    }
}

/// The scene defaults (the `standard` fidelity: RODAS4 then BDF at rtol 3e-5) keep the invariants to their own tolerance: the energy audit closes to less
/// than rtol of the largest energy, the friction heat never falls by more than rtol of itself
/// (while the contact sticks, its slip velocity is held by the constraint to integration
/// error, so F_t v_rel may dip below zero by that much), and the first impact is within the
/// accuracy budget (0.1 %) of DOPRI5 at 1e-9.
#[test]
fn standard_numerics_keep_the_invariants() {
    for (speed, mu, dur) in [(8000.0, 0.1, 1.0), (8000.0, 0.4, 0.2), (3000.0, 0.3, 0.5)] {
        let mut s = Scene::paper();
        s.speed_rpm = speed;
        s.mu_dynamic = mu;
        s.classification.max_extension_s = 0.0;
        let rtol = s.solver.rtol;
        let mut w = HeatWatch::default();
        let r = simulate_observed(&s, &opts(dur), &mut w).unwrap();
        let mut tight = scene(speed, mu);
        tight.solver.rtol = 1e-9;
        let t = run(&tight, 0.05);
        let e = &r.energy;
        let drop_j = Bodies::of(&s).m_r * s.gravity_m_s2 * s.clearance_m;
        eprintln!(
            "{speed} r/min mu {mu}: residual {:.2e}, heat drop {:.2e} J, first impact {:.2} vs {:.2} N",
            e.residual_rel, w.max_drop_j, r.features.first_contact_force_n,
            t.features.first_contact_force_n
        );
        // Measured: residuals 4e-6 to 9e-6; the heat falls by at most 1.5e-5 J of 12 J;
        // first impacts within 6e-5.
        assert!(e.residual_rel < rtol, "{speed} r/min mu {mu}: {e:?}");
        assert!(
            w.max_drop_j <= rtol * e.friction_heat_j.max(drop_j),
            "heat fell by {} J of {} J",
            w.max_drop_j,
            e.friction_heat_j
        );
        let rel = rel(
            r.features.first_contact_force_n,
            t.features.first_contact_force_n,
            1.0,
        );
        assert!(
            rel < 1e-3,
            "{speed} r/min mu {mu}: first impact off by {rel:e}"
        );
    }
}

/// An orbit's sample times strictly increase, also where a run ends on a step's end and the
/// final state is recorded (a whirl stopped by the whirl rule).
#[test]
fn orbit_sample_times_strictly_increase() {
    for (speed, mu) in [(8000.0, 0.4), (8000.0, 0.1)] {
        let o = DropOptions {
            duration_s: 0.3,
            orbit_points: Some(2000),
            ..Default::default()
        };
        let r = simulate(&scene(speed, mu), &o).unwrap();
        let orbit = r.orbit.expect("an orbit was asked for");
        assert!(orbit.samples.len() > 100, "{} samples", orbit.samples.len());
        for w in orbit.samples.windows(2) {
            assert!(
                w[1].t_s > w[0].t_s,
                "{speed} r/min, mu {mu}: samples at {} then {}",
                w[0].t_s,
                w[1].t_s
            );
        }
    }
}

// ------------------------------------------------------------------------------------------
// 12. Continuity at zero gravity
// ------------------------------------------------------------------------------------------

/// A vertical machine (g = 0): the race starts centred, where its zero-clearance support
/// carries nothing, and must still be held by its balls once it moves. The drop is the limit
/// of drops under a vanishing gravity: with g = 1e-6 m/s^2 the race's sag is 1e-14 m and the
/// fall's timing shifts by far less than the integration error. When the race started off
/// its support at g = 0 (its guard at zero never crossed), it ran free of its balls and the
/// same drop whirled at 22 kN instead of 905 N.
#[test]
fn a_drop_without_gravity_is_the_limit_of_a_vanishing_gravity() {
    let run_with = |g: f64| {
        let mut s = scene(8000.0, 0.3);
        s.gravity_m_s2 = g;
        // Something must bring the rotor to the race: a lateral release velocity.
        s.release_velocity_m_s = [0.005, 0.0];
        run(&s, 0.1)
    };
    let (zero, tiny) = (run_with(0.0), run_with(1e-6));
    let (f0, f1) = (
        zero.features.max_contact_force_n,
        tiny.features.max_contact_force_n,
    );
    let race_r = |r: &DropReport| r.final_state[ix::XB].hypot(r.final_state[ix::YB]);
    // Integration error at rtol 1e-5 (the two drops take different steps): 1e-3.
    assert!(
        rel(f0, f1, 0.0) < 1e-3,
        "max force {f0} N at g = 0, {f1} N at g = 1e-6"
    );
    // The race is held within micrometres of its support's centre.
    assert!(race_r(&zero) < 1e-5, "race {} m off centre", race_r(&zero));
}

// ------------------------------------------------------------------------------------------
// 13. A contact stepped over
// ------------------------------------------------------------------------------------------

/// A contact 5e6 times stiffer than the paper's at the default numerics, without friction:
/// the rotor once fell through the race (19 m in 2 s) and the drop passed its energy audit;
/// model version 8 failed it with the typed `unphysical` error ("a contact was stepped
/// over"). The cause was the event loop's, not the stiffness: the contact's guard reached
/// exactly zero (penetration exactly 0 at a graze), and the loop watched a guard only once
/// positive (version 10 watches it from zero). It now rocks at the bottom like the paper's rotor, its energy books
/// closed. (The check itself: `a_rotor_through_the_race_with_the_contact_open_is_unphysical`
/// in `drop.rs`.) Two deep penetrations that are not a stepped-over contact pass: a contact
/// the damper opened while still overlapping (never-pull rule, at g = 0 after a fast lateral
/// release), and a 400 t rotor sunk into the race with the contact acting.
#[test]
fn a_contact_5e6_times_stiffer_and_deep_penetrations_pass() {
    let opts = |duration_s: f64| DropOptions {
        duration_s,
        ..Default::default()
    };
    let mut stiffer = Scene::paper();
    stiffer.contact_stiffness_n_per_m_e = 1e16;
    stiffer.mu_dynamic = 0.0;
    let r = simulate(&stiffer, &opts(1.0)).unwrap_or_else(|e| panic!("stiffer: {e}"));
    assert_eq!(
        r.verdict.class,
        whirlmap_core::classify::OrbitClass::Pendulum
    );
    assert!(r.energy.residual_rel < 1e-6, "{:?}", r.energy);
    // The damper opened the contact while overlapping (its raw force negative): kept.
    let mut opened = Scene::paper();
    opened.speed_rpm = 1000.0;
    opened.gravity_m_s2 = 0.0;
    opened.release_velocity_m_s = [0.5, 0.0];
    opened.clearance_m = 1e-5;
    opened.contact_stiffness_n_per_m_e = 1.988e6;
    opened.contact_damping_n_s_per_m = 1e4;
    opened.classification.max_extension_s = 0.0;
    simulate(&opened, &opts(0.006)).unwrap_or_else(|e| panic!("opened: {e}"));
    // A 400 t rotor on the paper's race: penetrations of millimetres, the contact acting.
    let mut heavy = Scene::paper();
    heavy.rotor_mass_kg = 4e5;
    heavy.rotor_polar_moi_kg_m2 = 4e3;
    simulate(&heavy, &opts(1.0)).unwrap_or_else(|e| panic!("heavy: {e}"));
}

/// Counts the steps that start in free flight with the contact guard at exactly zero.
#[derive(Default)]
struct ZeroGuardWatch {
    steps: u64,
}

impl Observer<DropSystem, N> for ZeroGuardWatch {
    type Halt = Infallible;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Infallible> {
        let mut g = [0.0; MAX_GUARDS];
        sys.guards(step.dense.t0(), &step.dense.y0(), &mut g);
        if !sys.mode.contact && g[whirlmap_core::model::Guard::Contact.index()] == 0.0 {
            self.steps += 1;
        }
        ControlFlow::Continue(())
    }
}

/// A grazing contact whose penetration reaches exactly zero (its raw force still pushing,
/// from the damper term) opens there, and the free-flight contact guard,
/// `-min(delta / s, F / F_ref)`, starts at exactly zero. The driver once watched a guard only
/// after it had been positive, so the graze closing again went unseen, the rotor fell through
/// the race, and the drop ended with the typed `unphysical` error ("a contact was stepped
/// over"). Found among random drops at the numerics `draft` had then (ROS34PW2, the gap
/// bound, the race tolerance x1000, rtol 1e-4), 0.0985 s in; the drop keeps them. The
/// observer checks that the drop still meets such a step, so a change of numerics that no
/// longer reaches the exact zero does not leave this test passing without testing anything.
#[test]
fn a_contact_that_grazes_to_exactly_zero_closes_again() {
    let mut s = Scene::paper();
    s.speed_rpm = 1000.0;
    s.mu_dynamic = 0.25;
    s.race_speed_rad_s = 100.0;
    s.drag_enabled = false;
    s.solver.rtol = 1e-4;
    s.solver.method = whirlmap_core::Method::Ros34pw2;
    s.solver.free_flight_gap_bound = true;
    s.solver.race_atol_scale = 1000.0;
    s.solver.race_velocity_atol_from_force = false;
    let mut watch = ZeroGuardWatch::default();
    let r = simulate_observed(&s, &opts(0.3), &mut watch)
        .unwrap_or_else(|e| panic!("drop failed: {e}"));
    assert!(
        watch.steps >= 1,
        "no free-flight step started at a zero guard"
    );
    assert!(
        r.energy.residual_rel.abs() < 1e-3,
        "energy audit: {:?}",
        r.energy
    );
    let reference = run(&whirlmap_core::Fidelity::Reference.applied(&s), 0.3);
    assert_eq!(r.verdict.class, reference.verdict.class);
}
