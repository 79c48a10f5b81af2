//! The analytic stiff Jacobian of the drop model (for the linearly implicit steppers), its
//! energy integrals' rows included, against central finite differences of the right-hand
//! side, at states taken from real drops.

use std::convert::Infallible;
use std::ops::ControlFlow;
use whirlmap_core::model::{ix, DropSystem, Slip, N};
use whirlmap_core::ode::{Observer, OdeSystem, StepView};
use whirlmap_core::{simulate_observed, DropOptions, FrictionLaw, Method, Scene};

/// Checks the translational rows at every 10th accepted step; counts the checks per mode.
struct Check {
    quasi_static: bool,
    /// Whether the drop runs a Rosenbrock method (RODAS4, Rodas5P), whose matrix holds every
    /// term (the accumulators' rows, the sticking constraint).
    exact: bool,
    /// The rotor's and the race's contact radii (m).
    radii: (f64, f64),
    every: usize,
    seen: usize,
    checked: [usize; 3],
    worst: f64,
    worst_quad: f64,
    quad_checks: usize,
}

impl Observer<DropSystem, N> for Check {
    type Halt = Infallible;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<Infallible> {
        self.seen += 1;
        if !self.seen.is_multiple_of(self.every) {
            return ControlFlow::Continue(());
        }
        // The sticking constraint's dependence on the state is left out of the W-method's
        // matrix by design; RODAS4's holds it.
        let sticking = sys.mode.contact && sys.mode.slip == Slip::Sticking;
        // The quasi-static race's constraint slopes are left out too (a screening model).
        if sticking && (!self.exact || self.quasi_static) {
            return ControlFlow::Continue(());
        }
        let y = step.dense.y1();
        // A central difference with a 1e-12 m step cannot resolve the Hertz law's d^(3/2)
        // within a few steps of first touch (measured: a 1 % mismatch at d = 1.1e-12 m, where
        // the difference straddles d = 0): check contact states that are at least 1 nm in.
        let d = (y[ix::XR] - y[ix::XB]).hypot(y[ix::YR] - y[ix::YB]) - sys.clearance_m();
        if sys.mode.contact && d < 1e-9 {
            return ControlFlow::Continue(());
        }
        let sj = sys
            .stiff_jacobian(0.0, &y)
            .expect("the drop model supplies a Jacobian");
        let mut f0 = [0.0; N];
        sys.rhs(0.0, &y, &mut f0);
        // Rows: rotor and race accelerations; columns: every coupled component.
        for b in 0..sj.len {
            let c = sj.idx[b];
            // With a massless race its translation is not a state (it stays zero).
            if self.quasi_static && matches!(c, ix::XB | ix::YB | ix::VXB | ix::VYB) {
                continue;
            }
            let scale = match c {
                ix::XR | ix::YR | ix::XB | ix::YB => 1e-12,
                ix::WR | ix::WB => 1e-5,
                _ => 1e-9,
            };
            let (mut yp, mut ym) = (y, y);
            yp[c] += scale;
            ym[c] -= scale;
            let (mut fp, mut fm) = ([0.0; N], [0.0; N]);
            sys.rhs(0.0, &yp, &mut fp);
            sys.rhs(0.0, &ym, &mut fm);
            // The accelerations' rows; with RODAS4's matrix, which leaves out nothing but the
            // unbalance terms, also the spins' rows (the race's only where the support carries
            // 1 N: the drag's load term, load^1.33, has a zero slope at zero load that a
            // central difference across it does not see). An entry below 1e-4 of its row's
            // largest is not resolved here (the drag's share of the sticking friction's slope
            // in the race's spin): the drag's slopes are checked on their own (`model::drag`).
            let support_n = sys.forces_in(&y, sys.mode).support_n;
            let rows = if self.exact { 4..10 } else { 4..8 };
            for a in rows {
                let r = sj.idx[a];
                if self.quasi_static && (6..8).contains(&a) {
                    continue;
                }
                if r == ix::WB && support_n.abs() < 1.0 {
                    continue;
                }
                let fd = (fp[r] - fm[r]) / (2.0 * scale);
                // Row scale: the largest analytic entry in the row.
                let row_max = (0..sj.len)
                    .map(|k| sj.jac[(a, k)].abs())
                    .fold(1.0, f64::max);
                let err = (sj.jac[(a, b)] - fd).abs() / row_max;
                self.worst = self.worst.max(err);
                assert!(
                    err < 1e-4,
                    "row {r} col {c}: analytic {:e} fd {fd:e} (row max {row_max:e}), mode {:?}",
                    sj.jac[(a, b)],
                    sys.mode
                );
            }
            // The accumulators' rows. Friction's power F_t v_rel is a product with the slip
            // velocity, a difference of two surface speeds (about 16 m/s each, leaving 1e-9
            // m/s while rolling): a central difference is quantised by that sum's rounding,
            // |F_t| 4 eps (sum of the speeds) / step (measured: the same value at steps of
            // 1e-12 and 1e-11 m, 3e-4 off, and the analytic value from 1e-9 m on). So the
            // analytic entry must agree, within 1e-4 of the row's largest entry of the same
            // kind, with the difference at the base step or at 100 times it, each less its
            // rounding noise. The drag's Palmgren load term grows as load^1.33, whose slope is
            // zero at zero load but whose central difference across it is not: its row is
            // checked where the support carries at least 1 N.
            let f0 = sys.forces_in(&y, sys.mode);
            let speeds = (y[ix::VXR] - y[ix::VXB]).hypot(y[ix::VYR] - y[ix::VYB])
                + (y[ix::WR] * self.radii.0).abs()
                + (y[ix::WB] * self.radii.1).abs();
            let slip_noise = f0.friction_n.abs() * 4.0 * f64::EPSILON * speeds / (2.0 * scale);
            let (mut fp100, mut fm100) = ([0.0; N], [0.0; N]);
            let (mut yp100, mut ym100) = (y, y);
            yp100[c] += 100.0 * scale;
            ym100[c] -= 100.0 * scale;
            sys.rhs(0.0, &yp100, &mut fp100);
            sys.rhs(0.0, &ym100, &mut fm100);
            for a in 0..sj.quad_len {
                let r = sj.quad_idx[a];
                if r == ix::E_DRAG && f0.support_n.abs() < 1.0 {
                    continue;
                }
                let fd = (fp[r] - fm[r]) / (2.0 * scale);
                let fd100 = (fp100[r] - fm100[r]) / (200.0 * scale);
                // Positions, velocities and spins have different units.
                let kind = match b {
                    0..4 => 0..4,
                    4..8 => 4..8,
                    _ => 8..sj.len,
                };
                let row_max = kind.map(|k| sj.quad[(a, k)].abs()).fold(1e-12, f64::max);
                // Rounding of the power itself over the step (where the row is zero), and of
                // the slip velocity in friction's power.
                let mut noise = 8.0 * f64::EPSILON * (fp[r].abs() + fm[r].abs()) / (2.0 * scale);
                if r == ix::E_FRIC {
                    noise += slip_noise;
                }
                let an = sj.quad[(a, b)];
                let off = ((an - fd).abs() - noise).min((an - fd100).abs() - noise / 100.0);
                let err = off.max(0.0) / row_max;
                self.worst_quad = self.worst_quad.max(err);
                self.quad_checks += 1;
                assert!(
                    err < 1e-4,
                    "energy row {r} col {c}: analytic {an:e} fd {fd:e} (100x step {fd100:e}, \
                     row max {row_max:e}), mode {:?}",
                    sys.mode
                );
            }
        }
        self.checked[if !sys.mode.contact {
            0
        } else if sticking {
            2
        } else {
            1
        }] += 1;
        ControlFlow::Continue(())
    }
}

fn check(scene: Scene) -> Check {
    check_for(scene, 0.05)
}

/// Checks the Jacobian along the first `duration_s` of a drop of `scene`.
fn check_for(scene: Scene, duration_s: f64) -> Check {
    let mut c = Check {
        quasi_static: scene.quasi_static_race,
        exact: scene.solver.method.needs_exact_jacobian(),
        radii: (scene.rotor_radius_m(), scene.race_bore_radius_m()),
        every: 10,
        seen: 0,
        checked: [0; 3],
        worst: 0.0,
        worst_quad: 0.0,
        quad_checks: 0,
    };
    let opts = DropOptions {
        duration_s,
        ..Default::default()
    };
    simulate_observed(&scene, &opts, &mut c).unwrap();
    let states = c.checked.iter().sum::<usize>();
    if c.exact {
        // Every checked state checks the accumulators' rows too.
        assert!(
            c.quad_checks > states,
            "{} accumulator checks",
            c.quad_checks
        );
    } else {
        assert_eq!(
            c.quad_checks, 0,
            "the W-method's matrix has no accumulator rows"
        );
    }
    c
}

/// `scene` run by RODAS4, whose Jacobian holds every term.
fn exact(mut scene: Scene) -> Scene {
    scene.solver.method = Method::Rodas4;
    scene
}

#[test]
fn jacobian_matches_finite_differences_in_free_flight_and_slipping_contact() {
    let mut s = Scene::paper();
    s.mu_dynamic = 0.3;
    let c = check(s.clone());
    assert!(c.checked[0] > 3 && c.checked[1] > 3, "{:?}", c.checked);
    eprintln!("switched law: worst {:e}, checks {:?}", c.worst, c.checked);
    let c = check(exact(s));
    assert!(c.checked[0] > 3 && c.checked[1] > 3, "{:?}", c.checked);
    eprintln!(
        "switched law, RODAS4's matrix: worst {:e} (accumulator rows {:e}), checks {:?}",
        c.worst, c.worst_quad, c.checked
    );
}

#[test]
fn rodas4s_jacobian_matches_finite_differences_while_the_rotor_rolls() {
    // A pendulum drop: after the first impacts the rotor rolls on the race (sticking), where
    // the constraint's friction follows the support force.
    let mut s = exact(Scene::paper());
    s.mu_dynamic = 0.1;
    let c = check_for(s, 0.4);
    assert!(c.checked[2] > 3, "{:?}", c.checked);
    eprintln!(
        "rolling, RODAS4's matrix: worst {:e} (accumulator rows {:e}), checks {:?}",
        c.worst, c.worst_quad, c.checked
    );
}

#[test]
fn jacobian_matches_finite_differences_with_regularised_friction_and_quasi_static_race() {
    let mut s = Scene::paper();
    s.mu_dynamic = 0.3;
    s.friction_law = FrictionLaw::Regularised { v_eps_m_s: 1e-3 };
    let c = check(exact(s.clone()));
    assert!(c.checked[1] > 3, "{:?}", c.checked);
    s.friction_law = FrictionLaw::Switched;
    s.quasi_static_race = true;
    let c = check(exact(s));
    assert!(c.checked[1] > 3, "{:?}", c.checked);
}

#[test]
fn jacobian_matches_finite_differences_with_the_radial_only_support_damper() {
    let mut s = Scene::paper();
    s.mu_dynamic = 0.3;
    s.support_damper = whirlmap_core::SupportDamper::RadialOnly;
    let c = check(exact(s));
    assert!(c.checked[0] > 3 && c.checked[1] > 3, "{:?}", c.checked);
    eprintln!(
        "radial-only support damper, RODAS4's matrix: worst {:e} (accumulator rows {:e}), checks {:?}",
        c.worst, c.worst_quad, c.checked
    );
}

fn drop_with(method: whirlmap_core::Method, rtol: f64, gap: bool) -> whirlmap_core::DropReport {
    let mut s = Scene::paper();
    s.solver.method = method;
    s.solver.rtol = rtol;
    s.solver.free_flight_gap_bound = gap;
    let opts = DropOptions {
        duration_s: 0.1,
        ..Default::default()
    };
    whirlmap_core::simulate(&s, &opts).unwrap()
}

/// The implicit steppers with the free-flight gap bound against DOPRI5 at rtol 1e-9 on the
/// bouncing phase (13 impacts, free flights, friction switches): same impacts and class,
/// forces converging as the tolerance tightens, and an energy audit that closes.
#[test]
fn implicit_steppers_converge_to_the_reference_on_a_bouncing_drop() {
    let reference = drop_with(Method::Dopri5, 1e-9, false);
    for method in [
        Method::Ros34pw2,
        Method::Rodas4,
        Method::Rodas5p,
        Method::Radau5,
        Method::Rodas4Bdf,
        Method::Rodas4Ndf,
    ] {
        converges_to(&reference, method);
    }
}

/// The BDF alone on the same bouncing phase: it restarts at order 1 after every switch, so its
/// impacts are less accurate than the one-step methods' at a tolerance (the reason RODAS4 takes
/// them in `rodas4_bdf`), but it still converges to the reference as the tolerance tightens.
#[test]
fn the_bdf_alone_converges_on_the_bouncing_drop() {
    let reference = drop_with(Method::Dopri5, 1e-9, false);
    let rf = &reference.features;
    let mut errs = Vec::new();
    for rtol in [1e-4, 1e-6, 1e-8] {
        let r = drop_with(Method::Bdf, rtol, true);
        let f = &r.features;
        let err = ((f.first_contact_force_n - rf.first_contact_force_n).abs()
            / rf.first_contact_force_n)
            .max((f.max_contact_force_n - rf.max_contact_force_n).abs() / rf.max_contact_force_n);
        eprintln!("Bdf rtol {rtol:e}: force error {err:e}, {:?}", r.stats);
        assert_eq!(f.impacts, rf.impacts, "rtol {rtol:e}");
        assert!(
            r.energy.residual_rel < 1e-5,
            "rtol {rtol:e}: {:?}",
            r.energy
        );
        errs.push(err);
    }
    assert!(errs[1] < errs[0] && errs[2] < errs[1], "{errs:?}");
    assert!(errs[2] < 1e-5, "{errs:?}");
}

fn converges_to(reference: &whirlmap_core::DropReport, method: Method) {
    let rf = &reference.features;
    let mut last_err = f64::INFINITY;
    for rtol in [1e-4, 1e-6, 1e-8] {
        let r = drop_with(method, rtol, true);
        let f = &r.features;
        let err = ((f.first_contact_force_n - rf.first_contact_force_n).abs()
            / rf.first_contact_force_n)
            .max((f.max_contact_force_n - rf.max_contact_force_n).abs() / rf.max_contact_force_n);
        eprintln!(
            "{method:?} rtol {rtol:e}: force error {err:e}, {:?}, residual {:e}",
            r.stats, r.energy.residual_rel
        );
        assert_eq!(f.impacts, rf.impacts, "{method:?} rtol {rtol:e}");
        assert!(
            (f.first_contact_time_s - rf.first_contact_time_s).abs()
                < 1e-6 * rf.first_contact_time_s,
            "first contact {} vs {}",
            f.first_contact_time_s,
            rf.first_contact_time_s
        );
        assert!(err < 1e-3, "{method:?} rtol {rtol:e}: force error {err:e}");
        assert!(
            r.energy.residual_rel < 1e-5,
            "rtol {rtol:e}: {:?}",
            r.energy
        );
        assert!(
            err < last_err || err < 1e-8,
            "{method:?}: no convergence: {err:e} after {last_err:e}"
        );
        last_err = err;
    }
    assert!(
        last_err < 1e-6,
        "{method:?} rtol 1e-8: force error {last_err:e}"
    );
}

/// RODAS4 then BDF leaves every impact to RODAS4: on the 1 s pendulum drop, whose budgeted
/// outputs all come from its first impact, the first and the maximum contact force and the
/// peak heat power are RODAS4's to the bit. The rolling that follows, stepped by the BDF at a
/// tenth of the tolerance, ends in the same class with the friction heat within a few
/// tolerances of RODAS4's, in about as many steps for less than half of the right-hand-side
/// evaluations (one or two a step against six).
#[test]
fn rodas4_then_bdf_keeps_rodas4s_impacts_and_rolls_for_fewer_evaluations() {
    let run = |method| {
        let mut s = Scene::paper();
        s.solver.method = method;
        whirlmap_core::simulate(&s, &DropOptions::default()).unwrap()
    };
    let (a, b) = (run(Method::Rodas4), run(Method::Rodas4Bdf));
    let (fa, fb) = (&a.features, &b.features);
    for (name, x, y) in [
        (
            "first force",
            fa.first_contact_force_n,
            fb.first_contact_force_n,
        ),
        (
            "maximum force",
            fa.max_contact_force_n,
            fb.max_contact_force_n,
        ),
        (
            "peak heat power",
            fa.peak_heat_power_w,
            fb.peak_heat_power_w,
        ),
    ] {
        assert_eq!(x.to_bits(), y.to_bits(), "{name}: {x} against {y}");
    }
    assert_eq!(a.verdict.class, b.verdict.class);
    let heat = |r: &whirlmap_core::DropReport| r.energy.friction_heat_j;
    let rel = (heat(&a) - heat(&b)).abs() / heat(&a);
    assert!(
        rel < 10.0 * Scene::paper().solver.rtol,
        "friction heat apart by {rel:e}"
    );
    eprintln!("RODAS4 {:?}\nRODAS4 then BDF {:?}", a.stats, b.stats);
    assert!(
        2 * b.stats.rhs_evals < a.stats.rhs_evals,
        "{:?} against {:?}",
        b.stats,
        a.stats
    );
    assert!(
        b.stats.steps < a.stats.steps + a.stats.steps / 10,
        "{:?}",
        b.stats
    );
}

/// The thermal model runs the dynamics in macro steps of 1 ms, each ended by the observer;
/// the next macro step goes on from the same state with the drag's load a step further
/// (eq. 31). RODAS4 then BDF keeps its BDF across them (it hands over only after 2 ms, so a
/// restart at each would leave every step to RODAS4): the thermal drop takes as few
/// right-hand-side evaluations as the drop without the thermal model, and its outputs are
/// within a few tolerances of RODAS4's.
#[test]
fn rodas4_then_bdf_keeps_its_bdf_across_the_thermal_macro_steps() {
    let run = |method, thermal: bool| {
        let mut s = Scene::paper();
        s.solver.method = method;
        if thermal {
            s.thermal = Some(whirlmap_core::ThermalParams::default());
        }
        whirlmap_core::simulate(&s, &DropOptions::default()).unwrap()
    };
    let plain = run(Method::Rodas4Bdf, false);
    let (a, b) = (run(Method::Rodas4, true), run(Method::Rodas4Bdf, true));
    eprintln!(
        "RODAS4 {:?}\nRODAS4 then BDF {:?}\nwithout the thermal model {:?}",
        a.stats, b.stats, plain.stats
    );
    assert!(
        b.stats.rhs_evals < plain.stats.rhs_evals + plain.stats.rhs_evals / 10,
        "{:?} against {:?}",
        b.stats,
        plain.stats
    );
    assert!(
        2 * b.stats.rhs_evals < a.stats.rhs_evals,
        "{:?} against {:?}",
        b.stats,
        a.stats
    );
    let rtol = Scene::paper().solver.rtol;
    let (ta, tb) = (a.thermal.as_ref().unwrap(), b.thermal.as_ref().unwrap());
    for (name, x, y) in [
        (
            "friction heat",
            a.energy.friction_heat_j,
            b.energy.friction_heat_j,
        ),
        ("drag work", a.energy.drag_work_j, b.energy.drag_work_j),
        (
            "final thermal load",
            ta.final_thermal_load_n,
            tb.final_thermal_load_n,
        ),
    ] {
        assert!(
            (x - y).abs() <= 10.0 * rtol * x.abs(),
            "{name}: {x} against {y}"
        );
    }
    assert_eq!(a.verdict.class, b.verdict.class);
}
