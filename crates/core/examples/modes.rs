//! Diagnostic: the modes of the drop model where the BDF steps, and the BDF orders' stability
//! on them (docs/performance.md#the-bdfs-highest-order).
//!
//! `cargo run --release -p whirlmap-core --example modes -- [t=0.51] [rpm=8000] [mu=0.1]
//! [max_order=4]`
//!
//! Runs the drop to the first accepted step ending after `t`, takes the stiff Jacobian at its
//! end (the coupled rotor and race translations and spins), and prints each eigenvalue
//! `lambda` with its undamped frequency `|lambda| / 2 pi`, damping ratio, angle from the
//! negative real axis, and
//! `h |lambda|` for the step just taken; then, for the BDF of orders 1 to 5, the range of
//! `h |lambda|` along that mode's ray where the formula is unstable (a root of
//! `rho(zeta) - z zeta^k` outside the unit circle), on a grid of 0.01 up to 10 (so a range
//! that starts below 0.01 prints as starting at 0.01).
use nalgebra::{Complex, DMatrix};
use std::ops::ControlFlow;
use whirlmap_core::ode::{Observer, OdeSystem, StepView};
use whirlmap_core::*;

/// The first accepted step ending after `at`: its length and the Jacobian at its end.
struct At {
    at: f64,
    found: Option<(f64, f64, DMatrix<f64>)>,
}
impl Observer<model::DropSystem, { model::N }> for At {
    type Halt = std::convert::Infallible;
    fn on_step(
        &mut self,
        sys: &model::DropSystem,
        s: &StepView<'_, { model::N }>,
    ) -> ControlFlow<Self::Halt> {
        let t = s.dense.t1();
        if t <= self.at || self.found.is_some() {
            return ControlFlow::Continue(());
        }
        let sj = sys
            .stiff_jacobian(t, &s.dense.y1())
            .expect("the model has one");
        let n = sj.len;
        let jac = DMatrix::from_fn(n, n, |i, j| sj.jac[(i, j)]);
        self.found = Some((t, t - s.dense.t0(), jac));
        ControlFlow::Continue(())
    }
}

/// The largest root modulus of the BDF of order `k` at `z = h lambda`: the roots of
/// `sum_{j=1..k} (1/j) (zeta - 1)^j zeta^(k-j) - z zeta^k`, from its companion matrix.
fn largest_root(k: usize, z: Complex<f64>) -> f64 {
    let mut c = vec![Complex::new(0.0, 0.0); k + 1];
    for j in 1..=k {
        let mut binom = 1.0;
        for i in 0..=j {
            // (zeta - 1)^j = sum_i C(j, i) zeta^i (-1)^(j - i)
            let sign = if (j - i) % 2 == 0 { 1.0 } else { -1.0 };
            c[k - j + i] += Complex::new(sign * binom / j as f64, 0.0);
            binom = binom * (j - i) as f64 / (i + 1) as f64;
        }
    }
    c[k] -= z;
    let lead = c[k];
    let comp = DMatrix::from_fn(k, k, |i, j| {
        if i == 0 {
            -c[k - 1 - j] / lead
        } else if i == j + 1 {
            Complex::new(1.0, 0.0)
        } else {
            Complex::new(0.0, 0.0)
        }
    });
    comp.eigenvalues()
        .map_or(f64::NAN, |e| e.iter().map(|r| r.norm()).fold(0.0, f64::max))
}

fn main() {
    let mut scene = Scene::paper();
    let mut at = 0.51;
    for a in std::env::args().skip(1) {
        let (k, v) = a.split_once('=').expect("key=value");
        let x: f64 = v.parse().expect("a number");
        match k {
            "t" => at = x,
            "rpm" => scene.speed_rpm = x,
            "mu" => scene.mu_dynamic = x,
            "max_order" => scene.solver.bdf_max_order = x as u32,
            _ => panic!("unknown key {k}"),
        }
    }
    let mut obs = At { at, found: None };
    let opts = DropOptions {
        duration_s: at + 0.01,
        ..Default::default()
    };
    simulate_observed(&scene, &opts, &mut obs).expect("the drop runs");
    let (t, h, jac) = obs.found.expect("a step after t");
    println!("t = {t:.6} s, step h = {h:.3e} s, mode as the drop left it");
    let mut modes: Vec<Complex<f64>> = jac
        .complex_eigenvalues()
        .iter()
        .copied()
        .filter(|l| l.im >= 0.0 && l.norm() > 1.0)
        .collect();
    modes.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    for l in modes {
        let angle = l.im.atan2(-l.re);
        println!(
            "lambda {:>10.4e} {:+.4e}i: |lambda| / 2 pi {:>8.1} Hz, damping ratio {:.2e}, \
             {:.3} deg from the negative real axis, h |lambda| {:.2}",
            l.re,
            l.im,
            l.norm() / std::f64::consts::TAU,
            -l.re / l.norm(),
            angle.to_degrees(),
            h * l.norm()
        );
        for k in 1..=5 {
            let ray = Complex::from_polar(1.0, std::f64::consts::PI - angle);
            let unstable: Vec<f64> = (1..=1000)
                .map(|i| i as f64 * 0.01)
                .filter(|&r| largest_root(k, ray * r) > 1.0 + 1e-9)
                .collect();
            match (unstable.first(), unstable.last()) {
                (Some(a), Some(b)) => {
                    println!("    order {k}: unstable for h |lambda| in [{a:.2}, {b:.2}]")
                }
                _ => println!("    order {k}: stable for h |lambda| up to 10"),
            }
        }
    }
}
