//! The two-entry memo of `DropSystem::forces`: what it returns is exactly what a fresh
//! evaluation gives (every field, bit for bit), a changed mode or thermal load is never served
//! from it, and in a real drop it does serve the repeated step-end and midpoint evaluations.

use std::convert::Infallible;
use std::ops::ControlFlow;
use whirlmap_core::model::{ix, DropSystem, Forces, Mode, ModelEvals, Slip, N};
use whirlmap_core::ode::{Observer, StepView};
use whirlmap_core::{simulate_observed, DropOptions, Scene};

/// Every field of `Forces`, as bits (`Forces` has no `PartialEq`; its `Debug` would hide a
/// difference in a NaN payload).
fn bits(f: &Forces) -> Vec<u64> {
    let mut v = vec![
        f.dist_m,
        f.delta_m,
        f.delta_dot_m_s,
        f.v_rel_m_s,
        f.normal_n,
        f.normal_raw_n,
        f.friction_n,
        f.friction_required_n,
        f.support_n,
        f.support_raw_n,
        f.drag_torque_n_m,
        f.drag_powers.nu0_n_pow_2_3,
        f.drag_powers.load_torque_n_m,
        f.contact_pow,
        f.friction_power_w,
        f.bearing_power_w,
        f.damping_power_w,
    ];
    v.extend(f.n.iter());
    v.extend(f.t.iter());
    v.extend(f.acc);
    v.into_iter().map(f64::to_bits).collect()
}

/// At every accepted step: the step end and midpoint, asked for again through the memo, equal
/// a fresh `forces_in`, and the driver's midpoint value, where it hands one over, is the
/// interpolant's there bit for bit; the counters at the end, less this observer's own requests.
struct Check {
    steps: u64,
    /// Steps with the driver's midpoint value (not cut at an event) and steps without.
    midpoint_given: u64,
    midpoint_absent: u64,
    evals: ModelEvals,
    own_hits: u64,
    own_misses: u64,
}
impl Observer<DropSystem, N> for Check {
    type Halt = Infallible;
    fn on_step(&mut self, sys: &DropSystem, s: &StepView<'_, N>) -> ControlFlow<Infallible> {
        let d = s.dense;
        let tm = 0.5 * (d.t0() + d.t1());
        match s.midpoint {
            Some(ym) => {
                let fresh = d.eval(tm);
                assert!(
                    ym.iter()
                        .zip(&fresh)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "midpoint at t = {tm}: {ym:?} against {fresh:?}"
                );
                self.midpoint_given += 1;
            }
            None => self.midpoint_absent += 1,
        }
        let before = sys.model_evals();
        for y in [d.y1(), d.eval(tm)] {
            assert_eq!(bits(&sys.forces(&y)), bits(&sys.forces_in(&y, sys.mode)));
        }
        let after = sys.model_evals();
        self.own_hits += after.reused - before.reused;
        self.own_misses += after.computed - before.computed;
        self.steps += 1;
        self.evals = after;
        ControlFlow::Continue(())
    }
}

fn drop_checked(scene: &Scene, duration_s: f64) -> Check {
    let mut c = Check {
        steps: 0,
        midpoint_given: 0,
        midpoint_absent: 0,
        evals: ModelEvals::default(),
        own_hits: 0,
        own_misses: 0,
    };
    let opts = DropOptions {
        duration_s,
        ..Default::default()
    };
    simulate_observed(scene, &opts, &mut c).expect("drop runs");
    c
}

#[test]
fn memo_serves_repeats_with_the_exact_values_along_real_drops() {
    // A pendulum drop (impacts, slipping, sticking) and a whirl drop, explicit and implicit.
    let mut whirl = Scene::paper();
    whirl.mu_dynamic = 0.4;
    let mut ros = Scene::paper();
    ros.solver.method = whirlmap_core::scene::Method::Ros34pw2;
    for (scene, dur) in [(Scene::paper(), 0.2), (whirl, 0.03), (ros, 0.2)] {
        let c = drop_checked(&scene, dur);
        assert!(c.steps > 100);
        // Only the steps cut at an event (the impacts and mode switches) lack the driver's
        // midpoint value.
        assert!(c.midpoint_absent > 0 && c.midpoint_given > 10 * c.midpoint_absent);
        // Without this observer's own requests: the step end is asked for by the driver's
        // guards and the monitor after the stepper computed it, the midpoint by the guards
        // and then the monitor (in contact), so the drop itself reuses at least one
        // evaluation per step.
        let reused = c.evals.reused - c.own_hits;
        let computed = c.evals.computed - c.own_misses;
        assert!(reused >= c.steps, "{reused} reused for {} steps", c.steps);
        assert!(computed > c.steps);
    }
}

#[test]
fn a_new_mode_or_thermal_load_is_never_served_from_the_memo() {
    let scene = Scene::paper();
    let mut sys = DropSystem::new(&scene);
    let mut y = sys.initial_state(scene.spin_rad_s());
    // The rotor pressed into the race, sliding, with a race that moves and spins.
    y[ix::YR] = y[ix::YB] - scene.clearance_m - 2e-6;
    y[ix::VXR] = 0.05;
    y[ix::VYR] = -0.02;
    y[ix::VXB] = 0.01;
    y[ix::WB] = 100.0;
    let slipping = Mode {
        contact: true,
        support: true,
        slip: Slip::Slipping(1.0),
    };
    sys.mode = slipping;
    let a = sys.forces(&y);
    assert_eq!(sys.model_evals().computed, 1);
    assert_eq!(bits(&sys.forces(&y)), bits(&a));
    assert_eq!(sys.model_evals().reused, 1);
    assert!(a.normal_n > 0.0 && a.friction_n != 0.0);

    // Sticking at the same state: a different friction force, computed afresh.
    sys.mode = Mode {
        slip: Slip::Sticking,
        ..slipping
    };
    let b = sys.forces(&y);
    assert_eq!(sys.model_evals().computed, 2);
    assert_eq!(bits(&b), bits(&sys.forces_in(&y, sys.mode)));
    assert_ne!(bits(&b), bits(&a));

    // The thermal load changes the drag torque (eq. 31): not served either.
    sys.mode = slipping;
    sys.thermal_load_n = 500.0;
    let c = sys.forces(&y);
    assert_eq!(sys.model_evals().computed, 3);
    assert_eq!(bits(&c), bits(&sys.forces_in(&y, slipping)));
    assert_ne!(c.drag_torque_n_m.to_bits(), a.drag_torque_n_m.to_bits());

    // A state one ulp away is a different state.
    let mut y2 = y;
    y2[ix::XR] = f64::from_bits(y2[ix::XR].to_bits() + 1);
    sys.forces(&y2);
    assert_eq!(sys.model_evals().computed, 4);
}
