//! One harness for the steppers' order and tolerance: every stepper (DOPRI5, DOP853,
//! ROS34PW2, RODAS4, Rodas5P, RADAU5; the multistep BDF and NDF, and RODAS4 then either, in
//! the adaptive tests only) runs a set of reference problems with closed-form solutions, and
//! for each the harness checks
//!
//! - the observed convergence order on fixed steps (the error of `h` against `h / 2`) is the
//!   order of the method's stability function (these problems are linear: its order, or
//!   Rodas5P's 6 for its 5), and
//! - tolerance proportionality: with adaptive steps the global error falls as `rtol`
//!   tightens, stays within a small multiple of `rtol`, and falls at a rate close to `rtol`'s.
//!
//! The problems: exponential decay at two rates, the harmonic oscillator, for the implicit
//! steppers also a stiff linear system (eigenvalues -1 and -1000) whose solution lies on the
//! slow manifold, and for the W-method also the harmonic oscillator with a deliberately wrong
//! Jacobian (a W-method keeps its order with any matrix; a Rosenbrock method does not, which a
//! test below shows). Separate tests take the implicit steppers' own order on a nonlinear
//! problem (two logistic equations) and the order of their interpolants at the steps'
//! midpoints. The observed orders and slopes print with `--nocapture`.

use whirlmap_core::ode::{
    integrate, Bdf, Dop853, Dopri5, Formula, NoGuard, NoObserver, OdeSystem, Radau5, Rodas4,
    Rodas4Bdf, Rodas5p, Ros34pw2, StepControl, Stepper, StiffJacobian, Stop,
};

mod common;
use common::Harmonic;

/// A reference problem: a two-component system with its exact solution.
trait Reference: OdeSystem<2, Guard = NoGuard> {
    /// Its name, for messages.
    fn name(&self) -> &'static str;
    /// The state at time 0.
    fn y0(&self) -> [f64; 2];
    /// The exact solution at `t`.
    fn exact(&self, t: f64) -> [f64; 2];
    /// The time the runs end at.
    fn t_end(&self) -> f64;
}

/// y0' = -2 y0, y1' = -y1 / 2: exp(-2 t), exp(-t / 2).
struct Decay;
impl OdeSystem<2> for Decay {
    type Guard = NoGuard;
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = -2.0 * y[0];
        dy[1] = -0.5 * y[1];
    }
    fn stiff_jacobian(&self, _t: f64, _y: &[f64; 2]) -> Option<StiffJacobian> {
        let mut s = StiffJacobian::over(&[0, 1]);
        s.jac[(0, 0)] = -2.0;
        s.jac[(1, 1)] = -0.5;
        Some(s)
    }
}
impl Reference for Decay {
    fn name(&self) -> &'static str {
        "exponential decay"
    }
    fn y0(&self) -> [f64; 2] {
        [1.0, 1.0]
    }
    fn exact(&self, t: f64) -> [f64; 2] {
        [(-2.0 * t).exp(), (-0.5 * t).exp()]
    }
    fn t_end(&self) -> f64 {
        3.0
    }
}

impl Reference for Harmonic {
    fn name(&self) -> &'static str {
        if self.wrong_jacobian {
            "harmonic oscillator, wrong Jacobian"
        } else {
            "harmonic oscillator"
        }
    }
    fn y0(&self) -> [f64; 2] {
        [1.0, 0.0]
    }
    fn exact(&self, t: f64) -> [f64; 2] {
        [t.cos(), -t.sin()]
    }
    fn t_end(&self) -> f64 {
        4.0
    }
}

/// y0' = -y0, y1' = -1000 (y1 - y0) - y0: both exp(-t) from y(0) = (1, 1); the eigenvalue
/// -1000 makes it stiff (an explicit stepper's step would be bound to ~3e-3).
struct StiffLinear;
const STIFF: f64 = 1000.0;
impl OdeSystem<2> for StiffLinear {
    type Guard = NoGuard;
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = -y[0];
        dy[1] = -STIFF * (y[1] - y[0]) - y[0];
    }
    fn stiff_jacobian(&self, _t: f64, _y: &[f64; 2]) -> Option<StiffJacobian> {
        let mut s = StiffJacobian::over(&[0, 1]);
        s.jac[(0, 0)] = -1.0;
        s.jac[(1, 0)] = STIFF - 1.0;
        s.jac[(1, 1)] = -STIFF;
        Some(s)
    }
}
impl Reference for StiffLinear {
    fn name(&self) -> &'static str {
        "stiff linear system"
    }
    fn y0(&self) -> [f64; 2] {
        [1.0, 1.0]
    }
    fn exact(&self, t: f64) -> [f64; 2] {
        [(-t).exp(); 2]
    }
    fn t_end(&self) -> f64 {
        2.0
    }
}

/// Two logistic equations, y0' = y0 (1 - y0) and y1' = y1 (1 - y1) / 2 from (0.1, 0.2):
/// `1 / (1 + 9 e^-t)` and `1 / (1 + 4 e^(-t/2))`. Nonlinear, unlike the problems above: on a
/// linear problem a Rosenbrock method's error is that of its stability function, whose order
/// can exceed the method's (Rodas5P's matches `e^z` to order 6).
struct Logistic;
impl OdeSystem<2> for Logistic {
    type Guard = NoGuard;
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[0] * (1.0 - y[0]);
        dy[1] = 0.5 * y[1] * (1.0 - y[1]);
    }
    fn stiff_jacobian(&self, _t: f64, y: &[f64; 2]) -> Option<StiffJacobian> {
        let mut s = StiffJacobian::over(&[0, 1]);
        s.jac[(0, 0)] = 1.0 - 2.0 * y[0];
        s.jac[(1, 1)] = 0.5 * (1.0 - 2.0 * y[1]);
        Some(s)
    }
}
impl Reference for Logistic {
    fn name(&self) -> &'static str {
        "logistic equations"
    }
    fn y0(&self) -> [f64; 2] {
        [0.1, 0.2]
    }
    fn exact(&self, t: f64) -> [f64; 2] {
        [
            1.0 / (1.0 + 9.0 * (-t).exp()),
            1.0 / (1.0 + 4.0 * (-0.5 * t).exp()),
        ]
    }
    fn t_end(&self) -> f64 {
        4.0
    }
}

/// A stepper under test: how to make one, its order, the fixed steps at which its error is
/// well above rounding and well inside the asymptotic range, and the tolerances to sweep.
struct Method {
    name: &'static str,
    order: f64,
    /// The order of its stability function's match to `e^z`: the order it shows on the
    /// linear problems (at least `order`).
    linear_order: f64,
    make: fn(StepControl<2>) -> Box<dyn StepperBox>,
    /// Fixed step counts over `t_end`: the order is measured between `n` and `2 n`.
    steps: usize,
    /// Tolerances, loosest first.
    rtols: [f64; 3],
    /// Whether it runs the stiff problems.
    implicit: bool,
    /// Whether it is a W-method (its order holds with any matrix), so it runs the problem
    /// with a wrong Jacobian too.
    w_method: bool,
    /// The slope of the global error against the tolerance on a log scale: 1 when the
    /// error estimate's order matches the solution's; RADAU5's estimate is O(h^4) against
    /// a 5th-order solution, so its global error goes as rtol^(5/4).
    tol_slope: f64,
    /// How far the measured slope may be from `tol_slope`.
    slope_margin: f64,
    /// Whether it is a one-step method, whose order the fixed-step tests measure. The
    /// multistep BDF and NDF, and RODAS4 then either, change their order as they go (their
    /// orders on fixed steps are tested in `ode/bdf.rs`), so only their adaptive runs are
    /// tested here.
    one_step: bool,
}

/// Object-safe wrapper over the steppers: one run of a reference problem to its end.
trait StepperBox {
    fn run(&mut self, p: &dyn ReferenceDyn) -> [f64; 2];
}

/// [`Reference`] as a trait object, dispatching to the concrete problem.
trait ReferenceDyn {
    fn reference(&self) -> Problem<'_>;
}

/// The reference problems, by kind (the steppers are generic over the system).
enum Problem<'a> {
    Decay(&'a Decay),
    Harmonic(&'a Harmonic),
    Stiff(&'a StiffLinear),
    Logistic(&'a Logistic),
}

impl ReferenceDyn for Decay {
    fn reference(&self) -> Problem<'_> {
        Problem::Decay(self)
    }
}
impl ReferenceDyn for Harmonic {
    fn reference(&self) -> Problem<'_> {
        Problem::Harmonic(self)
    }
}
impl ReferenceDyn for StiffLinear {
    fn reference(&self) -> Problem<'_> {
        Problem::Stiff(self)
    }
}
impl ReferenceDyn for Logistic {
    fn reference(&self) -> Problem<'_> {
        Problem::Logistic(self)
    }
}

fn run_to_end<M: Stepper<2>, P: Reference>(st: &mut M, p: &P) -> [f64; 2] {
    let (mut t, mut y) = (0.0, p.y0());
    let stop = integrate(p, st, &mut t, &mut y, p.t_end(), &mut NoObserver)
        .unwrap_or_else(|e| panic!("{}: {e}", p.name()));
    assert!(matches!(stop, Stop::EndTime), "{}: {stop:?}", p.name());
    assert_eq!(t, p.t_end());
    y
}

impl<M: Stepper<2>> StepperBox for M {
    fn run(&mut self, p: &dyn ReferenceDyn) -> [f64; 2] {
        match p.reference() {
            Problem::Decay(p) => run_to_end(self, p),
            Problem::Harmonic(p) => run_to_end(self, p),
            Problem::Stiff(p) => run_to_end(self, p),
            Problem::Logistic(p) => run_to_end(self, p),
        }
    }
}

fn methods() -> [Method; 10] {
    [
        Method {
            name: "DOPRI5",
            order: 5.0,
            linear_order: 5.0,
            make: |c| Box::new(Dopri5::new(c)),
            steps: 40,
            rtols: [1e-4, 1e-7, 1e-10],
            implicit: false,
            w_method: false,
            tol_slope: 1.0,
            slope_margin: 0.2,
            one_step: true,
        },
        Method {
            name: "DOP853",
            order: 8.0,
            linear_order: 8.0,
            make: |c| Box::new(Dop853::new(c)),
            steps: 10,
            rtols: [1e-6, 1e-9, 1e-12],
            implicit: false,
            w_method: false,
            tol_slope: 1.0,
            slope_margin: 0.2,
            one_step: true,
        },
        Method {
            name: "ROS34PW2",
            order: 3.0,
            linear_order: 3.0,
            make: |c| Box::new(Ros34pw2::new(c)),
            steps: 200,
            rtols: [1e-4, 1e-6, 1e-8],
            implicit: true,
            w_method: true,
            tol_slope: 1.0,
            slope_margin: 0.2,
            one_step: true,
        },
        Method {
            name: "RODAS4",
            order: 4.0,
            linear_order: 4.0,
            make: |c| Box::new(Rodas4::new(c)),
            steps: 100,
            rtols: [1e-4, 1e-6, 1e-8],
            implicit: true,
            // A Rosenbrock method: its order needs the exact Jacobian (see the test below).
            w_method: false,
            tol_slope: 1.0,
            slope_margin: 0.2,
            one_step: true,
        },
        Method {
            name: "Rodas5P",
            order: 5.0,
            linear_order: 6.0,
            make: |c| Box::new(Rodas5p::new(c)),
            steps: 20,
            rtols: [1e-4, 1e-7, 1e-10],
            implicit: true,
            w_method: false,
            tol_slope: 1.0,
            slope_margin: 0.2,
            one_step: true,
        },
        Method {
            name: "RADAU5",
            order: 5.0,
            linear_order: 5.0,
            make: |c| Box::new(Radau5::new(c)),
            steps: 20,
            rtols: [1e-4, 1e-7, 1e-10],
            implicit: true,
            // A collocation method with a Newton iteration: the matrix only speeds the
            // iteration up, but a wrong one slows or stops its convergence.
            w_method: false,
            tol_slope: 1.25,
            slope_margin: 0.2,
            one_step: true,
        },
        Method {
            name: "BDF",
            order: 5.0,
            linear_order: 5.0,
            make: |c| Box::new(Bdf::new(c)),
            steps: 0,
            rtols: [1e-4, 1e-6, 1e-8],
            implicit: true,
            w_method: false,
            // Its error estimate is its own solution's, per step: the global error, a sum of
            // per-step errors at order k, falls as rtol^(k/(k+1)), k from 1 (after the start)
            // to 5.
            tol_slope: 0.7,
            slope_margin: 0.2,
            one_step: false,
        },
        Method {
            name: "RODAS4 then BDF",
            order: 4.0,
            linear_order: 4.0,
            make: |c| Box::new(Rodas4Bdf::new(c)),
            steps: 0,
            rtols: [1e-4, 1e-6, 1e-8],
            implicit: true,
            w_method: false,
            // RODAS4's slope (1) where it steps, the BDF's (0.5 to 0.83) once it takes over.
            tol_slope: 0.8,
            slope_margin: 0.25,
            one_step: false,
        },
        Method {
            name: "NDF",
            order: 5.0,
            linear_order: 5.0,
            make: |c| Box::new(Bdf::with_formula(c, Formula::Ndf)),
            steps: 0,
            rtols: [1e-4, 1e-6, 1e-8],
            implicit: true,
            w_method: false,
            // As the BDF's: its estimate is its own solution's error at order k.
            tol_slope: 0.7,
            slope_margin: 0.2,
            one_step: false,
        },
        Method {
            name: "RODAS4 then NDF",
            order: 4.0,
            linear_order: 4.0,
            make: |c| Box::new(Rodas4Bdf::with_formula(c, Formula::Ndf)),
            steps: 0,
            rtols: [1e-4, 1e-6, 1e-8],
            implicit: true,
            w_method: false,
            // As RODAS4 then BDF's.
            tol_slope: 0.8,
            slope_margin: 0.25,
            one_step: false,
        },
    ]
}

/// One reference problem as a method runs it: its name, the system, and the exact state at
/// the end time.
struct Case {
    name: &'static str,
    problem: Box<dyn ReferenceDyn>,
    exact: [f64; 2],
    t_end: f64,
}

impl Case {
    fn of<P: Reference + ReferenceDyn + 'static>(p: P) -> Self {
        Case {
            name: p.name(),
            exact: p.exact(p.t_end()),
            t_end: p.t_end(),
            problem: Box::new(p),
        }
    }
}

/// The problems a method runs.
fn problems(m: &Method) -> Vec<Case> {
    let mut v = vec![
        Case::of(Decay),
        Case::of(Harmonic {
            wrong_jacobian: false,
        }),
    ];
    if m.w_method {
        v.push(Case::of(Harmonic {
            wrong_jacobian: true,
        }));
    }
    if m.implicit {
        v.push(Case::of(StiffLinear));
    }
    v
}

/// The error norm of the whole state, so that a zero of one component cannot fake an order.
fn error(y: [f64; 2], exact: [f64; 2]) -> f64 {
    ((y[0] - exact[0]).powi(2) + (y[1] - exact[1]).powi(2)).sqrt()
}

#[test]
fn fixed_steps_converge_at_each_methods_order() {
    for m in methods().into_iter().filter(|m| m.one_step) {
        for Case {
            name,
            problem: p,
            exact,
            t_end,
        } in problems(&m)
        {
            // Every problem here is linear: the error is the stability function's.
            let expected = m.linear_order;
            let err_at = |n: usize| {
                let ctl = StepControl {
                    rtol: 1.0,
                    atol: [1.0; 2],
                    h_min: 0.0,
                    max_attempts: u64::MAX,
                    fixed_step: Some(t_end / n as f64),
                };
                error((m.make)(ctl).run(p.as_ref()), exact)
            };
            let (e1, e2) = (err_at(m.steps), err_at(2 * m.steps));
            let order = (e1 / e2).log2();
            println!("{} on {name}: observed order {order:.2}", m.name);
            assert!(
                (order - expected).abs() < 0.1 * expected,
                "{} on {name}: observed order {order:.2}, expected {expected} ({e1:e} -> {e2:e})",
                m.name,
            );
        }
    }
}

/// The implicit steppers on a nonlinear problem, where a Rosenbrock method's order is its
/// own and not its stability function's: Rodas5P's 5 (6 on the linear problems above).
#[test]
fn implicit_steppers_keep_their_order_on_a_nonlinear_problem() {
    for m in methods().into_iter().filter(|m| m.implicit && m.one_step) {
        let case = Case::of(Logistic);
        let err_at = |n: usize| {
            let ctl = StepControl {
                rtol: 1.0,
                atol: [1.0; 2],
                h_min: 0.0,
                max_attempts: u64::MAX,
                fixed_step: Some(case.t_end / n as f64),
            };
            error((m.make)(ctl).run(case.problem.as_ref()), case.exact)
        };
        let (e1, e2) = (err_at(m.steps), err_at(2 * m.steps));
        let order = (e1 / e2).log2();
        println!("{} on {}: observed order {order:.2}", m.name, case.name);
        assert!(
            (order - m.order).abs() < 0.1 * m.order,
            "{} on {}: observed order {order:.2}, expected {} ({e1:e} -> {e2:e})",
            m.name,
            case.name,
            m.order
        );
    }
}

#[test]
fn global_error_falls_in_proportion_to_the_tolerance() {
    for m in methods() {
        for Case {
            name,
            problem: p,
            exact,
            ..
        } in problems(&m)
        {
            let errs: Vec<f64> = m
                .rtols
                .iter()
                .map(|&rtol| {
                    let ctl = StepControl {
                        rtol,
                        atol: [rtol * 1e-3; 2],
                        h_min: 1e-14,
                        max_attempts: 10_000_000,
                        fixed_step: None,
                    };
                    error((m.make)(ctl).run(p.as_ref()), exact)
                })
                .collect();
            for (rtol, e) in m.rtols.iter().zip(&errs) {
                assert!(
                    *e < 100.0 * rtol,
                    "{} on {name}: rtol {rtol:e} gave error {e:e}",
                    m.name
                );
            }
            // The error falls at the rate the method's error estimate sets: its slope against
            // rtol on a log scale, from the loosest to the tightest (`Method::tol_slope`).
            let slope = (errs[0] / errs[2]).ln() / (m.rtols[0] / m.rtols[2]).ln();
            println!("{} on {name}: errors {errs:?}, slope {slope:.2}", m.name);
            assert!(
                errs[1] < errs[0]
                    && errs[2] < errs[1]
                    && (slope - m.tol_slope).abs() <= m.slope_margin,
                "{} on {name}: errors {errs:?} for rtol {:?} (slope {slope:.2})",
                m.name,
                m.rtols
            );
        }
    }
}

/// RODAS4 is a Rosenbrock method, not a W-method: with a matrix that is not the Jacobian it
/// still converges, but at a low order (its order conditions beyond the first assume the
/// exact Jacobian), unlike ROS34PW2, which keeps order 3 on the same problem (above).
#[test]
fn rodas4_loses_its_order_with_a_wrong_jacobian() {
    let p = Harmonic {
        wrong_jacobian: true,
    };
    let exact = p.exact(p.t_end());
    let err_at = |n: usize| {
        let ctl = StepControl {
            rtol: 1.0,
            atol: [1.0; 2],
            h_min: 0.0,
            max_attempts: u64::MAX,
            fixed_step: Some(p.t_end() / n as f64),
        };
        error(Rodas4::new(ctl).run(&p), exact)
    };
    let (e1, e2, e3) = (err_at(400), err_at(800), err_at(1600));
    let order = (e2 / e3).log2();
    println!("RODAS4, wrong Jacobian: observed order {order:.2}");
    assert!(
        e2 < e1 && (0.8..2.5).contains(&order),
        "observed order {order:.2} ({e1:e} -> {e2:e} -> {e3:e})"
    );
}

/// y0' = -y0 with its exact Jacobian, and the accumulator y1' = y0^2, which no right-hand side
/// reads: y0 = exp(-t), y1 = (1 - exp(-2 t)) / 2. `quadrature_row` hands the stepper the
/// accumulator's row `d y1' / d y0 = 2 y0` ([`StiffJacobian::quad`]).
struct Accumulator {
    quadrature_row: bool,
}
impl OdeSystem<2> for Accumulator {
    type Guard = NoGuard;
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = -y[0];
        dy[1] = y[0] * y[0];
    }
    fn stiff_jacobian(&self, _t: f64, y: &[f64; 2]) -> Option<StiffJacobian> {
        let mut s = StiffJacobian::over(&[0]);
        s.jac[(0, 0)] = -1.0;
        if self.quadrature_row {
            s.quad_idx[0] = 1;
            s.quad_len = 1;
            s.quad[(0, 0)] = 2.0 * y[0];
        }
        Some(s)
    }
}

/// RODAS4 on an accumulator: without its row in the matrix the accumulator converges at a low
/// order (the matrix is not the Jacobian there); with it, at the method's order 4. ROS34PW2, a
/// W-method, keeps its order 3 without the row.
#[test]
fn an_accumulators_row_gives_rodas4_its_order() {
    let t_end: f64 = 2.0;
    let exact = 0.5 * (1.0 - (-2.0 * t_end).exp());
    let ctl = |n: usize| StepControl {
        rtol: 1.0,
        atol: [1.0; 2],
        h_min: 0.0,
        max_attempts: u64::MAX,
        fixed_step: Some(t_end / n as f64),
    };
    let err_at = |quadrature_row: bool, n: usize, rodas: bool| {
        let sys = Accumulator { quadrature_row };
        let (mut t, mut y) = (0.0, [1.0, 0.0]);
        let stop = if rodas {
            integrate(
                &sys,
                &mut Rodas4::new(ctl(n)),
                &mut t,
                &mut y,
                t_end,
                &mut NoObserver,
            )
        } else {
            integrate(
                &sys,
                &mut Ros34pw2::new(ctl(n)),
                &mut t,
                &mut y,
                t_end,
                &mut NoObserver,
            )
        };
        assert!(matches!(stop, Ok(Stop::EndTime)));
        (y[1] - exact).abs()
    };
    let order = |row: bool, rodas: bool| (err_at(row, 40, rodas) / err_at(row, 80, rodas)).log2();
    let (with, without, w_method) = (order(true, true), order(false, true), order(false, false));
    println!(
        "accumulator: RODAS4 order {with:.2} with its row, {without:.2} without; ROS34PW2 {w_method:.2}"
    );
    assert!(
        (3.7..4.4).contains(&with),
        "RODAS4 with the row: order {with:.2}"
    );
    assert!(without < 3.3, "RODAS4 without the row: order {without:.2}");
    assert!(
        (2.7..3.4).contains(&w_method),
        "ROS34PW2 without the row: order {w_method:.2}"
    );
}

/// The decay problem with a system that widens the first (faster) component's absolute
/// tolerance a millionfold ([`OdeSystem::loosened_atol`]) and notes each time it is asked.
struct Widening {
    widen: bool,
    asked: std::cell::RefCell<Vec<(f64, [f64; 2])>>,
}
impl OdeSystem<2> for Widening {
    type Guard = NoGuard;
    fn rhs(&self, t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        Decay.rhs(t, y, dy)
    }
    fn stiff_jacobian(&self, t: f64, y: &[f64; 2]) -> Option<StiffJacobian> {
        Decay.stiff_jacobian(t, y)
    }
    fn loosened_atol(&self, t: f64, y: &[f64; 2], base: &[f64; 2]) -> Option<[f64; 2]> {
        self.asked.borrow_mut().push((t, *y));
        self.widen.then(|| [base[0] * 1e6, base[1]])
    }
}

/// Notes the start of every accepted step.
struct Starts(Vec<(f64, [f64; 2])>);
impl whirlmap_core::ode::Observer<Widening, 2> for Starts {
    type Halt = std::convert::Infallible;
    fn on_step(
        &mut self,
        _sys: &Widening,
        step: &whirlmap_core::ode::StepView<'_, 2>,
    ) -> std::ops::ControlFlow<Self::Halt> {
        self.0.push((step.dense.t0(), step.dense.y0()));
        std::ops::ControlFlow::Continue(())
    }
}

/// Every stepper asks the system for its tolerances exactly once per step, at the step's
/// start (the state the step begins from, not a stage), and uses the answer: with the faster
/// component's tolerance widened, its error no longer sets the step and the run takes fewer
/// steps, while the slower component stays within its tolerance.
#[test]
fn every_stepper_asks_for_the_tolerances_at_each_steps_start_and_uses_them() {
    fn run<M: Stepper<2>>(name: &str, make: impl Fn(StepControl<2>) -> M) {
        let mut steps = [0; 2];
        for widen in [false, true] {
            let sys = Widening {
                widen,
                asked: Default::default(),
            };
            let ctl = StepControl {
                rtol: 1e-8,
                atol: [1e-8; 2],
                h_min: 1e-14,
                max_attempts: 1_000_000,
                fixed_step: None,
            };
            let mut st = make(ctl);
            let (mut t, mut y) = (0.0, [1.0, 1.0]);
            let mut starts = Starts(Vec::new());
            integrate(&sys, &mut st, &mut t, &mut y, 3.0, &mut starts).unwrap();
            let asked = sys.asked.borrow();
            assert_eq!(asked.len() as u64, st.stats().steps, "{name} widen {widen}");
            assert_eq!(
                *asked, starts.0,
                "{name} widen {widen}: asked at the step starts"
            );
            let e1 = (y[1] - (-1.5f64).exp()).abs();
            assert!(
                e1 < 1e-6,
                "{name} widen {widen}: second component off by {e1:e}"
            );
            steps[widen as usize] = st.stats().steps;
        }
        assert!(
            steps[1] < steps[0],
            "{name}: {} steps widened against {}",
            steps[1],
            steps[0]
        );
        eprintln!(
            "{name}: {} steps, {} with the first component widened",
            steps[0], steps[1]
        );
    }
    run("DOPRI5", Dopri5::new);
    run("DOP853", Dop853::new);
    run("ROS34PW2", Ros34pw2::new);
    run("RODAS4", Rodas4::new);
    run("Rodas5P", Rodas5p::new);
    run("RADAU5", Radau5::new);
    run("BDF", Bdf::new);
    run("RODAS4 then BDF", Rodas4Bdf::new);
    run("NDF", |c| Bdf::with_formula(c, Formula::Ndf));
    run("RODAS4 then NDF", |c| {
        Rodas4Bdf::with_formula(c, Formula::Ndf)
    });
}

/// The largest error of a step's interpolant at its midpoint, over a run of [`Logistic`].
struct Midpoints(f64);
impl whirlmap_core::ode::Observer<Logistic, 2> for Midpoints {
    type Halt = std::convert::Infallible;
    fn on_step(
        &mut self,
        _sys: &Logistic,
        step: &whirlmap_core::ode::StepView<'_, 2>,
    ) -> std::ops::ControlFlow<Self::Halt> {
        let t = 0.5 * (step.dense.t0() + step.dense.t1());
        self.0 = self.0.max(error(step.dense.eval(t), Logistic.exact(t)));
        std::ops::ControlFlow::Continue(())
    }
}

/// The implicit steppers' interpolants between the steps' ends, on fixed steps: RODAS4's
/// cubic Hermite one is of order 3 (midpoint errors O(h^4)), so its midpoints converge at
/// order 4 with its solution, and RADAU5's, the same interpolant, at order 4 too; Rodas5P's own is of order 4 (O(h^5)), so its midpoints keep
/// the method's order 5, which the Hermite interpolant would cut to 4.
#[test]
fn the_implicit_steppers_interpolants_keep_their_order() {
    fn order<M: Stepper<2>>(make: impl Fn(StepControl<2>) -> M, n: usize) -> f64 {
        let err_at = |n: usize| {
            let ctl = StepControl {
                rtol: 1.0,
                atol: [1.0; 2],
                h_min: 0.0,
                max_attempts: u64::MAX,
                fixed_step: Some(Logistic.t_end() / n as f64),
            };
            let (mut t, mut y) = (0.0, Logistic.y0());
            let mut mid = Midpoints(0.0);
            integrate(
                &Logistic,
                &mut make(ctl),
                &mut t,
                &mut y,
                Logistic.t_end(),
                &mut mid,
            )
            .unwrap();
            mid.0
        };
        (err_at(n) / err_at(2 * n)).log2()
    }
    let (rodas4, rodas5p) = (order(Rodas4::new, 40), order(Rodas5p::new, 20));
    let radau5 = order(Radau5::new, 20);
    println!("midpoint orders: RODAS4 {rodas4:.2}, Rodas5P {rodas5p:.2}, RADAU5 {radau5:.2}");
    assert!((rodas4 - 4.0).abs() < 0.4, "RODAS4: {rodas4:.2}");
    assert!((rodas5p - 5.0).abs() < 0.5, "Rodas5P: {rodas5p:.2}");
    // RADAU5's Hermite interpolant, as RODAS4's: O(h^4) at the midpoints.
    assert!((radau5 - 4.0).abs() < 0.4, "RADAU5: {radau5:.2}");
}

/// Van der Pol's oscillator with stiffness 1e-3: y0' = y1, y1' = ((1 - y0^2) y1 - y0) / 1e-3,
/// a standard stiff test (Hairer and Wanner, IV.10), whose relaxation jumps change the error
/// from step to step.
struct VanDerPol;
const VDP_EPS: f64 = 1e-3;
impl OdeSystem<2> for VanDerPol {
    type Guard = NoGuard;
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[1];
        dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / VDP_EPS;
    }
    fn stiff_jacobian(&self, _t: f64, y: &[f64; 2]) -> Option<StiffJacobian> {
        let mut s = StiffJacobian::over(&[0, 1]);
        s.jac[(0, 1)] = 1.0;
        s.jac[(1, 0)] = (-2.0 * y[0] * y[1] - 1.0) / VDP_EPS;
        s.jac[(1, 1)] = (1.0 - y[0] * y[0]) / VDP_EPS;
        Some(s)
    }
}

/// RADAU5's predictive step-size controller on Van der Pol (to t = 2 from (2, -0.66), rtol =
/// atol = 1e-6): measured 12 rejected steps in 461 with it and 66 in 448 without, so more
/// than 30 says the controller is gone. Its end state agrees with RODAS4's to 1e-5.
#[test]
fn radau5_predicts_the_step_on_van_der_pol() {
    let ctl = StepControl {
        rtol: 1e-6,
        atol: [1e-6; 2],
        h_min: 1e-14,
        max_attempts: 1_000_000,
        fixed_step: None,
    };
    let run = |st: &mut dyn FnMut(&mut f64, &mut [f64; 2]) -> whirlmap_core::ode::Stats| {
        let (mut t, mut y) = (0.0, [2.0, -0.66]);
        let stats = st(&mut t, &mut y);
        assert_eq!(t, 2.0);
        (y, stats)
    };
    let mut radau5 = Radau5::new(ctl);
    let (y, stats) = run(&mut |t, y| {
        integrate(&VanDerPol, &mut radau5, t, y, 2.0, &mut NoObserver).unwrap();
        radau5.stats()
    });
    let mut rodas4 = Rodas4::new(ctl);
    let (y4, _) = run(&mut |t, y| {
        integrate(&VanDerPol, &mut rodas4, t, y, 2.0, &mut NoObserver).unwrap();
        rodas4.stats()
    });
    println!("RADAU5 on Van der Pol: {stats:?}");
    assert!(stats.rejected <= 30, "{stats:?}");
    assert!(
        (y[0] - y4[0]).abs() < 1e-5 && (y[1] - y4[1]).abs() < 1e-5,
        "{y:?} {y4:?}"
    );
}
